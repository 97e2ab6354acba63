#include "gpilqg/control/warm_start.hpp"

#include <limits>
#include <stdexcept>

namespace gpilqg {
namespace {

/// The nominal cost of a noise-free rollout, +infinity when it diverged.
double rollout_cost(const Cost& cost, const RolloutResult& r) {
  return r.finite ? trajectory_cost(cost, r.trajectory) : std::numeric_limits<double>::infinity();
}

}  // namespace

WarmStartControls warm_start_controls(const StepModel& model, const Cost& cost, const AffinePolicy& previous,
                                      const VectorCRef& x0) {
  const int T = previous.horizon();
  if (previous.u_bar.rows() != model.control_dim() || previous.x_bar.rows() != model.state_dim() ||
      previous.x_bar.cols() != T + 1 || static_cast<int>(previous.K.size()) != T || previous.k.rows() != model.control_dim() ||
      previous.k.cols() != T || x0.size() != model.state_dim())
    throw std::invalid_argument("warm_start_controls: the previous policy or x0 does not fit the model's dimensions");
  std::mt19937_64 unused_rng;  // noise-free rollouts draw nothing
  PolicyRolloutSettings noise_free;
  noise_free.process_noise = false;
  const RolloutResult closed = rollout_policy(model, previous, x0, noise_free, unused_rng);
  const RolloutResult open = rollout(model, x0, previous.u_bar);
  const double closed_cost = rollout_cost(cost, closed);
  const double open_cost = rollout_cost(cost, open);
  WarmStartControls out;
  if (closed.finite && closed_cost <= open_cost) {
    out.controls = closed.trajectory.u;
    out.kind = WarmStart::ClosedLoop;
    out.cost = closed_cost;
    out.other_cost = open_cost;
  } else {
    out.controls = previous.u_bar;
    out.kind = WarmStart::OpenLoop;
    out.cost = open_cost;
    out.other_cost = closed_cost;
  }
  return out;
}

}  // namespace gpilqg
