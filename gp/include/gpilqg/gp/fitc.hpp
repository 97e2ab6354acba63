#pragma once
/// @file fitc.hpp
/// FITC / SPGP: the sparse pseudo-input Gaussian process of Snelson and Ghahramani (2006), with the
/// ARD squared exponential kernel (kernel.hpp) and GPML 4.2's conventions (infFITC / apxSparse).
///
/// Model (Snelson & Ghahramani 2006, eqs. 5-9; Quinonero-Candela & Rasmussen 2005, sec. 6):
///
///   Kuu = k(Xu, Xu) + snu2 I (M x M),  Kuf = k(Xu, X) (M x N),  Qff = Kfu Kuu^-1 Kuf,
///   Lambda = diag( max(diag(Kff - Qff), 0) ) + sn2 I + diag(v),  r ~ N(0, Qff + Lambda),
///   (v: the noise variances known per training point, TrainingSet::noise_variance; zero when none),
///
/// where r are the targets (the GP layer is zero-mean: a prior mean has been subtracted, see
/// prior_mean.hpp). The jitter snu2 follows GPML's rule snu2 = 1e-6 trace(Kuu)/M = 1e-6 sf2, which
/// scales with sf2 and so enters d/dlog sf, or is a fixed value (FitcJitter).
///
/// Parameter vector (hyperparameters.hpp): theta = [log l (D); log sf; log sn; vec(Xu) (M*D,
/// column-major)]. The pseudo-inputs are optimised jointly with the hyperparameters.
///
/// Cost: one NLML with its full gradient (hyperparameters and all M*D pseudo-input coordinates) is
/// O(N M^2 + N M D) time, six O(N M^2) BLAS-3-like products, O(N M) memory; no N x N matrix and no
/// per-parameter N x M temporary. A prediction with gradients is O(M D + M^2).

#include <cstdint>
#include <memory>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

/// How the jitter snu2 on the diagonal of Kuu is chosen.
enum class FitcJitterKind {
  Relative,  ///< snu2 = value * trace(Kuu)/M = value * sf2 (GPML 4.2's rule with value = 1e-6)
  Fixed,     ///< snu2 = value, independent of the hyperparameters
};

/// The jitter rule. Default: GPML's, snu2 = 1e-6 trace(Kuu)/M. It is part of the model (the NLML and
/// its gradient include it); the escalating JitterSchedule only adds to it when Kuu still fails.
struct FitcJitter {
  FitcJitterKind kind = FitcJitterKind::Relative;
  double value = 1e-6;  ///< relative factor or absolute snu2; finite and >= 0

  static FitcJitter gpml() { return {}; }
  static FitcJitter fixed(double snu2) { return {FitcJitterKind::Fixed, snu2}; }
  /// snu2 for signal variance sf2 (for the SE kernel trace(Kuu)/M = sf2).
  double jitter(double sf2) const { return kind == FitcJitterKind::Relative ? value * sf2 : value; }
  /// Throws std::invalid_argument naming the value.
  void validate() const;
};

/// Index layout of the packed FITC parameter vector.
struct FitcLayout {
  int input_dim = 0;  ///< D
  int inducing = 0;   ///< M

  int size() const { return input_dim + 2 + inducing * input_dim; }
  /// Offset of vec(Xu); entry (m, d) of Xu is at inducing_offset() + d * M + m.
  int inducing_offset() const { return input_dim + 2; }

  /// [hyperparameters (D + 2); vec(Xu)] (throws std::invalid_argument on a size mismatch).
  Vector pack(const VectorCRef& hyper, const MatrixCRef& inducing_inputs) const;
  /// The M x D pseudo-inputs of a packed vector.
  Matrix inducing_inputs(const VectorCRef& theta) const;
  /// The layout of a parameter vector of `size` entries for D inputs (M = (size - D - 2) / D);
  /// throws std::invalid_argument when no M >= 1 fits.
  static FitcLayout from_size(int size, int input_dim);
};

class FitcPredictor;

