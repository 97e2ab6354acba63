#pragma once
/// @file moment_matcher.hpp
/// The one interface PDDP's belief dynamics (gp_belief_dynamics.hpp) propagates through: exact moment
/// matching of E independent zero-mean GP outputs f_a(z) under a Gaussian input z ~ N(mu, Sigma)
/// (D inputs), with analytic derivatives with respect to mu and Sigma. Implementations:
///
///   SeArdMomentMatcher (moment_matching.hpp)       SE-ARD kernel sums over centres: the exact GP
///                                                  (shared training inputs) and FITC (each output
///                                                  its own pseudo-inputs)
///   SsgpMomentMatcher (ssgp_moment_matching.hpp)   trigonometric features: the sparse spectrum GP
///
/// and moment_matcher_for (fitted_moment_matcher.hpp) builds the right one from fitted backends.
///
/// Moments (every implementation):
///   M_a  = E[m_a(z)]                                          mean of the posterior mean m_a (E)
///   S_ab = Cov[m_a(z), m_b(z)] + delta_ab E[v_a(z)]           (E x E), v_a the latent variance
///   C_:a = Cov[z, m_a(z)] = Sigma E[grad m_a(z)]              (D x E, Stein's lemma)
/// S is the covariance of the latent f(z) (GP variance without the noise sn^2, as in PILCO's gp0).
///
/// Sigma: only its symmetric part sym(Sigma) = (Sigma + Sigma') / 2 is read, and the moments are
/// defined as functions of sym(Sigma) for any square Sigma. Consequently the derivatives with respect
/// to the entries Sigma_ij (treated as D^2 independent numbers) satisfy d/dSigma_ij = d/dSigma_ji, and
/// a perturbation of one entry alone moves sym(Sigma) by half of it in (i, j) and in (j, i).
/// A caller whose covariance is parameterised by packed entries p_ij (i <= j, one number setting both
/// Sigma_ij and Sigma_ji) must add the two: d/dp_ij = d/dSigma_ij + d/dSigma_ji (= 2 d/dSigma_ij) for
/// i != j, and d/dp_ii = d/dSigma_ii.
///
/// Derivative layout (all column-major vec, as Eigen stores matrices):
///   dmean_dmu         E x D       (a, d)                 = d M_a / d mu_d
///   dmean_dsigma      E x D*D     (a, i + D j)           = d M_a / d Sigma_ij
///   dcovariance_dmu   E*E x D     (a + E b, d)           = d S_ab / d mu_d
///   dcovariance_dsigma E*E x D*D  (a + E b, i + D j)     = d S_ab / d Sigma_ij
///   dcross_dmu        D*E x D     (k + D a, d)           = d C_ka / d mu_d
///   dcross_dsigma     D*E x D*D   (k + D a, i + D j)     = d C_ka / d Sigma_ij
/// i.e. row r of a d.../dsigma block reshaped column-major to D x D is the (symmetric) gradient matrix
/// of one output entry.
///
/// Identities every implementation satisfies (and the code uses): dM_a/dSigma = 1/2 d^2 M_a/dmu^2
/// (the heat equation of the Gaussian expectation), C_:a = Sigma dM_a/dmu.
///
/// Threading and allocation: a matcher is immutable after construction and may be shared between
/// threads; each thread uses its own MomentMatch, which may also lend the call helper threads
/// (MomentMatch::threads). After the first call with a given MomentMatch (and the same matcher and
/// thread count), propagate does not allocate.

#include <string_view>
#include <vector>

#include <Eigen/Cholesky>

#include "gpilqg/core/fork_join.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg::gp {

/// Which derivatives propagate computes.
enum class MomentDerivatives {
  None,  ///< moments only (M, S, C); derivative blocks keep their previous contents
  All,   ///< moments and all six derivative blocks (w.r.t. mu and Sigma)
};

