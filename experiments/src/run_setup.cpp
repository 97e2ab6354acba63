#include "gpilqg/experiments/run_setup.hpp"

#include <vector>

#include "gpilqg/core/fnv_hash.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {

RunModels make_run_models(const RunConfig& c) {
  const auto step_model = [&](const ModelSpec& model) {
    return make_step_model(model.build(c.noise), c.integrator, c.dt, c.substeps);
  };
  return {step_model(c.world), step_model(c.simulator)};
}

QuadraticCost make_task_cost(const RunConfig& c, const RunTask& task) {
  const Matrix Q = task.Q.asDiagonal();
  const Matrix R = task.R.asDiagonal();
  const Matrix Qf = task.Qf.asDiagonal();
  if (!task.track_line) return QuadraticCost(c.dt, Q, R, Qf, task.goal);
  const Matrix x_ref = straight_line_reference(task.x0, task.goal, task.horizon);
  const Matrix u_ref = c.u_init.replicate(1, task.horizon);  // track around the configured nominal control
  return QuadraticCost::tracking(c.dt, Q, R, Qf, x_ref, u_ref);
}

std::mt19937_64 make_rng(std::uint64_t seed, int task, RandomStream stream, std::initializer_list<std::uint64_t> index) {
  std::vector<std::uint32_t> words = {static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                                      static_cast<std::uint32_t>(task), static_cast<std::uint32_t>(stream)};
  for (const std::uint64_t i : index) words.push_back(static_cast<std::uint32_t>(i));
  std::seed_seq sequence(words.begin(), words.end());
  return std::mt19937_64(sequence);
}

std::uint64_t derive_seed(std::uint64_t seed, int task, RandomStream stream, std::initializer_list<std::uint64_t> index) {
  auto rng = make_rng(seed, task, stream, index);
  return rng();
}

std::uint64_t stream_id(const std::string& algorithm) {
  // FNV-1a from 1469598103934665603, the offset basis without its last digit: every random stream of a
  // run derives from these numbers, so they stay as they are.
  return fnv1a_64(algorithm, 1469598103934665603ull);
}

std::uint64_t gp_fit_seed(std::uint64_t seed, int task, const std::string& algorithm, int rows) {
  return derive_seed(seed, task, RandomStream::GpFit, {stream_id(algorithm), static_cast<std::uint64_t>(rows)});
}

std::mt19937_64 data_rollout_rng(std::uint64_t seed, int task, const std::string& algorithm, int round, int rollout) {
  return make_rng(seed, task, RandomStream::DataRollout,
                  {stream_id(algorithm), static_cast<std::uint64_t>(round), static_cast<std::uint64_t>(rollout)});
}

}  // namespace gpilqg
