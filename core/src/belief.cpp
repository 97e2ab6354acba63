#include "gpilqg/core/belief.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg {

int belief_dim(int n) { return n + n * (n + 1) / 2; }

int vech_index(int n, int i, int j) {
  if (i < j) std::swap(i, j);  // lower triangle: row i >= column j
  // Columns 0..j-1 hold n, n-1, ..., n-j+1 entries.
  return j * n - j * (j - 1) / 2 + (i - j);
}

void pack_belief(const VectorCRef& mu, const MatrixCRef& Sigma, VectorRef v) {
  const int n = static_cast<int>(mu.size());
  if (Sigma.rows() != n || Sigma.cols() != n || v.size() != belief_dim(n))
    throw std::invalid_argument("pack_belief: sizes do not match n = " + std::to_string(n));
  v.head(n) = mu;
  int k = n;
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) v(k++) = 0.5 * (Sigma(i, j) + Sigma(j, i));
}

void unpack_belief(const VectorCRef& v, int n, Vector& mu, Matrix& Sigma) {
  if (v.size() != belief_dim(n))
    throw std::invalid_argument("unpack_belief: " + std::to_string(v.size()) + " entries; expected " +
                                std::to_string(belief_dim(n)));
  mu = v.head(n);
  Sigma.resize(n, n);
  int k = n;
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      Sigma(i, j) = v(k);
      Sigma(j, i) = v(k);
      ++k;
    }
}

}  // namespace gpilqg
