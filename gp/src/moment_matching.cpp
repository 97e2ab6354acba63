/// @file moment_matching.cpp
/// SeArdMomentMatcher: construction, validation, the predictive mean M, the input-output covariance C
/// and their derivatives. The covariance S is in moment_matching_covariance.cpp.
///
/// Notation (per output a; see moment_matching.hpp): w = diag(W_a), V = V_a = X_a - 1 mu' (rows nu_i',
/// one per centre of output a),
/// Rt_a = W^1/2 Sigma W^1/2 + I (eigenvalues >= 1 for a PSD Sigma), and
///
///   P_a = (Sigma + Lambda_a)^-1 = W^1/2 Rt_a^-1 W^1/2,   |Sigma W_a + I| = |Rt_a|,
///   T_a = V P_a            (rows t_i' = (P_a nu_i)'),
///   q_ai = sf^2 |Rt_a|^-1/2 exp(-1/2 nu_i' t_i),   gamma_a = beta_a .* q_a,   M_a = sum_i gamma_ai,
///   g_a = dM_a/dmu = T_a' gamma_a                          (dq_i/dmu = q_i t_i),
///   C_:a = Sigma P_a sum_i gamma_ai nu_i = Sigma g_a.
///
/// Derivatives (dq_i/dSigma = q_i (t_i t_i' - P_a) / 2, dt_i/dSigma_kl = -P_:k t_il):
///   H_a = T_a' diag(gamma_a) T_a - M_a P_a     (D x D, symmetric) = d^2 M_a / dmu^2,
///   dM_a/dSigma = H_a / 2,   dC_:a/dmu = Sigma H_a,
///   dC_ka/dSigma_ij (before symmetrisation) = (P_a Lambda_a)_ik g_j - C_ka (P_a)_ij / 2
///                                              + 1/2 sum_n gamma_n (Sigma t_n)_k t_ni t_nj,
/// using I - Sigma P_a = Lambda_a P_a. Because the moments are functions of sym(Sigma), the reported
/// derivative is the symmetric part of this partial derivative (header comment).
///
/// Kept for the covariance (moment_matching_covariance.cpp): q_a, log|Rt_a|, A_a = V W_a,
/// B_a = W_a - P_a = W^1/2 (I - Rt_a^-1) W^1/2 (formed from I - Rt_a^-1, so exactly 0 at Sigma = 0),
/// c_ai = 1/2 nu_i' B_a nu_i, and with derivatives u_a = A_a' gamma_a and E_a = A_a' diag(gamma_a) A_a.

#include "gpilqg/gp/moment_matching.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "moment_matching_internal.hpp"

