/// @file moment_matching_covariance.cpp
/// SeArdMomentMatcher: the predictive covariance S and its derivatives (pairs of outputs a <= b).
///
/// Per pair, with W = W_a + W_b, Lambda = W^-1, Rt = W^1/2 Sigma W^1/2 + I (|R| = |Rt| for PILCO's
/// R = Sigma W + I), and
///
///   P  = (Sigma + Lambda)^-1      = W^1/2 Rt^-1 W^1/2,
///   Xi = R^-1 Sigma = Lambda - Lambda P Lambda = Lambda^1/2 (I - Rt^-1) Lambda^1/2   (symmetric PSD),
///   G  = P Lambda                 = W^1/2 Rt^-1 Lambda^1/2,
///
/// the log of Q_ij = E[k_a(x_i, z) k_b(x_j, z)] is assembled in one sum (no separate kernel values):
///
///   log Q_ij = log sf_a^2 + log sf_b^2 - 1/2 log|Rt|
///              + [-1/2 nu_i' W_a nu_i + 1/2 a_i' Xi a_i] + [-1/2 nu_j' W_b nu_j + 1/2 b_j' Xi b_j]
///              + a_i' Xi b_j,                       a_i = W_a nu_i, b_j = W_b nu_j,
///
/// (the cross term is one N x N GEMM, (A_a Xi) A_b'), and with Omega = diag(beta_a) Q diag(beta_b)
/// - delta_ab Kinv_a .* Q:
///
///   S_ab = sum_ij Omega_ij - M_a M_b + delta_ab sf_a^2.
///
/// Derivatives. d log Q_ij / dmu = G z_ij and d log Q_ij / dSigma = -1/2 P + 1/2 y_ij y_ij' with
/// z_ij = a_i + b_j and y_ij = G z_ij (from d log|R| / dSigma = P, dXi = Lambda P dSigma P Lambda and
/// I - W Xi = P Lambda). Summing with the weights Omega_ij, r = Omega 1, c = Omega' 1:
///
///   dS_ab/dmu    = G (W_a V' r + W_b V' c) - (M_b g_a + M_a g_b)
///   dS_ab/dSigma = -1/2 (1' r) P + 1/2 G J G' - 1/2 (M_b H_a + M_a H_b),
///   J = W_a V' diag(r) V W_a + W_b V' diag(c) V W_b + W_a (V' Omega V) W_b + W_b (V' Omega' V) W_a,
///
/// where g_a = dM_a/dmu and H_a / 2 = dM_a/dSigma come from moment_matching.cpp. The only O(N^2 D)
/// step of the derivatives is Omega V (one GEMM), so they cost about as much as S itself.

#include "gpilqg/gp/moment_matching.hpp"
#include "moment_matching_internal.hpp"

