#include "sparse_factor.hpp"

#include <algorithm>
#include <cmath>

namespace gpilqg::gp::detail {

void SimplicialFactor::compute_elimination_tree() {
  parent.assign(at(size), -1);
  for (int j = 0; j < size; ++j) {
    int smallest = -1;
    for (int q = column_start[at(j)] + 1; q < column_start[at(j + 1)]; ++q)
      if (smallest < 0 || row[at(q)] < smallest) smallest = row[at(q)];
    parent[at(j)] = smallest;
  }
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
