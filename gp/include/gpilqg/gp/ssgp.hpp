#pragma once
/// @file ssgp.hpp
/// Sparse spectrum GP (SSGP) of Lazaro-Gredilla, Quinonero-Candela, Rasmussen and Figueiras-Vidal
/// (2010, JMLR 11), with the conventions of the authors' ssgpr.m.
///
/// Model (paper, sec. 2 and eqs. 5-8): m spectral points w_r (rows of W, m x D, unscaled), frequencies
/// s_r = w_r ./ l, features phi(x) = [cos(S x); sin(S x)] (2m), and
///
///   f(x) = phi(x)' a,   a ~ N(0, sf2/m I_2m),   y_i = f(x_i) + noise_i, noise_i ~ N(0, sn2 + v_i),
///
/// which approximates the SE ARD kernel sf2 exp(-0.5 sum_d (x_d - z_d)^2 / l_d^2) by its Monte Carlo
/// spectral estimate (sf2/m) sum_r cos(s_r'(x - z)) (Bochner's theorem; exact as m -> infinity when
/// w_r ~ N(0, I)). sn2 is learned; v_i >= 0 is a noise variance known per point
/// (TrainingSet::noise_variance), 0 when none is given (ssgpr.m's model). The GP layer is zero-mean:
/// targets are residuals (prior_mean.hpp).
///
/// Parameter vector (hyperparameters.hpp): theta = [log l (D); log sf; log sn; vec(W) (m*D,
/// column-major)]. The spectral points are optimised jointly with the hyperparameters.
///
/// Cost: one NLML with its gradient is O(N m^2 + N m D) (one rank-N update Phi'Phi, one N x 2m by
/// 2m x 2m product), O(N m) memory. A prediction with gradients is O(m D + m^2).

#include <memory>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

/// Index layout of the packed SSGP parameter vector.
struct SsgpLayout {
  int input_dim = 0;    ///< D
  int frequencies = 0;  ///< m (2m features)

  int size() const { return input_dim + 2 + frequencies * input_dim; }
  /// Offset of vec(W); entry (r, d) of W is at spectral_offset() + d * m + r.
  int spectral_offset() const { return input_dim + 2; }

  /// [hyperparameters (D + 2); vec(W)] (throws std::invalid_argument on a size mismatch).
  Vector pack(const VectorCRef& hyper, const MatrixCRef& spectral_points) const;
  /// The m x D unscaled spectral points W of a packed vector.
  Matrix spectral_points(const VectorCRef& theta) const;
  /// The layout of a vector of `size` entries for D inputs; throws std::invalid_argument when no
  /// m >= 1 fits.
  static SsgpLayout from_size(int size, int input_dim);
};

class SsgpPredictor;

/// The SSGP negative log marginal likelihood (ssgpr.m; paper eq. 8), extended to known noise variances
/// v_i: with u_i = sn2 / (sn2 + v_i) (U = diag(u), U = I without known noise), a = m sn2/sf2,
/// A = Phi'U Phi + a I = L L' (2m x 2m), b = Phi'U r, alpha = A^-1 b:
///
///   nlml = (r'U r - b'alpha) / (2 sn2) + sum(log diag L) - m log a + 1/2 sum_i log(sn2 + v_i) + N/2 log(2 pi).
///
/// This is the Gaussian nlml of y ~ N(0, (sf2/m) Phi Phi' + diag(sn2 + v_i)) in weight space: with
/// the noise precisions Wn = diag(1/(sn2 + v_i)) = U / sn2, the weights' posterior precision is
/// Sigma_w^-1 = Phi'Wn Phi + (m/sf2) I = A / sn2 and their mean Sigma_w Phi'Wn r = alpha. Without known
/// noise it is ssgpr.m's nlml, N/2 log(2 pi sn2) being the last two terms.
///
/// Gradient (our derivation, in ssgp_likelihood.cpp; e = r - Phi alpha, h_i = phi_i'A^-1 phi_i):
///   dnlml/dPhi     = Gamma = U (Phi A^-1 - e alpha' / sn2)                          (N x 2m)
///   dnlml/dz_ir    = Gamma_{i,m+r} cos(z_ir) - Gamma_{i,r} sin(z_ir),  z = X S'   (N x m)
///   dnlml/dS       = (dnlml/dz)' X,   dnlml/dW = dnlml/dS ./ l',
///   dnlml/dlog l_d = -sum_r (dnlml/dS)_rd S_rd,
///   dnlml/da       = alpha'alpha / (2 sn2) + tr(A^-1)/2 - m/a,
///   dnlml/dlog sf  = -2a dnlml/da,
///   dnlml/dlog sn  = sum_i u_i - (r'U r - b'alpha)/sn2 + 2a dnlml/da
///                    + sum_i u_i (1 - u_i) (e_i^2 / sn2 + h_i)
/// (without known noise: N - (r'r - b'alpha)/sn2 + 2a dnlml/da). Escalated jitter (JitterSchedule,
/// relative to N/2, the mean of diag(Phi'Phi) and a bound on that of diag(Phi'U Phi), a constant) is
/// added to the ridge a in A only, so the gradient stays exact for the value returned.
///
/// Immutable once built and shareable between threads: the O(N m) scratch of an evaluation lives in the
/// caller's workspace (make_workspace()).
class SsgpLikelihood {
 public:
  /// X: N x D inputs, r: N targets, `frequencies`: m >= 1. `threads` > 1 splits the O(N m^2) work
  /// over blocks of training points (at least 500 points per thread; same results up to the order
  /// of a few sums). `noise_variance`: the known noise variances v (N values >= 0), or empty for none
  /// (TrainingSet::noise_variance). Throws std::invalid_argument on empty or non-finite data,
  /// mismatched sizes, m < 1, threads < 1, an invalid schedule or invalid known noise variances.
  SsgpLikelihood(const MatrixCRef& X, const VectorCRef& r, int frequencies, JitterSchedule schedule = {},
                 int threads = 1, const VectorCRef& noise_variance = Vector());

