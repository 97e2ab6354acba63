#include "gpilqg/experiments/reference_plans.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/model_file.hpp"

namespace gpilqg {

std::vector<SimplerModel> simpler_models(const LoopModel& config, const ActuatorNoise& noise, const ModelSpec& planned_on) {
  ModelSpec preset;
  preset.system = config.simulator.system;
  preset.preset = config.simulator.preset;
  const std::pair<std::string, ModelSpec> candidates[] = {
      {fmt::format("the system's preset '{}' alone", to_string(preset.preset)), preset},
      {"the config's simulator", config.simulator}};
  std::vector<std::string> seen{diagnosis::model_file_text(planned_on)};
  std::vector<SimplerModel> models;
  for (const auto& [name, spec] : candidates) {
    std::string text = diagnosis::model_file_text(spec);
    if (std::find(seen.begin(), seen.end(), text) != seen.end()) continue;
    seen.push_back(std::move(text));
    models.push_back({name, make_step_model(spec.build(noise), config.integrator, config.dt, config.substeps)});
  }
  return models;
}

void ReferencePlans::keep(std::string name, AffinePolicy policy) {
  names.push_back(std::move(name));
  policies.push_back(std::move(policy));
}

std::string ReferencePlans::start_name(int start) const {
  if (start <= 0 || start > static_cast<int>(names.size())) return kUsualStart;
  return names[static_cast<std::size_t>(start - 1)];
}

ReferencePlans reference_plans(const DdpTask& task, DdpVariant variant, const LoopModel& config,
                               const ActuatorNoise& noise, const ModelSpec& planned_on) {
  ReferencePlans plans;
  for (const SimplerModel& simpler : simpler_models(config, noise, planned_on)) {
    plans.keep("the plan on " + simpler.name, plan_with_ddp(task, simpler.model, variant, Matrix()).policy);
  }
  return plans;
}

}  // namespace gpilqg