/// The FITC negative log marginal likelihood (GPML infFITC) of one data set:
///
///   nlZ = 0.5 r' (Qff + Lambda)^-1 r + 0.5 log|Qff + Lambda| + N/2 log(2 pi)
///       = 0.5 r' alpha + sum(log diag La) + 0.5 sum(log Lambda) + N/2 log(2 pi),
///
/// with Kuu = Luu Luu', V = Luu^-1 Kuf, A = I + V Lambda^-1 V' = La La', gamma = A^-1 V Lambda^-1 r
/// and alpha = Lambda^-1 (r - V' gamma) = (Qff + Lambda)^-1 r (matrix inversion lemma).
///
/// The gradient is a chain rule through three adjoints, dnlZ/dKuf (M x N), dnlZ/dKuu (M x M) and
/// dnlZ/ddiag(Kff), contracted with the kernel's derivatives as matrix products (derivation in
/// fitc_likelihood.cpp). Entries clipped by max(., 0) contribute no gradient (the derivative of the
/// clipped function). Escalated jitter is proportional to sf2 (JitterSchedule is relative to the
/// mean diagonal sf2), and the gradient accounts for it, so the gradient is exact for the value
/// returned in every case.
///
/// Immutable once built and shareable between threads: the O(N M) scratch of an evaluation lives in the
/// caller's workspace (make_workspace()).
class FitcLikelihood {
 public:
  /// X: N x D training inputs, r: N targets, `inducing`: M >= 1. `threads` > 1 splits the O(N M^2)
  /// work over blocks of training points (at least 500 points per thread; same results up to the
  /// order of a few sums). Throws std::invalid_argument on empty or non-finite data, mismatched
  /// sizes, M < 1, threads < 1, or an invalid jitter rule or schedule.
  ///
  /// `known_noise` (N entries, or empty for none): a noise variance v_i known at each training point
  /// (TrainingSet::noise_variance), added to the learned sn2 in Lambda_ii = max(Kff_ii - Qff_ii, 0) +
  /// sn2 + v_i. FITC's Lambda is diagonal already, so the known part changes neither the structure nor
  /// the gradient's formulas: d Lambda_ii / d sn2 = 1 as before, and v is constant.
  FitcLikelihood(const MatrixCRef& X, const VectorCRef& r, int inducing, FitcJitter jitter = {},
                 JitterSchedule schedule = {}, int threads = 1, const Vector& known_noise = {});

  const FitcLayout& layout() const { return layout_; }
  int parameter_count() const { return layout_.size(); }
  const FitcJitter& jitter_rule() const { return jitter_; }

  /// nlZ at theta; fills `gradient` (resized to parameter_count()) when not null. Never NaN: a
  /// non-finite theta or a failed factorisation gives status Failed, value +infinity and a zero
  /// gradient. Throws std::invalid_argument only for a wrongly sized theta.
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient, LikelihoodWorkspace& workspace) const;
  /// The same with a temporary workspace.
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient = nullptr) const;
  /// A workspace for evaluate(), sized on first use and reused after.
  std::unique_ptr<LikelihoodWorkspace> make_workspace() const;

  /// The cached posterior at theta, and the conditioning report. Throws std::runtime_error when no
  /// factorisation is possible even with the largest jitter.
  FitcPredictor predictor(const VectorCRef& theta, ConditioningReport* report = nullptr) const;

 private:
  struct Workspace;
  /// Factorises at theta into `w`; the returned status is Failed when impossible.
  NlmlEvaluation factorise(const VectorCRef& theta, Workspace& w) const;

  Matrix X_;
  Vector r_;
  Vector known_noise_;  ///< v_i, N entries (zeros when none was given)
  Vector centre_;  ///< mean of X: inputs are centred internally (the kernel is stationary)
  FitcLayout layout_;
  FitcJitter jitter_;
  JitterSchedule schedule_;
  int threads_ = 1;
};

/// The fitted FITC posterior, cached so that one query costs O(M D + M^2):
///
///   mu(x)  = k_u(x)' beta,                     beta = Sigma^-1 Kuf Lambda^-1 r = Luu^-T gamma,
///   s2(x)  = max(sf2 + k_u(x)' C k_u(x), 0),   C = Sigma^-1 - Kuu^-1 = Luu^-T (A^-1 - I) Luu^-1,
///
/// with Sigma = Kuu + Kuf Lambda^-1 Kfu (Snelson & Ghahramani 2006, eq. 8; GPML gp.m with infFITC's
/// post.alpha and post.L = C). mu is the zero-mean GP's latent mean, s2 the latent variance.
/// Gradients (d k_u,m / dx = k_u,m (xu_m - x) ./ l^2):
///   dmu/dx = (Xu' (beta .* k) - x (beta' k)) ./ l^2,   ds2/dx = 2 (Xu' (c .* k) - x (c' k)) ./ l^2,
/// with c = C k; ds2/dx = 0 where s2 was clamped at 0.
class FitcPredictor {
 public:
  FitcPredictor() = default;

