#include "gpilqg/experiments/gp_settings.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {

GpSettings read_gp_settings(const TomlFields& f, const GpSettings& defaults) {
  f.only_keys("gp", {"backend", "exact_points", "inducing", "frequencies", "restarts", "max_evaluations", "known_noise"});
  GpSettings s = defaults;
  s.backend = f.string("gp.backend", defaults.backend);
  s.backend_settings.exact_points = f.integer_in("gp.exact_points", 2, limits::kMaxExactPoints, defaults.backend_settings.exact_points);
  s.backend_settings.inducing = f.integer_in("gp.inducing", 1, limits::kMaxInducing, defaults.backend_settings.inducing);
  s.backend_settings.frequencies = f.integer_in("gp.frequencies", 1, limits::kMaxFrequencies, defaults.backend_settings.frequencies);
  try {
    (void)gp::make_backend(s.backend, s.backend_settings);
  } catch (const std::invalid_argument& e) {
    f.fail("gp.backend", e.what());
  }
  s.restarts = f.integer_in("gp.restarts", 0, limits::kMaxRestarts, defaults.restarts);
  s.max_evaluations = f.integer_in("gp.max_evaluations", 1, limits::kMaxEvaluations, defaults.max_evaluations);
  s.known_noise = f.boolean("gp.known_noise", defaults.known_noise);
  if (s.known_noise && !gp::make_backend(s.backend, s.backend_settings)->takes_known_noise())
    f.fail("gp.known_noise", fmt::format("is true with backend '{}', which does not take a known noise variance per "
                                         "point; expected a backend that does ({}), or known_noise = false",
                                         s.backend, fmt::join(gp::backends_taking_known_noise(), ", ")));
  return s;
}

}  // namespace gpilqg
