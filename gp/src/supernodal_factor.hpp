#pragma once
/// @file supernodal_factor.hpp
/// Internal: a supernodal Cholesky factor K = P' L L' P copied out of CHOLMOD into plain arrays, and
/// what the compact backend's likelihood does with it: solves, log-determinant and the sparse inverse
/// subset by the Takahashi recurrence in block form (dense products per supernode).
///
/// Layout (CHOLMOD's): supernode s holds the columns [first_column[s], first_column[s+1]); its row
/// structure is rows[row_start[s] .. row_start[s+1]) (ascending, the supernode's own columns first);
/// its values are a dense column-major (#rows x #columns) block at value_start[s] (the part above the
/// diagonal is unused).
///
/// Block Takahashi (selected inversion, as in Lin et al.'s SelInv): for supernode s with
/// L_s = [L11; L21] (L11 its diagonal block, L21 the rows B below), Z = K^-1 in the permuted order:
///   Lt  = L21 L11^-1,
///   Z21 = -Z(B, B) Lt,
///   Z11 = L11^-T L11^-1 - Lt' Z21,
/// for s from the last supernode to the first; Z(B, B) has been computed by then and lies on the
/// structure of later supernodes (the supernodal fill pattern is closed). Z is stored in the same
/// layout as L. With one column per supernode this is the scalar recurrence of compact.hpp.

#include <cstdint>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "sparse_factor.hpp"

namespace gpilqg::gp::detail {

struct SupernodalFactor {
  int size = 0;
  std::vector<int> first_column;  ///< supernodes + 1
  std::vector<int> row_start;     ///< supernodes + 1
  std::vector<int> value_start;   ///< supernodes + 1
  std::vector<int> rows;          ///< row structure of every supernode
  std::vector<double> value;      ///< dense blocks
  std::vector<int> permutation;   ///< permuted index k holds original point permutation[k]
  std::vector<int> inverse_permutation;

  int supernodes() const { return static_cast<int>(first_column.size()) - 1; }
  /// Stored entries (including CHOLMOD's explicit zeros from relaxed amalgamation).
  std::int64_t nonzeros() const;
  /// Smallest L_ii^2 (-1 when a diagonal entry is not finite).
  double smallest_pivot() const;
  /// sum_i log L_ii, i.e. 0.5 log det K.
  double half_log_determinant() const;
  /// x = K^-1 b (both in the original order).
  void solve(const Vector& b, Vector& x) const;
  /// Z = K^-1 on the supernodal pattern, same layout as `value` (block Takahashi above). Throws
  /// std::logic_error if the pattern is not closed (a broken invariant).
  std::vector<double> inverse_subset() const;
  /// The same factor column by column (diagonal first), with its elimination tree, for sparse solves.
  SimplicialFactor simplicial() const;
};

}  // namespace gpilqg::gp::detail
