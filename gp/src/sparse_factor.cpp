#include "sparse_factor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg::gp::detail {

namespace {
inline std::size_t at(int index) { return static_cast<std::size_t>(index); }
}  // namespace

double SimplicialFactor::half_log_determinant() const {
  double sum = 0.0;
  for (int j = 0; j < size; ++j) sum += std::log(diagonal(j));
  return sum;
}

void SimplicialFactor::compute_elimination_tree() {
  parent.assign(at(size), -1);
  for (int j = 0; j < size; ++j) {
    int smallest = -1;
    for (int q = column_start[at(j)] + 1; q < column_start[at(j + 1)]; ++q)
      if (smallest < 0 || row[at(q)] < smallest) smallest = row[at(q)];
    parent[at(j)] = smallest;
  }
}

void SimplicialFactor::solve(const Vector& b, Vector& x) const {
  Vector y(size);
  for (int k = 0; k < size; ++k) y(k) = b(permutation[at(k)]);
  for (int j = 0; j < size; ++j) {  // L y' = y
    const double v = y(j) / diagonal(j);
    y(j) = v;
    for (int q = column_start[at(j)] + 1; q < column_start[at(j + 1)]; ++q) y(row[at(q)]) -= value[at(q)] * v;
  }
  for (int j = size - 1; j >= 0; --j) {  // L' y'' = y'
    double v = y(j);
    for (int q = column_start[at(j)] + 1; q < column_start[at(j + 1)]; ++q) v -= value[at(q)] * y(row[at(q)]);
    y(j) = v / diagonal(j);
  }
  x.resize(size);
  for (int k = 0; k < size; ++k) x(permutation[at(k)]) = y(k);
}

std::vector<double> SimplicialFactor::inverse_subset() const {
  std::vector<double> z(value.size(), 0.0);
  std::vector<int> position(at(size), -1);  // row -> its entry in the current column, or -1
  for (int i = size - 1; i >= 0; --i) {
    const int first = column_start[at(i)], last = column_start[at(i + 1)];
    const double lii = value[at(first)];
    for (int p = first + 1; p < last; ++p) {
      position[at(row[at(p)])] = p;
      z[at(p)] = 0.0;
    }
    // Z_ji = -sum_{k in struct(L_:i)} Lt_ki Z_kj for every j in struct(L_:i): column j of Z (j > i,
    // already final) holds Z_kj for k >= j; each k > j of the structure found there contributes to
    // both Z_ji (through Lt_ki) and, by symmetry, Z_ki (through Lt_ji).
    std::int64_t found = 0;
    for (int p = first + 1; p < last; ++p) {
      const int j = row[at(p)];
      const double lt_ji = value[at(p)] / lii;
      const int column_first = column_start[at(j)];
      z[at(p)] -= lt_ji * z[at(column_first)];
      for (int q = column_first + 1; q < column_start[at(j + 1)]; ++q) {
        const int m = position[at(row[at(q)])];
        if (m < 0) continue;
        const double z_kj = z[at(q)];
        z[at(p)] -= value[at(m)] / lii * z_kj;
        z[at(m)] -= lt_ji * z_kj;
        ++found;
      }
    }
    const std::int64_t count = last - first - 1;
    if (found != count * (count - 1) / 2)
      throw std::logic_error("sparse inverse subset: column " + std::to_string(i) +
                             " reads entries outside the factor's pattern (not a Cholesky fill pattern)");
    double diagonal_value = 1.0 / (lii * lii);
    for (int p = first + 1; p < last; ++p) {
      diagonal_value -= value[at(p)] / lii * z[at(p)];
      position[at(row[at(p)])] = -1;
    }
    z[at(first)] = diagonal_value;
  }
  return z;
}

double sparse_quadratic_form(const SimplicialFactor& factor, const int* support, const double* k, int count,
                             const SparseSolveScratch& ws, double* weights) {
  int* marks = ws.marks;
  int* reach = ws.reach;
  int reach_size = 0;
  for (int s = 0; s < count; ++s) {
    int j = factor.inverse_permutation[at(support[s])];
    ws.values[j] = k[s];
    while (j >= 0 && marks[j] == 0) {
      marks[j] = 1;
      reach[reach_size++] = j;
      j = factor.parent[at(j)];
    }
  }
  std::sort(reach, reach + reach_size);
  double explained = 0.0;
  for (int t = 0; t < reach_size; ++t) {  // v = L^-1 P k on the reach
    const int j = reach[t];
    const double v = ws.values[j] / factor.diagonal(j);
    ws.values[j] = v;
    explained += v * v;
    for (int q = factor.column_start[at(j)] + 1; q < factor.column_start[at(j + 1)]; ++q)
      ws.values[factor.row[at(q)]] -= factor.value[at(q)] * v;
  }
  if (weights != nullptr) {
    for (int t = reach_size - 1; t >= 0; --t) {  // L^-T v on the reach (its rows are ancestors)
      const int j = reach[t];
      double x = ws.values[j];
      for (int q = factor.column_start[at(j)] + 1; q < factor.column_start[at(j + 1)]; ++q)
        x -= factor.value[at(q)] * ws.back[factor.row[at(q)]];
      ws.back[j] = x / factor.diagonal(j);
    }
    for (int s = 0; s < count; ++s) weights[s] = ws.back[factor.inverse_permutation[at(support[s])]];
  }
  for (int t = 0; t < reach_size; ++t) {
    const int j = reach[t];
    ws.values[j] = 0.0;
    ws.back[j] = 0.0;
    marks[j] = 0;
  }
  return explained;
}

}  // namespace gpilqg::gp::detail
