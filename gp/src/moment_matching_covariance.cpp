/// @file moment_matching_covariance.cpp
/// SeArdMomentMatcher: the predictive covariance S and its derivatives (pairs of outputs a <= b).
///
/// Per pair, with W = W_a + W_b, Lambda = W^-1, Rt = W^1/2 Sigma W^1/2 + I (|R| = |Rt| for PILCO's
/// R = Sigma W + I), and
///
///   P  = (Sigma + Lambda)^-1      = W^1/2 Rt^-1 W^1/2,
///   Xi = R^-1 Sigma = Lambda - Lambda P Lambda = Lambda^1/2 (I - Rt^-1) Lambda^1/2   (symmetric PSD),
///   G  = P Lambda                 = W^1/2 Rt^-1 Lambda^1/2,
///   B  = W - P = W Xi W           = W^1/2 (I - Rt^-1) W^1/2,
///
/// and the same for one output a (P_a, G_a = P_a Lambda_a, B_a = W_a - P_a; moment_matching.cpp),
///
///   log Q_ij = log sf_a^2 + log sf_b^2 - 1/2 log|Rt|
///              - 1/2 nu_i' W_a nu_i - 1/2 nu_j' W_b nu_j + 1/2 z_ij' Xi z_ij,   z_ij = a_i + b_j,
///   log q_ai = log sf_a^2 - 1/2 log|Rt_a| - 1/2 nu_i' W_a nu_i + c_ai,   c_ai = 1/2 nu_i' B_a nu_i,
///
/// with a_i = W_a nu_ai, b_j = W_b nu_bj (-1/2 nu' P_a nu = -1/2 nu' W_a nu + 1/2 nu' B_a nu). Rows i
/// run over output a's N_a centres, columns j over output b's N_b (the same set for the exact GP).
///
/// Centred form. Q_ij = q_ai q_bj exp(D_ij), where the kernel terms -1/2 nu' W nu and log sf^2 cancel
/// exactly and are never formed:
///
///   D_ij = -1/2 (log|Rt| - log|Rt_a| - log|Rt_b|) + [1/2 a_i' Xi a_i - c_ai] + [1/2 b_j' Xi b_j - c_bj]
///          + a_i' Xi b_j
///
/// (the cross term is one N x N GEMM, (A_a Xi) A_b'). Every term is O(Sigma) and is formed from
/// I - Rt^-1 (exactly 0 at Sigma = 0), so D = 0 exactly at Sigma = 0. Since sum_i beta_ai q_ai = M_a,
/// beta_a' (q_a q_b') beta_b = M_a M_b exactly, and the covariance is
///
///   S_ab = sum_ij gamma_ai gamma_bj expm1(D_ij) + delta_ab V_a,          gamma_a = beta_a .* q_a,
///   V_a  = sf_a^2 - tr(Kinv_a Q_aa) = sf_a^2 - q_a' Kinv_a q_a - sum_ij Kinv_a,ij q_ai q_aj expm1(D_ij),
///
/// V_a = E[sf^2 - k(z)' Kinv k(z)] >= 0, which at Sigma = 0 is the latent variance at mu. Rounding
/// error: instead of ~eps N |gamma|^2 for beta' Q beta - M_a M_b, the first sum carries ~eps N |gamma|^2
/// |D| (|D| ~ |Sigma W|), and V_a ~eps |q|' |Kinv| |q| (the limit set by the rounding of Kinv itself).
/// V_a is clamped at 0; where it is, it contributes nothing to the derivatives (a one-sided, zero
/// derivative at the kink). D is capped at 700 before expm1: D_ij > 700 requires
/// max(q_ai, q_bj) < sf^2 e^-700, where Q_ij is negligible, and the cap avoids 0 * inf.
///
/// Derivatives. d log Q_ij / dmu = G z_ij and d log Q_ij / dSigma = -1/2 P + 1/2 y_ij y_ij' with
/// y_ij = G z_ij (from d log|R| / dSigma = P, dXi = Lambda P dSigma P Lambda and I - W Xi = P Lambda);
/// likewise d log q_ai / dmu = G_a a_i (= t_ai) and d log q_ai / dSigma = -1/2 P_a + 1/2 G_a a_i a_i' G_a'.
/// By the product rule, beta_ai beta_bj Q_ij = Omega_ij + gamma_ai gamma_bj with
///
///   Omega = gamma_a gamma_b' .* expm1(D) - delta_ab [V_a not clamped] Kinv_a .* Q_aa,
///   dS_ab = sum_ij Omega_ij d log Q_ij + sum_ij gamma_ai gamma_bj dD_ij,
///
/// (the second sum is d(sum beta beta' .* Q) - d(M_a M_b) for the rank-one part), and
/// dD_ij = d log Q_ij - d log q_ai - d log q_bj is small with Sigma: with Delta_a = G - G_a =
/// (P_a - P) Sigma (0 at Sigma = 0), P - P_a - P_b = B_a + B_b - B, u_a = A_a' gamma_a and
/// E_a = A_a' diag(gamma_a) A_a,
///
///   sum gamma gamma' dD / dmu    = M_b Delta_a u_a + M_a Delta_b u_b,
///   sum gamma gamma' dD / dSigma = -1/2 M_a M_b (B_a + B_b - B) + 1/2 G (u_a u_b' + u_b u_a') G'
///                                  + 1/2 M_b (G E_a G' - G_a E_a G_a') + 1/2 M_a (G E_b G' - G_b E_b G_b'),
///   G E_a G' - G_a E_a G_a' = Delta_a E_a G' + G_a E_a Delta_a'.
///
/// Summing the first part with r = Omega 1, c = Omega' 1:
///
///   dS_ab/dmu    = G (W_a V_a' r + W_b V_b' c) + M_b Delta_a u_a + M_a Delta_b u_b,
///   dS_ab/dSigma = -1/2 (1'r) P + 1/2 G J G' - 1/2 M_a M_b (B_a + B_b - B)
///                  + 1/2 M_b (Delta_a E_a G' + G_a E_a Delta_a') + 1/2 M_a (Delta_b E_b G' + G_b E_b Delta_b'),
///   J = W_a V_a' diag(r) V_a W_a + W_b V_b' diag(c) V_b W_b + W_a (V_a' Omega V_b) W_b
///       + W_b (V_b' Omega' V_a) W_a
///       + u_a u_b' + u_b u_a'.
///
/// (The uncentred form used Omega = diag(beta_a) Q diag(beta_b) - delta_ab Kinv .* Q and subtracted
/// M_b g_a + M_a g_b and 1/2 (M_b H_a + M_a H_b): O(|beta|^2) cancellations that the centred form
/// replaces with the rank-one part summed analytically.)
/// The only O(N^2 D) step of the derivatives is Omega V (one GEMM), so they cost about as much as S.

