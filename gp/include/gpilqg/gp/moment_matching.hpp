#pragma once
/// @file moment_matching.hpp
/// Exact moment matching of a multi-output SE-ARD Gaussian process under a Gaussian input, with
/// analytic derivatives with respect to the input's mean and covariance, as the belief dynamics of
/// PDDP (Pan & Theodorou, "Probabilistic Differential Dynamic Programming", NIPS 2014). The moments are
/// PILCO's (Deisenroth, Fox & Rasmussen, "Gaussian Processes for Data-Efficient Learning in Robotics
/// and Control", TPAMI 2015, the moment-matching long-term predictions; Deisenroth's thesis "Efficient
/// Reinforcement Learning using Gaussian Processes", KIT 2010); the derivatives are derived here (see
/// the two source files) and checked against central differences in tests/gp/moment_matching_test.cpp.
///
/// Model. E outputs, each an independent zero-mean GP on the same N training inputs x_i (rows of X,
/// N x D) with the SE-ARD kernel
///
///   k_a(x, x') = sf_a^2 exp(-1/2 (x - x')' W_a (x - x')),   W_a = Lambda_a^-1 = diag(1 / l_a^2),
///
/// weights beta_a = (K_a + sn_a^2 I)^-1 y_a (N) and Kinv_a = (K_a + sn_a^2 I)^-1 (N x N).
/// The test input is z ~ N(mu, Sigma) (D, D x D). With nu_i = x_i - mu:
///
///   mean        M_a = beta_a' q_a,
///               q_ai = sf_a^2 |Sigma W_a + I|^-1/2 exp(-1/2 nu_i' (Sigma + Lambda_a)^-1 nu_i)
///   covariance  S_ab = beta_a' Q_ab beta_b - M_a M_b + delta_ab (sf_a^2 - tr(Kinv_a Q_aa)),
///               Q_ab,ij = k_a(x_i, mu) k_b(x_j, mu) |R|^-1/2 exp(1/2 z_ij' R^-1 Sigma z_ij),
///               R = Sigma (W_a + W_b) + I,  z_ij = W_a nu_i + W_b nu_j
///   cross-cov.  C_:a = Cov[z, f_a(z)] = Sigma (Sigma + Lambda_a)^-1 sum_i beta_ai q_ai nu_i   (D x E)
///
/// S is the covariance of the latent f(z) (GP variance without the noise sn^2, as in PILCO's gp0).
///
/// Evaluation (documented in moment_matching.cpp): every determinant and inverse comes from the
/// Cholesky factor of a scaled matrix Rt = W^1/2 Sigma W^1/2 + I (W = W_a, or W_a + W_b for a pair),
/// whose eigenvalues are >= 1 for a PSD Sigma, so a singular Sigma (e.g. zero rows and columns for
/// deterministic controls, or Sigma = 0) is fine.
///
/// S is never formed as beta_a' Q_ab beta_b - M_a M_b: with nearly noise-free data (sn ~ 1e-3 std y)
/// |beta| reaches 1e4..1e6 and that difference of two O(|beta|^2) numbers loses every digit (negative
/// variances, off-diagonals ~1e-4 at Sigma = 0). Instead (moment_matching_covariance.cpp)
///
///   Q_ab,ij = q_ai q_bj exp(D_ij),   D_ij = log Q_ab,ij - log q_ai - log q_bj   (D = 0 at Sigma = 0),
///   S_ab    = beta_a' (Q_ab - q_a q_b') beta_b + delta_ab V_a,
///             (Q_ab - q_a q_b')_ij = q_ai q_bj expm1(D_ij),
///   V_a     = max(0, sf_a^2 - q_a' Kinv_a q_a - <Kinv_a, Q_aa - q_a q_a'>)  (= E[latent variance]),
///
/// with D_ij assembled directly from O(Sigma) terms (never as a difference of logs or exponentials),
/// so at Sigma = 0 the off-diagonal entries are exactly 0 and V_a is the plain latent variance
/// sf^2 - k(mu)' Kinv k(mu). V_a can be no more accurate than Kinv allows: one rounding of each entry
/// of Kinv already moves k' Kinv k by up to eps |k|' |Kinv| |k| (~1e-9 sf^2 when K + sn^2 I has a
/// condition number ~1e9); the clamp at 0 keeps that rounding from making S indefinite, and where it
/// acts V_a's derivatives are 0.
///
/// Sigma: only its symmetric part sym(Sigma) = (Sigma + Sigma') / 2 is read, and the moments are
/// defined as functions of sym(Sigma) for any square Sigma. Consequently the derivatives with respect
/// to the entries Sigma_ij (treated as D^2 independent numbers) satisfy d/dSigma_ij = d/dSigma_ji, and
/// a perturbation of one entry alone moves sym(Sigma) by half of it in (i, j) and in (j, i).
/// A caller whose covariance is parameterised by packed entries p_ij (i <= j, one number setting both
/// Sigma_ij and Sigma_ji) must add the two: d/dp_ij = d/dSigma_ij + d/dSigma_ji (= 2 d/dSigma_ij) for
/// i != j, and d/dp_ii = d/dSigma_ii.
/// Sigma need not be positive semidefinite (finite differences step to slightly negative variances),
/// but every Rt must be positive definite; otherwise propagate throws.
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
/// Cost per call (N training points, D inputs, E outputs), dominated by the E(E+1)/2 output pairs,
/// each of which needs an N x N matrix of exponentials:
///   moments only      E(E+1)/2 (2 N^2 D flops (one GEMM) + N^2 expm1 (N^2/2 when a = b)) + E O(N D^2)
///   with derivatives  adds E(E+1)/2 (2 N^2 D flops (one more GEMM) + O(N^2)) + E O(N D^3)
/// The derivatives with respect to Sigma cost no more than the moments: d log Q_ij / dSigma is
/// -1/2 P + 1/2 y_ij y_ij' with y_ij = G (W_a nu_i + W_b nu_j) affine in separate i and j terms, so
/// sum_ij Omega_ij y_ij y_ij' reduces to V' diag(r) V, V' diag(c) V and V' Omega V (V = X - 1 mu').
/// Without derivatives, most of the time goes into expm1 and the GEMM
/// (bench/moment_matching_bench.cpp has the figures).
///
/// Threading and allocation: SeArdMomentMatcher is immutable after construction and may be shared
/// between threads; each thread uses its own MomentMatch. After the first call with a given
/// MomentMatch (and the same matcher dimensions), propagate does not allocate.

