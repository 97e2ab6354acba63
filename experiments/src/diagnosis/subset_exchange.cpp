#include "gpilqg/experiments/diagnosis/subset_exchange.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace gpilqg::diagnosis {

bool lowers_by_more_than_its_error(const std::vector<double>& before, const std::vector<double>& after) {
  const auto K = static_cast<double>(before.size());
  double total = 0.0, score = 0.0;
  for (std::size_t f = 0; f < before.size(); ++f) {
    total += before[f] - after[f];
    score += std::abs(before[f]);
  }
  if (total <= std::sqrt(std::numeric_limits<double>::epsilon()) * score) return false;  // rounding
  if (before.size() < 2) return true;
  double spread = 0.0;
  for (std::size_t f = 0; f < before.size(); ++f) spread += std::pow(before[f] - after[f] - total / K, 2);
  return total > std::sqrt(K / (K - 1.0) * spread);
}

std::vector<int> exchanged(const FoldScores& folds, int candidates, std::vector<int> set, const MayJoin& may_join,
                           int max_rounds, std::vector<Exchange>* made) {
  const auto sum = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); };
  for (int round = 0; round < max_rounds; ++round) {
    const std::vector<double> now = folds(set);
    double least = std::numeric_limits<double>::infinity();
    std::vector<double> least_folds;
    std::size_t where = 0;
    int in = -1;
    for (std::size_t i = 0; i < set.size(); ++i) {
      for (int c = 0; c < candidates; ++c) {
        if (std::find(set.begin(), set.end(), c) != set.end() || !may_join(c, c)) continue;
        bool allowed = true;
        for (std::size_t j = 0; j < set.size() && allowed; ++j) allowed = j == i || may_join(set[j], c);
        if (!allowed) continue;
        std::vector<int> trial = set;
        trial[i] = c;
        std::vector<double> scores = folds(trial);
        const double total = sum(scores);
        if (total < least) {
          least = total;
          least_folds = std::move(scores);
          where = i;
          in = c;
        }
      }
    }
    if (in < 0 || !lowers_by_more_than_its_error(now, least_folds)) break;
    if (made != nullptr) made->push_back({set[where], in});
    set[where] = in;
  }
  return set;
}

}  // namespace gpilqg::diagnosis
