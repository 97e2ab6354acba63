/// @file ssgp_moment_matching.cpp
/// SsgpMomentMatcher: construction, validation, the mean M, the input-output covariance C and their
/// derivatives (formulas in ssgp_moment_matching.hpp). The covariance S is in
/// ssgp_moment_matching_covariance.cpp.
///
/// Per output a: theta = S_a mu, [c; n] = [cos theta; sin theta] (ssgp_sincos.hpp, the predictor's own
/// cos and sin), T_a = S_a Sigma (rows (Sigma s_r)'), h = 1/2 rowsum(T_a .* S_a), e = exp(-h),
/// gamma and eta, M_a = e' gamma, g_a = -S_a' (e .* eta), C_:a = Sigma g_a, and with derivatives
/// H_a = -S_a' diag(e .* gamma) S_a and third(k, i + D j) = sum_r e_r eta_r T_rk s_ri s_rj.

#include "gpilqg/gp/ssgp_moment_matching.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "moment_matching_internal.hpp"
#include "ssgp_sincos.hpp"

namespace gpilqg::gp {

using detail::shape;
using detail::view;

namespace {

[[noreturn]] void fail_ssgp(const std::string& message) {
  throw std::invalid_argument("SsgpMomentMatcher: " + message);
}

}  // namespace

SsgpMomentMatcher::SsgpMomentMatcher(std::vector<SsgpOutput> outputs) : outputs_(std::move(outputs)) {
  if (outputs_.empty()) fail_ssgp("outputs is empty, need at least one output");
  const Eigen::Index d = outputs_[0].frequencies.cols();
  for (std::size_t a = 0; a < outputs_.size(); ++a) {
    const SsgpOutput& o = outputs_[a];
    const std::string name = "outputs[" + std::to_string(a) + "]";
    const Eigen::Index m = o.frequencies.rows();
    if (m == 0 || o.frequencies.cols() == 0)
      fail_ssgp(name + ".frequencies is " + shape(m, o.frequencies.cols()) + ", need at least one row and column");
    if (o.frequencies.cols() != d)
      fail_ssgp(name + ".frequencies has " + std::to_string(o.frequencies.cols()) + " columns, expected D = " +
           std::to_string(d) + " (the columns of outputs[0].frequencies)");
    if (o.weights.size() != 2 * m)
      fail_ssgp(name + ".weights has " + std::to_string(o.weights.size()) + " entries, expected 2m = " +
           std::to_string(2 * m) + " (twice the rows of frequencies)");
    if (o.variance.rows() != 2 * m || o.variance.cols() != 2 * m)
      fail_ssgp(name + ".variance is " + shape(o.variance.rows(), o.variance.cols()) + ", expected 2m x 2m = " +
           shape(2 * m, 2 * m));
    if (!o.frequencies.allFinite()) fail_ssgp(name + ".frequencies has a non-finite entry");
    if (!o.weights.allFinite()) fail_ssgp(name + ".weights has a non-finite entry");
    if (!o.variance.allFinite()) fail_ssgp(name + ".variance has a non-finite entry");
    max_frequencies_ = std::max(max_frequencies_, m);
  }
  input_dim_ = static_cast<int>(d);
}

void SsgpMomentMatcher::prepare(MomentMatch& out, bool derivatives) const {
  const Eigen::Index m = max_frequencies_;
  const Eigen::Index d = input_dim_;
  SsgpMomentScratch& s = out.ssgp_scratch;
  s.sigma.resize(d, d);
  const std::size_t e = outputs_.size();
  s.projected.resize(e);
  for (auto* v : {&s.cosine, &s.sine, &s.half_spread, &s.damping, &s.in_phase, &s.quadrature, &s.mean_features,
                  &s.gradient})
    v->resize(e);
  for (std::size_t a = 0; a < e; ++a) {
    const Eigen::Index ma = outputs_[a].frequencies.rows();
    s.projected[a].resize(ma, d);
    for (auto* v : {&s.cosine, &s.sine, &s.half_spread, &s.damping, &s.in_phase, &s.quadrature}) (*v)[a].resize(ma);
    s.mean_features[a].resize(2 * ma);
    s.gradient[a].resize(d);
  }
  for (Matrix* x : {&s.kappa, &s.cosh_part, &s.sinh_part, &s.plain, &s.wx, &s.wy, &s.wz, &s.wz2, &s.work})
    x->resize(m, m);
  for (Vector* v : {&s.rows, &s.cols}) v->resize(m);
  for (Vector* v : {&s.vm, &s.vm2}) v->resize(2 * m);
  s.dm.resize(m, d);
  s.dm2.resize(m, d);
  for (Matrix* x : {&s.dd, &s.dd2}) x->resize(d, d);
  s.dvec.resize(d);
  if (derivatives) {
    s.outer.resize(m, d * d);
    s.third.resize(d, d * d);
  }
}

void SsgpMomentMatcher::evaluate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out,
                                 bool derivatives) const {
  prepare(out, derivatives);
  SsgpMomentScratch& s = out.ssgp_scratch;
  s.sigma = 0.5 * (sigma + sigma.transpose());
  propagate_mean(mu, out, derivatives);
  for (std::size_t a = 0; a < outputs_.size(); ++a)
    for (std::size_t b = a; b < outputs_.size(); ++b) propagate_pair(out, a, b, derivatives);
}

