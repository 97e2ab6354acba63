#pragma once
/// @file compact_pattern.hpp
/// Internal: which training points lie within the support of a compactly supported kernel, without
/// O(N^2) work. The inputs are scaled by 1/l_d (support radius 1); a grid of unit cells over the
/// (up to) three scaled coordinates with the largest range sorts the points by cell. A query visits the
/// 3^k cells around its own (k <= 3 grid coordinates) and tests the full D-dimensional distance of the
/// points in them. With D <= 3 that is the classic cell list; above, the grid prunes with the three most
/// informative coordinates and the distance test does the rest (exact either way: no pair with r < 1
/// is missed, because |u_d - v_d| < 1 on every grid coordinate is necessary for r < 1).

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "compact_kernel.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg::gp::detail {

/// The lower triangle of K's sparsity pattern in compressed-column form (original point order): column
/// j holds row j (the diagonal, first) then the rows i > j with r(x_i, x_j) < 1, ascending.
struct LowerPattern {
  int size = 0;
  std::vector<int> column_start;  ///< size + 1 offsets
  std::vector<int> row;           ///< nonzeros
  std::int64_t nonzeros() const { return static_cast<std::int64_t>(row.size()); }
};

class NeighbourGrid {
 public:
  /// Builds the grid over `inputs` (N x D) scaled by `inverse_lengthscales` (D). Keeps a copy of the
  /// scaled points in cell order.
  NeighbourGrid(const Matrix& inputs, const Vector& inverse_lengthscales);

  int size() const { return static_cast<int>(order_.size()); }

  /// Calls visit(i, r2) for every point i (original index) with squared scaled distance r2 < 1 from
  /// z (unscaled, D entries). `scaled_query` is caller-owned scratch of D doubles. Allocation-free.
  template <class Visit>
  void for_each_neighbour(const VectorCRef& z, double* scaled_query, Visit&& visit) const {
    for (int d = 0; d < dims_; ++d) scaled_query[d] = z(d) * inverse_lengthscales_(d);
    for_each_candidate_cell(scaled_query, [&](int begin, int end) {
      for (int p = begin; p < end; ++p) {
        const double r2 = squared_distance(p, scaled_query);
        if (r2 < 1.0) visit(order_[static_cast<std::size_t>(p)], r2);
      }
    });
  }

  /// The lower pattern of all pairs with r < 1. Returns false (and leaves `out` partly filled) as soon
  /// as it would exceed `max_nonzeros` entries. With `threads` > 1 the columns are split over threads.
  bool lower_pattern(std::int64_t max_nonzeros, int threads, LowerPattern& out) const;

 private:
  using Cell = std::array<std::int64_t, 3>;
  Cell cell_of(const double* scaled) const;
  double squared_distance(int sorted_index, const double* scaled) const {
    const double* p = scaled_.data() + static_cast<std::ptrdiff_t>(sorted_index) * dims_;
    double r2 = 0.0;
    for (int d = 0; d < dims_; ++d) {
      const double t = p[d] - scaled[d];
      r2 += t * t;
    }
    return r2;
  }
  /// Calls range(begin, end) for the sorted-index range of every occupied cell within one cell of
  /// the query's along each grid coordinate.
  template <class Range>
  void for_each_candidate_cell(const double* scaled, Range&& range) const {
    const Cell centre = cell_of(scaled);
    const int stencil = stencil_size_;
    for (int s = 0; s < stencil; ++s) {
      Cell cell = centre;
      int code = s;
      for (int g = 0; g < grid_dims_; ++g) {
        cell[static_cast<std::size_t>(g)] += code % 3 - 1;
        code /= 3;
      }
      const auto it = std::lower_bound(cells_.begin(), cells_.end(), cell);
      if (it == cells_.end() || *it != cell) continue;
      const auto c = static_cast<std::size_t>(it - cells_.begin());
      range(cell_start_[c], cell_start_[c + 1]);
    }
  }

  int dims_ = 0;
  int grid_dims_ = 0;
  int stencil_size_ = 1;               ///< 3^grid_dims_
  std::array<int, 3> grid_coordinate_{};  ///< which scaled coordinates the grid uses
  Vector inverse_lengthscales_;
  std::vector<double> scaled_;  ///< N x D row-major, points in cell order
  std::vector<int> order_;      ///< original index of each sorted point
  std::vector<int> position_;   ///< sorted position of each original point
  std::vector<Cell> cells_;     ///< occupied cells, sorted
  std::vector<int> cell_start_; ///< cells_.size() + 1 offsets into the sorted points
};

}  // namespace gpilqg::gp::detail
