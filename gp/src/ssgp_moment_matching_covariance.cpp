/// @file ssgp_moment_matching_covariance.cpp
/// SsgpMomentMatcher: the covariance S and its derivatives, one pair of outputs a <= b at a time
/// (formulas in ssgp_moment_matching.hpp):
///
///   kappa = T_a S_b' = S_a Sigma S_b'   (m_a x m_b, one product),
///   per entry t = |kappa|, x = expm1(-t), p = exp(t - h_ar - h_bq) (= e_ar e_bq / (1 + x) for t < 1):
///     Ch = p x^2 / 2,  Sh = -sign(kappa) p x (2 + x) / 2,  E = p (1 + x)     (a == b: lower triangle, mirrored),
///   S_ab = gamma_a' Ch gamma_b + eta_a' Sh eta_b + delta_ab max(V_a, 0),
///   V_a  = Ebar' C_a Ebar + <Ch, X(C_a)> + <Sh, Y(C_a)>,
///
/// then, with the pair's weights X, Y, Z, Z' (rank one gamma/eta products, plus C_a's when a == b and
/// V_a is not clamped), rho_a, rho_b, P and Q of the header give d/dmu and d/dSigma.

#include <cmath>

#include "gpilqg/gp/ssgp_moment_matching.hpp"
#include "moment_matching_internal.hpp"

