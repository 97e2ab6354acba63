/// SSGP negative log marginal likelihood and its analytic gradient (formulas in ssgp.hpp).
///
/// Weight-space form. With noise variances s_i = sn2 + v_i (v_i known, 0 without known noise),
/// Wn = diag(1/s_i), u_i = sn2 / s_i (U = sn2 Wn) and a = m sn2/sf2, the weights' posterior precision
/// is Sigma_w^-1 = Phi'Wn Phi + (m/sf2) I = A / sn2 with A = Phi'U Phi + a I, their posterior mean
/// Sigma_w Phi'Wn r = A^-1 Phi'U r = alpha, and the Gaussian nlml of y ~ N(0, (sf2/m) Phi Phi' + diag(s))
/// (matrix determinant lemma and Woodbury),
///   nlml = 1/2 r'Wn r - 1/2 (Phi'Wn r)' Sigma_w (Phi'Wn r) + 1/2 log|Sigma_w^-1| + m log(sf2/m)
///          + 1/2 sum_i log s_i + N/2 log(2 pi),
/// is, after log|Sigma_w^-1| = log|A| - 2m log sn2 and m log(sf2/m) = m log sn2 - m log a,
///   nlml = Q / (2 sn2) + 0.5 log|A| - m log a + 1/2 sum_i log s_i + N/2 log(2 pi),   Q = r'U r - b'alpha,
/// with b = Phi'U r. Without known noise U = I and this is ssgpr.m's nlml; that case keeps its own,
/// unweighted arithmetic.
///
/// Derivation of the gradient (jitter j, if any, sits in A = Phi'U Phi + (a + j) I as a constant):
///  - Phi (U, a fixed), dA = dPhi'U Phi + Phi'U dPhi, db = dPhi'U r:
///      dQ = -(2 db'alpha - alpha'dA alpha) = -2 e'U dPhi alpha,   e = r - Phi alpha,
///      d(0.5 log|A|) = tr(A^-1 Phi'U dPhi),
///    so dnlml/dPhi = U (Phi A^-1 - e alpha'/sn2).
///  - a (dA = da I): dQ = alpha'alpha da, d(0.5 log|A|) = 0.5 tr(A^-1) da, so
///    dnlml/da = alpha'alpha/(2 sn2) + tr(A^-1)/2 - m/a; a = m sn2/sf2 gives dnlml/dlog sf = -2a dnlml/da.
///  - q = log sn2 moves sn2 (d sn2 = sn2 dq), a (da = a dq) and u_i (du_i = u_i (1 - u_i) dq). Through
///    U: dQ = e'dU e (db = Phi'dU r, dA = Phi'dU Phi), d(0.5 log|A|) = 0.5 sum_i du_i h_i with
///    h_i = phi_i'A^-1 phi_i; and d(1/2 sum log s_i) = 1/2 sum_i u_i dq. Hence
///      dnlml/dq = -Q/(2 sn2) + a dnlml/da + 1/2 sum_i u_i + 1/2 sum_i u_i (1 - u_i) (e_i^2/sn2 + h_i),
///    and dnlml/dlog sn = 2 dnlml/dq. Without known noise u_i = 1: N - Q/sn2 + 2a dnlml/da.
/// Phi_ir = cos(z_ir), Phi_i,m+r = sin(z_ir), z_ir = s_r'x_i, s_rd = W_rd / l_d chain the rest.

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpilqg/gp/ssgp.hpp"
#include "gpilqg/core/workspace.hpp"
#include "parallel.hpp"
#include "sparse_linalg.hpp"
#include "ssgp_sincos.hpp"

