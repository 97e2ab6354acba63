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
/// Model. E outputs, each an independent zero-mean GP with the SE-ARD kernel
///
///   k_a(x, x') = sf_a^2 exp(-1/2 (x - x')' W_a (x - x')),   W_a = Lambda_a^-1 = diag(1 / l_a^2),
///
/// whose posterior mean and latent variance are kernel sums over output a's own N_a centres x_ai
/// (rows of X_a, N_a x D):
///
///   m_a(z) = beta_a' k_a(X_a, z),   v_a(z) = sf_a^2 - k_a(X_a, z)' Kinv_a k_a(X_a, z).
///
/// The exact GP: X_a = the training inputs, beta_a = (K_a + sn_a^2 I)^-1 y_a, Kinv_a =
/// (K_a + sn_a^2 I)^-1 (all outputs share X). FITC (fitc.hpp): X_a = output a's pseudo-inputs Xu_a
/// (M x D), beta_a = (Kuu + Kuf Lambda^-1 Kfu)^-1 Kuf Lambda^-1 r and Kinv_a = Kuu^-1 -
/// (Kuu + Kuf Lambda^-1 Kfu)^-1 (Kuu with its jitter): FitcPredictor's beta and -C.
/// The test input is z ~ N(mu, Sigma) (D, D x D). With nu_ai = x_ai - mu:
///
///   mean        M_a = beta_a' q_a,
///               q_ai = sf_a^2 |Sigma W_a + I|^-1/2 exp(-1/2 nu_ai' (Sigma + Lambda_a)^-1 nu_ai)
///   covariance  S_ab = beta_a' Q_ab beta_b - M_a M_b + delta_ab (sf_a^2 - tr(Kinv_a Q_aa)),
///               Q_ab,ij = k_a(x_ai, mu) k_b(x_bj, mu) |R|^-1/2 exp(1/2 z_ij' R^-1 Sigma z_ij)   (N_a x N_b),
///               R = Sigma (W_a + W_b) + I,  z_ij = W_a nu_ai + W_b nu_bj
///   cross-cov.  C_:a = Cov[z, f_a(z)] = Sigma (Sigma + Lambda_a)^-1 sum_i beta_ai q_ai nu_ai   (D x E)
///
/// Nothing in the derivation (PILCO's, and the derivatives in the two source files) needs the two
/// outputs of a pair to share centres: Q_ab is N_a x N_b, and every sum over i runs over output a's
/// centres, over j over output b's. Shared inputs are the special case X_a = X for all a, at the same
/// cost (the centred V_a = X_a - 1 mu' is formed per output either way, O(E N D), against the
/// O(E^2 N^2 D) of the pairs).
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
/// The Sigma convention (only sym(Sigma) is read) and the derivative layout are MomentMatcher's
/// (moment_matcher.hpp). Sigma need not be positive semidefinite (finite differences step to slightly
/// negative variances), but every Rt must be positive definite; otherwise propagate throws.
///
/// Cost per call (N centres per output, D inputs, E outputs), dominated by the E(E+1)/2 output pairs,
/// each of which needs an N x N matrix of exponentials:
///   moments only      E(E+1)/2 (2 N^2 D flops (one GEMM) + N^2 expm1 (N^2/2 when a = b)) + E O(N D^2)
///   with derivatives  adds E(E+1)/2 (2 N^2 D flops (one more GEMM) + O(N^2)) + E O(N D^3)
/// The derivatives with respect to Sigma cost no more than the moments: d log Q_ij / dSigma is
/// -1/2 P + 1/2 y_ij y_ij' with y_ij = G (W_a nu_i + W_b nu_j) affine in separate i and j terms, so
/// sum_ij Omega_ij y_ij y_ij' reduces to V_a' diag(r) V_a, V_b' diag(c) V_b and V_a' Omega V_b
/// (V_a = X_a - 1 mu').
/// Without derivatives, most of the time goes into expm1 and the GEMM
/// (bench/moment_matching_bench.cpp has the figures).
///
/// Threading and allocation: as every MomentMatcher (moment_matcher.hpp). With MomentMatch::threads
/// > 1 the outputs and then the output pairs are dealt out to the threads (ForkJoin); each writes
/// only its own entries, so the results are bit for bit those of one thread.

#include <cstddef>
#include <string_view>
#include <utility>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp {

/// One output of the moment matcher: SE-ARD hyperparameters and the conditioned GP weights over its
/// N_a centres.
struct SeArdOutput {
  Vector log_lengthscales;      ///< log l_d (D)
  double log_signal_std = 0.0;  ///< log sf
  Vector beta;                  ///< exact GP: (K + sn^2 I)^-1 y (N_a)
  Matrix Kinv;                  ///< exact GP: (K + sn^2 I)^-1 (N_a x N_a); only its product with symmetric Q_aa is used
};