void SsgpMomentMatcher::propagate_mean(const VectorCRef& mu, MomentMatch& out, bool derivatives) const {
  SsgpMomentScratch& s = out.ssgp_scratch;
  const Eigen::Index d = input_dim_;
  for (std::size_t a = 0; a < outputs_.size(); ++a) {
    const SsgpOutput& o = outputs_[a];
    const auto ai = static_cast<Eigen::Index>(a);
    const Eigen::Index m = o.frequencies.rows();
    const auto alpha_c = o.weights.head(m);
    const auto alpha_s = o.weights.tail(m);
    Vector& c = s.cosine[a];
    Vector& n = s.sine[a];
    Vector& e = s.damping[a];
    c.noalias() = o.frequencies * mu;  // theta, then cos theta in place
    ssgp_detail::sincos_many(c.data(), c.data(), n.data(), static_cast<long>(m));
    Matrix& t = s.projected[a];
    t.noalias() = o.frequencies * s.sigma;
    s.half_spread[a] = 0.5 * t.cwiseProduct(o.frequencies).rowwise().sum();
    e = (-s.half_spread[a].array()).exp().matrix();
    Vector& gamma = s.in_phase[a];
    Vector& eta = s.quadrature[a];
    gamma = alpha_c.cwiseProduct(c) + alpha_s.cwiseProduct(n);
    eta = alpha_c.cwiseProduct(n) - alpha_s.cwiseProduct(c);
    s.mean_features[a] << e.cwiseProduct(c), e.cwiseProduct(n);
    out.mean(ai) = e.dot(gamma);
    auto weights = view(s.rows, m);
    weights = -e.cwiseProduct(eta);
    Vector& g = s.gradient[a];
    g.noalias() = o.frequencies.transpose() * weights;
    out.cross_covariance.col(ai).noalias() = s.sigma * g;
    if (!derivatives) continue;

    // H = -S' diag(e .* gamma) S
    auto scaled = view(s.dm, m, d);
    weights = -e.cwiseProduct(gamma);  // evaluated first: colwise() *= an expression makes a temporary
    scaled = o.frequencies;
    scaled.array().colwise() *= weights.array();
    s.dd.noalias() = o.frequencies.transpose() * scaled;
    detail::write_mean_derivatives(out, ai, s.sigma, g, s.dd);

    // dC_ka/dSigma_ij = 1/2 (delta_ki g_j + delta_kj g_i) + 1/2 sum_r e_r eta_r T_rk s_ri s_rj
    auto sigma_s = view(s.dm2, m, d);
    sigma_s = t;
    weights = e.cwiseProduct(eta);
    detail::weighted_third_moment(o.frequencies, sigma_s, weights, view(s.outer, m, d * d), s.third);
    for (Eigen::Index k = 0; k < d; ++k) {
      const Eigen::Index row = k + d * ai;
      out.dcross_dsigma.row(row) = 0.5 * s.third.row(k);
      for (Eigen::Index j = 0; j < d; ++j) {
        out.dcross_dsigma(row, k + d * j) += 0.5 * g(j);
        out.dcross_dsigma(row, j + d * k) += 0.5 * g(j);
      }
    }
  }
}

}  // namespace gpilqg::gp