  const SsgpLayout& layout() const { return layout_; }
  int parameter_count() const { return layout_.size(); }

  /// nlml at theta; fills `gradient` (resized to parameter_count()) when not null. Never NaN: a
  /// non-finite theta or a failed factorisation gives status Failed, +infinity and a zero gradient.
  /// Throws std::invalid_argument only for a wrongly sized theta.
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient, LikelihoodWorkspace& workspace) const;
  /// The same with a temporary workspace.
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient = nullptr) const;
  /// A workspace for evaluate(), sized on first use and reused after.
  std::unique_ptr<LikelihoodWorkspace> make_workspace() const;

  /// The cached posterior at theta and the conditioning report. Throws std::runtime_error when no
  /// factorisation is possible even with the largest jitter.
  SsgpPredictor predictor(const VectorCRef& theta, ConditioningReport* report = nullptr) const;

 private:
  struct Workspace;
  /// Factorises at theta into `w`; the returned status is Failed when impossible.
  NlmlEvaluation factorise(const VectorCRef& theta, Workspace& w) const;

  Matrix X_;
  Vector r_;
  Vector known_;  ///< v: N known noise variances, or empty
  SsgpLayout layout_;
  JitterSchedule schedule_;
  int threads_ = 1;
};

/// The fitted SSGP posterior (ssgpr.m's prediction), cached so that one query is O(m D + m^2):
///
///   mu(x) = phi(x)' alpha,   s2(x) = max(phi(x)' C phi(x), 0),   C = sn2 A^-1 = Sigma_w,
///
/// alpha and C the posterior mean and covariance of the weights (SsgpLikelihood: with known noise
/// variances, A = Phi'U Phi + a I and C = (Phi' diag(1/(sn2 + v_i)) Phi + (m/sf2) I)^-1),
///   dmu/dx = S' (alpha_s .* cos(z) - alpha_c .* sin(z)),  ds2/dx = 2 S' (c_s .* cos(z) - c_c .* sin(z)),
///
/// with z = S x, c = C phi(x), and _c / _s the cosine and sine halves. s2 is the latent variance.
class SsgpPredictor {
 public:
  SsgpPredictor() = default;

  int input_dim() const { return static_cast<int>(S_.cols()); }
  int frequencies() const { return static_cast<int>(S_.rows()); }
  /// The scaled frequencies S = W ./ l' (m x D).
  const Matrix& frequency_matrix() const { return S_; }
  const Vector& alpha() const { return alpha_; }
  /// C = sn2 A^-1 = Sigma_w (2m x 2m, symmetric): s2(x) = phi(x)' C phi(x).
  const Matrix& variance_matrix() const { return C_; }

  /// Latent mean at x (D entries) and, for each non-null pointer, the variance, d mean / dx and
  /// d variance / dx (D doubles each). Scratch owned by the caller (no allocation): phi receives the
  /// 2m features, c receives C phi (2m doubles).
  void predict(const VectorCRef& x, double* phi, double* c, double& mean, double* variance = nullptr,
               double* dmean = nullptr, double* dvariance = nullptr) const;

 private:
  friend class SsgpLikelihood;
  Matrix S_;      ///< m x D
  Vector alpha_;  ///< 2m
  Matrix C_;      ///< 2m x 2m, symmetric
};

/// The posterior of `model` when it is a fitted SSGP ("ssgp"), else nullptr: what moment matching
/// (ssgp_moment_matching.hpp) reads. The pointer lives as long as `model`.
const SsgpPredictor* ssgp_posterior(const FittedGp& model);

/// Options of the SSGP backend.
struct SsgpOptions {
  int frequencies = 100;   ///< m, the number of spectral points (2m features)
  int initial_draws = 50;  ///< W ~ N(0, I) draws tried at the initial hyperparameters; the best is kept
  int threads = 1;         ///< threads for one NLML evaluation (>= 1; see SsgpLikelihood)
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// The SSGP backend ("ssgp"). objective(): SsgpLikelihood with bounds (hyperparameter_bounds; W
/// unbounded) and initial values (initial_hyperparameters and the best of `initial_draws` random W
/// with FitOptions::seed). condition(): m is read from the parameter vector's length. Both take the
/// training set's known noise variances (TrainingSet::noise_variance) into the likelihood and the
/// posterior.
class SsgpBackend final : public GpBackend {
 public:
  explicit SsgpBackend(SsgpOptions options = {});
  std::string_view name() const override { return "ssgp"; }
  bool takes_known_noise() const override { return true; }
  const SsgpOptions& options() const { return options_; }

  std::unique_ptr<MarginalLikelihoodObjective> objective(const TrainingSet& data,
                                                         const FitOptions& options) const override;
  std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters,
                                      const JitterSchedule& jitter = {}) const override;

 private:
  SsgpOptions options_;
};

}  // namespace gpilqg::gp
