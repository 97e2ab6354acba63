#include "gpilqg/experiments/transition_data.hpp"

#include "gpilqg/experiments/task_actions.hpp"

namespace gpilqg {

void TransitionData::append(const RealRollout& rollout, int iteration_index) {
  const int T = rollout.steps_completed;
  const int n = static_cast<int>(rollout.measured.rows());
  const int m = static_cast<int>(rollout.truth.u.rows());
  const int old = size();
  x.conservativeResize(old + T, n);
  u.conservativeResize(old + T, m);
  x_next.conservativeResize(old + T, n);
  for (int t = 0; t < T; ++t) {
    x.row(old + t) = rollout.measured.col(t).transpose();
    u.row(old + t) = rollout.truth.u.col(t).transpose();
    x_next.row(old + t) = rollout.measured.col(t + 1).transpose();
    iteration.push_back(iteration_index);
  }
}

void TransitionData::append(const MeasurementSet& set, int iteration_index) {
  const int n = static_cast<int>(set.system.states.size());
  const int m = static_cast<int>(set.system.controls.size());
  for (const Episode& e : set.episodes) {
    const int T = e.length() - 1;
    if (T <= 0) continue;
    const int old = size();
    x.conservativeResize(old + T, n);
    u.conservativeResize(old + T, m);
    x_next.conservativeResize(old + T, n);
    x.middleRows(old, T) = e.x.topRows(T);
    u.middleRows(old, T) = e.u.topRows(T);
    x_next.middleRows(old, T) = e.x.bottomRows(T);
    iteration.insert(iteration.end(), static_cast<std::size_t>(T), iteration_index);
  }
}

TransitionData TransitionData::head(int rows) const {
  TransitionData out;
  out.x = x.topRows(rows);
  out.u = u.topRows(rows);
  out.x_next = x_next.topRows(rows);
  out.iteration.assign(iteration.begin(), iteration.begin() + rows);
  return out;
}

}  // namespace gpilqg
