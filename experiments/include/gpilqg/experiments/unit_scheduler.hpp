#pragma once
/// @file unit_scheduler.hpp
/// Which unit of work to start next when several workers share a list of units with dependencies
/// (`mpirun -np K gpilqg run`, `gpilqg sweep`, `gpilqg profile` under MPI).
///
/// List scheduling by the longest remaining path: a unit is ready when every unit it depends on has
/// finished, and among the ready units the one with the largest "upward rank"
///     rank(u) = weight(u) + max over the units v that depend on u of rank(v)
/// starts first (ties: the earlier unit in the list). Starting long chains early keeps the last
/// worker from waiting on a chain that was started late (HEFT's priority, Topcuoglu et al. 2002, with
/// one kind of processor). The weights are rough expected costs; they change the order, never the
/// results.
///
/// Not thread-safe: the coordinator that owns it serialises the calls.

#include <optional>
#include <vector>

namespace gpilqg {

class UnitScheduler {
 public:
  /// `depends_on[i]`: the units unit i needs (each index < number of units, no cycles: every unit
  /// depends only on earlier ones); `weight[i]` > 0. Throws std::invalid_argument otherwise.
  UnitScheduler(std::vector<std::vector<int>> depends_on, std::vector<double> weight);

  /// The ready unit to start now (marked running), or nothing when no unit is ready at the moment.
  std::optional<int> next();
  /// Unit `index`, returned by next(), has finished; its dependents may become ready.
  void finished(int index);
  /// Unit `index` (returned by next()) is put back, e.g. it was given to a worker that stopped.
  void requeue(int index);

  int size() const { return static_cast<int>(state_.size()); }
  int finished_count() const { return finished_; }
  int running_count() const { return running_; }
  /// Every unit has finished.
  bool all_finished() const { return finished_ == size(); }
  /// The scheduling priority of unit i (its upward rank).
  double priority(int index) const { return priority_.at(static_cast<std::size_t>(index)); }

 private:
  enum class State { Waiting, Running, Finished };
  std::vector<std::vector<int>> depends_on_;
  std::vector<double> priority_;
  std::vector<State> state_;
  int finished_ = 0, running_ = 0;
};

}  // namespace gpilqg