namespace gpilqg::gp {

using detail::tiled_product;
using detail::view;

namespace {

/// p = e_r e_q / (1 + x) needs e_r e_q above this (a normal number with full precision) ...
constexpr double kTiny = 1e-290;
/// ... and t = |kappa| below this, where 1 + x = e^-t >= 0.37 carries no cancellation.
constexpr double kDivideBelow = 1.0;

/// The weights X, Y, Z, Z' of a pair (rows x cols views of the scratch buffers).
struct WeightViews {
  detail::MatrixView x, y, z, z2;
};

WeightViews weight_views(SsgpMomentScratch& s, Eigen::Index rows, Eigen::Index cols) {
  return {view(s.wx, rows, cols), view(s.wy, rows, cols), view(s.wz, rows, cols), view(s.wz2, rows, cols)};
}

}  // namespace

void SsgpMomentMatcher::variance_weights(SsgpMomentScratch& s, std::size_t a, bool with_z) const {
  const Matrix& C = outputs_[a].variance;
  const Eigen::Index m = outputs_[a].frequencies.rows();
  const Vector& c = s.cosine[a];
  const Vector& n = s.sine[a];
  auto [wx, wy, wz, wz2] = weight_views(s, m, m);
  // Blocks B_rq = [[C_cc, C_cs]; [C_sc, C_ss]]_rq with u_r = [c_r; n_r], u_r^perp = [n_r; -c_r].
  for (Eigen::Index q = 0; q < m; ++q)
    for (Eigen::Index r = 0; r < m; ++r) {
      const double cc = C(r, q), cs = C(r, m + q), sc = C(m + r, q), ss = C(m + r, m + q);
      const double cr = c(r), nr = n(r), cq = c(q), nq = n(q);
      wx(r, q) = cr * (cc * cq + cs * nq) + nr * (sc * cq + ss * nq);  // u_r' B u_q
      wy(r, q) = nr * (cc * nq - cs * cq) - cr * (sc * nq - ss * cq);  // u_r^perp' B u_q^perp
      if (!with_z) continue;
      wz(r, q) = cr * (cc * nq - cs * cq) + nr * (sc * nq - ss * cq);   // u_r' B u_q^perp
      wz2(r, q) = nr * (cc * cq + cs * nq) - cr * (sc * cq + ss * nq);  // u_r^perp' B u_q
    }
}

void SsgpMomentMatcher::propagate_pair(MomentMatch& out, std::size_t a, std::size_t b, bool derivatives) const {
  SsgpMomentScratch& s = out.ssgp_scratch;
  const SsgpOutput& oa = outputs_[a];
  const SsgpOutput& ob = outputs_[b];
  const auto ai = static_cast<Eigen::Index>(a);
  const auto bi = static_cast<Eigen::Index>(b);
  const bool same = a == b;
  const Eigen::Index ma = oa.frequencies.rows();
  const Eigen::Index mb = ob.frequencies.rows();
  const Eigen::Index d = input_dim_;
  const Vector& gamma_a = s.in_phase[a];
  const Vector& gamma_b = s.in_phase[b];
  const Vector& eta_a = s.quadrature[a];
  const Vector& eta_b = s.quadrature[b];

  // Ch, Sh and E of every pair of frequencies (file comment: no overflow, no cancellation).
  auto kappa = view(s.kappa, ma, mb);
  auto ch = view(s.cosh_part, ma, mb);
  auto sh = view(s.sinh_part, ma, mb);
  auto plain = view(s.plain, ma, mb);
  tiled_product(s.projected[a], ob.frequencies.transpose(), kappa);
  const Vector& ha = s.half_spread[a];
  const Vector& hb = s.half_spread[b];
  const Vector& ea = s.damping[a];
  const Vector& eb = s.damping[b];
  for (Eigen::Index q = 0; q < mb; ++q)
    for (Eigen::Index r = same ? q : 0; r < ma; ++r) {
      const double k = kappa(r, q);
      const double t = std::abs(k);
      const double x = std::expm1(-t);
      // p = exp(t - h_r - h_q) = e_r e_q / e^-t with e^-t = 1 + x, accurate to rounding while t < 1
      // (beyond, 1 + x cancels: relative error eps e^t) and e_r e_q is a normal number; else exp().
      const double ee = ea(r) * eb(q);
      const double p = t < kDivideBelow && ee > kTiny ? ee / (1.0 + x) : std::exp(t - ha(r) - hb(q));
      ch(r, q) = 0.5 * p * x * x;
      sh(r, q) = (k >= 0.0 ? -0.5 : 0.5) * p * x * (2.0 + x);
      plain(r, q) = p * (1.0 + x);
    }
  if (same)
    for (Eigen::Index q = 0; q + 1 < mb; ++q)
      for (auto* x : {&ch, &sh, &plain}) x->row(q).tail(mb - q - 1) = x->col(q).tail(mb - q - 1).transpose();

  // Cov[m_a, m_b] = gamma_a' Ch gamma_b + eta_a' Sh eta_b.
  auto rows = view(s.rows, ma);
  auto cols = view(s.cols, ma);
  rows.noalias() = ch * gamma_b;
  cols.noalias() = sh * eta_b;
  double value = gamma_a.dot(rows) + eta_a.dot(cols);

  // V_a = Ebar' C Ebar + <Ch, X(C)> + <Sh, Y(C)>, clamped at 0 (then no derivatives).
  bool variance = false;
  auto w = view(s.vm, 2 * ma);
  if (same) {
    w.noalias() = oa.variance * s.mean_features[a];
    variance_weights(s, a, derivatives);
    const double expected = s.mean_features[a].dot(w) + (ch.cwiseProduct(view(s.wx, ma, ma))).sum() +
                            (sh.cwiseProduct(view(s.wy, ma, ma))).sum();
    variance = expected > 0.0;
    if (variance) value += expected;
  }
  out.covariance(ai, bi) = value;
  out.covariance(bi, ai) = value;
  if (!derivatives) return;

  // The pair's weights: rank one, added to C_a's when they count.
  auto [wx, wy, wz, wz2] = weight_views(s, ma, mb);
  if (!variance) {
    wx.setZero();
    wy.setZero();
    wz.setZero();
    wz2.setZero();
  }
  wx.noalias() += gamma_a * gamma_b.transpose();
  wy.noalias() += eta_a * eta_b.transpose();
  wz.noalias() += gamma_a * eta_b.transpose();
  wz2.noalias() += eta_a * gamma_b.transpose();

  // d/dmu = S_a' rho_a + S_b' rho_b
  auto rho_b = view(s.cols, mb);
  rows = (sh.cwiseProduct(wz) - ch.cwiseProduct(wz2)).rowwise().sum();
  rho_b = (sh.cwiseProduct(wz2) - ch.cwiseProduct(wz)).colwise().sum().transpose();
  s.dvec.noalias() = oa.frequencies.transpose() * rows;
  s.dvec.noalias() += ob.frequencies.transpose() * rho_b;

  // d/dSigma = -1/2 (S_a' diag(P 1) S_a + S_b' diag(P' 1) S_b) + 1/2 (S_a' Q S_b + S_b' Q' S_a)
  auto work = view(s.work, ma, mb);
  work = ch.cwiseProduct(wx) + sh.cwiseProduct(wy);  // P
  rows = work.rowwise().sum();
  rho_b = work.colwise().sum().transpose();
  auto scaled_a = view(s.dm, ma, d);
  auto scaled_b = view(s.dm2, mb, d);
  scaled_a = oa.frequencies;
  scaled_a.array().colwise() *= rows.array();
  tiled_product(oa.frequencies.transpose(), scaled_a, s.dd);
  scaled_b = ob.frequencies;
  scaled_b.array().colwise() *= rho_b.array();
  tiled_product(ob.frequencies.transpose(), scaled_b, s.dd2);
  s.dd = -0.5 * (s.dd + s.dd2);
  work = sh.cwiseProduct(wx) + (ch + plain).cwiseProduct(wy);  // Q
  tiled_product(work, ob.frequencies, scaled_a);
  tiled_product(oa.frequencies.transpose(), scaled_a, s.dd2);
  s.dd += 0.5 * (s.dd2 + s.dd2.transpose());

  if (variance) {
    // The mean-feature part Ebar' C Ebar, w = C Ebar = [w_c; w_s]:
    //   d/dmu = 2 S' (e .* (w_s .* c - w_c .* n)),  d/dSigma = -S' diag(e .* (w_c .* c + w_s .* n)) S.
    const Vector& e = s.damping[a];
    const Vector& c = s.cosine[a];
    const Vector& n = s.sine[a];
    rows = 2.0 * e.cwiseProduct(w.tail(ma).cwiseProduct(c) - w.head(ma).cwiseProduct(n));
    s.dvec.noalias() += oa.frequencies.transpose() * rows;
    rows = e.cwiseProduct(w.head(ma).cwiseProduct(c) + w.tail(ma).cwiseProduct(n));
    scaled_a = oa.frequencies;
    scaled_a.array().colwise() *= rows.array();
    tiled_product(oa.frequencies.transpose(), scaled_a, s.dd2);
    s.dd -= s.dd2;
  }
  detail::write_covariance_derivatives(out, ai, bi, s.dvec, s.dd);
}

}  // namespace gpilqg::gp