/// Conditions one SE-ARD GP on (inputs (N x D), targets (N)): builds K + sn^2 I with the kernel above,
/// factorises it (Cholesky) and returns beta and Kinv. A convenience for callers that hold raw data and
/// hyperparameters. Throws std::invalid_argument on mismatched sizes, non-finite values, or when
/// K + sn^2 I is not numerically positive definite (increase the noise).
SeArdOutput condition_se_ard_output(const MatrixCRef& inputs, const VectorCRef& targets,
                                    const VectorCRef& log_lengthscales, double log_signal_std,
                                    double log_noise_std);

/// Moment matching of E SE-ARD GP outputs, each over its own centres X_a (or all over shared X).
/// See the file comment.
class SeArdMomentMatcher final : public MomentMatcher {
 public:
  /// Shared centres. X: training inputs (N x D, N >= 1, D >= 1); outputs: E >= 1 entries with
  /// log_lengthscales of size D, beta of size N and Kinv of size N x N, all finite. Throws
  /// std::invalid_argument naming the offending field (e.g. "outputs[2].beta") otherwise.
  SeArdMomentMatcher(Matrix inputs, std::vector<SeArdOutput> outputs);
  /// Per-output centres: centres[a] (N_a x D, the same D for all) belongs to outputs[a] (beta of size
  /// N_a, Kinv N_a x N_a). Throws std::invalid_argument naming the field (e.g. "centres[1]") otherwise.
  /// (Pass a std::vector<Matrix>: a braced list {X0, X1} would also match Eigen's initializer-list
  /// Matrix constructor of the shared form.)
  SeArdMomentMatcher(std::vector<Matrix> centres, std::vector<SeArdOutput> outputs);

  int input_dim() const override { return input_dim_; }
  int output_dim() const override { return static_cast<int>(outputs_.size()); }
  /// N_a, the number of centres of output a.
  int training_size(int output) const { return static_cast<int>(outputs_.at(static_cast<std::size_t>(output)).centres.rows()); }

 protected:
  std::string_view name() const override { return "SeArdMomentMatcher"; }
  void evaluate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out, bool derivatives) const override;

 private:
  struct OutputData {
    Matrix centres;                       ///< X_a (N_a x D)
    Vector inverse_squared_lengthscales;  ///< w_a = 1 / l_a^2 (D)
    Vector sqrt_w;                        ///< sqrt(w_a) = 1 / l_a (D)
    Vector lengthscales;                  ///< l_a (D)
    double log_signal_variance = 0.0;     ///< log sf_a^2
    double signal_variance = 0.0;         ///< sf_a^2
    Vector beta;
    Matrix Kinv;
  };

  /// The constructors' common part: validates `outputs` against `centres` (already checked) and
  /// stores both; `shared` only words the messages ("rows of inputs").
  void build(std::vector<Matrix> centres, std::vector<SeArdOutput> outputs, bool shared);
  /// Sizes `out` for this matcher (the worker buffers for `workers` workers).
  void prepare(MomentMatch& out, bool derivatives, int workers) const;
  /// How many of `threads` one propagation uses: 1 unless the pair matrices are large enough
  /// (pair_work_ >= kParallelPairWork) to repay handing work to a helper thread, and never more than
  /// there are pairs.
  int workers_for(int threads) const;
  /// Factorises Rt = diag(s) Sigma diag(s) + I into worker.llt and returns log|Rt|; worker.rt_inverse
  /// receives Rt^-1. Outputs a and b (a == b: one output) name the matrix in the error message.
  double factor_scaled(const Matrix& sigma, MomentMatchWorkerScratch& worker, const Vector& s, std::size_t a,
                       std::size_t b) const;
  /// Output a's moments M_a, C_:a (and derivatives), and the per-output quantities the pairs use.
  void propagate_mean(MomentMatch& out, std::size_t a, MomentMatchWorkerScratch& worker, const VectorCRef& mu,
                      bool derivatives) const;
  /// S_ab = S_ba (and derivatives) of the pair a <= b (moment_matching_covariance.cpp).
  void propagate_covariance(MomentMatch& out, std::size_t a, std::size_t b, MomentMatchWorkerScratch& worker,
                            bool derivatives) const;
  void cross_covariance_derivatives(MomentMatch& out, std::size_t a, MomentMatchWorkerScratch& worker) const;

  /// Sum of N_a N_b over the pairs below which one propagation stays on one thread: about N = 80
  /// centres with E = 4 outputs, where a belief step takes ~0.2 ms and a hand-off ~10-20 us.
  static constexpr double kParallelPairWork = 65536.0;

  int input_dim_ = 0;
  Eigen::Index max_centres_ = 0;  ///< max_a N_a, the size of the pair buffers
  std::vector<OutputData> outputs_;
  std::vector<std::pair<std::size_t, std::size_t>> pair_order_;  ///< pairs a <= b, largest N_a N_b first
  double pair_work_ = 0.0;                                       ///< sum of N_a N_b over pair_order_
};

}  // namespace gpilqg::gp
