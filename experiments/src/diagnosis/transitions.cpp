#include "gpilqg/experiments/diagnosis/transitions.hpp"

#include <fmt/format.h>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/input_delay.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/heldout_blocks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace gpilqg::diagnosis {

std::vector<int> Transitions::rows(bool heldout_rows) const {
  std::vector<int> out;
  for (int i = 0; i < size(); ++i)
    if (heldout[static_cast<std::size_t>(i)] == heldout_rows) out.push_back(i);
  return out;
}

std::vector<int> heldout_episodes(const MeasurementSet& set, double fraction) {
  const auto count = static_cast<int>(set.episodes.size());
  if (count < 2)
    throw DataProblem("the data has " + std::to_string(count) +
                                " episode(s); expected at least 2, since the diagnosis holds whole episodes out");
  return heldout_indices(count, fraction);
}

int position_by_name(const SystemSignature& system, int velocity) {
  const std::string& name = system.states[static_cast<std::size_t>(velocity)].name;
  if (name.size() <= 4 || !name.ends_with("_dot")) return -1;
  return index_of(system.states, name.substr(0, name.size() - 4));
}

std::vector<int> estimated_velocity_positions(const MeasurementSet& set) {
  if (set.estimated_states.empty()) return {};
  const auto estimated = [&](int state) {
    const std::string& name = set.system.states[static_cast<std::size_t>(state)].name;
    return std::find(set.estimated_states.begin(), set.estimated_states.end(), name) != set.estimated_states.end();
  };
  std::vector<int> out(set.system.states.size(), -1);
  for (int v = 0; v < static_cast<int>(out.size()); ++v) {
    const int position = position_by_name(set.system, v);
    if (position >= 0 && estimated(v) && !estimated(position)) out[static_cast<std::size_t>(v)] = position;
  }
  return out;
}

Transitions make_transitions(const MeasurementSet& set, const std::vector<int>& heldout, double dt) {
  const auto n = static_cast<Eigen::Index>(set.system.states.size());
  const auto m = static_cast<Eigen::Index>(set.system.controls.size());
  Eigen::Index rows = 0;
  for (const Episode& e : set.episodes) rows += std::max(e.length() - 1, 0);
  Transitions out;
  out.x.resize(rows, n);
  out.u.resize(rows, m);
  out.x_next.resize(rows, n);
  out.t.resize(rows);
  out.episode.reserve(static_cast<std::size_t>(rows));
  out.heldout.reserve(static_cast<std::size_t>(rows));
  Eigen::Index row = 0;
  for (std::size_t k = 0; k < set.episodes.size(); ++k) {
    const Episode& e = set.episodes[k];
    if (e.length() < 2) continue;
    if (!(std::abs(e.dt() - dt) <= 1e-6 * dt)) {
      std::ostringstream os;
      os.precision(17);
      os << "episode " << e.id << " has dt = " << e.dt() << " s; expected " << dt
         << " s like the first episode (within 1e-6 relative)";
      throw DataProblem(os.str());
    }
    const bool held = std::find(heldout.begin(), heldout.end(), static_cast<int>(k)) != heldout.end();
    const Eigen::Index steps = e.length() - 1;
    out.x.middleRows(row, steps) = e.x.topRows(steps);
    out.u.middleRows(row, steps) = e.u.topRows(steps);
    out.x_next.middleRows(row, steps) = e.x.bottomRows(steps);
    out.t.segment(row, steps) = e.t.head(steps);
    for (Eigen::Index s = 0; s < steps; ++s) {
      out.episode.push_back(static_cast<int>(k));
      out.heldout.push_back(held);
    }
    row += steps;
  }
  out.position_of = estimated_velocity_positions(set);
  return out;
}

void check_measurement_range(const MeasurementSet& set) {
  const auto check = [](const Episode& e, const MatrixCRef& values, const std::vector<Quantity>& columns) {
    for (Eigen::Index s = 0; s < values.rows(); ++s)
      for (Eigen::Index j = 0; j < values.cols(); ++j)
        if (std::abs(values(s, j)) > kDivergedStateMagnitude)
          throw DataProblem(fmt::format(
              "episode {} at t = {}: column '{}' is {:g}; expected |value| <= {:g} (the bound beyond which a state "
              "counts as diverged)", e.id, e.t(s), columns[static_cast<std::size_t>(j)].name, values(s, j),
              kDivergedStateMagnitude));
  };
  for (const Episode& e : set.episodes) {
    check(e, e.x, set.system.states);
    check(e, e.u, set.system.controls);
  }
}

bool prediction_diverged(const VectorCRef& x) { return check_divergence(x) != RolloutStatus::Completed; }

Matrix applied_controls(const Transitions& data, double delay) {
  if (delay == 0.0) return data.u;
  Matrix out(data.u.rows(), data.u.cols());
  for (int first = 0; first < data.size();) {
    int end = first;
    while (end < data.size() && data.episode[static_cast<std::size_t>(end)] == data.episode[static_cast<std::size_t>(first)]) ++end;
    out.middleRows(first, end - first) = delay_controls(data.u.middleRows(first, end - first), delay);
    first = end;
  }
  return out;
}

Matrix one_step_predictions(const StepModel& model, const Transitions& data, int* diverged, double input_delay) {
  const Matrix u = applied_controls(data, input_delay);
  Matrix out(data.size(), model.state_dim());
  Vector next(model.state_dim());
  const auto workspace = model.make_workspace();
  int bad = 0;
  for (int i = 0; i < data.size(); ++i) {
    model.step(data.x.row(i).transpose(), u.row(i).transpose(), next, nullptr, *workspace);
    if (!prediction_diverged(next)) {
      out.row(i) = next.transpose();
    } else {
      out.row(i) = data.x.row(i);
      ++bad;
    }
  }
  if (diverged != nullptr) *diverged = bad;
  return out;
}

KStepPredictions k_step_predictions(const StepModel& model, const MeasurementSet& set,
                                    const std::vector<int>& episodes, int k, int stride, double input_delay) {
  if (k < 1 || stride < 1) throw std::invalid_argument("k_step_predictions: k and stride must be >= 1");
  const int n = model.state_dim();
  KStepPredictions out;
  out.k = k;
  std::vector<Vector> measured, predicted;
  Vector x(n), next(n);
  const auto workspace = model.make_workspace();
  for (int index : episodes) {
    const Episode& e = set.episodes.at(static_cast<std::size_t>(index));
    const Matrix u = delay_controls(e.u, input_delay);
    for (int s = 0; s + k < e.length(); s += stride) {
      x = e.x.row(s).transpose();
      bool finite = true;
      for (int j = 0; j < k && finite; ++j) {
        model.step(x, u.row(s + j).transpose(), next, nullptr, *workspace);
        finite = !prediction_diverged(next);
        x = next;
      }
      if (!finite) {
        ++out.diverged;
        continue;
      }
      measured.push_back(e.x.row(s + k).transpose());
      predicted.push_back(x);
      out.episode.push_back(index);
      out.start.push_back(s);
    }
  }
  out.measured.resize(static_cast<Eigen::Index>(measured.size()), n);
  out.predicted.resize(static_cast<Eigen::Index>(predicted.size()), n);
  for (std::size_t w = 0; w < measured.size(); ++w) {
    out.measured.row(static_cast<Eigen::Index>(w)) = measured[w].transpose();
    out.predicted.row(static_cast<Eigen::Index>(w)) = predicted[w].transpose();
  }
  return out;
}

}  // namespace gpilqg::diagnosis
