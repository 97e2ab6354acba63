#pragma once
/// @file whiteness.hpp
/// The residual whiteness test of system identification: is the one-step residual of the held-out
/// episodes white, or is there time structure left that a better model would predict?
///
/// Autocorrelation, within episodes. With r~ = r - mean(r) over the N held-out samples,
///
///   rho(k) = sum_{(t, t+k) in one episode} r~_t r~_{t+k} / sum_t r~_t^2,   k = 0..L,
///
/// so rho(0) = 1 and a pair of samples from two episodes never counts (the end of one episode says
/// nothing about the start of the next). n_k = sum_e max(0, T_e - k) is the number of pairs at lag k.
///
/// Band. For white noise rho(k), k >= 1, is approximately N(0, n_k / N^2), with n_k <= N; the usual
/// 95% band is +-1.96 / sqrt(N) (MATLAB `resid`, Ljung 1999 section 16.6), slightly conservative when
/// the samples come from several episodes. About 5% of the lags fall outside it by chance.
///
/// Decision: the Ljung-Box portmanteau test at level alpha = 5%,
///
///   Q = N (N + 2) sum_{k=1..L, n_k > 0} rho(k)^2 / n_k   ~  chi-square(d)  for white noise,
///
/// d the number of lags with n_k > 0 (one episode: n_k = N - k, the textbook Q). The residual is
/// `white` when Q <= chi2_{0.95}(d), i.e. p = P(chi2(d) > Q) >= 0.05. No degree of freedom is taken
/// away for fitted parameters: the held-out episodes were not used to fit the model. Why this and not
/// "at most 5% of the L lags outside the band": with L = 20 that rule allows one lag outside, and
/// white noise puts two or more outside with probability 1 - 0.95^20 - 20 0.05 0.95^19 = 26%, so it
/// would call a quarter of white residuals coloured; Q has its stated 5% false-alarm rate and pools
/// the evidence of many small correlations. The count outside the band is reported beside it.
///
/// Reading it. The one-step residual of even the true model is not white when the states are measured
/// with noise: r_t = e_{t+1} - A e_t + w_t (e the observation noise, A = d phi / d x near the identity
/// for a small dt) is a moving average with rho(1) near -1/2 where the observation noise dominates. A
/// coloured residual says the one-step errors are predictable from the past; whether from missing
/// physics or from the noise is what the noise floor and the GP (residual_analysis.hpp) decide. The
/// verdict does not use this test.

#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

/// rho(k), k = 0..max_lag, of `series` (rows in time order within each episode; episode[t] the episode
/// of row t, the rows of one episode contiguous). All zeros when the series is constant; 0 at lags
/// without pairs. Throws std::invalid_argument for max_lag < 0 or mismatched sizes.
Vector autocorrelation(const VectorCRef& series, const std::vector<int>& episode, int max_lag);

/// n_k, k = 0..max_lag: pairs (t, t + k) of rows of one episode.
std::vector<long> lag_pairs(const std::vector<int>& episode, int max_lag);

/// Ljung-Box Q of an autocorrelation (rho(0) first) with its pair counts and N.
double ljung_box(const VectorCRef& autocorrelation, const std::vector<long>& pairs, long samples);

struct StateWhiteness {
  std::string name;
  Vector autocorrelation;     ///< L + 1 values, lag 0 first
  int outside_band = 0;       ///< lags 1..L with |rho(k)| > band
  double ljung_box = 0.0;     ///< Q
  double p_value = 1.0;       ///< P(chi2(d) > Q)
  bool white = true;          ///< Q <= critical_value (p >= level)
};

struct Whiteness {
  int max_lag = 0;            ///< L
  long samples = 0;           ///< N, held-out residual samples
  int degrees_of_freedom = 0; ///< d, lags 1..L with at least one pair
  double band = 0.0;          ///< 1.96 / sqrt(N) (1.96 when N = 0)
  double level = 0.05;        ///< alpha of the Ljung-Box test
  double critical_value = 0.0;  ///< chi2_{1 - alpha}(d) (0 when d = 0)
  std::vector<StateWhiteness> states;
};

/// The test on every state's residual over the held-out rows of `data` (data.rows(true)).
/// `residual` is N_all x n (every row of data), `names` the n state names. Never NaN: a zero residual
/// is white with Q = 0, p = 1.
Whiteness whiteness_test(const Transitions& data, const Matrix& residual, const std::vector<std::string>& names,
                         int max_lag, double level = 0.05);

}  // namespace gpilqg::diagnosis
