#include "gpilqg/experiments/unit_scheduler.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gpilqg {

UnitScheduler::UnitScheduler(std::vector<std::vector<int>> depends_on, std::vector<double> weight)
    : depends_on_(std::move(depends_on)), priority_(std::move(weight)), state_(depends_on_.size(), State::Waiting) {
  const int n = static_cast<int>(depends_on_.size());
  if (static_cast<int>(priority_.size()) != n)
    throw std::invalid_argument("UnitScheduler: one weight per unit is needed");
  for (int i = 0; i < n; ++i) {
    if (!(priority_[static_cast<std::size_t>(i)] > 0.0))
      throw std::invalid_argument("UnitScheduler: unit " + std::to_string(i) + " has a weight that is not positive");
    for (const int d : depends_on_[static_cast<std::size_t>(i)])
      if (d < 0 || d >= i)
        throw std::invalid_argument("UnitScheduler: unit " + std::to_string(i) + " depends on unit " + std::to_string(d) +
                                    ", which does not come before it");
  }
  // Upward ranks, from the last unit back: every dependent of u comes after u.
  std::vector<double> behind(static_cast<std::size_t>(n), 0.0);
  for (int i = n - 1; i >= 0; --i) {
    auto& p = priority_[static_cast<std::size_t>(i)];
    p += behind[static_cast<std::size_t>(i)];
    for (const int d : depends_on_[static_cast<std::size_t>(i)])
      behind[static_cast<std::size_t>(d)] = std::max(behind[static_cast<std::size_t>(d)], p);
  }
}

std::optional<int> UnitScheduler::next() {
  std::optional<int> best;
  for (int i = 0; i < size(); ++i) {
    if (state_[static_cast<std::size_t>(i)] != State::Waiting) continue;
    const auto& deps = depends_on_[static_cast<std::size_t>(i)];
    const bool ready = std::all_of(deps.begin(), deps.end(), [&](int d) { return state_[static_cast<std::size_t>(d)] == State::Finished; });
    if (ready && (!best || priority(i) > priority(*best))) best = i;
  }
  if (best) {
    state_[static_cast<std::size_t>(*best)] = State::Running;
    ++running_;
  }
  return best;
}

void UnitScheduler::finished(int index) {
  auto& s = state_.at(static_cast<std::size_t>(index));
  if (s != State::Running) throw std::logic_error("UnitScheduler::finished: unit " + std::to_string(index) + " is not running");
  s = State::Finished;
  --running_;
  ++finished_;
}

void UnitScheduler::requeue(int index) {
  auto& s = state_.at(static_cast<std::size_t>(index));
  if (s != State::Running) throw std::logic_error("UnitScheduler::requeue: unit " + std::to_string(index) + " is not running");
  s = State::Waiting;
  --running_;
}

}  // namespace gpilqg
