/// FITC negative log marginal likelihood and its analytic gradient (see fitc.hpp for the model).
///
/// Derivation of the gradient (our own, in the notation of fitc.hpp; it agrees with GPML infFITC's
/// and Snelson's spgp_lik but is arranged as six O(N M^2) matrix products and no per-parameter
/// N x M temporaries). With C = Qff + Lambda, Lambda = diag(max(Kff - Qff, 0)) + sn2 I + diag(v) (v the
/// known noise variances, constant), alpha = C^-1 r and G = C^-1 - alpha alpha',
///
///   dnlZ = 0.5 tr(G dC),   dC = dQ + dLambda,   dQ = dKuf' B + B' dKuf - B' dKuu B,  B = Kuu^-1 Kuf,
///   dLambda = diag(mask .* (ddiag(Kff) - diag(dQ))) + dsn2 I,   mask_i = [Kff_ii - Qff_ii > 0].
///
/// Collecting terms with h = mask .* diag(G):
///
///   dnlZ/dKuf  = P = B G - B diag(h)                          (M x N)
///   dnlZ/dKuu  = -0.5 P B'                                    (M x M, symmetric)
///   dnlZ/ddiag(Kff) = 0.5 h,     dnlZ/dsn2 = 0.5 tr(G)        (the sn2 term is not clipped)
///
/// The identities B C^-1 = Sigma^-1 Kuf Lambda^-1 (Sigma = Kuu + Kuf Lambda^-1 Kfu = Luu A Luu'),
/// B alpha = beta = Luu^-T gamma and Kuf Lambda^-1 Kfu = Sigma - Kuu turn these into
///
///   P      = X1 Lambda^-1 - B diag(h) - beta alpha',       X1 = Sigma^-1 Kuf = (Luu^-T A^-1) V,
///   P B'   = Kuu^-1 - Sigma^-1 - B diag(h) B' - beta beta',  Kuu^-1 - Sigma^-1 = Luu^-T (I - A^-1) Luu^-1,
///   diag(G)_i = 1/Lambda_i - (Kfu X1)_ii / Lambda_i^2 - alpha_i^2.
///
/// Cost: V = Luu^-1 Kuf (triangular solve), A (rank-N update), X1 (one M x M by M x N product),
/// B = Luu^-T V (triangular solve, in place), B diag(h) B' (triangular product): six M^2 N flop
/// units; everything else is O(N M + M^3 + N M D).
///
/// The SE kernel's derivatives then contract as (on scaled inputs xs = x ./ l, E = P .* Kuf,
/// F = dnlZ/dKuu .* k(Xu, Xu) without jitter):
///
///   dnlZ/dlog l_d  = sum_mi E_mi (xus_md - xs_id)^2 + sum_mn F_mn (xus_md - xus_nd)^2
///   dnlZ/dxu_md    = [ (E Xs)_md - xus_md (E 1)_m + 2 (F Xus)_md - 2 xus_md (F 1)_m ] / l_d
///   dnlZ/dlog sf   = 2 sum(E) + 2 <dnlZ/dKuu, Kuu_jit> + sf2 sum(h)
///   dnlZ/dlog sn   = sn2 tr(G)
///
/// where Kuu_jit includes snu2 under the relative jitter rule (snu2 = 1e-6 sf2 scales with sf2) and
/// excludes it under the fixed rule; jitter added by escalation (relative to sf2) is always included.
/// The squared distances are expanded as sums of matrix products (E Xs, etc.), with the inputs
/// centred first to limit cancellation.
///
/// The N training points are processed in blocks of columns (one per thread), with per-block partial
/// sums of the M x M and M x D quantities added afterwards.

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/core/workspace.hpp"
#include "blas_lapack.hpp"
#include "parallel.hpp"
#include "sparse_linalg.hpp"