/// The buffers one worker of an SE-ARD propagation (moment_matching*.cpp) uses for the output or the
/// pair of outputs it is working on; room for the largest N, used through views. Internal.
struct MomentMatchWorkerScratch {
  Eigen::LLT<Matrix> llt;                ///< factor of the current scaled matrix Rt (D x D)
  Matrix rt, rt_inverse, xi, gain, pair_precision, dd, dd2, inner;  ///< D x D
  Matrix pair_shrink, delta_a, delta_b;                            ///< D x D, derivatives only
  Matrix nd, nd2;                                                  ///< room for N_max x D
  Vector row_term, col_term, row_sums, col_sums;                   ///< room for N_max
  Matrix nn;                             ///< blocks of expm1(D), then Omega, of one pair (room for N_max x N_max)
  Matrix omega_v;                        ///< Omega V_b of one pair (room for N_max x D), derivatives only
  Matrix outer;                          ///< t_ni t_nj (room for N_max x D*D), derivatives only
  Matrix third;                          ///< sum_n gamma_n (Sigma t_n)_k t_ni t_nj (D x D*D), derivatives only
  Vector sqrt_w_pair, lengthscale_pair, dvec, dvec2;               ///< D
};

/// Scratch space of one SE-ARD propagation (moment_matching.cpp), sized on first use. Internal: the
/// contents are unspecified. Per-output entries have N_a rows (that output's centres) and are written
/// by the worker that owns the output; `workers` holds one MomentMatchWorkerScratch per worker.
struct MomentMatchScratch {
  Matrix sigma;                          ///< sym(Sigma) (D x D)
  std::vector<Matrix> centred;           ///< V_a = X_a - 1 mu' (N_a x D) per output
  std::vector<Matrix> precision;         ///< P_a = (Sigma + Lambda_a)^-1 (D x D) per output
  std::vector<Matrix> precision_lambda;  ///< P_a Lambda_a (D x D) per output
  std::vector<Matrix> solved;            ///< T_a = V_a P_a (N_a x D) per output
  std::vector<Matrix> scaled;            ///< A_a = V_a W_a (N_a x D) per output
  std::vector<Matrix> hessian;           ///< H_a = T_a' diag(gamma_a) T_a - M_a P_a (D x D) per output
  std::vector<Vector> weighted;          ///< gamma_a = beta_a .* q_a (N_a) per output
  std::vector<Vector> kernel_mean;       ///< q_a (N_a) per output
  std::vector<Vector> log_shift;         ///< c_ai = 1/2 nu_i' B_a nu_i (N_a) per output
  std::vector<Matrix> shrink;            ///< B_a = W_a - P_a = W_a^1/2 (I - Rt_a^-1) W_a^1/2 (D x D) per output
  std::vector<Vector> gradient;          ///< g_a = dM_a/dmu = T_a' gamma_a (D) per output
  std::vector<Vector> scaled_sum;        ///< u_a = A_a' gamma_a (D) per output, derivatives only
  std::vector<Matrix> scaled_scatter;    ///< E_a = A_a' diag(gamma_a) A_a (D x D) per output, derivatives only
  Vector log_det;                        ///< log|Rt_a| (E)
  std::vector<MomentMatchWorkerScratch> workers;  ///< one per worker thread
};

