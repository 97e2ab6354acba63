#pragma once
/// @file ssgp_moment_matching.hpp
/// Exact moment matching of E sparse spectrum GP outputs (ssgp.hpp; Lazaro-Gredilla et al., JMLR 2010)
/// under a Gaussian input z ~ N(mu, Sigma), with analytic derivatives with respect to mu and Sigma:
/// the MomentMatcher (moment_matcher.hpp) that lets SSGP serve PDDP. The SSGP posterior is linear in
/// trigonometric features, whose Gaussian expectations have closed forms (the characteristic function
/// E[exp(i s'z)] = exp(i s'mu - 1/2 s' Sigma s)); the same idea as moment matching with random Fourier
/// features (e.g. Pan, Yan, Theodorou & Boots, "Prediction under uncertainty in sparse spectrum Gaussian
/// processes with applications to filtering and control", ICML 2017). Derived here and checked against
/// Monte Carlo and central differences in tests/gp/ssgp_moment_matching_test.cpp.
///
/// Model (SsgpPredictor). Output a has m_a frequencies s_r (rows of S_a = W_a ./ l_a', m_a x D), features
/// phi_a(z) = [cos(S_a z); sin(S_a z)] (2 m_a), posterior mean and latent variance
///
///   m_a(z) = phi_a(z)' alpha_a,   v_a(z) = phi_a(z)' C_a phi_a(z),   C_a = sn_a^2 A_a^-1 (2m_a x 2m_a),
///
/// alpha_a = [alpha_c; alpha_s] and C_a the posterior mean and covariance of the weights (the sf^2/m
/// scaling of SSGP lives in A, so phi is unscaled; with known noise variances A_a = Phi'U Phi + a I,
/// ssgp.hpp). Nothing below depends on how alpha_a and C_a were obtained.
///
/// Per frequency (output a; theta_r = s_r' mu, c_r = cos theta_r, n_r = sin theta_r):
///
///   h_r = 1/2 s_r' Sigma s_r,   e_r = exp(-h_r) = |E[exp(i s_r' z)]|,
///   E[cos s_r'z] = e_r c_r,     E[sin s_r'z] = e_r n_r,
///   gamma_r = alpha_c,r c_r + alpha_s,r n_r,    eta_r = alpha_c,r n_r - alpha_s,r c_r
///   (d gamma_r / d theta_r = -eta_r, d eta_r / d theta_r = gamma_r).
///
/// Mean and input-output covariance (Stein's lemma, Cov[z, g(z)] = Sigma E[grad g] = Sigma dM/dmu):
///
///   M_a  = sum_r e_r gamma_r,
///   g_a  = dM_a/dmu = -S_a' (e .* eta),
///   H_a  = d^2 M_a/dmu^2 = -S_a' diag(e .* gamma) S_a,     dM_a/dSigma = H_a / 2,
///   C_:a = Sigma g_a,   dC_:a/dmu = Sigma H_a,
///   dC_ka/dSigma_ij = sym_ij[ delta_ki g_j ] + 1/2 sum_r e_r eta_r (Sigma s_r)_k s_ri s_rj.
///
/// Covariance. For a pair of frequencies s_r (output a) and s_q (output b), the product formulas
/// cos A cos B = (cos(A - B) + cos(A + B)) / 2 etc. bring in the sum and difference frequencies s_r +- s_q,
/// whose damping is exp(-1/2 (s_r +- s_q)' Sigma (s_r +- s_q)) = e_r e_q exp(-+kappa_rq) with
/// kappa_rq = s_r' Sigma s_q. Subtracting the product of the means in closed form leaves only
///
///   E_rq = e_r e_q,   Ch_rq = E_rq (cosh kappa_rq - 1),   Sh_rq = E_rq sinh kappa_rq,
///   Cov[cos_r, cos_q] = Ch c_r c_q + Sh n_r n_q,     Cov[sin_r, sin_q] = Sh c_r c_q + Ch n_r n_q,
///   Cov[cos_r, sin_q] = Ch c_r n_q - Sh n_r c_q,     Cov[sin_r, cos_q] = Ch n_r c_q - Sh c_r n_q,
///
/// (cos_r = cos s_r'z), all exactly 0 at Sigma = 0. Hence, for any weight matrix B (2m_a x 2m_b) with
/// 2 x 2 blocks B_rq over (cos, sin), u_r = [c_r; n_r] and u_r^perp = [n_r; -c_r]:
///
///   <B, Cov[phi_a, phi_b]> = sum_rq Ch_rq X_rq + Sh_rq Y_rq,
///   X_rq = u_r' B_rq u_q,   Y_rq = u_r^perp' B_rq u_q^perp,
///
/// and the moments are
///
///   S_ab = <alpha_a alpha_b', Cov[phi_a, phi_b]> + delta_ab V_a
///        = gamma_a' Ch gamma_b + eta_a' Sh eta_b + delta_ab V_a          (X = gamma gamma', Y = eta eta'),
///   V_a  = E[v_a(z)] = Ebar_a' C_a Ebar_a + <C_a, Cov[phi_a]>,   Ebar_a = E[phi_a] = [e .* c; e .* n],
///
/// never a difference of second moments (S is centred by construction, as moment_matching.hpp's is).
/// V_a is clamped at 0 (with zero derivatives there) like SeArdMomentMatcher's and SsgpPredictor's.
///
/// Derivatives of sum_rq Ch X + Sh Y for one pair. With Z_rq = u_r' B_rq u_q^perp and
/// Z'_rq = u_r^perp' B_rq u_q (for B = alpha_a alpha_b': Z = gamma_a eta_b', Z' = eta_a gamma_b'),
/// dX/dtheta_r = -Z'_rq, dX/dtheta_q = -Z_rq, dY/dtheta_r = Z_rq, dY/dtheta_q = Z'_rq, and
/// dCh/dkappa = Sh, dSh/dkappa = Ch + E, d(Ch, Sh)/dL = (Ch, Sh) for L = log E = -h_r - h_q:
///
///   rho_a = (Sh .* Z - Ch .* Z') 1,   rho_b = (Sh .* Z' - Ch .* Z)' 1,
///   d/dmu    = S_a' rho_a + S_b' rho_b,
///   P = Ch .* X + Sh .* Y,   Q = Sh .* X + (Ch + E) .* Y,
///   d/dSigma = -1/2 (S_a' diag(P 1) S_a + S_b' diag(P' 1) S_b) + 1/2 (S_a' Q S_b + S_b' Q' S_a),
///
/// and for the mean-feature part of V_a, with w = C_a Ebar_a = [w_c; w_s]:
///   d(Ebar' C Ebar)/dmu = 2 S_a' (e .* (w_s .* c - w_c .* n)),
///   d(Ebar' C Ebar)/dSigma = -S_a' diag(e .* (w_c .* c + w_s .* n)) S_a.
/// For a = b the weights are X = gamma gamma' + X(C_a) etc. (X(C_a): B = C_a), one pass.
///
/// Evaluation. Ch, Sh and E are formed without overflow or cancellation from t = |kappa| and
/// L + t = -1/2 (s_r -+ s_q)' Sigma (s_r -+ s_q) (<= 0 for a PSD Sigma): with x = expm1(-t) and
/// p = exp(L + t) (= e_r e_q / (1 + x) while t < 1, where 1 + x = e^-t has no cancellation),
///   Ch = p x^2 / 2,   Sh = -sign(kappa) p x (2 + x) / 2,   E = p (1 + x),
/// so Ch and Sh are accurate to rounding for tiny Sigma and stay finite where e_r e_q underflows (large
/// Sigma: E[cos^2] still tends to 1/2). Any symmetric Sigma is accepted (the formulas are analytic in
/// Sigma); a result that overflows (Sigma far from positive semidefinite) throws, as MomentMatcher says.
///
/// The Sigma convention (only sym(Sigma) is read) and the derivative layout are MomentMatcher's.
///
/// Cost per call (m frequencies per output, D inputs, E outputs): E(E+1)/2 pairs, each an m x m matrix
/// of one expm1 per entry (and one exp where t = |kappa| >= 1, rare for the small beliefs of PDDP; half
/// of the entries when a = b), one (m x D)(D x m) product, and with
/// derivatives one more (D x m)(m x m) product and O(m^2) elementwise work; plus E O(m D^2).