namespace gpilqg::gp {

using detail::tiled_product;
using detail::shape;
using detail::view;

namespace {

[[noreturn]] void fail_se_ard(const std::string& message) {
  throw std::invalid_argument("SeArdMomentMatcher: " + message);
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Conditioning helper

SeArdOutput condition_se_ard_output(const MatrixCRef& inputs, const VectorCRef& targets,
                                    const VectorCRef& log_lengthscales, double log_signal_std,
                                    double log_noise_std) {
  const Eigen::Index n = inputs.rows();
  const Eigen::Index d = inputs.cols();
  const auto bad = [](const std::string& message) {
    throw std::invalid_argument("condition_se_ard_output: " + message);
  };
  if (n == 0 || d == 0) bad("inputs is " + shape(n, d) + ", need at least one row and column");
  if (targets.size() != n)
    bad("targets has " + std::to_string(targets.size()) + " entries, expected " + std::to_string(n));
  if (log_lengthscales.size() != d)
    bad("log_lengthscales has " + std::to_string(log_lengthscales.size()) + " entries, expected " +
        std::to_string(d));
  if (!inputs.allFinite()) bad("inputs has a non-finite entry");
  if (!targets.allFinite()) bad("targets has a non-finite entry");
  if (!log_lengthscales.allFinite() || !std::isfinite(log_signal_std) || !std::isfinite(log_noise_std))
    bad("a hyperparameter is not finite");
  const Vector w = (-2.0 * log_lengthscales.array()).exp().matrix();
  const double sf2 = std::exp(2.0 * log_signal_std);
  const double sn2 = std::exp(2.0 * log_noise_std);
  Matrix k(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = j; i < n; ++i) {
      const double r2 = ((inputs.row(i) - inputs.row(j)).array().square() * w.transpose().array()).sum();
      k(i, j) = k(j, i) = sf2 * std::exp(-0.5 * r2);
    }
  k.diagonal().array() += sn2;
  const Eigen::LLT<Matrix> llt(k);
  if (llt.info() != Eigen::Success) bad("K + sn^2 I is not numerically positive definite (raise the noise)");
  SeArdOutput out;
  out.log_lengthscales = log_lengthscales;
  out.log_signal_std = log_signal_std;
  out.beta = llt.solve(targets);
  out.Kinv = llt.solve(Matrix::Identity(n, n));
  if (!out.beta.allFinite() || !out.Kinv.allFinite())
    bad("K + sn^2 I is too ill-conditioned (non-finite weights; raise the noise)");
  return out;
}

// ------------------------------------------------------------------------------------------------
// Construction

namespace {

/// Throws unless `x` (named `label`) has at least one row and column (exactly `d` columns when d > 0)
/// and finite entries.
void check_centres(const Matrix& x, const std::string& label, Eigen::Index d) {
  if (x.rows() == 0 || x.cols() == 0)
    fail_se_ard(label + " is " + shape(x.rows(), x.cols()) + ", need at least one row and one column");
  if (d > 0 && x.cols() != d)
    fail_se_ard(label + " has " + std::to_string(x.cols()) + " columns, expected D = " + std::to_string(d) +
         " (the columns of centres[0])");
  if (!x.allFinite()) fail_se_ard(label + " has a non-finite entry");
}

}  // namespace

SeArdMomentMatcher::SeArdMomentMatcher(Matrix inputs, std::vector<SeArdOutput> outputs) {
  check_centres(inputs, "inputs", 0);
  if (outputs.empty()) fail_se_ard("outputs is empty, need at least one output");
  std::vector<Matrix> centres(outputs.size(), inputs);
  build(std::move(centres), std::move(outputs), true);
}

SeArdMomentMatcher::SeArdMomentMatcher(std::vector<Matrix> centres, std::vector<SeArdOutput> outputs) {
  if (outputs.empty()) fail_se_ard("outputs is empty, need at least one output");
  if (centres.size() != outputs.size())
    fail_se_ard("centres has " + std::to_string(centres.size()) + " matrices for " + std::to_string(outputs.size()) +
         " outputs; expected one per output");
  for (std::size_t a = 0; a < centres.size(); ++a)
    check_centres(centres[a], "centres[" + std::to_string(a) + "]", a == 0 ? 0 : centres[0].cols());
  build(std::move(centres), std::move(outputs), false);
}

void SeArdMomentMatcher::build(std::vector<Matrix> centres, std::vector<SeArdOutput> outputs, bool shared) {
  const Eigen::Index d = centres[0].cols();
  input_dim_ = static_cast<int>(d);
  outputs_.reserve(outputs.size());
  for (std::size_t a = 0; a < outputs.size(); ++a) {
    SeArdOutput& src = outputs[a];
    const Eigen::Index n = centres[a].rows();
    const std::string name = "outputs[" + std::to_string(a) + "]";
    const std::string rows = shared ? "rows of inputs" : "rows of centres[" + std::to_string(a) + "]";
    if (src.log_lengthscales.size() != d)
      fail_se_ard(name + ".log_lengthscales has " + std::to_string(src.log_lengthscales.size()) +
           " entries, expected D = " + std::to_string(d) + " (columns of the centres)");
    if (src.beta.size() != n)
      fail_se_ard(name + ".beta has " + std::to_string(src.beta.size()) + " entries, expected N = " +
           std::to_string(n) + " (" + rows + ")");
    if (src.Kinv.rows() != n || src.Kinv.cols() != n)
      fail_se_ard(name + ".Kinv is " + shape(src.Kinv.rows(), src.Kinv.cols()) + ", expected N x N = " + shape(n, n));
    if (!src.log_lengthscales.allFinite()) fail_se_ard(name + ".log_lengthscales has a non-finite entry");
    if (!std::isfinite(src.log_signal_std)) fail_se_ard(name + ".log_signal_std is not finite");
    if (!src.beta.allFinite()) fail_se_ard(name + ".beta has a non-finite entry");
    if (!src.Kinv.allFinite()) fail_se_ard(name + ".Kinv has a non-finite entry");
    OutputData o;
    o.centres = std::move(centres[a]);
    o.inverse_squared_lengthscales = (-2.0 * src.log_lengthscales.array()).exp().matrix();
    o.sqrt_w = (-src.log_lengthscales.array()).exp().matrix();
    o.lengthscales = src.log_lengthscales.array().exp().matrix();
    o.log_signal_variance = 2.0 * src.log_signal_std;
    o.signal_variance = std::exp(o.log_signal_variance);
    const auto positive_finite = [](const Vector& v) {
      return v.allFinite() && (v.array() > 0.0).all();
    };
    if (!positive_finite(o.inverse_squared_lengthscales) || !positive_finite(o.lengthscales))
      fail_se_ard(name + ".log_lengthscales out of range (1/l^2 or l^2 overflows)");
    if (!std::isfinite(o.signal_variance) || !(o.signal_variance > 0.0))
      fail_se_ard(name + ".log_signal_std out of range (sf^2 overflows)");
    o.beta = std::move(src.beta);
    o.Kinv = std::move(src.Kinv);
    max_centres_ = std::max(max_centres_, n);
    outputs_.push_back(std::move(o));
  }
  for (std::size_t a = 0; a < outputs_.size(); ++a)
    for (std::size_t b = a; b < outputs_.size(); ++b) pair_order_.emplace_back(a, b);
  const auto work = [this](const std::pair<std::size_t, std::size_t>& p) {
    return static_cast<double>(outputs_[p.first].centres.rows()) * static_cast<double>(outputs_[p.second].centres.rows());
  };
  std::stable_sort(pair_order_.begin(), pair_order_.end(), [&](const auto& x, const auto& y) { return work(x) > work(y); });
  for (const auto& p : pair_order_) pair_work_ += work(p);
}

// ------------------------------------------------------------------------------------------------
// Propagation

void SeArdMomentMatcher::prepare(MomentMatch& out, bool derivatives, int workers) const {
  const Eigen::Index n = max_centres_;
  const Eigen::Index d = input_dim_;
  const Eigen::Index e = static_cast<Eigen::Index>(outputs_.size());
  MomentMatchScratch& s = out.scratch;
  s.sigma.resize(d, d);
  // Per output: rows(a) rows (N_a) by `cols` columns.
  const auto size_all = [this](std::vector<Matrix>& v, bool per_output_rows, Eigen::Index rows, Eigen::Index cols) {
    v.resize(outputs_.size());
    for (std::size_t a = 0; a < outputs_.size(); ++a) v[a].resize(per_output_rows ? outputs_[a].centres.rows() : rows, cols);
  };
  const auto size_all_vectors = [this](std::vector<Vector>& v, bool per_output, Eigen::Index size) {
    v.resize(outputs_.size());
    for (std::size_t a = 0; a < outputs_.size(); ++a) v[a].resize(per_output ? outputs_[a].centres.rows() : size);
  };
  size_all(s.centred, true, 0, d);
  size_all(s.precision, false, d, d);
  size_all(s.precision_lambda, false, d, d);
  size_all(s.solved, true, 0, d);
  size_all(s.scaled, true, 0, d);
  size_all(s.hessian, false, d, d);
  size_all_vectors(s.weighted, true, 0);
  size_all_vectors(s.kernel_mean, true, 0);
  size_all_vectors(s.log_shift, true, 0);
  size_all(s.shrink, false, d, d);
  size_all_vectors(s.gradient, false, d);
  s.log_det.resize(e);
  // Grow only: a MomentMatch that alternates between thread counts keeps its buffers.
  if (s.workers.size() < static_cast<std::size_t>(workers)) s.workers.resize(static_cast<std::size_t>(workers));
  for (MomentMatchWorkerScratch& w : s.workers) {
    for (Matrix* m : {&w.rt, &w.rt_inverse, &w.xi, &w.gain, &w.pair_precision, &w.dd, &w.dd2, &w.inner})
      m->resize(d, d);
    w.nd.resize(n, d);
    w.nd2.resize(n, d);
    for (Vector* v : {&w.row_term, &w.col_term, &w.row_sums, &w.col_sums}) v->resize(n);
    w.nn.resize(n, n);
    for (Vector* v : {&w.sqrt_w_pair, &w.lengthscale_pair, &w.dvec, &w.dvec2}) v->resize(d);
    if (derivatives) {
      w.outer.resize(n, d * d);
      w.omega_v.resize(n, d);
      w.third.resize(d, d * d);
      for (Matrix* m : {&w.pair_shrink, &w.delta_a, &w.delta_b}) m->resize(d, d);
    }
  }
  if (derivatives) {
    size_all_vectors(s.scaled_sum, false, d);
    size_all(s.scaled_scatter, false, d, d);
  }
}

double SeArdMomentMatcher::factor_scaled(const Matrix& sigma, MomentMatchWorkerScratch& w, const Vector& sqrt_w,
                                         std::size_t a, std::size_t b) const {
  w.rt.noalias() = sqrt_w.asDiagonal() * sigma * sqrt_w.asDiagonal();
  w.rt.diagonal().array() += 1.0;
  w.llt.compute(w.rt);
  const auto diagonal = w.llt.matrixLLT().diagonal();
  if (w.llt.info() != Eigen::Success || !diagonal.allFinite() || !(diagonal.array() > 0.0).all()) {
    const std::string what = a == b ? "output " + std::to_string(a)
                                    : "outputs " + std::to_string(a) + " and " + std::to_string(b);
    throw std::invalid_argument(
        "SeArdMomentMatcher::propagate: Sigma is too far from positive semidefinite: "
        "W^1/2 Sigma W^1/2 + I is not positive definite for " + what);
  }
  w.rt_inverse.setIdentity();
  w.llt.solveInPlace(w.rt_inverse);
  return 2.0 * diagonal.array().log().sum();
}

int SeArdMomentMatcher::workers_for(int threads) const {
  if (threads <= 1 || pair_work_ < kParallelPairWork) return 1;
  return std::min(threads, static_cast<int>(pair_order_.size()));
}

void SeArdMomentMatcher::evaluate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out,
                                  bool derivatives) const {
  const int workers = workers_for(out.threads);
  prepare(out, derivatives, workers);
  MomentMatchScratch& s = out.scratch;
  s.sigma = 0.5 * (sigma + sigma.transpose());
  const auto e = static_cast<int>(outputs_.size());
  // The outputs, then the pairs of outputs (largest first), dealt out to the workers; every output
  // and every pair writes its own entries of `out`, so the results do not depend on the split.
  out.fork_join.run(workers, [&](int worker, int count) {
    for (int a = worker; a < e; a += count)
      propagate_mean(out, static_cast<std::size_t>(a), s.workers[static_cast<std::size_t>(worker)], mu, derivatives);
  });
  std::atomic<std::size_t> next_pair{0};
  out.fork_join.run(workers, [&](int worker, int) {
    MomentMatchWorkerScratch& w = s.workers[static_cast<std::size_t>(worker)];
    for (std::size_t p = next_pair++; p < pair_order_.size(); p = next_pair++)
      propagate_covariance(out, pair_order_[p].first, pair_order_[p].second, w, derivatives);
  });
}

void SeArdMomentMatcher::propagate_mean(MomentMatch& out, std::size_t a, MomentMatchWorkerScratch& w,
                                        const VectorCRef& mu, bool derivatives) const {
  MomentMatchScratch& s = out.scratch;
  const Eigen::Index d = input_dim_;
  const OutputData& o = outputs_[a];
  const auto ai = static_cast<Eigen::Index>(a);
  s.centred[a] = o.centres.rowwise() - mu.transpose();
  const Matrix& v = s.centred[a];
  auto nd = view(w.nd, v.rows(), d);
  const double log_det = factor_scaled(s.sigma, w, o.sqrt_w, a, a);
  s.log_det(ai) = log_det;

  Matrix& p = s.precision[a];
  p.noalias() = o.sqrt_w.asDiagonal() * w.rt_inverse * o.sqrt_w.asDiagonal();
  Matrix& p_lambda = s.precision_lambda[a];  // P Lambda = W^1/2 Rt^-1 Lambda^1/2
  p_lambda.noalias() = o.sqrt_w.asDiagonal() * w.rt_inverse * o.lengthscales.asDiagonal();

  Matrix& t = s.solved[a];
  tiled_product(v, p, t);
  // gamma_i = beta_i q_i, q_i = exp(log sf^2 - 1/2 log|Rt| - 1/2 nu_i' P nu_i)
  const double log_c = o.log_signal_variance - 0.5 * log_det;
  Vector& q = s.kernel_mean[a];
  q = t.cwiseProduct(v).rowwise().sum();
  q = (log_c - 0.5 * q.array()).exp().matrix();
  Vector& gamma = s.weighted[a];
  gamma = q.cwiseProduct(o.beta);
  const double m = gamma.sum();
  out.mean(ai) = m;
  Vector& g = s.gradient[a];
  g.noalias() = t.transpose() * gamma;
  out.cross_covariance.col(ai).noalias() = s.sigma * g;

  // For the pairs: A_a = V W_a, B_a = W_a - P_a = W_a^1/2 (I - Rt_a^-1) W_a^1/2 formed without the
  // subtraction W_a - P_a (exactly 0 at Sigma = 0), and c_ai = 1/2 nu_i' B_a nu_i.
  Matrix& scaled = s.scaled[a];
  scaled.noalias() = v * o.inverse_squared_lengthscales.asDiagonal();
  w.dd = -w.rt_inverse;
  w.dd.diagonal().array() += 1.0;
  Matrix& shrink = s.shrink[a];
  shrink.noalias() = o.sqrt_w.asDiagonal() * w.dd * o.sqrt_w.asDiagonal();
  tiled_product(v, shrink, nd);
  s.log_shift[a] = 0.5 * nd.cwiseProduct(v).rowwise().sum();

  if (!derivatives) return;
  // u_a = A_a' gamma_a and E_a = A_a' diag(gamma_a) A_a for the covariance derivatives.
  s.scaled_sum[a].noalias() = scaled.transpose() * gamma;
  nd = scaled;
  nd.array().colwise() *= gamma.array();
  tiled_product(scaled.transpose(), nd, s.scaled_scatter[a]);
  Matrix& h = s.hessian[a];
  nd = t;
  nd.array().colwise() *= gamma.array();
  tiled_product(t.transpose(), nd, h);
  h -= m * p;
  detail::write_mean_derivatives(out, ai, s.sigma, g, h);
  cross_covariance_derivatives(out, a, w);
}

void SeArdMomentMatcher::cross_covariance_derivatives(MomentMatch& out, std::size_t a,
                                                       MomentMatchWorkerScratch& w) const {
  MomentMatchScratch& s = out.scratch;
  const Eigen::Index d = input_dim_;
  const auto ai = static_cast<Eigen::Index>(a);
  const Matrix& t = s.solved[a];

  const Matrix& p = s.precision[a];
  const Matrix& p_lambda = s.precision_lambda[a];
  const Vector& g = s.gradient[a];

  // third(k, i + D j) = sum_n gamma_n s_nk t_ni t_nj with s_n = Sigma t_n: one (D x N) (N x D^2) GEMM.
  auto sigma_t = view(w.nd, t.rows(), d);
  tiled_product(t, s.sigma, sigma_t);
  detail::weighted_third_moment(t, sigma_t, s.weighted[a], view(w.outer, t.rows(), d * d), w.third);

  // Symmetrised: 1/2 third_k - 1/2 C_ka P + 1/2 ((P Lambda)_:k g' + g (P Lambda)_:k').
  for (Eigen::Index k = 0; k < d; ++k) {
    const Eigen::Index row = k + d * ai;
    const double c = out.cross_covariance(k, ai);
    for (Eigen::Index j = 0; j < d; ++j)
      for (Eigen::Index i = 0; i < d; ++i)
        out.dcross_dsigma(row, i + d * j) =
            0.5 * (w.third(k, i + d * j) - c * p(i, j) + p_lambda(i, k) * g(j) + g(i) * p_lambda(j, k));
  }
}

}  // namespace gpilqg::gp
