#include "gpilqg/experiments/plan_config.hpp"

#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {

PlanConfig read_plan_config(const std::filesystem::path& file) {
  const toml::table root = TomlFields::parse(file);
  return read_plan_config(TomlFields(root, file));
}

PlanConfig read_plan_config(const TomlFields& f) {
  PlanConfig c;
  c.problem = read_solve_config(f, {"gp"}, "robust_ilqg", {"observation"});
  const int n = static_cast<int>(f.system("system.name").states.size());
  c.observation_std = f.state_vector("noise.observation", n, Vector::Zero(n));
  if ((c.observation_std.array() < 0.0).any())
    f.fail("noise.observation", "has negative entries; expected standard deviations >= 0");
  if (c.problem.solver.variant == DdpVariant::ILQR)
    f.fail("solver.algorithm", "'ilqr' ignores the noise and the GP's uncertainty; expected \"robust_ilqg\" (the "
                               "paper) or \"ilqg\" (the GP's mean only)");
  c.gp = read_gp_settings(f, GpSettings{});
  return c;
}

}  // namespace gpilqg