namespace gpilqg::gp {

struct SsgpLikelihood::Workspace final : LikelihoodWorkspace {
  Vector inv_ell;  // 1 / l (D)
  double sf2 = 0, sn2 = 0, a = 0;
  int workers = 1;                 // threads splitting the N training points into blocks of rows
  Matrix S;                        // m x D, W ./ l'
  Matrix Phi;                      // N x 2m, [cos(X S'), sin(X S')]
  Matrix Gamma;                    // N x 2m, scratch: U^(1/2) Phi (known noise), then dnlml/dPhi
  Vector u;                        // N, sn2 / (sn2 + v_i) (known noise only)
  Matrix PhiTPhi;                  // 2m x 2m, lower triangle of Phi'U Phi
  Matrix L;                        // 2m x 2m, chol(Phi'U Phi + a I), lower
  Vector b;                        // 2m, Phi'U r
  Vector alpha;                    // 2m
  double rr_minus_ba = 0;          // Q = r'U r - b'alpha
  std::vector<Matrix> partial_mm;  // per worker: Phi'U Phi over its rows
  std::vector<Matrix> partial_md;  // per worker: Phi'U r (2m x 1), then dnlml/dS (m x D)
  std::vector<double> partial_u;   // per worker: sum u_i (1 - u_i) (e_i^2/sn2 + h_i) (known noise only)
};

namespace {

/// Throws std::invalid_argument unless `v` is empty or holds N finite values >= 0.
void validate_known_noise(const VectorCRef& v, Eigen::Index N) {
  if (v.size() != 0 && v.size() != N)
    throw std::invalid_argument("SsgpLikelihood: " + std::to_string(v.size()) + " known noise variances for " +
                                std::to_string(N) + " targets; expected " + std::to_string(N) + " or none");
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!(std::isfinite(v(i)) && v(i) >= 0.0))
      throw std::invalid_argument("SsgpLikelihood: known noise variance " + std::to_string(i) + " is " +
                                  std::to_string(v(i)) + "; expected a finite value >= 0");
}

/// u_i = sn2 / (sn2 + v_i), each in (0, 1]; false when one is not a positive finite number.
bool noise_weights(const Vector& v, double sn2, Vector& u) {
  u = (sn2 / (sn2 + v.array())).matrix();
  return u.allFinite() && (u.array() > 0.0).all();
}

/// The noise terms of the nlml, 1/2 sum_i log(sn2 + v_i) + N/2 log(2 pi) (N/2 log(2 pi sn2) without
/// known noise).
double noise_log_terms(const Vector& v, double sn2, Eigen::Index N) {
  if (v.size() == 0) return 0.5 * static_cast<double>(N) * (sparse_detail::kLog2Pi + std::log(sn2));
  return 0.5 * (static_cast<double>(N) * sparse_detail::kLog2Pi + (sn2 + v.array()).log().sum());
}

}  // namespace

SsgpLikelihood::SsgpLikelihood(const MatrixCRef& X, const VectorCRef& r, int frequencies,
                               JitterSchedule schedule, int threads, const VectorCRef& noise_variance)
    : X_(X), r_(r), known_(noise_variance), schedule_(schedule), threads_(threads) {
  sparse_detail::validate_likelihood_inputs("SsgpLikelihood", X, r, frequencies, "spectral points", threads);
  validate_known_noise(noise_variance, r.size());
  schedule.validate();
  layout_ = SsgpLayout{static_cast<int>(X.cols()), frequencies};
}

std::unique_ptr<LikelihoodWorkspace> SsgpLikelihood::make_workspace() const {
  return std::make_unique<Workspace>();
}

