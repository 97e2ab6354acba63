#pragma once
/// @file moment_matching_internal.hpp
/// Private helper of moment_matching*.cpp: a matrix product that never touches the heap.
///
/// Eigen's GEMM packs blocks of its operands into buffers of kc x mc and kc x nc scalars whose sizes
/// come from a cache-size heuristic; buffers above EIGEN_STACK_ALLOCATION_LIMIT (128 KiB) are
/// heap-allocated on every call (e.g. Omega (N x N) times V (N x D) at N = 300). Splitting every
/// dimension into tiles of at most 128 bounds both buffers by 128 x 128 doubles = 128 KiB, so they
/// always live on the stack, whatever the machine's caches, and propagate stays allocation-free
/// (DESIGN.md practice 1) at any N.

#include <algorithm>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp::detail {

inline constexpr Eigen::Index kProductTile = 128;

/// dst = lhs * rhs (dst pre-sized, not aliasing lhs or rhs); lhs and rhs may be transposes or blocks.
template <class Lhs, class Rhs>
void tiled_product(const Lhs& lhs, const Rhs& rhs, Matrix& dst) {
  const Eigen::Index m = lhs.rows();
  const Eigen::Index k = lhs.cols();
  const Eigen::Index n = rhs.cols();
  constexpr Eigen::Index t = kProductTile;
  if (m <= t && k <= t && n <= t) {
    dst.noalias() = lhs * rhs;
    return;
  }
  if (k == 0) {
    dst.setZero();
    return;
  }
  for (Eigen::Index j = 0; j < n; j += t) {
    const Eigen::Index nj = std::min(t, n - j);
    for (Eigen::Index i = 0; i < m; i += t) {
      const Eigen::Index mi = std::min(t, m - i);
      auto target = dst.block(i, j, mi, nj);
      for (Eigen::Index p = 0; p < k; p += t) {
        const Eigen::Index kp = std::min(t, k - p);
        if (p == 0)
          target.noalias() = lhs.block(i, p, mi, kp) * rhs.block(p, j, kp, nj);
        else
          target.noalias() += lhs.block(i, p, mi, kp) * rhs.block(p, j, kp, nj);
      }
    }
  }
}

}  // namespace gpilqg::gp::detail