#include <cstddef>
#include <vector>

#include <Eigen/Cholesky>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp {

/// One output of the moment matcher: SE-ARD hyperparameters and the conditioned GP weights.
struct SeArdOutput {
  Vector log_lengthscales;      ///< log l_d (D)
  double log_signal_std = 0.0;  ///< log sf
  Vector beta;                  ///< (K + sn^2 I)^-1 y (N)
  Matrix Kinv;                  ///< (K + sn^2 I)^-1 (N x N); only its product with symmetric Q_aa is used
};

/// Conditions one SE-ARD GP on (inputs (N x D), targets (N)): builds K + sn^2 I with the kernel above,
/// factorises it (Cholesky) and returns beta and Kinv. A convenience for callers that hold raw data and
/// hyperparameters. Throws std::invalid_argument on mismatched sizes, non-finite values, or when
/// K + sn^2 I is not numerically positive definite (increase the noise).
SeArdOutput condition_se_ard_output(const MatrixCRef& inputs, const VectorCRef& targets,
                                    const VectorCRef& log_lengthscales, double log_signal_std,
                                    double log_noise_std);

/// Which derivatives propagate computes.
enum class MomentDerivatives {
  None,  ///< moments only (M, S, C); derivative blocks keep their previous contents
  All,   ///< moments and all six derivative blocks (w.r.t. mu and Sigma)
};

