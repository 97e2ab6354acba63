#pragma once
/// @file transition_data.hpp
/// The measured transitions Algorithm 1 learns from, one row per step: x_t, u_t, x_{t+1} as the real
/// system's sensors saw them, each labelled with the round whose rollouts produced it. They come from
/// rollouts on a simulated world (`gpilqg run`) or from measurement files (`gpilqg plan --data`).

#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

struct RealRollout;

struct TransitionData {
  Matrix x, u, x_next;
  std::vector<int> iteration;  ///< the round whose rollouts produced each row (-1: an earlier task)
  int size() const { return static_cast<int>(x.rows()); }
  /// Appends the completed transitions of a rollout: its measured states and applied controls.
  void append(const RealRollout& rollout, int iteration);
  /// Appends every pair of consecutive rows of every episode, in file order: (x_t, u_t) -> x_{t+1}.
  /// The control of an episode's last row starts no transition and is not used.
  void append(const MeasurementSet& set, int iteration);
  /// The first `rows` rows.
  TransitionData head(int rows) const;
};

}  // namespace gpilqg