/// Scratch space of one SSGP propagation (ssgp_moment_matching.cpp), sized on first use. Internal:
/// the contents are unspecified. Per-output entries have m_a rows (that output's frequencies); the
/// pair buffers have room for the largest m and are used through views.
struct SsgpMomentScratch {
  Matrix sigma;                     ///< sym(Sigma) (D x D)
  std::vector<Matrix> projected;    ///< T_a = S_a Sigma (m_a x D) per output
  std::vector<Vector> cosine;       ///< c_a = cos(S_a mu) (m_a) per output
  std::vector<Vector> sine;         ///< n_a = sin(S_a mu) (m_a) per output
  std::vector<Vector> half_spread;  ///< 1/2 s_r' Sigma s_r (m_a) per output
  std::vector<Vector> damping;      ///< e_a = exp(-1/2 s_r' Sigma s_r) (m_a) per output
  std::vector<Vector> in_phase;     ///< gamma_a = alpha_c .* c + alpha_s .* n (m_a) per output
  std::vector<Vector> quadrature;   ///< eta_a = alpha_c .* n - alpha_s .* c (m_a) per output
  std::vector<Vector> mean_features;  ///< E[phi_a] = [e .* c; e .* n] (2 m_a) per output
  std::vector<Vector> gradient;     ///< g_a = dM_a/dmu (D) per output
  Matrix kappa, cosh_part, sinh_part, plain;  ///< s_r' Sigma s_q, and e^L (cosh - 1), e^L sinh, e^L (room for m_max^2)
  Matrix wx, wy, wz, wz2, work;     ///< weights X, Y, Z, Z' of one pair and a product buffer (room for m_max^2)
  Vector rows, cols, vm, vm2;       ///< room for m_max (vm, vm2: 2 m_max)
  Matrix dm, dm2;                   ///< room for m_max x D
  Matrix outer;                     ///< s_ri s_rj (room for m_max x D*D), derivatives only
  Matrix third;                     ///< D x D*D, derivatives only
  Matrix dd, dd2;                   ///< D x D
  Vector dvec;                      ///< D
};

/// Result of one propagation; reuse it across calls (it holds the scratch space).
struct MomentMatch {
  Vector mean;                   ///< M (E)
  Matrix covariance;             ///< S (E x E), symmetric
  Matrix cross_covariance;       ///< C = Cov[z, f(z)] (D x E)
  bool has_derivatives = false;  ///< whether the blocks below belong to the last call
  Matrix dmean_dmu;              ///< E x D
  Matrix dmean_dsigma;           ///< E x D*D
  Matrix dcovariance_dmu;        ///< E*E x D
  Matrix dcovariance_dsigma;     ///< E*E x D*D
  Matrix dcross_dmu;             ///< D*E x D
  Matrix dcross_dsigma;          ///< D*E x D*D
  MomentMatchScratch scratch;    ///< SeArdMomentMatcher's
  SsgpMomentScratch ssgp_scratch;  ///< SsgpMomentMatcher's
  /// Threads one propagation may use (>= 1; the caller's choice). SeArdMomentMatcher shares the
  /// outputs, then the pairs of outputs, among them when the N x N pair matrices are large enough
  /// to repay the hand-off (SsgpMomentMatcher ignores it); the results do not depend on it.
  int threads = 1;
  ForkJoin fork_join;            ///< the helper threads, started on the first call that uses them
};

/// Exact moment matching of E GP outputs under a Gaussian input (see the file comment).
class MomentMatcher {
 public:
  virtual ~MomentMatcher() = default;

  virtual int input_dim() const = 0;   ///< D
  virtual int output_dim() const = 0;  ///< E

  /// Moments of f(z), z ~ N(mu, Sigma), into `out` (resized as needed), and their derivatives when
  /// asked for. mu: D; Sigma: D x D (only its symmetric part is read; see the file comment).
  /// Throws std::invalid_argument when a size is wrong, mu or Sigma has a non-finite entry, Sigma is
  /// outside the implementation's domain (e.g. too far from positive semidefinite), or (overflow) a
  /// result would not be finite: no NaN is ever returned. After a throw, `out` holds unspecified
  /// values and has_derivatives is false; it can be reused.
  void propagate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out,
                 MomentDerivatives derivatives = MomentDerivatives::None) const;

 protected:
  /// The class name, for error messages ("SeArdMomentMatcher").
  virtual std::string_view name() const = 0;
  /// The moments (and derivatives when `derivatives`) into `out`, whose result blocks propagate has
  /// already sized; mu and Sigma are checked for size and finiteness.
  virtual void evaluate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out, bool derivatives) const = 0;
};

}  // namespace gpilqg::gp