NlmlEvaluation SsgpLikelihood::factorise(const VectorCRef& theta, Workspace& w) const {
  if (theta.size() != layout_.size())
    throw std::invalid_argument("SsgpLikelihood: parameter vector has " + std::to_string(theta.size()) +
                                " entries, expected " + std::to_string(layout_.size()) +
                                " (D = " + std::to_string(layout_.input_dim) +
                                ", m = " + std::to_string(layout_.frequencies) + ")");
  if (!theta.allFinite()) return sparse_detail::failed_evaluation();
  const int D = layout_.input_dim;
  const int m = layout_.frequencies;
  const Eigen::Index N = X_.rows();

  w.inv_ell = (-theta.head(D)).array().exp();
  w.sf2 = std::exp(2.0 * theta(D));
  w.sn2 = std::exp(2.0 * theta(D + 1));
  w.a = static_cast<double>(m) * w.sn2 / w.sf2;
  if (!w.inv_ell.allFinite() || !std::isfinite(w.sf2) || !(w.sf2 > 0.0) || !std::isfinite(w.sn2) ||
      !(w.sn2 > 0.0) || !std::isfinite(w.a) || !(w.a > 0.0))
    return sparse_detail::failed_evaluation();
  const bool known = known_.size() > 0;
  if (known && !noise_weights(known_, w.sn2, w.u)) return sparse_detail::failed_evaluation();
  w.S = layout_.spectral_points(theta) * w.inv_ell.asDiagonal();

  // Per block of training points: features Phi = [cos(X S'), sin(X S')] and the partial sums of
  // Phi'U Phi (one rank update, of U^(1/2) Phi with known noise) and Phi'U r.
  w.workers = static_cast<int>(
      std::max<Eigen::Index>(1, std::min<Eigen::Index>(threads_, N / sparse_detail::kPointsPerWorker)));
  w.Phi.resize(N, 2 * m);
  if (known) w.Gamma.resize(N, 2 * m);
  w.partial_mm.resize(static_cast<std::size_t>(w.workers));
  w.partial_md.resize(static_cast<std::size_t>(w.workers));
  detail::run_workers(w.workers, w.workers, [&](int worker, int workers) {
    const auto [begin, end] = sparse_detail::share(N, worker, workers);
    const Eigen::Index n = end - begin;
    auto Phi = w.Phi.middleRows(begin, n);
    Phi.leftCols(m).noalias() = X_.middleRows(begin, n) * w.S.transpose();
    for (Eigen::Index r = 0; r < m; ++r)
      ssgp_detail::sincos_many(&w.Phi(begin, r), &w.Phi(begin, r), &w.Phi(begin, m + r), n);
    Matrix& P = w.partial_mm[static_cast<std::size_t>(worker)];
    P.setZero(2 * m, 2 * m);
    Matrix& b = w.partial_md[static_cast<std::size_t>(worker)];
    b.resize(2 * m, 1);
    if (known) {
      const auto u = w.u.segment(begin, n).array();
      auto root_u_Phi = w.Gamma.middleRows(begin, n);
      root_u_Phi.array() = Phi.array().colwise() * u.sqrt();
      P.selfadjointView<Eigen::Lower>().rankUpdate(root_u_Phi.transpose());
      b.noalias() = Phi.transpose() * (u * r_.segment(begin, n).array()).matrix();
    } else {
      P.selfadjointView<Eigen::Lower>().rankUpdate(Phi.transpose());
      b.noalias() = Phi.transpose() * r_.segment(begin, n);
    }
  });
  if (!w.Phi.allFinite()) return sparse_detail::failed_evaluation();
  w.PhiTPhi.setZero(2 * m, 2 * m);
  w.b.setZero(2 * m);
  for (int k = 0; k < w.workers; ++k) {
    w.PhiTPhi.triangularView<Eigen::Lower>() += w.partial_mm[static_cast<std::size_t>(k)];
    w.b += w.partial_md[static_cast<std::size_t>(k)].col(0);
  }

  // A = Phi'U Phi + a I = L L' (extra jitter when needed, relative to N/2 = mean(diag(Phi'Phi)) >=
  // mean(diag(Phi'U Phi)): a constant, so the gradient stays exact).
  NlmlEvaluation e;
  const auto chol =
      sparse_detail::cholesky_with_jitter(w.PhiTPhi, w.a, 0.5 * static_cast<double>(N), schedule_, w.L);
  sparse_detail::merge(chol, e.status, e.jitter);
  if (chol.status == FactorStatus::Failed) return sparse_detail::failed_evaluation(e.jitter);

  // alpha = A^-1 Phi'U r.
  w.alpha = w.b;
  w.L.triangularView<Eigen::Lower>().solveInPlace(w.alpha);
  w.L.transpose().triangularView<Eigen::Upper>().solveInPlace(w.alpha);
  const double rUr = known ? r_.dot(w.u.cwiseProduct(r_)) : r_.squaredNorm();
  w.rr_minus_ba = rUr - w.b.dot(w.alpha);

  e.value = w.rr_minus_ba / (2.0 * w.sn2) + w.L.diagonal().array().log().sum() -
            static_cast<double>(m) * std::log(w.a) + noise_log_terms(known_, w.sn2, N);
  if (!std::isfinite(e.value)) return sparse_detail::failed_evaluation(e.jitter);
  return e;
}

NlmlEvaluation SsgpLikelihood::evaluate(const VectorCRef& theta, Vector* gradient) const {
  const auto workspace = make_workspace();
  return evaluate(theta, gradient, *workspace);
}

