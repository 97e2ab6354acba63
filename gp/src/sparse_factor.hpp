#pragma once
/// @file sparse_factor.hpp
/// Internal: a sparse Cholesky factor K = P' L L' P in plain arrays (simplicial, compressed columns,
/// in the permuted order, the diagonal first in every column), and what the compact backend does with
/// it: full solves, sparse solves over an elimination-tree reach, and the sparse inverse subset.

#include <cstdint>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp::detail {

struct SimplicialFactor {
  int size = 0;
  std::vector<int> column_start;   ///< size + 1
  std::vector<int> row;            ///< row indices (permuted order), diagonal first in each column
  std::vector<double> value;       ///< L entries
  std::vector<int> permutation;    ///< P: permuted index k holds original point permutation[k]
  std::vector<int> inverse_permutation;  ///< original point i sits at inverse_permutation[i]
  std::vector<int> parent;         ///< elimination tree: smallest off-diagonal row of each column, -1 at roots

  std::int64_t nonzeros() const { return static_cast<std::int64_t>(row.size()); }
  double diagonal(int column) const { return value[static_cast<std::size_t>(column_start[static_cast<std::size_t>(column)])]; }
  /// sum_i log L_ii, i.e. 0.5 log det K.
  double half_log_determinant() const;
  /// Fills `parent` from the pattern.
  void compute_elimination_tree();

  /// x = K^-1 b (both in the original order, N entries).
  void solve(const Vector& b, Vector& x) const;

  /// The sparse inverse subset: Z = K^-1 on the pattern of L (same layout as `value`, permuted
  /// order), by the Takahashi recurrence (compact.hpp). Throws std::logic_error if the pattern is not
  /// closed under the recurrence (a broken invariant: it is for every Cholesky fill pattern).
  std::vector<double> inverse_subset() const;
};

/// Caller-owned scratch of sparse_quadratic_form: `values` and `back` N doubles, `marks` and `reach`
/// N ints; values, back and marks all zero between calls (the function leaves them so).
struct SparseSolveScratch {
  double* values;
  double* back;
  int* marks;
  int* reach;
};

/// For k with nonzeros only at the original points `support` (values `k`, `count` entries):
///   v = L^-1 P k  over the elimination-tree reach of P(support), returns |v|^2 = k' K^-1 k;
///   when `weights` is not null, also w = K^-1 k at the support points (weights[s] for support[s]),
///   from L^-T v restricted to the reach (closed under ancestors, so exact).
/// Touches only the reach (cost: the entries of L in the reach's columns). Allocation-free.
double sparse_quadratic_form(const SimplicialFactor& factor, const int* support, const double* k, int count,
                             const SparseSolveScratch& scratch, double* weights);

}  // namespace gpilqg::gp::detail