#include "gpilqg/gp/moment_matching.hpp"

#include <algorithm>
#include <cmath>

#include "moment_matching_internal.hpp"
#include "moment_matching_pair_sums.hpp"

namespace gpilqg::gp {

using detail::tiled_product;
using detail::view;

void SeArdMomentMatcher::propagate_covariance(MomentMatch& out, std::size_t a, std::size_t b,
                                              MomentMatchWorkerScratch& w, bool derivatives) const {
  MomentMatchScratch& s = out.scratch;
  const Eigen::Index d = input_dim_;
  const OutputData& oa = outputs_[a];
  const OutputData& ob = outputs_[b];
  const auto ai = static_cast<Eigen::Index>(a);
  const auto bi = static_cast<Eigen::Index>(b);
  const bool same = a == b;
  const Vector& gamma_a = s.weighted[a];
  const Vector& gamma_b = s.weighted[b];
  // Output a's centres index the rows (N_a), output b's the columns (N_b).
  const Matrix& v_a = s.centred[a];
  const Matrix& v_b = s.centred[b];
  const Eigen::Index n_a = v_a.rows();
  const Eigen::Index n_b = v_b.rows();
  auto nd_a = view(w.nd, n_a, d);
  auto nd_b = view(w.nd2, n_b, d);
  auto row_term = view(w.row_term, n_a);
  auto col_term = view(w.col_term, n_b);
  auto row_sums = view(w.row_sums, n_a);
  auto col_sums = view(w.col_sums, n_b);

  w.sqrt_w_pair = (oa.inverse_squared_lengthscales + ob.inverse_squared_lengthscales).cwiseSqrt();
  w.lengthscale_pair = w.sqrt_w_pair.cwiseInverse();
  const double log_det = factor_scaled(s.sigma, w, w.sqrt_w_pair, a, b);
  w.dd = -w.rt_inverse;  // I - Rt^-1, exactly 0 at Sigma = 0
  w.dd.diagonal().array() += 1.0;
  w.xi.noalias() = w.lengthscale_pair.asDiagonal() * w.dd * w.lengthscale_pair.asDiagonal();
  if (derivatives)
    w.pair_shrink.noalias() = w.sqrt_w_pair.asDiagonal() * w.dd * w.sqrt_w_pair.asDiagonal();

  // D = log(Q / (q_a q_b')): row and column parts, then the cross term, all O(Sigma).
  const Matrix& scaled_a = s.scaled[a];
  const Matrix& scaled_b = s.scaled[b];
  tiled_product(scaled_a, w.xi, nd_a);
  row_term = 0.5 * nd_a.cwiseProduct(scaled_a).rowwise().sum() - s.log_shift[a];
  if (same) {
    col_term = row_term;
  } else {
    tiled_product(scaled_b, w.xi, nd_b);
    col_term = 0.5 * nd_b.cwiseProduct(scaled_b).rowwise().sum() - s.log_shift[b];
  }
  row_term.array() += -0.5 * (log_det - s.log_det(ai) - s.log_det(bi));

  // The N_a x N_b sums, a block of columns at a time (moment_matching_pair_sums.hpp).
  const detail::PairTerms terms{nd_a, scaled_b, row_term, col_term, gamma_a, gamma_b, v_b,
                                same ? &oa.Kinv : nullptr, same ? &s.kernel_mean[a] : nullptr};
  const double ma = out.mean(ai);
  const double mb = out.mean(bi);
  detail::PairSums sums;
  if (same) {
    const Vector& q = s.kernel_mean[a];
    col_sums.noalias() = oa.Kinv * q;
    const double q_kinv_q = q.dot(col_sums);
    // gamma' expm1(D) gamma = beta' (Q - q q') beta and <Kinv, Q - q q'>; Omega with its Kinv term
    sums = detail::pair_sums(terms, true, derivatives, w);
    const double expected_variance = oa.signal_variance - q_kinv_q - sums.kinv_centred;
    const bool clamped = !(expected_variance > 0.0);
    out.covariance(ai, ai) = sums.centred + (clamped ? 0.0 : expected_variance);
    if (!derivatives) return;
    // Clamped (rare): Omega = gamma gamma' .* expm1(D) without the Kinv term, so once more.
    if (clamped) sums = detail::pair_sums(terms, false, true, w);
  } else {
    // Omega = gamma_a gamma_b' .* expm1(D) = diag(beta_a) (Q - q_a q_b') diag(beta_b).
    sums = detail::pair_sums(terms, false, derivatives, w);
    out.covariance(ai, bi) = sums.total;
    out.covariance(bi, ai) = sums.total;
    if (!derivatives) return;
  }
  const double total = sums.total;  // 1' Omega 1
  auto omega_v = view(w.omega_v, n_a, d);

  w.gain.noalias() = w.sqrt_w_pair.asDiagonal() * w.rt_inverse * w.lengthscale_pair.asDiagonal();
  w.pair_precision.noalias() = w.sqrt_w_pair.asDiagonal() * w.rt_inverse * w.sqrt_w_pair.asDiagonal();
  // Delta_a = G - G_a = (P_a - P) Sigma, exactly 0 at Sigma = 0.
  w.dd = s.precision[a] - w.pair_precision;
  w.delta_a.noalias() = w.dd * s.sigma;
  w.dd = s.precision[b] - w.pair_precision;
  w.delta_b.noalias() = w.dd * s.sigma;
  const Vector& u_a = s.scaled_sum[a];
  const Vector& u_b = s.scaled_sum[b];

  // d/dmu = G (W_a V_a' r + W_b V_b' c) + M_b Delta_a u_a + M_a Delta_b u_b
  w.dvec.noalias() = v_a.transpose() * row_sums;
  w.dvec2.noalias() = v_b.transpose() * col_sums;
  w.dvec = oa.inverse_squared_lengthscales.cwiseProduct(w.dvec) +
           ob.inverse_squared_lengthscales.cwiseProduct(w.dvec2);
  w.dvec2.noalias() = w.gain * w.dvec;
  w.dvec2.noalias() += mb * (w.delta_a * u_a);
  w.dvec2.noalias() += ma * (w.delta_b * u_b);

  // d/dSigma: J, then -1/2 (1'r) P + 1/2 G J G' + the rank-one correction (file comment).
  nd_a = v_a;
  nd_a.array().colwise() *= row_sums.array();
  tiled_product(v_a.transpose(), nd_a, w.dd);
  w.inner.noalias() = oa.inverse_squared_lengthscales.asDiagonal() * w.dd *
                      oa.inverse_squared_lengthscales.asDiagonal();
  nd_b = v_b;
  nd_b.array().colwise() *= col_sums.array();
  tiled_product(v_b.transpose(), nd_b, w.dd);
  w.inner.noalias() += ob.inverse_squared_lengthscales.asDiagonal() * w.dd *
                       ob.inverse_squared_lengthscales.asDiagonal();
  tiled_product(v_a.transpose(), omega_v, w.dd);
  w.dd2.noalias() = oa.inverse_squared_lengthscales.asDiagonal() * w.dd *
                    ob.inverse_squared_lengthscales.asDiagonal();
  w.inner += w.dd2 + w.dd2.transpose();
  // 1/2 (u_a u_b' + u_b u_a') joins J: G J G' then carries 1/2 G (u_a u_b' + u_b u_a') G'.
  w.inner.noalias() += u_a * u_b.transpose();
  w.inner.noalias() += u_b * u_a.transpose();
  w.dd2.noalias() = w.gain * w.inner;
  w.dd.noalias() = w.dd2 * w.gain.transpose();
  w.dd = 0.5 * w.dd - (0.5 * total) * w.pair_precision -
         (0.5 * ma * mb) * (s.shrink[a] + s.shrink[b] - w.pair_shrink);
  // + 1/2 M_b (Delta_a E_a G' + G_a E_a Delta_a') + 1/2 M_a (Delta_b E_b G' + G_b E_b Delta_b')
  w.dd2.noalias() = w.delta_a * s.scaled_scatter[a];
  w.dd.noalias() += (0.5 * mb) * (w.dd2 * w.gain.transpose());
  w.dd2.noalias() = s.precision_lambda[a] * s.scaled_scatter[a];
  w.dd.noalias() += (0.5 * mb) * (w.dd2 * w.delta_a.transpose());
  w.dd2.noalias() = w.delta_b * s.scaled_scatter[b];
  w.dd.noalias() += (0.5 * ma) * (w.dd2 * w.gain.transpose());
  w.dd2.noalias() = s.precision_lambda[b] * s.scaled_scatter[b];
  w.dd.noalias() += (0.5 * ma) * (w.dd2 * w.delta_b.transpose());
  detail::write_covariance_derivatives(out, ai, bi, w.dvec2, w.dd);
}

}  // namespace gpilqg::gp