  int input_dim() const { return static_cast<int>(inv_lengthscale_.size()); }
  int inducing() const { return static_cast<int>(inducing_inputs_.rows()); }
  double signal_variance() const { return sf2_; }
  const Matrix& inducing_inputs() const { return inducing_inputs_; }
  const Vector& beta() const { return beta_; }
  const Matrix& variance_matrix() const { return C_; }

  /// Latent mean at x (D entries) and, for each non-null pointer, the variance, d mean / dx and
  /// d variance / dx (D doubles each). Scratch owned by the caller (no allocation): k receives
  /// k(Xu, x) (M doubles), c receives C k (M doubles), xs the scaled input x ./ l (D doubles).
  void predict(const VectorCRef& x, double* k, double* c, double* xs, double& mean,
               double* variance = nullptr, double* dmean = nullptr, double* dvariance = nullptr) const;

 private:
  friend class FitcLikelihood;
  Vector inv_lengthscale_;  ///< 1 / l (D)
  double sf2_ = 0.0;
  Matrix inducing_inputs_;  ///< Xu (M x D)
  Matrix scaled_inducing_;  ///< Xu ./ l' (M x D)
  Vector beta_;             ///< M
  Matrix C_;                ///< M x M, symmetric
};

/// The posterior of `model` when it is a fitted FITC GP ("fitc"), else nullptr: what moment matching
/// (moment_matching.hpp, per-output centres) reads. The pointer lives as long as `model`.
const FitcPredictor* fitc_posterior(const FittedGp& model);

/// How the pseudo-inputs are initialised.
enum class FitcInitialisation {
  KMeans,        ///< k-means++ seeding (Arthur & Vassilvitskii 2007), then Lloyd iterations
  RandomSubset,  ///< a uniform random subset of the training inputs
};

/// M pseudo-inputs for the inputs X (N x D): the rows are compared after dividing column d by
/// scale(d) (the initial length-scales). k-means++ picks the first centre uniformly and each further
/// one with probability proportional to the squared distance to the nearest centre chosen; then
/// `kmeans_iterations` Lloyd steps move every centre to the mean of its points (a centre left
/// without points stays). Returns all N inputs when M >= N. Deterministic for a given seed.
Matrix initial_pseudo_inputs(const MatrixCRef& X, int M, const VectorCRef& scale, FitcInitialisation method,
                             std::uint64_t seed, int kmeans_iterations = 10);

/// Options of the FITC backend.
struct FitcOptions {
  int inducing = 100;  ///< M, the number of pseudo-inputs (min(M, N) are used)
  FitcJitter jitter = FitcJitter::gpml();
  FitcInitialisation initialisation = FitcInitialisation::KMeans;
  int kmeans_iterations = 10;          ///< Lloyd steps after the k-means++ seeding (>= 0)
  bool optimise_pseudo_inputs = true;  ///< false: pseudo-inputs stay at their initial values
  int threads = 1;                     ///< threads for one NLML evaluation (>= 1; see FitcLikelihood)
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// The FITC backend ("fitc"). objective(): FitcLikelihood with bounds (hyperparameter_bounds; each
/// pseudo-input coordinate within the data's range widened by that range on both sides) and initial
/// values (initial_hyperparameters, pseudo-inputs from initial_pseudo_inputs with FitOptions::seed).
/// condition(): M is read from the parameter vector's length, so a saved model loads with any
/// FitcOptions::inducing (the jitter rule must match the one used for fitting).
class FitcBackend final : public GpBackend {
 public:
  explicit FitcBackend(FitcOptions options = {});
  std::string_view name() const override { return "fitc"; }
  bool takes_known_noise() const override { return true; }
  const FitcOptions& options() const { return options_; }

  std::unique_ptr<MarginalLikelihoodObjective> objective(const TrainingSet& data,
                                                         const FitOptions& options) const override;
  std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters,
                                      const JitterSchedule& jitter = {}) const override;

 private:
  FitcOptions options_;
};

}  // namespace gpilqg::gp
