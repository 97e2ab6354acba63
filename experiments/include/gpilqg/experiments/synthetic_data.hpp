#pragma once
/// @file synthetic_data.hpp
/// Synthetic measurement sets: roll a system out under random excitation with process noise (the
/// paper's dx = f dt + F dw) and record it with Gaussian observation noise, in the measurement contract
/// of docs/formats.md#measurement-data-csv-and-hdf5. This is how the test suite and the tutorials make
/// "real-world" data with a known ground truth.

#include <cstdint>
#include <stdexcept>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/measurements.hpp"

namespace gpilqg {

struct ExcitationSettings {
  int episodes = 5;             ///< number of episodes
  int steps = 200;              ///< samples per episode (T); the last sample's control is still recorded
  double dt = 0.02;             ///< sampling step [s]
  int substeps = 10;            ///< RK4 sub-steps per sample: the "real world" is integrated finely
  Vector nominal_state;         ///< centre of the initial states (empty: zero)
  Vector initial_spread;        ///< half-width of the uniform initial-state spread (empty: zero)
  Vector nominal_control;       ///< centre of the excitation (empty: zero)
  Vector control_amplitude;     ///< half-width of the uniform excitation (empty: one per control)
  int hold_steps = 5;           ///< each random control level is held for this many samples
  Vector observation_std;       ///< std of Gaussian noise added to each recorded state (empty: none)
  std::uint64_t seed = 1;       ///< the same seed gives the same data, bit for bit
  /// The world applies the command of this many control periods earlier (input_delay.hpp); the data
  /// record the commands.
  double input_delay = 0.0;

  /// Throws std::invalid_argument naming the field when a value or a size is invalid.
  void validate(int n, int m) const;
};

/// Per-system defaults that keep an open-loop excitation in a meaningful region: the cart-pole
/// starts near hanging with +-5 N excitation; the quadrotor starts near (0, 0, 5) with hover thrust
/// plus +-10% excitation for short episodes.
ExcitationSettings default_excitation(const Dynamics& system);

/// Simulates the episodes. Process noise comes from the system's noise model. An episode that
/// diverges (non-finite state) is cut at its last finite sample and reported in the returned count;
/// the set never contains a non-finite number.
struct SyntheticData {
  MeasurementSet set;
  int truncated_episodes = 0;
};
/// Throws ExcitationDiverged when every episode diverges before its second sample (nothing to
/// record): the settings (dt, control_amplitude) drive the system out at once. Its message names no
/// setting, so that each caller names its own way to change them (`simulate`: --dt).
SyntheticData simulate_measurements(const DynamicsPtr& system, const ExcitationSettings& settings);

struct ExcitationDiverged : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

}  // namespace gpilqg