namespace gpilqg::gp {

using detail::tiled_product;

void SeArdMomentMatcher::propagate_covariance(MomentMatch& out, bool derivatives) const {
  MomentMatchScratch& s = out.scratch;
  const Eigen::Index n = inputs_.rows();
  const Eigen::Index d = inputs_.cols();
  const auto e = static_cast<Eigen::Index>(outputs_.size());
  const Matrix& v = s.centred;

  for (std::size_t a = 0; a < outputs_.size(); ++a) {
    for (std::size_t b = a; b < outputs_.size(); ++b) {
      const OutputData& oa = outputs_[a];
      const OutputData& ob = outputs_[b];
      const auto ai = static_cast<Eigen::Index>(a);
      const auto bi = static_cast<Eigen::Index>(b);
      const bool same = a == b;

      s.sqrt_w_pair = (oa.inverse_squared_lengthscales + ob.inverse_squared_lengthscales).cwiseSqrt();
      s.lengthscale_pair = s.sqrt_w_pair.cwiseInverse();
      const double log_det = factor_scaled(s, s.sqrt_w_pair, a, b);
      s.dd = -s.rt_inverse;
      s.dd.diagonal().array() += 1.0;
      s.xi.noalias() = s.lengthscale_pair.asDiagonal() * s.dd * s.lengthscale_pair.asDiagonal();

      // Row and column parts of log Q, then the cross term and the exponential, column by column.
      const Matrix& scaled_a = s.scaled[a];
      const Matrix& scaled_b = s.scaled[b];
      tiled_product(scaled_a, s.xi, s.nd);
      s.row_term = s.log_kernel[a] + 0.5 * s.nd.cwiseProduct(scaled_a).rowwise().sum();
      if (same) {
        s.col_term = s.row_term;
      } else {
        tiled_product(scaled_b, s.xi, s.nd2);
        s.col_term = s.log_kernel[b] + 0.5 * s.nd2.cwiseProduct(scaled_b).rowwise().sum();
      }
      s.row_term.array() += oa.log_signal_variance + ob.log_signal_variance - 0.5 * log_det;
      tiled_product(s.nd, scaled_b.transpose(), s.nn);
      if (same) {
        // Q_aa is symmetric: exponentiate the lower triangle (the exponentials dominate the cost) and mirror.
        for (Eigen::Index j = 0; j < n; ++j) {
          const Eigen::Index len = n - j;
          s.nn.col(j).tail(len) =
              ((s.nn.col(j).tail(len) + s.row_term.tail(len)).array() + s.col_term(j)).exp().matrix();
        }
        for (Eigen::Index j = 0; j + 1 < n; ++j) s.nn.row(j).tail(n - j - 1) = s.nn.col(j).tail(n - j - 1).transpose();
      } else {
        for (Eigen::Index j = 0; j < n; ++j)
          s.nn.col(j) = ((s.nn.col(j) + s.row_term).array() + s.col_term(j)).exp().matrix();
      }

      // Omega in place of Q.
      if (same) {
        for (Eigen::Index j = 0; j < n; ++j)
          s.nn.col(j) = s.nn.col(j).cwiseProduct(oa.beta * ob.beta(j) - oa.Kinv.col(j));
      } else {
        for (Eigen::Index j = 0; j < n; ++j) s.nn.col(j) = s.nn.col(j).cwiseProduct(oa.beta) * ob.beta(j);
      }
      const double total = s.nn.sum();
      const double ma = out.mean(ai);
      const double mb = out.mean(bi);
      double sab = total - ma * mb;
      if (same) sab += oa.signal_variance;
      out.covariance(ai, bi) = sab;
      out.covariance(bi, ai) = sab;

      if (!derivatives) continue;
      s.row_sums = s.nn.rowwise().sum();
      s.col_sums = s.nn.colwise().sum().transpose();
      s.gain.noalias() = s.sqrt_w_pair.asDiagonal() * s.rt_inverse * s.lengthscale_pair.asDiagonal();
      s.pair_precision.noalias() = s.sqrt_w_pair.asDiagonal() * s.rt_inverse * s.sqrt_w_pair.asDiagonal();

      // d/dmu
      s.dvec.noalias() = v.transpose() * s.row_sums;
      s.dvec2.noalias() = v.transpose() * s.col_sums;
      s.dvec = oa.inverse_squared_lengthscales.cwiseProduct(s.dvec) +
               ob.inverse_squared_lengthscales.cwiseProduct(s.dvec2);
      s.dvec2.noalias() = s.gain * s.dvec;
      s.dvec2 -= mb * s.gradient[a] + ma * s.gradient[b];
      out.dcovariance_dmu.row(ai + e * bi) = s.dvec2.transpose();
      out.dcovariance_dmu.row(bi + e * ai) = s.dvec2.transpose();

      // d/dSigma: J, then -1/2 (1'r) P + 1/2 G J G' - 1/2 (M_b H_a + M_a H_b).
      s.nd = v;
      s.nd.array().colwise() *= s.row_sums.array();
      tiled_product(v.transpose(), s.nd, s.dd);
      s.inner.noalias() = oa.inverse_squared_lengthscales.asDiagonal() * s.dd *
                          oa.inverse_squared_lengthscales.asDiagonal();
      s.nd = v;
      s.nd.array().colwise() *= s.col_sums.array();
      tiled_product(v.transpose(), s.nd, s.dd);
      s.inner.noalias() += ob.inverse_squared_lengthscales.asDiagonal() * s.dd *
                           ob.inverse_squared_lengthscales.asDiagonal();
      tiled_product(s.nn, v, s.nd2);
      tiled_product(v.transpose(), s.nd2, s.dd);
      s.dd2.noalias() = oa.inverse_squared_lengthscales.asDiagonal() * s.dd *
                        ob.inverse_squared_lengthscales.asDiagonal();
      s.inner += s.dd2 + s.dd2.transpose();
      s.dd2.noalias() = s.gain * s.inner;
      s.dd.noalias() = s.dd2 * s.gain.transpose();
      s.dd = 0.5 * s.dd - (0.5 * total) * s.pair_precision - 0.5 * (mb * s.hessian[a] + ma * s.hessian[b]);
      for (Eigen::Index j = 0; j < d; ++j)
        for (Eigen::Index i = 0; i < j; ++i) s.dd(i, j) = s.dd(j, i) = 0.5 * (s.dd(i, j) + s.dd(j, i));
      const auto flat = Eigen::Map<const Vector>(s.dd.data(), d * d).transpose();
      out.dcovariance_dsigma.row(ai + e * bi) = flat;
      out.dcovariance_dsigma.row(bi + e * ai) = flat;
    }
  }
}

}  // namespace gpilqg::gp
