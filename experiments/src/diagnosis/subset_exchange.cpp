#include "gpilqg/experiments/diagnosis/subset_exchange.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

namespace gpilqg::diagnosis {

bool lowers_by_more_than_its_error(const std::vector<double>& before, const std::vector<double>& after) {
  if (before.size() != after.size())
    throw std::invalid_argument(fmt::format("screening scores of {} folds compared with scores of {} folds",
                                            before.size(), after.size()));
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
  struct Trial {
    double total;
    std::size_t where;
    int in;
    std::vector<double> folds;
  };
  std::vector<double> now = folds(set);
  for (int round = 0; round < max_rounds; ++round) {
    std::vector<Trial> trials;
    for (std::size_t i = 0; i < set.size(); ++i) {
      const int member = set[i];
      for (int c = 0; c < candidates; ++c) {
        if (std::find(set.begin(), set.end(), c) != set.end() || !may_join(c, c)) continue;
        bool allowed = true;
        for (std::size_t j = 0; j < set.size() && allowed; ++j) allowed = j == i || may_join(set[j], c);
        if (!allowed) continue;
        set[i] = c;  // the trial, in place
        std::vector<double> scores = folds(set);
        set[i] = member;
        const double total = std::accumulate(scores.begin(), scores.end(), 0.0);
        trials.push_back({total, i, c, std::move(scores)});
      }
    }
    // The least score first; stable, so ties go to the earlier member and candidate.
    std::stable_sort(trials.begin(), trials.end(), [](const Trial& x, const Trial& y) { return x.total < y.total; });
    const auto passing = std::find_if(trials.begin(), trials.end(),
                                      [&](const Trial& t) { return lowers_by_more_than_its_error(now, t.folds); });
    if (passing == trials.end()) break;
    if (made != nullptr) made->push_back({set[passing->where], passing->in});
    set[passing->where] = passing->in;
    now = std::move(passing->folds);  // the scores of the set it is now
  }
  return set;
}

}  // namespace gpilqg::diagnosis
