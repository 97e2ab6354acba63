/// SSGP negative log marginal likelihood and its analytic gradient (formulas in ssgp.hpp).
///
/// Derivation of the gradient: with nlml = (r'r - r'Phi alpha)/(2 sn2) + 0.5 log|A| - m log a + ...,
/// alpha = A^-1 Phi' r and dA = dPhi'Phi + Phi'dPhi (+ da I):
///   d(r'Phi alpha) = r'dPhi alpha + alpha'(dPhi'r - dA alpha) = 2 e'dPhi alpha - da alpha'alpha,
///   d(0.5 log|A|)  = tr(A^-1 Phi' dPhi) + 0.5 da tr(A^-1),
/// so dnlml/dPhi = Phi A^-1 - e alpha'/sn2 and dnlml/da = alpha'alpha/(2 sn2) + tr(A^-1)/2 - m/a.
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
  Matrix Gamma;                    // N x 2m, scratch for dnlml/dPhi
  Matrix PhiTPhi;                  // 2m x 2m, lower triangle
  Matrix L;                        // 2m x 2m, chol(Phi'Phi + a I), lower
  Vector b;                        // 2m, Phi' r
  Vector alpha;                    // 2m
  double rr_minus_ba = 0;          // r'r - b'alpha
  std::vector<Matrix> partial_mm;  // per worker: Phi'Phi over its rows
  std::vector<Matrix> partial_md;  // per worker: Phi' r (2m x 1), then dnlml/dS (m x D)
};

SsgpLikelihood::SsgpLikelihood(const MatrixCRef& X, const VectorCRef& r, int frequencies,
                               JitterSchedule schedule, int threads)
    : X_(X), r_(r), schedule_(schedule), threads_(threads) {
  sparse_detail::validate_likelihood_inputs("SsgpLikelihood", X, r, frequencies, "spectral points", threads);
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
  w.S = layout_.spectral_points(theta) * w.inv_ell.asDiagonal();

  // Per block of training points: features Phi = [cos(X S'), sin(X S')] and the partial sums of
  // Phi'Phi (one rank update) and Phi' r.
  w.workers = static_cast<int>(
      std::max<Eigen::Index>(1, std::min<Eigen::Index>(threads_, N / sparse_detail::kPointsPerWorker)));
  w.Phi.resize(N, 2 * m);
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
    P.selfadjointView<Eigen::Lower>().rankUpdate(Phi.transpose());
    Matrix& b = w.partial_md[static_cast<std::size_t>(worker)];
    b.resize(2 * m, 1);
    b.noalias() = Phi.transpose() * r_.segment(begin, n);
  });
  if (!w.Phi.allFinite()) return sparse_detail::failed_evaluation();
  w.PhiTPhi.setZero(2 * m, 2 * m);
  w.b.setZero(2 * m);
  for (int k = 0; k < w.workers; ++k) {
    w.PhiTPhi.triangularView<Eigen::Lower>() += w.partial_mm[static_cast<std::size_t>(k)];
    w.b += w.partial_md[static_cast<std::size_t>(k)].col(0);
  }

  // A = Phi'Phi + a I = L L' (extra jitter relative to mean(diag(Phi'Phi)) = N/2 when needed).
  NlmlEvaluation e;
  const auto chol =
      sparse_detail::cholesky_with_jitter(w.PhiTPhi, w.a, 0.5 * static_cast<double>(N), schedule_, w.L);
  sparse_detail::merge(chol, e.status, e.jitter);
  if (chol.status == FactorStatus::Failed) return sparse_detail::failed_evaluation(e.jitter);

  // alpha = A^-1 Phi' r.
  w.alpha = w.b;
  w.L.triangularView<Eigen::Lower>().solveInPlace(w.alpha);
  w.L.transpose().triangularView<Eigen::Upper>().solveInPlace(w.alpha);
  w.rr_minus_ba = r_.squaredNorm() - w.b.dot(w.alpha);

  e.value = w.rr_minus_ba / (2.0 * w.sn2) + w.L.diagonal().array().log().sum() -
            static_cast<double>(m) * std::log(w.a) +
            0.5 * static_cast<double>(N) * (sparse_detail::kLog2Pi + std::log(w.sn2));
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

  // Per block: Gamma = Phi A^-1 - e alpha'/sn2 with e = r - Phi alpha; dnlml/dz = Gamma_s .* cos(z)
  // - Gamma_c .* sin(z) (into the left half of Gamma); partial dnlml/dS = (dnlml/dz)' X.
  w.Gamma.resize(N, 2 * m);
  detail::run_workers(w.workers, w.workers, [&](int worker, int workers) {
    const auto [begin, end] = sparse_detail::share(N, worker, workers);
    const Eigen::Index n = end - begin;
    const auto Phi = w.Phi.middleRows(begin, n);
    auto Gamma = w.Gamma.middleRows(begin, n);
    Vector e_block = r_.segment(begin, n);
    e_block.noalias() -= Phi * w.alpha;
    Gamma.noalias() = Phi * Ainv;
    Gamma.noalias() -= e_block * alpha_scaled.transpose();
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
  grad(D + 1) = static_cast<double>(N) - w.rr_minus_ba / w.sn2 + 2.0 * w.a * dnlml_da;

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
