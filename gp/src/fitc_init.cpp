/// Initial pseudo-inputs for FITC: k-means++ seeding (Arthur & Vassilvitskii 2007, "k-means++: the
/// advantages of careful seeding") followed by Lloyd iterations, or a uniform random subset.

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/training_set.hpp"

namespace gpilqg::gp {

namespace {

/// Squared distance from every row of Xs to `centre` (scaled coordinates).
void distances_to(const Matrix& Xs, const Eigen::RowVectorXd& centre, Vector& out) {
  out = (Xs.rowwise() - centre).rowwise().squaredNorm();
}

Matrix kmeans(const Matrix& Xs, int M, std::mt19937_64& rng, int iterations) {
  const Eigen::Index N = Xs.rows();
  Matrix centres(M, Xs.cols());
  // Seeding: first centre uniform; then proportional to the squared distance to the nearest centre.
  std::uniform_int_distribution<Eigen::Index> uniform(0, N - 1);
  centres.row(0) = Xs.row(uniform(rng));
  Vector nearest, d2;
  distances_to(Xs, centres.row(0), nearest);
  for (int m = 1; m < M; ++m) {
    const double total = nearest.sum();
    Eigen::Index pick = 0;
    if (total > 0.0 && std::isfinite(total)) {
      std::uniform_real_distribution<double> u(0.0, total);
      const double target = u(rng);
      double cumulative = 0.0;
      pick = N - 1;
      for (Eigen::Index i = 0; i < N; ++i) {
        cumulative += nearest(i);
        if (cumulative >= target && nearest(i) > 0.0) {
          pick = i;
          break;
        }
      }
    } else {
      pick = uniform(rng);  // fewer distinct points than centres: duplicates are unavoidable
    }
    centres.row(m) = Xs.row(pick);
    distances_to(Xs, centres.row(m), d2);
    nearest = nearest.cwiseMin(d2);
  }
  // Lloyd iterations: assign each point to its nearest centre, move centres to the means.
  std::vector<int> owner(static_cast<std::size_t>(N), 0);
  for (int it = 0; it < iterations; ++it) {
    const Vector c2 = centres.rowwise().squaredNorm();
    bool changed = false;
    for (Eigen::Index i = 0; i < N; ++i) {
      const Vector dist = c2 - 2.0 * centres * Xs.row(i).transpose();
      Eigen::Index best = 0;
      dist.minCoeff(&best);
      if (owner[static_cast<std::size_t>(i)] != static_cast<int>(best) || it == 0) changed = true;
      owner[static_cast<std::size_t>(i)] = static_cast<int>(best);
    }
    if (!changed) break;
    Matrix sums = Matrix::Zero(M, Xs.cols());
    Vector counts = Vector::Zero(M);
    for (Eigen::Index i = 0; i < N; ++i) {
      sums.row(owner[static_cast<std::size_t>(i)]) += Xs.row(i);
      counts(owner[static_cast<std::size_t>(i)]) += 1.0;
    }
    for (int m = 0; m < M; ++m)
      if (counts(m) > 0.0) centres.row(m) = sums.row(m) / counts(m);
  }
  return centres;
}

}  // namespace

Matrix initial_pseudo_inputs(const MatrixCRef& X, int M, const VectorCRef& scale, FitcInitialisation method,
                             std::uint64_t seed, int kmeans_iterations) {
  if (X.rows() < 1 || X.cols() < 1 || M < 1 || scale.size() != X.cols() || kmeans_iterations < 0)
    throw std::invalid_argument(
        "initial_pseudo_inputs: need N >= 1 inputs, M >= 1, one scale per input "
        "dimension and kmeans_iterations >= 0; got X " +
        std::to_string(X.rows()) + " x " + std::to_string(X.cols()) + ", M = " + std::to_string(M) + ", " +
        std::to_string(scale.size()) + " scales, kmeans_iterations = " + std::to_string(kmeans_iterations));
  if (!(scale.array() > 0.0).all() || !scale.allFinite())
    throw std::invalid_argument("initial_pseudo_inputs: scales must be finite and > 0");
  if (M >= X.rows()) return X;
  if (method == FitcInitialisation::RandomSubset) {
    const std::vector<int> rows = uniform_subsample(static_cast<int>(X.rows()), M, seed);
    Matrix out(M, X.cols());
    for (int m = 0; m < M; ++m) out.row(m) = X.row(rows[static_cast<std::size_t>(m)]);
    return out;
  }
  std::mt19937_64 rng(seed);
  const Matrix Xs = X * scale.cwiseInverse().asDiagonal();
  return kmeans(Xs, M, rng, kmeans_iterations) * scale.asDiagonal();
}

}  // namespace gpilqg::gp
