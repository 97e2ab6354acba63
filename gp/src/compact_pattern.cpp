#include "compact_pattern.hpp"

#include <cmath>
#include <numeric>

#include "parallel.hpp"

namespace gpilqg::gp::detail {

NeighbourGrid::NeighbourGrid(const Matrix& inputs, const Vector& inverse_lengthscales)
    : dims_(static_cast<int>(inputs.cols())), inverse_lengthscales_(inverse_lengthscales) {
  const auto n = static_cast<int>(inputs.rows());
  // Grid coordinates: the (up to) three scaled coordinates with the largest range.
  Vector range(dims_);
  for (int d = 0; d < dims_; ++d)
    range(d) = n > 0 ? (inputs.col(d).maxCoeff() - inputs.col(d).minCoeff()) * inverse_lengthscales_(d) : 0.0;
  std::vector<int> by_range(static_cast<std::size_t>(dims_));
  std::iota(by_range.begin(), by_range.end(), 0);
  std::stable_sort(by_range.begin(), by_range.end(), [&](int a, int b) { return range(a) > range(b); });
  grid_dims_ = std::min(dims_, 3);
  for (int g = 0; g < grid_dims_; ++g) grid_coordinate_[static_cast<std::size_t>(g)] = by_range[static_cast<std::size_t>(g)];
  stencil_size_ = 1;
  for (int g = 0; g < grid_dims_; ++g) stencil_size_ *= 3;

  std::vector<Cell> cell(static_cast<std::size_t>(n));
  Vector scaled(dims_);
  for (int i = 0; i < n; ++i) {
    scaled = inputs.row(i).transpose().cwiseProduct(inverse_lengthscales_);
    cell[static_cast<std::size_t>(i)] = cell_of(scaled.data());
  }
  order_.resize(static_cast<std::size_t>(n));
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(),
                   [&](int a, int b) { return cell[static_cast<std::size_t>(a)] < cell[static_cast<std::size_t>(b)]; });
  position_.resize(static_cast<std::size_t>(n));
  scaled_.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(dims_));
  cells_.clear();
  cell_start_.clear();
  for (int p = 0; p < n; ++p) {
    const int i = order_[static_cast<std::size_t>(p)];
    position_[static_cast<std::size_t>(i)] = p;
    for (int d = 0; d < dims_; ++d)
      scaled_[static_cast<std::size_t>(p) * static_cast<std::size_t>(dims_) + static_cast<std::size_t>(d)] =
          inputs(i, d) * inverse_lengthscales_(d);
    if (cells_.empty() || cells_.back() != cell[static_cast<std::size_t>(i)]) {
      cells_.push_back(cell[static_cast<std::size_t>(i)]);
      cell_start_.push_back(p);
    }
  }
  cell_start_.push_back(n);
}

NeighbourGrid::Cell NeighbourGrid::cell_of(const double* scaled) const {
  Cell cell{0, 0, 0};
  for (int g = 0; g < grid_dims_; ++g) {
    // Clamped far beyond any data so that the +-1 stencil cannot overflow.
    const double c = std::floor(scaled[grid_coordinate_[static_cast<std::size_t>(g)]]);
    cell[static_cast<std::size_t>(g)] = static_cast<std::int64_t>(std::clamp(c, -4.0e18, 4.0e18));
  }
  return cell;
}

bool NeighbourGrid::lower_pattern(std::int64_t max_nonzeros, int threads, LowerPattern& out) const {
  const int n = size();
  struct Share {
    std::vector<int> counts;  // entries of each column in the share
    std::vector<int> rows;
    bool within_budget = true;
  };
  const int workers = std::max(1, std::min(threads, n / 2000 + 1));
  std::vector<Share> shares(static_cast<std::size_t>(workers));
  run_workers(workers, workers, [&](int worker, int count) {
    Share& share = shares[static_cast<std::size_t>(worker)];
    const int begin = static_cast<int>(static_cast<std::int64_t>(n) * worker / count);
    const int end = static_cast<int>(static_cast<std::int64_t>(n) * (worker + 1) / count);
    share.counts.reserve(static_cast<std::size_t>(end - begin));
    for (int j = begin; j < end; ++j) {
      const std::size_t first = share.rows.size();
      share.rows.push_back(j);
      const double* scaled = scaled_.data() + static_cast<std::ptrdiff_t>(position_[static_cast<std::size_t>(j)]) * dims_;
      for_each_candidate_cell(scaled, [&](int cell_begin, int cell_end) {
        for (int q = cell_begin; q < cell_end; ++q) {
          const int i = order_[static_cast<std::size_t>(q)];
          if (i > j && squared_distance(q, scaled) < 1.0) share.rows.push_back(i);
        }
      });
      std::sort(share.rows.begin() + static_cast<std::ptrdiff_t>(first) + 1, share.rows.end());
      share.counts.push_back(static_cast<int>(share.rows.size() - first));
      if (static_cast<std::int64_t>(share.rows.size()) > max_nonzeros) {
        share.within_budget = false;
        return;
      }
    }
  });
  std::int64_t total = 0;
  for (const Share& share : shares) {
    if (!share.within_budget) return false;
    total += static_cast<std::int64_t>(share.rows.size());
  }
  if (total > max_nonzeros) return false;
  out.size = n;
  out.row.clear();
  out.row.reserve(static_cast<std::size_t>(total));
  out.column_start.assign(1, 0);
  out.column_start.reserve(static_cast<std::size_t>(n) + 1);
  for (const Share& share : shares) {
    out.row.insert(out.row.end(), share.rows.begin(), share.rows.end());
    for (int c : share.counts) out.column_start.push_back(out.column_start.back() + c);
  }
  return true;
}

}  // namespace gpilqg::gp::detail