#include <cstddef>
#include <string_view>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp {

/// One SSGP output as SsgpPredictor holds it.
struct SsgpOutput {
  Matrix frequencies;  ///< S = W ./ l' (m x D): rows s_r, the scaled spectral points
  Vector weights;      ///< alpha = [alpha_c; alpha_s] (2m): m(z) = phi(z)' alpha
  Matrix variance;     ///< C = sn^2 A^-1 = Sigma_w (2m x 2m), symmetric: v(z) = phi(z)' C phi(z)
};

/// Moment matching of E SSGP outputs (each with its own frequencies). See the file comment.
class SsgpMomentMatcher final : public MomentMatcher {
 public:
  /// outputs: E >= 1 entries, all with the same D >= 1 columns of frequencies, m_a >= 1 rows, weights
  /// of size 2 m_a and variance 2 m_a x 2 m_a, all finite. Throws std::invalid_argument naming the
  /// field (e.g. "outputs[1].variance") otherwise.
  explicit SsgpMomentMatcher(std::vector<SsgpOutput> outputs);

  int input_dim() const override { return input_dim_; }
  int output_dim() const override { return static_cast<int>(outputs_.size()); }

 protected:
  std::string_view name() const override { return "SsgpMomentMatcher"; }
  void evaluate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out, bool derivatives) const override;

 private:
  void prepare(MomentMatch& out, bool derivatives) const;
  void propagate_mean(const VectorCRef& mu, MomentMatch& out, bool derivatives) const;
  /// One pair a <= b: S_ab (with V_a when a == b) and its derivatives.
  void propagate_pair(MomentMatch& out, std::size_t a, std::size_t b, bool derivatives) const;
  /// The weights X(C_a), Y(C_a) (and Z, Z' when `with_z`) of output a's variance into scratch wx, wy
  /// (wz, wz2), m_a x m_a.
  void variance_weights(SsgpMomentScratch& s, std::size_t a, bool with_z) const;

  int input_dim_ = 0;
  Eigen::Index max_frequencies_ = 0;  ///< max_a m_a, the size of the pair buffers
  std::vector<SsgpOutput> outputs_;
};

}  // namespace gpilqg::gp
