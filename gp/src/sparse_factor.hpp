#pragma once
/// @file sparse_factor.hpp
/// Internal: a sparse Cholesky factor K = P' L L' P column by column (simplicial, compressed columns
/// in the permuted order, the diagonal first in every column) with its elimination tree, and the
/// sparse solve that prediction needs: only over the elimination-tree reach of the test point's
/// neighbours, not over all N.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp::detail {

/// The std::size_t position of a factor index (the factors hold int indices, as CHOLMOD does).
inline std::size_t at(int index) { return static_cast<std::size_t>(index); }

struct SimplicialFactor {
  int size = 0;
  std::vector<int> column_start;   ///< size + 1
  std::vector<int> row;            ///< row indices (permuted order), diagonal first in each column
  std::vector<double> value;       ///< L entries
  std::vector<int> inverse_permutation;  ///< original point i sits at inverse_permutation[i]
  std::vector<int> parent;         ///< elimination tree: smallest off-diagonal row of each column, -1 at roots

  double diagonal(int column) const { return value[static_cast<std::size_t>(column_start[static_cast<std::size_t>(column)])]; }
  /// Fills `parent` from the pattern.
  void compute_elimination_tree();
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
