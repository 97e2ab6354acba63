#include "gpilqg/experiments/loop_diagnosis.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg {

MeasurementSet episodes_of(const TransitionData& data, const SystemSignature& signature, double dt) {
  MeasurementSet set;
  set.system = signature;
  const int N = data.size();
  int start = 0;
  for (int i = 1; i <= N; ++i) {
    const bool ends = i == N || data.iteration[static_cast<std::size_t>(i)] != data.iteration[static_cast<std::size_t>(i - 1)] ||
                      data.x.row(i) != data.x_next.row(i - 1);
    if (!ends) continue;
    const int T = i - start;  // transitions: T + 1 samples, the last one's control unused
    Episode e;
    e.id = static_cast<long>(set.episodes.size());
    e.t = Vector::LinSpaced(T + 1, 0.0, T * dt);
    e.x.resize(T + 1, data.x.cols());
    e.x.topRows(T) = data.x.middleRows(start, T);
    e.x.row(T) = data.x_next.row(i - 1);
    e.u.resize(T + 1, data.u.cols());
    e.u.topRows(T) = data.u.middleRows(start, T);
    e.u.row(T) = data.u.row(i - 1);
    set.episodes.push_back(std::move(e));
    start = i;
  }
  return set;
}

LoopModel loop_model(const RunConfig& config) { return {config.simulator, config.integrator, config.substeps, config.dt}; }

LoopDiagnosis diagnose_loop_data(const LoopModel& model, const TransitionData& data, int round, std::uint64_t seed,
                                 const std::function<void(const std::string&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  LoopDiagnosis out;
  out.round = round;
  out.transitions = data.size();
  out.model = model.simulator;
  diagnosis::DiagnoseRequest request;  // the command's defaults, with --auto
  request.system = model.simulator.system;
  request.auto_select = true;
  request.integrator = std::string(to_string(model.integrator));
  request.seed = seed;
  diagnosis::DiagnosisOptions options = diagnosis::diagnosis_options(request);
  options.model = model.simulator;
  options.substeps = std::max(model.substeps, 1);  // a MuJoCo model steps with its own integrator (substeps 0)
  options.progress = progress;
  try {
    const diagnosis::DiagnosisReport report =
        diagnosis::diagnose(episodes_of(data, system_signature(model.simulator.system), model.dt), options);
    out.verdict = report.verdict.status;
    out.reason = report.verdict.reason;
    out.adopted = out.verdict == "explained" && report.model_next.input_delay == 0.0;
    if (out.adopted) out.model = report.model_next;
    else if (out.verdict == "explained")  // the solvers and rollouts apply each control at once
      out.reason = fmt::format("the diagnosed model has an input delay of {} control periods, which the planners do not "
                               "apply; {}",
                               report.model_next.input_delay, out.reason);
  } catch (const diagnosis::DataProblem& e) {  // data the diagnosis cannot use: the loop goes on without it
    out.verdict = "failed";
    out.reason = e.what();
  } catch (const std::invalid_argument& e) {
    throw diagnosis::own_failure(fmt::format("the {} transitions of rounds 0 to {}", data.size(), round), e);
  }
  out.changes = out.model.describe();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::shared_ptr<const StepModel> planning_simulator(const LoopModel& model, const ActuatorNoise& noise,
                                                    const std::shared_ptr<const StepModel>& simulator,
                                                    const std::optional<LoopDiagnosis>& diagnosis) {
  if (!diagnosis || !diagnosis->adopted) return simulator;
  return make_step_model(diagnosis->model.build(noise), model.integrator, model.dt, model.substeps);
}

std::string diagnosis_summary(const LoopDiagnosis& d) {
  const std::string when =
      d.round < 0 ? std::string("adopted by the previous task")
                  : fmt::format("after round {} ({} transitions, {:.1f} s)", d.round, d.transitions, d.seconds);
  if (!d.adopted) return fmt::format("{} {}: the simulator stays; {}", d.verdict, when, d.reason);
  return fmt::format("{} {}: {}", d.verdict, when, d.changes.empty() ? std::string("no change") : fmt::format("{}", fmt::join(d.changes, "; ")));
}

int diagnosed_from(const std::optional<LoopDiagnosis>& diagnosis) {
  if (!diagnosis || !diagnosis->adopted) return -1;
  return diagnosis->round + 1;
}

}  // namespace gpilqg
