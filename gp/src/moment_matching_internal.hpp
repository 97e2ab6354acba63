#pragma once
/// @file moment_matching_internal.hpp
/// Private helpers of the moment matchers (moment_matching*.cpp, ssgp_moment_matching*.cpp): a matrix
/// product that never touches the heap, views into buffers sized for the largest output, and the
/// pieces of the mean and cross-covariance derivatives that both matchers assemble the same way.
///
/// Eigen's GEMM packs blocks of its operands into buffers of kc x mc and kc x nc scalars whose sizes
/// come from a cache-size heuristic; buffers above EIGEN_STACK_ALLOCATION_LIMIT (128 KiB) are
/// heap-allocated on every call (e.g. Omega (N x N) times V (N x D) at N = 300). Splitting every
/// dimension into tiles of at most 128 bounds both buffers by 128 x 128 doubles = 128 KiB, so they
/// always live on the stack, whatever the machine's caches, and propagate stays allocation-free
/// (docs/architecture.md#models-and-workspaces) at any N.

#include <algorithm>
#include <string>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp::detail {

inline constexpr Eigen::Index kProductTile = 128;

/// dst = lhs * rhs, or dst += lhs * rhs when `accumulate` (dst pre-sized, not aliasing lhs or rhs);
/// lhs and rhs may be transposes or blocks, dst a matrix, a view (MatrixView) or a block of one.
template <class Lhs, class Rhs, class Dst>
void tiled_product(const Lhs& lhs, const Rhs& rhs, Dst&& dst, bool accumulate = false) {
  const Eigen::Index m = lhs.rows();
  const Eigen::Index k = lhs.cols();
  const Eigen::Index n = rhs.cols();
  constexpr Eigen::Index t = kProductTile;
  if (m <= t && k <= t && n <= t) {
    if (accumulate)
      dst.noalias() += lhs * rhs;
    else
      dst.noalias() = lhs * rhs;
    return;
  }
  if (k == 0) {
    if (!accumulate) dst.setZero();
    return;
  }
  for (Eigen::Index j = 0; j < n; j += t) {
    const Eigen::Index nj = std::min(t, n - j);
    for (Eigen::Index i = 0; i < m; i += t) {
      const Eigen::Index mi = std::min(t, m - i);
      auto target = dst.block(i, j, mi, nj);
      for (Eigen::Index p = 0; p < k; p += t) {
        const Eigen::Index kp = std::min(t, k - p);
        if (p == 0 && !accumulate)
          target.noalias() = lhs.block(i, p, mi, kp) * rhs.block(p, j, kp, nj);
        else
          target.noalias() += lhs.block(i, p, mi, kp) * rhs.block(p, j, kp, nj);
      }
    }
  }
}

/// "rows x cols", for error messages.
inline std::string shape(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + " x " + std::to_string(cols);
}

/// A rows x cols matrix over the first rows * cols entries of `buffer` (column-major, contiguous), so
/// that one buffer sized for the largest output serves outputs of every size without reallocating.
/// The view starts where the buffer does, so it keeps Eigen's allocation alignment.
using MatrixView = Eigen::Map<Matrix, Eigen::AlignedMax>;
using VectorView = Eigen::Map<Vector, Eigen::AlignedMax>;

inline MatrixView view(Matrix& buffer, Eigen::Index rows, Eigen::Index cols) {
  eigen_assert(rows * cols <= buffer.size());
  return MatrixView(buffer.data(), rows, cols);
}
inline VectorView view(Vector& buffer, Eigen::Index size) {
  eigen_assert(size <= buffer.size());
  return VectorView(buffer.data(), size);
}

/// third(k, i + D j) = sum_n w_n y_nk t_ni t_nj (D x D^2) for the rows t_n of `t` and y_n of `y`
/// (N x D each): one (D x N)(N x D^2) product. `y` is overwritten (its rows scaled by w); `outer`
/// (N x D^2) is scratch.
template <class T, class W>
void weighted_third_moment(const T& t, MatrixView y, const W& w, MatrixView outer, Matrix& third) {
  const Eigen::Index d = t.cols();
  for (Eigen::Index j = 0; j < d; ++j)
    for (Eigen::Index i = 0; i < d; ++i) outer.col(i + d * j) = t.col(i).cwiseProduct(t.col(j));
  y.array().colwise() *= w.array();
  tiled_product(y.transpose(), outer, third);
}

/// The derivative rows of output a that follow from g = dM_a/dmu and H = d^2 M_a/dmu^2 (symmetric)
/// alone: dM_a/dmu = g', dM_a/dSigma = vec(H)' / 2 (heat equation), dC_:a/dmu = Sigma H (C = Sigma g).
inline void write_mean_derivatives(MomentMatch& out, Eigen::Index a, const Matrix& sigma, const Vector& g,
                                   const Matrix& h) {
  const Eigen::Index d = g.size();
  out.dmean_dmu.row(a) = g.transpose();
  out.dmean_dsigma.row(a) = 0.5 * Eigen::Map<const Vector>(h.data(), d * d).transpose();
  out.dcross_dmu.middleRows(a * d, d).noalias() = sigma * h;
}

/// Writes the D x D gradient `grad` of S_ab (symmetrised in place) to the rows (a, b) and (b, a) of
/// dcovariance_dsigma, and `dmu` (D) to those of dcovariance_dmu.
inline void write_covariance_derivatives(MomentMatch& out, Eigen::Index a, Eigen::Index b, const Vector& dmu,
                                         Matrix& grad) {
  const Eigen::Index e = out.mean.size();
  const Eigen::Index d = grad.rows();
  out.dcovariance_dmu.row(a + e * b) = dmu.transpose();
  out.dcovariance_dmu.row(b + e * a) = dmu.transpose();
  for (Eigen::Index j = 0; j < d; ++j)
    for (Eigen::Index i = 0; i < j; ++i) grad(i, j) = grad(j, i) = 0.5 * (grad(i, j) + grad(j, i));
  const auto flat = Eigen::Map<const Vector>(grad.data(), d * d).transpose();
  out.dcovariance_dsigma.row(a + e * b) = flat;
  out.dcovariance_dsigma.row(b + e * a) = flat;
}

}  // namespace gpilqg::gp::detail
