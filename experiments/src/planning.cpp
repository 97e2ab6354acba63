#include "gpilqg/experiments/planning.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/core/version.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/reference_plans.hpp"
#include "gpilqg/experiments/run_setup.hpp"

namespace gpilqg {
namespace {

/// The algorithm whose random streams `gpilqg plan` and `gpilqg rollout` share with `gpilqg run`.
constexpr const char* kAlgorithm = "gp_ilqg";

bool same_relative(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)); }

/// Every data file's transitions, file i labelled i; an episode sampled at another dt is an error.
TransitionData read_data(const std::vector<std::filesystem::path>& files, const SystemSignature& signature, double dt) {
  TransitionData data;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const MeasurementSet set = read_measurements(files[i], signature);
    for (const Episode& e : set.episodes)
      if (!same_relative(e.dt(), dt))
        throw DataError(files[i], fmt::format("episode {}", e.id), fmt::format("its step is {} s", e.dt()),
                        fmt::format("the config's [system] dt = {} s (to 1e-6 relative)", dt));
    data.append(set, static_cast<int>(i));
  }
  return data;
}

/// The previous policy must be a round of the same problem.
void check_previous(const PolicyFile& previous, const std::filesystem::path& file, const SolveConfig& c,
                    const SystemSignature& signature) {
  const auto fail = [&](const std::string& attribute, const std::string& found, const std::string& expected) {
    throw InputError(fmt::format("{}: attribute '/policy@{}' is {}; expected {} (the config's)", file.string(),
                                 attribute, found, expected));
  };
  if (previous.state_names != names_of(signature.states) || previous.control_names != names_of(signature.controls))
    fail("state_names", fmt::format("[{}] / [{}]", fmt::join(previous.state_names, ", "), fmt::join(previous.control_names, ", ")),
         fmt::format("the states and controls of {}", c.system));
  check_policy_system(previous, file, c.system);
  if (!same_relative(previous.dt, c.dt)) fail("dt", fmt::format("{}", previous.dt), fmt::format("{}", c.dt));
  if (previous.policy.horizon() != c.horizon)
    fail("horizon", std::to_string(previous.policy.horizon()), std::to_string(c.horizon));
}

}  // namespace

PlannedPolicy plan_policy(const PlanRequest& request) {
  const SolveConfig& c = request.config.problem;
  const GpSettings& gp_settings = request.config.gp;
  if (request.diagnose && request.data_files.empty())
    throw InputError("diagnose: no measurement files to diagnose; expected data files with it (--data FILE, or "
                     "Python's data=[...])");
  const SystemSignature signature = system_signature(c.system);
  std::shared_ptr<const StepModel> simulator = make_solve_model(c);
  const QuadraticCost cost = make_solve_cost(c);
  const DdpTask task = ddp_task(c, cost);

  const TransitionData data = read_data(request.data_files, signature, c.dt);
  PlannedPolicy out;
  ModelSpec planned_on = c.simulator;
  if (request.diagnose && data.size() > 0) {
    const LoopModel model{c.simulator, c.integrator, c.substeps, c.dt};
    out.diagnosis = diagnose_loop_data(model, data, static_cast<int>(request.data_files.size()) - 1,
                                       derive_seed(request.seed, 0, RandomStream::Diagnosis, {stream_id(kAlgorithm), 0}));
    simulator = planning_simulator(model, c.noise, simulator, out.diagnosis);
    if (out.diagnosis->adopted) planned_on = out.diagnosis->model;
  }
  const std::string simulator_text = diagnosis::model_file_text(planned_on);
  const auto backend = gp::make_backend(gp_settings.backend, gp_settings.backend_settings);

  GpRoundInputs inputs;
  inputs.data = &data;
  inputs.backend = backend.get();
  inputs.variant = c.solver.variant;
  inputs.observation_std = request.config.observation_std;
  inputs.known_noise = gp_settings.known_noise;
  ReferencePlans references =
      reference_plans(task, DdpVariant::ILQG, LoopModel{c.simulator, c.integrator, c.substeps, c.dt}, c.noise, planned_on);
  inputs.fit.restarts = gp_settings.restarts;
  inputs.fit.max_evaluations = gp_settings.max_evaluations;
  inputs.fit.seed = gp_fit_seed(request.seed, 0, kAlgorithm, data.size());
  int round = data.size() > 0 ? 1 : 0;
  if (request.previous) {
    const PolicyFile previous = read_policy_file(*request.previous);
    check_previous(previous, *request.previous, c, signature);
    inputs.previous_u_bar = previous.policy.u_bar;
    references.keep(kPreviousRoundsPolicy, previous.policy);
    round = previous.round + 1;
    if (!previous.model_backend.empty()) {
      if (previous.model_backend != gp_settings.backend)
        throw InputError(fmt::format("{}: group '/model' was fitted with backend '{}'; expected the config's [gp] "
                                     "backend '{}' (a warm start needs the same backend)",
                                     request.previous->string(), previous.model_backend, gp_settings.backend));
      // The previous GP learned the error of the simulator it was planned on: a warm start needs the same.
      if (previous.simulator_model.empty() || previous.simulator_model == simulator_text)
        inputs.previous_model = read_policy_model(*request.previous, simulator, gp_settings.backend_settings);
    }
  }

  inputs.plans_to_keep = references.policies;
  GpRound result = plan_gp_ilqg_round(task, simulator, inputs);
  out.model = std::dynamic_pointer_cast<const gp::ResidualModel>(result.plan.model);
  out.summary = result.plan.summary;
  out.start = references.start_name(result.plan.start);
  out.data_rows = data.size();
  out.fit_seconds = result.fit_seconds;
  out.warm_started_gp = inputs.previous_model != nullptr && data.size() > 0;
  PolicyFile& f = out.file;
  f.policy = file_policy(result.plan.policy);
  if (!f.policy.u_min.size()) f.policy.u_min = c.u_min;
  if (!f.policy.u_max.size()) f.policy.u_max = c.u_max;
  f.dt = c.dt;
  f.system = c.system;
  f.state_names = names_of(signature.states);
  f.control_names = names_of(signature.controls);
  f.predicted_cost = result.plan.nominal_cost;
  f.expected_cost = result.plan.predicted_cost;
  f.round = round;
  for (const auto& file : request.data_files) f.data_files.push_back(file.string());
  f.created = utc_timestamp();
  f.gpilqg_version = kVersionString;
  f.simulator_model = simulator_text;
  out.planned_on = planned_on;
  return out;
}

}  // namespace gpilqg
