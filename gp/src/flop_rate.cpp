/// dense_flop_rate (flop_rate.hpp): timing the library's own Cholesky and inverse.

#include "gpilqg/gp/flop_rate.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "dense_cholesky.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg::gp {

double measure_dense_flop_rate(int threads) {
  if (threads < 1) throw std::invalid_argument("dense_flop_rate: threads = " + std::to_string(threads) + "; expected >= 1");
  const Eigen::Index n = kFlopRateSize;
  // A(i, j) = 1 / (1 + |i - j|) + n [i = j]: symmetric and strictly diagonally dominant (the
  // off-diagonal sum of a row is below 2 ln n + 2 < n), hence positive definite; O(n^2) to build.
  Matrix a(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) a(i, j) = 1.0 / (1.0 + static_cast<double>(std::abs(i - j)));
  a.diagonal().array() += static_cast<double>(n);
  Matrix work(n, n);
  double fastest = 0.0;
  for (int run = 0; run < 2; ++run) {
    work = a;
    const auto start = std::chrono::steady_clock::now();
    if (!detail::cholesky_in_place(work, threads)) throw std::logic_error("dense_flop_rate: the test matrix is not positive definite");
    detail::inverse_from_cholesky(work, threads);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fastest = run == 0 ? seconds : std::min(fastest, seconds);
  }
  const double flops = static_cast<double>(n) * static_cast<double>(n) * static_cast<double>(n);
  return flops / std::max(fastest, 1e-9);
}

double dense_flop_rate(int threads) {
  static std::mutex mutex;
  static std::map<int, double> measured;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto found = measured.find(threads);
  if (found != measured.end()) return found->second;
  const double rate = measure_dense_flop_rate(threads);
  measured.emplace(threads, rate);
  return rate;
}

}  // namespace gpilqg::gp
