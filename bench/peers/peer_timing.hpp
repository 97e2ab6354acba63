#pragma once
/// @file peer_timing.hpp
/// Wall-clock time of one unit of work repeated k times (std::chrono::steady_clock), as
/// compare_peers.py times the peer: every repetition's seconds, their minimum (best of k: the
/// figure least disturbed by other jobs on a shared machine) and their median.

#include <algorithm>
#include <chrono>
#include <vector>

namespace gpilqg::bench {

struct RepeatedTiming {
  std::vector<double> seconds;  ///< one entry per repetition, in the order they ran
  double best = 0.0;            ///< min(seconds)
  double median = 0.0;          ///< middle entry of the sorted seconds (mean of the two middle ones for even k)
};

/// Runs `work()` `repeats` (>= 1) times and times each run on its own.
template <class Work>
RepeatedTiming time_repeated(int repeats, Work&& work) {
  RepeatedTiming timing;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    timing.seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::vector<double> sorted = timing.seconds;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t k = sorted.size();
  timing.best = sorted.front();
  timing.median = k % 2 == 1 ? sorted[k / 2] : 0.5 * (sorted[k / 2 - 1] + sorted[k / 2]);
  return timing;
}

}  // namespace gpilqg::bench
