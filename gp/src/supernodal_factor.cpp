#include "supernodal_factor.hpp"

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gpilqg::gp::detail {

namespace {
using ConstBlock = Eigen::Map<const Matrix>;
}  // namespace

std::int64_t SupernodalFactor::nonzeros() const { return static_cast<std::int64_t>(value.size()); }

double SupernodalFactor::smallest_pivot() const {
  double smallest = std::numeric_limits<double>::infinity();
  for (int s = 0; s < supernodes(); ++s) {
    const int columns = first_column[at(s + 1)] - first_column[at(s)];
    const int height = row_start[at(s + 1)] - row_start[at(s)];
    for (int c = 0; c < columns; ++c) {
      const double diagonal = value[at(value_start[at(s)] + c * height + c)];
      if (!std::isfinite(diagonal)) return -1.0;
      smallest = std::min(smallest, diagonal * diagonal);
    }
  }
  return smallest;
}

double SupernodalFactor::half_log_determinant() const {
  double sum = 0.0;
  for (int s = 0; s < supernodes(); ++s) {
    const int columns = first_column[at(s + 1)] - first_column[at(s)];
    const int height = row_start[at(s + 1)] - row_start[at(s)];
    for (int c = 0; c < columns; ++c) sum += std::log(value[at(value_start[at(s)] + c * height + c)]);
  }
  return sum;
}

void SupernodalFactor::solve(const Vector& b, Vector& x) const {
  Vector y(size), below;
  for (int k = 0; k < size; ++k) y(k) = b(permutation[at(k)]);
  auto block = [&](int s, int& first, int& columns, int& height) {
    first = first_column[at(s)];
    columns = first_column[at(s + 1)] - first;
    height = row_start[at(s + 1)] - row_start[at(s)];
    return ConstBlock(value.data() + value_start[at(s)], height, columns);
  };
  int first = 0, columns = 0, height = 0;
  for (int s = 0; s < supernodes(); ++s) {  // L y' = y
    const ConstBlock l = block(s, first, columns, height);
    auto ys = y.segment(first, columns);
    l.topRows(columns).triangularView<Eigen::Lower>().solveInPlace(ys);
    below.noalias() = l.bottomRows(height - columns) * ys;
    for (int a = 0; a < height - columns; ++a) y(rows[at(row_start[at(s)] + columns + a)]) -= below(a);
  }
  for (int s = supernodes() - 1; s >= 0; --s) {  // L' y'' = y'
    const ConstBlock l = block(s, first, columns, height);
    below.resize(height - columns);
    for (int a = 0; a < height - columns; ++a) below(a) = y(rows[at(row_start[at(s)] + columns + a)]);
    auto ys = y.segment(first, columns);
    ys.noalias() -= l.bottomRows(height - columns).transpose() * below;
    l.topRows(columns).triangularView<Eigen::Lower>().transpose().solveInPlace(ys);
  }
  x.resize(size);
  for (int k = 0; k < size; ++k) x(permutation[at(k)]) = y(k);
}

std::vector<double> SupernodalFactor::inverse_subset() const {
  std::vector<double> z(value.size(), 0.0);
  std::vector<int> supernode_of(at(size));
  for (int s = 0; s < supernodes(); ++s)
    for (int k = first_column[at(s)]; k < first_column[at(s + 1)]; ++k) supernode_of[at(k)] = s;
  std::vector<int> relative(at(size), -1);
  Matrix z22, lt, z21, inverse11;
  for (int s = supernodes() - 1; s >= 0; --s) {
    const int columns = first_column[at(s + 1)] - first_column[at(s)];
    const int height = row_start[at(s + 1)] - row_start[at(s)];
    const int nb = height - columns;
    const int* below = rows.data() + row_start[at(s)] + columns;
    const ConstBlock l(value.data() + value_start[at(s)], height, columns);
    // Gather Z(B, B) (both triangles) from the supernodes that own the columns of B.
    z22.resize(nb, nb);
    for (int b = 0; b < nb;) {
      const int t = supernode_of[at(below[b])];
      const int t_height = row_start[at(t + 1)] - row_start[at(t)];
      const int t_columns = first_column[at(t + 1)] - first_column[at(t)];
      for (int q = 0; q < t_height; ++q) relative[at(rows[at(row_start[at(t)] + q)])] = q;
      const ConstBlock zt(z.data() + value_start[at(t)], t_height, t_columns);
      for (; b < nb && below[b] < first_column[at(t + 1)]; ++b) {
        const int c = below[b] - first_column[at(t)];
        for (int a = b; a < nb; ++a) {
          const int r = relative[at(below[a])];
          if (r < 0)
            throw std::logic_error("sparse inverse subset: supernode " + std::to_string(s) +
                                   " needs an entry outside the factor's pattern (not a Cholesky fill pattern)");
          z22(a, b) = z22(b, a) = zt(r, c);
        }
      }
      for (int q = 0; q < t_height; ++q) relative[at(rows[at(row_start[at(t)] + q)])] = -1;
    }
    const auto l11 = l.topRows(columns).triangularView<Eigen::Lower>();
    inverse11 = l11.solve(Matrix::Identity(columns, columns));
    lt.noalias() = l.bottomRows(nb) * inverse11;        // Lt = L21 L11^-1
    z21.noalias() = -z22 * lt;                           // Z21 = -Z(B, B) Lt
    Eigen::Map<Matrix> zs(z.data() + value_start[at(s)], height, columns);
    zs.topRows(columns).noalias() = inverse11.transpose() * inverse11;  // L11^-T L11^-1
    zs.topRows(columns).noalias() -= lt.transpose() * z21;
    zs.bottomRows(nb) = z21;
  }
  return z;
}

SimplicialFactor SupernodalFactor::simplicial() const {
  SimplicialFactor f;
  f.size = size;
  f.inverse_permutation = inverse_permutation;
  f.column_start.assign(1, 0);
  f.column_start.reserve(at(size) + 1);
  for (int s = 0; s < supernodes(); ++s) {
    const int columns = first_column[at(s + 1)] - first_column[at(s)];
    const int height = row_start[at(s + 1)] - row_start[at(s)];
    const ConstBlock l(value.data() + value_start[at(s)], height, columns);
    for (int c = 0; c < columns; ++c) {
      for (int r = c; r < height; ++r) {
        f.row.push_back(rows[at(row_start[at(s)] + r)]);
        f.value.push_back(l(r, c));
      }
      f.column_start.push_back(static_cast<int>(f.row.size()));
    }
  }
  f.compute_elimination_tree();
  return f;
}

}  // namespace gpilqg::gp::detail