/// Scratch space of one propagation, sized on first use. Internal: the contents are unspecified.
struct MomentMatchScratch {
  Matrix sigma;                          ///< sym(Sigma) (D x D)
  Matrix centred;                        ///< V = X - 1 mu' (N x D)
  std::vector<Matrix> precision;         ///< P_a = (Sigma + Lambda_a)^-1 (D x D) per output
  std::vector<Matrix> precision_lambda;  ///< P_a Lambda_a (D x D) per output
  std::vector<Matrix> solved;            ///< T_a = V P_a (N x D) per output
  std::vector<Matrix> scaled;            ///< A_a = V W_a (N x D) per output
  std::vector<Matrix> hessian;           ///< H_a = T_a' diag(gamma_a) T_a - M_a P_a (D x D) per output
  std::vector<Vector> weighted;          ///< gamma_a = beta_a .* q_a (N) per output
  std::vector<Vector> kernel_mean;       ///< q_a (N) per output
  std::vector<Vector> log_shift;         ///< c_ai = 1/2 nu_i' B_a nu_i (N) per output
  std::vector<Matrix> shrink;            ///< B_a = W_a - P_a = W_a^1/2 (I - Rt_a^-1) W_a^1/2 (D x D) per output
  std::vector<Vector> gradient;          ///< g_a = dM_a/dmu = T_a' gamma_a (D) per output
  std::vector<Vector> scaled_sum;        ///< u_a = A_a' gamma_a (D) per output, derivatives only
  std::vector<Matrix> scaled_scatter;    ///< E_a = A_a' diag(gamma_a) A_a (D x D) per output, derivatives only
  Vector log_det;                        ///< log|Rt_a| (E)
  Eigen::LLT<Matrix> llt;                ///< factor of the current scaled matrix Rt (D x D)
  Matrix rt, rt_inverse, xi, gain, pair_precision, dd, dd2, inner;  ///< D x D
  Matrix pair_shrink, delta_a, delta_b;                            ///< D x D, derivatives only
  Matrix nd, nd2;                                                  ///< N x D
  Vector row_term, col_term, row_sums, col_sums;                   ///< N
  Matrix nn;                             ///< D, expm1(D), then Omega of one pair (N x N)
  Matrix outer;                          ///< t_ni t_nj (N x D*D), derivatives only
  Matrix third;                          ///< sum_n gamma_n (Sigma t_n)_k t_ni t_nj (D x D*D), derivatives only
  Vector sqrt_w_pair, lengthscale_pair, dvec, dvec2;               ///< D
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
  MomentMatchScratch scratch;
};

/// Moment matching of E SE-ARD GP outputs sharing the training inputs X. See the file comment.
class SeArdMomentMatcher {
 public:
  /// X: training inputs (N x D, N >= 1, D >= 1); outputs: E >= 1 entries with log_lengthscales of
  /// size D, beta of size N and Kinv of size N x N, all finite. Throws std::invalid_argument naming
  /// the offending field (e.g. "outputs[2].beta") otherwise.
  SeArdMomentMatcher(Matrix inputs, std::vector<SeArdOutput> outputs);

  int input_dim() const { return static_cast<int>(inputs_.cols()); }
  int output_dim() const { return static_cast<int>(outputs_.size()); }
  int training_size() const { return static_cast<int>(inputs_.rows()); }

  /// Moments of f(z), z ~ N(mu, Sigma), into `out` (resized as needed), and their derivatives when
  /// asked for. mu: D; Sigma: D x D (only its symmetric part is read; see the file comment).
  /// Throws std::invalid_argument when a size is wrong, mu or Sigma has a non-finite entry, Sigma is
  /// too far from positive semidefinite for some Rt to be positive definite, or (overflow) a result
  /// would not be finite: no NaN is ever returned. After a throw, `out` holds unspecified values and
  /// has_derivatives is false; it can be reused.
  void propagate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out,
                 MomentDerivatives derivatives = MomentDerivatives::None) const;

 private:
  struct OutputData {
    Vector inverse_squared_lengthscales;  ///< w_a = 1 / l_a^2 (D)
    Vector sqrt_w;                        ///< sqrt(w_a) = 1 / l_a (D)
    Vector lengthscales;                  ///< l_a (D)
    double log_signal_variance = 0.0;     ///< log sf_a^2
    double signal_variance = 0.0;         ///< sf_a^2
    Vector beta;
    Matrix Kinv;
  };

  void prepare(MomentMatch& out, bool derivatives) const;
  /// Factorises Rt = diag(s) Sigma diag(s) + I into scratch.llt and returns log|Rt|; scratch.rt_inverse
  /// receives Rt^-1. Outputs a and b (a == b: one output) name the matrix in the error message.
  double factor_scaled(MomentMatchScratch& scratch, const Vector& s, std::size_t a, std::size_t b) const;
  void propagate_mean(MomentMatch& out, bool derivatives) const;
  void propagate_covariance(MomentMatch& out, bool derivatives) const;
  void cross_covariance_derivatives(MomentMatch& out, std::size_t a) const;

  Matrix inputs_;
  std::vector<OutputData> outputs_;
};

}  // namespace gpilqg::gp
