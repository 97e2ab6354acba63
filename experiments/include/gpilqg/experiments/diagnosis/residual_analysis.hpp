#pragma once
/// @file residual_analysis.hpp
/// What the one-step residuals r_t = x_{t+1} - phi(x_t, u_t) of a model say: fit scores, the noise
/// floor and the structure a GP finds in them, and where (in time and in the state-input space) they are
/// large.
///
/// Noise floor. A GP per state on z = [x; u] (gp::ResidualModel, fitted on the training episodes) splits
/// the residual into a smooth function of z and white noise; its noise standard deviation sn_i is the
/// part no function of the measured state and input can predict: observation noise, process noise and
/// unresolved disturbances. That is the floor a model can reach on these data.
///
/// Structure. The GP's mean predicts the residual of the held-out episodes; the fraction of held-out
/// squared residual it removes, 1 - sum (r - mu)^2 / sum r^2, is the structure left in the model's error.
///
/// Relevance of input j for the residual of state i: the sensitivity
///   S_ij = mean_t |d mu_i / d z_j (z_t)| std(z_j),
/// the typical change of the predicted residual over one standard deviation of input j (length-scales
/// alone mislead: a short length-scale on an input along which the function has no amplitude says
/// nothing). `relevance` normalises each row to sum 1.

#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/step_model.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::diagnosis {

/// 100 (1 - |y - yhat| / |y - mean(y)|) with Euclidean norms over the samples. 100 when y is constant
/// and predicted exactly, 0 when y is constant and not; never NaN.
double fit_percent(const VectorCRef& y, const VectorCRef& y_hat);
/// Root mean square of the entries of `values` at `rows` (all rows when empty); 0 for no rows.
double rms(const VectorCRef& values, const std::vector<int>& rows = {});

/// GP settings of the residual analysis.
struct GpSettings {
  std::string backend = "exact";  ///< gp::make_backend name
  int points = 300;               ///< training subsample (exact) / inducing points / frequencies
  int restarts = 1;               ///< random restarts of the hyperparameter fit
  int threads = 2;                ///< outputs fitted concurrently
  std::uint64_t seed = 1;
};

/// A GP per state fitted to the training residuals, with its predictions at every transition.
struct ResidualGp {
  std::shared_ptr<const gp::ResidualModel> model;
  Vector noise_std;        ///< n, sn_i: the noise floor of state i's one-step residual
  Vector signal_variance;  ///< n, sf_i^2: the variance of the learned residual function
  Matrix mean;             ///< N x n, latent mean at every transition
  Matrix variance;         ///< N x n, latent variance at every transition
};

/// Fits the GPs on the training rows of (data, residual) around `simulator` (the model whose residual
/// it is) and predicts at every row.
ResidualGp fit_residual_gp(std::shared_ptr<const StepModel> simulator, const Transitions& data, const Matrix& residual,
                           const GpSettings& settings);

/// The latent mean at every row (N x c) of one GP per column of `targets` (N x c, any residual: a
/// generalised-force residual as well as a state residual), each fitted on the training rows with the
/// inputs (x_t, u_t) and `settings`: the flexible model of the remainder test under the
/// inverse-dynamics criterion (diagnosis.cpp). `left_out` (N x c, or null): entries that are not
/// equations of the criterion (a coordinate at standstill, InverseDynamicsCriterion): column i's GP is
/// not trained on them and its mean there is 0, as the target is, so they add nothing to a score of
/// target - mean. Throws std::invalid_argument for degenerate columns.
Matrix gp_column_means(const Transitions& data, const Matrix& targets, const GpSettings& settings,
                       const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>* left_out = nullptr);

/// Held-out structure per state: 1 - sum (r - mu)^2 / sum r^2 over held-out rows (0 when r is 0).
Vector gp_explained(const ResidualGp& gp, const Transitions& data, const Matrix& residual);

/// Raw sensitivities S (n x (n + m)) over the rows `rows` (at most `max_points`, evenly strided).
Matrix gp_sensitivity(const ResidualGp& gp, const Transitions& data, const std::vector<int>& rows, int max_points = 300);

/// Residual RMS of every state in quantile bins of one input.
struct BinnedResidual {
  std::string input;         ///< name of z_j
  Vector edges;              ///< bins + 1 edges (quantiles of z_j over all rows)
  Matrix rms;                ///< n x bins, residual RMS of state i in bin b (0 for an empty bin)
  std::vector<int> count;    ///< rows per bin
};
/// One entry per input z = [x; u], `bins` quantile bins each (ties can leave a bin empty).
std::vector<BinnedResidual> bin_residuals(const Transitions& data, const Matrix& residual,
                                          const std::vector<std::string>& input_names, int bins);

/// Normalised cross-correlation of the residual of state i with control j,
///   rho_ij(tau) = sum_t r~_i(t) u~_j(t - tau) / sqrt(sum r~_i^2 sum u~_j^2),  tau = -L..L,
/// with r~, u~ the de-meaned series and the sums taken within episodes only. tau > 0: the input leads.
/// The 95% band for "no correlation" is Bartlett's: 1.96 sqrt(sum_{k=-L}^{L} rho_rr(k) rho_uu(k) / N),
/// which widens the white-noise band 1.96 / sqrt(N) when both series are autocorrelated (a piecewise
/// constant excitation is).
struct CrossCorrelation {
  int max_lag = 0;
  /// values[i][j]: 2L + 1 entries, lag -L first.
  std::vector<std::vector<Vector>> values;
  Matrix band;         ///< n x m
  Matrix max_abs;      ///< n x m, max_tau |rho_ij(tau)|
};
CrossCorrelation cross_correlation(const Transitions& data, const Matrix& residual, int max_lag);

/// Residual RMS per episode (rows: episodes in file order, columns: states).
Matrix episode_rms(const Transitions& data, const Matrix& residual, int episodes);

}  // namespace gpilqg::diagnosis