NlmlEvaluation SsgpLikelihood::evaluate(const VectorCRef& theta, Vector* gradient,
                                        LikelihoodWorkspace& workspace) const {
  Workspace& w = workspace_as<Workspace>(workspace);
  const NlmlEvaluation e = factorise(theta, w);
  if (e.status == FactorStatus::Failed) {
    if (gradient != nullptr) gradient->setZero(layout_.size());
    return e;
  }
  if (gradient == nullptr) return e;
  const int D = layout_.input_dim;
  const int m = layout_.frequencies;
  const Eigen::Index N = X_.rows();

  Matrix Ainv = Matrix::Identity(2 * m, 2 * m);
  w.L.triangularView<Eigen::Lower>().solveInPlace(Ainv);
  w.L.transpose().triangularView<Eigen::Upper>().solveInPlace(Ainv);
  const Vector alpha_scaled = w.alpha / w.sn2;
  const bool known = known_.size() > 0;

  // Per block: Gamma = U (Phi A^-1 - e alpha'/sn2) with e = r - Phi alpha; dnlml/dz = Gamma_s .* cos(z)
  // - Gamma_c .* sin(z) (into the left half of Gamma); partial dnlml/dS = (dnlml/dz)' X. With known
  // noise also the partial sum of u_i (1 - u_i) (e_i^2/sn2 + h_i), h_i = (Phi A^-1)_i . phi_i, where
  // 1 - u_i = v_i / (sn2 + v_i) is formed without cancellation.
  w.Gamma.resize(N, 2 * m);
  w.partial_u.assign(static_cast<std::size_t>(w.workers), 0.0);
  detail::run_workers(w.workers, w.workers, [&](int worker, int workers) {
    const auto [begin, end] = sparse_detail::share(N, worker, workers);
    const Eigen::Index n = end - begin;
    const auto Phi = w.Phi.middleRows(begin, n);
    auto Gamma = w.Gamma.middleRows(begin, n);
    Vector e_block = r_.segment(begin, n);
    e_block.noalias() -= Phi * w.alpha;
    Gamma.noalias() = Phi * Ainv;
    if (known) {
      const auto u = w.u.segment(begin, n).array();
      const auto v = known_.segment(begin, n).array();
      const Vector h = (Gamma.array() * Phi.array()).rowwise().sum();
      w.partial_u[static_cast<std::size_t>(worker)] =
          (u * (v / (w.sn2 + v)) * (e_block.array().square() / w.sn2 + h.array())).sum();
    }
    Gamma.noalias() -= e_block * alpha_scaled.transpose();
    if (known) Gamma.array().colwise() *= w.u.segment(begin, n).array();
    Gamma.leftCols(m).array() = Gamma.rightCols(m).array() * Phi.leftCols(m).array() -
                                Gamma.leftCols(m).array() * Phi.rightCols(m).array();
    Matrix& GS = w.partial_md[static_cast<std::size_t>(worker)];
    GS.resize(m, D);
    GS.noalias() = Gamma.leftCols(m).transpose() * X_.middleRows(begin, n);
  });
  Matrix GS = Matrix::Zero(m, D);  // dnlml/dS
  for (int k = 0; k < w.workers; ++k) GS += w.partial_md[static_cast<std::size_t>(k)];

  gradient->resize(layout_.size());
  Vector& grad = *gradient;
  for (int d = 0; d < D; ++d) {
    grad(d) = -GS.col(d).dot(w.S.col(d));
    grad.segment(layout_.spectral_offset() + d * m, m) = GS.col(d) * w.inv_ell(d);
  }
  const double dnlml_da =
      w.alpha.squaredNorm() / (2.0 * w.sn2) + 0.5 * Ainv.trace() - static_cast<double>(m) / w.a;
  grad(D) = -2.0 * w.a * dnlml_da;
  if (known) {
    double weighted = 0.0;
    for (int k = 0; k < w.workers; ++k) weighted += w.partial_u[static_cast<std::size_t>(k)];
    grad(D + 1) = w.u.sum() - w.rr_minus_ba / w.sn2 + 2.0 * w.a * dnlml_da + weighted;
  } else {
    grad(D + 1) = static_cast<double>(N) - w.rr_minus_ba / w.sn2 + 2.0 * w.a * dnlml_da;
  }

  if (!grad.allFinite()) {
    grad.setZero();
    return sparse_detail::failed_evaluation(e.jitter);
  }
  return e;
}

SsgpPredictor SsgpLikelihood::predictor(const VectorCRef& theta, ConditioningReport* report) const {
  Workspace w;
  const NlmlEvaluation e = factorise(theta, w);
  if (e.status == FactorStatus::Failed)
    throw std::runtime_error(
        "SSGP: no positive definite factorisation at these parameters, even with "
        "jitter up to " +
        std::to_string(schedule_.last) + " times N/2");
  if (report != nullptr) {
    report->status = e.status;
    report->jitter = e.jitter;
    report->negative_log_marginal_likelihood = e.value;
  }
  const int m = layout_.frequencies;
  SsgpPredictor p;
  p.S_ = w.S;
  p.alpha_ = w.alpha;
  Matrix C = Matrix::Identity(2 * m, 2 * m);
  w.L.triangularView<Eigen::Lower>().solveInPlace(C);
  w.L.transpose().triangularView<Eigen::Upper>().solveInPlace(C);
  p.C_ = (0.5 * w.sn2) * (C + C.transpose());
  return p;
}

}  // namespace gpilqg::gp
