#pragma once
/// @file motion_period.hpp
/// The period of a measured motion from its zero crossings with hysteresis: what the simulation
/// criterion's window is measured in (criterion_choice.hpp).
///
/// Signal. One state column (a velocity: it oscillates about zero even when the position drifts),
/// sampled in several episodes at a common step dt. In each episode the column is centred on its
/// mean.
///
/// Hysteresis. A crossing is counted when the centred signal, having been below -b, rises above +b,
/// or having been above +b, falls below -b: half a period of an oscillation. The band is
/// b = 3 sigma_hat, sigma_hat the white-noise level of the column from its differences
/// (difference_noise_std, derivative_window.hpp), so noise alone almost never crosses the band twice
/// in opposite directions (a sample beyond 3 sigma has probability 0.13% on either side), whatever the
/// units and the sampling rate.
///
/// Period. With c_e crossings in episode e, the first at sample s_e and the last at sample l_e,
///
///   P = 2 dt sum_e (l_e - s_e) / sum_e (c_e - 1),
///
/// twice the mean spacing of consecutive crossings, pooled over the episodes with at least two. A
/// column whose centred values never leave the band (the pooled standard deviation is below b) does
/// not move beyond its noise: it is "still" and has no period. A column that moves but crosses fewer
/// than twice in every episode is slower than its longest episode: its period is +infinity.
///
/// Assumptions: an oscillation about a mean that is steady within an episode (a slow drift of a
/// velocity's mean lengthens the period), and a light enough decay that the oscillation stays above
/// the band for a few periods.

#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg::diagnosis {

struct MotionPeriod {
  int state = -1;          ///< the state column
  bool still = false;      ///< never beyond the band: no motion to measure
  double period = 0.0;     ///< P [s]; +infinity when slower than every episode; 0 when still
  long crossings = 0;      ///< crossings counted over all episodes
  double band = 0.0;       ///< b = 3 sigma_hat (units of the state)
};

/// The period of state column `state` of `data` (file comment). Episodes with fewer than 3 samples
/// are left out of the noise estimate. Throws std::invalid_argument for a column outside the state or
/// a set without episodes.
MotionPeriod motion_period(const MeasurementSet& data, int state);

}  // namespace gpilqg::diagnosis
