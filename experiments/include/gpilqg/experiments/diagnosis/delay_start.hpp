#pragma once
/// @file delay_start.hpp
/// Where the fit of `input_delay` starts: the lag of the peak cross-correlation between the input
/// response the data show and the one the model predicts.
///
/// With u_ref the mean measured input, the model's input response at row t is
/// p_t = phi(x_t, u_t) - phi(x_t, u_ref), and the measured one is m_t = x_{t+1} - phi(x_t, u_ref):
/// the part of the step the model's unforced motion does not explain. A system that applies its input
/// d periods late has m_t ~ p_{t-d}, so the weighted cross-correlation
///
///   rho(l) = sum_t <W m_t, p_{t-l}> / sqrt(sum_t |W^1/2 m_t|^2 sum_t |W^1/2 p_{t-l}|^2),
///
/// summed over the training rows of each episode with t - l in the same episode, peaks at l = d. The
/// start is argmax_{0 <= l <= max_lag} rho(l), a whole number of periods; the fit refines it to a
/// fraction. The lags span the delay's whole range, 0 to kMaxInputDelay periods: a delay beyond the
/// lags searched is not found from any start (a 45-period delay at 1 kHz came out as 4.5 from lags
/// up to 20, and an actuator gain of 0.007 "explained" the data better).

#include "gpilqg/core/input_delay.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// The lag in [0, max_lag] of the peak of rho (0 when no lag correlates positively).
int input_delay_start(const FitContext& context, int max_lag = static_cast<int>(kMaxInputDelay));

}  // namespace gpilqg::diagnosis