namespace gpilqg::gp {

using sparse_detail::cholesky_with_jitter;
namespace blas = detail::blas;

struct FitcLikelihood::Workspace final : LikelihoodWorkspace {
  Vector inv_ell;  // 1 / l (D)
  double sf2 = 0, sn2 = 0;
  double snu2 = 0;   // total jitter on Kuu (rule + escalation)
  double dsnu2 = 0;  // d snu2 / d log sf
  int workers = 1;   // threads splitting the N training points into blocks of columns
  Matrix Xs;         // N x D, centred and scaled training inputs
  Matrix Xu;         // M x D, pseudo-inputs (original coordinates)
  Matrix Xus;        // M x D, centred and scaled pseudo-inputs
  Matrix Kuu;        // M x M, without jitter
  Matrix Luu;        // M x M, chol(Kuu + snu2 I), lower
  Matrix U;          // M x N, Kuf
  Matrix V;          // M x N, Luu^-1 Kuf (B = Kuu^-1 Kuf after a gradient evaluation)
  Matrix Y;          // M x N, scratch (V Lambda^-1/2, then Sigma^-1 Kuf, then E)
  Matrix Z;          // M x N, scratch (B diag(h))
  Vector g;          // N, diag(Lambda)
  Vector mask;       // N, 1 where diag(Kff - Qff) > 0 else 0
  Vector Gdiag;      // N, diag((Qff + Lambda)^-1 - alpha alpha')
  Vector h;          // N, mask .* Gdiag
  Matrix A;          // M x M, I + V Lambda^-1 V'
  Matrix La;         // M x M, chol(A), lower
  Vector gamma;      // M
  Vector alpha;      // N
  // Per-worker partial sums over the worker's block of training points.
  std::vector<Matrix> partial_mm;  // M x M: V Lambda^-1 V', then B diag(h) B'
  std::vector<Matrix> partial_md;  // M x (D + 2): E Xs | E 1 | V Lambda^-1 r
  std::vector<Vector> partial_d;   // D + 2: sum_i (E'1)_i xs_id^2 | sum h | sum Gdiag
};

FitcLikelihood::FitcLikelihood(const MatrixCRef& X, const VectorCRef& r, int inducing, FitcJitter jitter,
                               JitterSchedule schedule, int threads, const Vector& known_noise)
    : X_(X),
      r_(r),
      known_noise_(known_noise.size() ? known_noise : Vector(Vector::Zero(X.rows()))),
      jitter_(jitter),
      schedule_(schedule),
      threads_(threads) {
  sparse_detail::validate_likelihood_inputs("FitcLikelihood", X, r, inducing, "pseudo-inputs", threads);
  if (known_noise_.size() != X.rows() || !known_noise_.allFinite() || (known_noise_.array() < 0.0).any())
    throw std::invalid_argument("FitcLikelihood: the known noise variances must be " + std::to_string(X.rows()) +
                                " finite numbers >= 0, one per training point");
  jitter.validate();
  schedule.validate();
  layout_ = FitcLayout{static_cast<int>(X.cols()), inducing};
  centre_ = X_.colwise().mean().transpose();
}

std::unique_ptr<LikelihoodWorkspace> FitcLikelihood::make_workspace() const {
  return std::make_unique<Workspace>();
}

NlmlEvaluation FitcLikelihood::factorise(const VectorCRef& theta, Workspace& w) const {
  if (theta.size() != layout_.size())
    throw std::invalid_argument("FitcLikelihood: parameter vector has " + std::to_string(theta.size()) +
                                " entries, expected " + std::to_string(layout_.size()) +
                                " (D = " + std::to_string(layout_.input_dim) +
                                ", M = " + std::to_string(layout_.inducing) + ")");
  if (!theta.allFinite()) return sparse_detail::failed_evaluation();
  const int D = layout_.input_dim;
  const int M = layout_.inducing;
  const Eigen::Index N = X_.rows();

  w.inv_ell = (-theta.head(D)).array().exp();
  w.sf2 = std::exp(2.0 * theta(D));
  w.sn2 = std::exp(2.0 * theta(D + 1));
  if (!w.inv_ell.allFinite() || !(w.inv_ell.array() > 0.0).all() || !std::isfinite(w.sf2) || !(w.sf2 > 0.0) ||
      !std::isfinite(w.sn2))
    return sparse_detail::failed_evaluation();

  w.Xu = layout_.inducing_inputs(theta);
  w.Xus = (w.Xu.rowwise() - centre_.transpose()) * w.inv_ell.asDiagonal();
  w.Xs = (X_.rowwise() - centre_.transpose()) * w.inv_ell.asDiagonal();

  // Kuu + snu2 I (GPML: snu2 = 1e-6 trace(Kuu)/M), more jitter (relative to sf2) if that fails.
  NlmlEvaluation e;
  sparse_detail::se_covariance(w.Xus, w.sf2, w.Kuu);
  const double base = jitter_.jitter(w.sf2);
  const auto chol_u = cholesky_with_jitter(w.Kuu, base, w.sf2, schedule_, w.Luu);
  sparse_detail::merge(chol_u, e.status, e.jitter);
  if (chol_u.status == FactorStatus::Failed) return sparse_detail::failed_evaluation(e.jitter);
  w.snu2 = base + chol_u.extra_jitter;
  w.dsnu2 = 2.0 * ((jitter_.kind == FitcJitterKind::Relative ? base : 0.0) + chol_u.extra_jitter);

  // Per block of training points: Kuf, V = Luu^-1 Kuf, Lambda = max(diag(Kff - Qff), 0) + sn2, and
  // the partial sums of V Lambda^-1 V' and V Lambda^-1 r.
  w.workers = static_cast<int>(
      std::max<Eigen::Index>(1, std::min<Eigen::Index>(threads_, N / sparse_detail::kPointsPerWorker)));
  w.U.resize(M, N);
  w.V.resize(M, N);
  w.Y.resize(M, N);
  w.g.resize(N);
  w.mask.resize(N);
  w.partial_mm.resize(static_cast<std::size_t>(w.workers));
  w.partial_md.resize(static_cast<std::size_t>(w.workers));
  detail::run_workers(w.workers, w.workers, [&](int worker, int workers) {
    const auto [begin, end] = sparse_detail::share(N, worker, workers);
    const Eigen::Index n = end - begin;
    auto U = w.U.middleCols(begin, n);
    auto V = w.V.middleCols(begin, n);
    auto Y = w.Y.middleCols(begin, n);
    sparse_detail::se_cross_covariance(w.Xus, w.Xs.middleRows(begin, n), w.sf2, U);
    V = U;
    blas::solve_lower(blas::Side::Left, blas::Transpose::No, w.Luu, V);
    for (Eigen::Index i = begin; i < end; ++i) {
      const double d = w.sf2 - w.V.col(i).squaredNorm();
      w.mask(i) = d > 0.0 ? 1.0 : 0.0;
      w.g(i) = std::max(d, 0.0) + w.sn2 + known_noise_(i);
    }
    Y = V * w.g.segment(begin, n).cwiseSqrt().cwiseInverse().asDiagonal();
    Matrix& A = w.partial_mm[static_cast<std::size_t>(worker)];
    A.setZero(M, M);
    blas::rank_update_lower(1.0, Y, blas::Transpose::No, 0.0, A);
    Matrix& md = w.partial_md[static_cast<std::size_t>(worker)];
    md.resize(M, D + 2);
    md.col(D + 1).noalias() = V * r_.segment(begin, n).cwiseQuotient(w.g.segment(begin, n));
  });
  if (!w.g.allFinite() || !(w.g.array() > 0.0).all()) return sparse_detail::failed_evaluation(e.jitter);

  // A = I + V Lambda^-1 V' = La La' (positive definite by construction; escalation as a safeguard).
  w.A.setIdentity(M, M);
  w.gamma.setZero(M);
  for (int k = 0; k < w.workers; ++k) {
    w.A.triangularView<Eigen::Lower>() += w.partial_mm[static_cast<std::size_t>(k)];
    w.gamma += w.partial_md[static_cast<std::size_t>(k)].col(D + 1);
  }
  const auto chol_a = cholesky_with_jitter(w.A, 0.0, 1.0, schedule_, w.La);
  sparse_detail::merge(chol_a, e.status, e.jitter);
  if (chol_a.status == FactorStatus::Failed) return sparse_detail::failed_evaluation(e.jitter);

  // gamma = A^-1 V Lambda^-1 r,  alpha = Lambda^-1 (r - V' gamma) = (Qff + Lambda)^-1 r.
  w.La.triangularView<Eigen::Lower>().solveInPlace(w.gamma);
  w.La.transpose().triangularView<Eigen::Upper>().solveInPlace(w.gamma);
  w.alpha = r_;
  w.alpha.noalias() -= w.V.transpose() * w.gamma;
  w.alpha.array() /= w.g.array();

  e.value = 0.5 * r_.dot(w.alpha) + w.La.diagonal().array().log().sum() + 0.5 * w.g.array().log().sum() +
            0.5 * static_cast<double>(N) * sparse_detail::kLog2Pi;
  if (!std::isfinite(e.value)) return sparse_detail::failed_evaluation(e.jitter);
  return e;
}

NlmlEvaluation FitcLikelihood::evaluate(const VectorCRef& theta, Vector* gradient) const {
  const auto workspace = make_workspace();
  return evaluate(theta, gradient, *workspace);
}

NlmlEvaluation FitcLikelihood::evaluate(const VectorCRef& theta, Vector* gradient,
                                        LikelihoodWorkspace& workspace) const {
  Workspace& w = workspace_as<Workspace>(workspace);
  const NlmlEvaluation e = factorise(theta, w);
  if (e.status == FactorStatus::Failed) {
    if (gradient != nullptr) gradient->setZero(layout_.size());
    return e;
  }
  if (gradient == nullptr) return e;
  const int D = layout_.input_dim;
  const int M = layout_.inducing;
  const Eigen::Index N = X_.rows();

  // R1 = Luu^-T A^-1, so that Sigma^-1 Kuf = R1 V (one product instead of two triangular solves).
  Matrix Ainv = Matrix::Identity(M, M);
  w.La.triangularView<Eigen::Lower>().solveInPlace(Ainv);
  w.La.transpose().triangularView<Eigen::Upper>().solveInPlace(Ainv);
  Matrix R1 = Ainv;
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(R1);
  Vector beta = w.gamma;  // beta = Luu^-T gamma = B alpha
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(beta);

  // Per block: X1 = Sigma^-1 Kuf; diag(G) = 1/Lambda - diag(Kfu X1)/Lambda^2 - alpha.^2 (note
  // diag(Kfu Sigma^-1 Kuf) = diag(V' A^-1 V)); h = mask .* diag(G); B = Luu^-T V = Kuu^-1 Kuf in place
  // of V; Z = B diag(h) and the partial sums of B diag(h) B' (one triangular product).
  w.Z.resize(M, N);
  w.Gdiag.resize(N);
  w.h.resize(N);
  w.partial_d.resize(static_cast<std::size_t>(w.workers));
  detail::run_workers(w.workers, w.workers, [&](int worker, int workers) {
    const auto [begin, end] = sparse_detail::share(N, worker, workers);
    const Eigen::Index n = end - begin;
    auto V = w.V.middleCols(begin, n);
    auto Y = w.Y.middleCols(begin, n);
    auto Z = w.Z.middleCols(begin, n);
    blas::multiply(1.0, R1, blas::Transpose::No, V, blas::Transpose::No, 0.0, Y);
    for (Eigen::Index i = begin; i < end; ++i) {
      const double s = w.U.col(i).dot(w.Y.col(i));
      const double gi = w.g(i);
      w.Gdiag(i) = 1.0 / gi - s / (gi * gi) - w.alpha(i) * w.alpha(i);
      w.h(i) = w.mask(i) * w.Gdiag(i);
    }
    blas::solve_lower(blas::Side::Left, blas::Transpose::Yes, w.Luu, V);
    Z = V * w.h.segment(begin, n).asDiagonal();
    Matrix& H = w.partial_mm[static_cast<std::size_t>(worker)];
    H.resize(M, M);
    blas::multiply(1.0, Z, blas::Transpose::No, V, blas::Transpose::Yes, 0.0, H);  // symmetric; lower used
    // P = dnlZ/dKuf = X1 Lambda^-1 - B diag(h) - beta alpha'; E = P .* Kuf, then its contractions.
    for (Eigen::Index i = begin; i < end; ++i) {
      auto col = w.Y.col(i);
      col = (col / w.g(i) - w.Z.col(i) - beta * w.alpha(i)).cwiseProduct(w.U.col(i));
    }
    const auto Xs = w.Xs.middleRows(begin, n);
    Matrix& md = w.partial_md[static_cast<std::size_t>(worker)];
    md.leftCols(D).noalias() = Y * Xs;  // E Xs
    md.col(D) = Y.rowwise().sum();      // E 1
    const Vector eT = Y.colwise().sum().transpose();
    Vector& d = w.partial_d[static_cast<std::size_t>(worker)];
    d.resize(D + 2);
    d.head(D).noalias() = Xs.cwiseAbs2().transpose() * eT;  // sum_i (E'1)_i xs_id^2
    d(D) = w.h.segment(begin, n).sum();
    d(D + 1) = w.Gdiag.segment(begin, n).sum();
  });
  Matrix H = Matrix::Zero(M, M);
  Matrix EX = Matrix::Zero(M, D);
  Vector e1 = Vector::Zero(M), sums = Vector::Zero(D + 2);
  for (int k = 0; k < w.workers; ++k) {
    H.triangularView<Eigen::Lower>() += w.partial_mm[static_cast<std::size_t>(k)];
    EX += w.partial_md[static_cast<std::size_t>(k)].leftCols(D);
    e1 += w.partial_md[static_cast<std::size_t>(k)].col(D);
    sums += w.partial_d[static_cast<std::size_t>(k)];
  }

  // dnlZ/dKuu = -0.5 P B' = -0.5 [Kuu^-1 - Sigma^-1 - B diag(h) B' - beta beta'],
  // Kuu^-1 - Sigma^-1 = Luu^-T (I - A^-1) Luu^-1.
  Matrix Akuu = Matrix::Identity(M, M) - Ainv;
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(Akuu);  // Luu^-T (I - A^-1)
  Akuu.transposeInPlace();                                              // (I - A^-1) Luu^-1
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(Akuu);  // Luu^-T (I - A^-1) Luu^-1
  Akuu.noalias() -= beta * beta.transpose();
  Akuu.triangularView<Eigen::Lower>() -= H;
  Akuu.triangularView<Eigen::StrictlyUpper>() = Akuu.transpose();
  Akuu *= -0.5;

  const Matrix F = Akuu.cwiseProduct(w.Kuu);  // M x M (jitter excluded)
  const Matrix FX = F * w.Xus;                // M x D
  const Vector f1 = F.rowwise().sum();        // M

  gradient->resize(layout_.size());
  Vector& grad = *gradient;
  const Matrix Xus2 = w.Xus.cwiseAbs2();
  for (int d = 0; d < D; ++d) {
    const double u_part = Xus2.col(d).dot(e1) - 2.0 * w.Xus.col(d).dot(EX.col(d)) + sums(d);
    const double k_part = 2.0 * (Xus2.col(d).dot(f1) - w.Xus.col(d).dot(FX.col(d)));
    grad(d) = u_part + k_part;
    grad.segment(layout_.inducing_offset() + d * M, M) =
        ((EX.col(d) - w.Xus.col(d).cwiseProduct(e1)) + 2.0 * (FX.col(d) - w.Xus.col(d).cwiseProduct(f1))) *
        w.inv_ell(d);
  }
  grad(D) = 2.0 * e1.sum() + 2.0 * Akuu.cwiseProduct(w.Kuu).sum() + w.dsnu2 * Akuu.trace() + w.sf2 * sums(D);
  grad(D + 1) = w.sn2 * sums(D + 1);

  if (!grad.allFinite()) {
    grad.setZero();
    return sparse_detail::failed_evaluation(e.jitter);
  }
  return e;
}

FitcPredictor FitcLikelihood::predictor(const VectorCRef& theta, ConditioningReport* report) const {
  Workspace w;
  const NlmlEvaluation e = factorise(theta, w);
  if (e.status == FactorStatus::Failed)
    throw std::runtime_error(
        "FITC: no positive definite factorisation at these parameters, even with "
        "jitter up to " +
        std::to_string(schedule_.last) + " times the mean diagonal");
  if (report != nullptr) {
    report->status = e.status;
    report->jitter = e.jitter;
    report->negative_log_marginal_likelihood = e.value;
  }
  const int M = layout_.inducing;
  FitcPredictor p;
  p.inv_lengthscale_ = w.inv_ell;
  p.sf2_ = w.sf2;
  p.inducing_inputs_ = w.Xu;
  p.scaled_inducing_ = w.Xu * w.inv_ell.asDiagonal();
  // beta = Luu^-T gamma;  C = Luu^-T (A^-1 - I) Luu^-1.
  p.beta_ = w.gamma;
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(p.beta_);
  Matrix Ainv = Matrix::Identity(M, M);
  w.La.triangularView<Eigen::Lower>().solveInPlace(Ainv);
  w.La.transpose().triangularView<Eigen::Upper>().solveInPlace(Ainv);
  Matrix C = Ainv - Matrix::Identity(M, M);
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(C);
  C.transposeInPlace();
  w.Luu.transpose().triangularView<Eigen::Upper>().solveInPlace(C);
  p.C_ = 0.5 * (C + C.transpose());
  return p;
}

}  // namespace gpilqg::gp
