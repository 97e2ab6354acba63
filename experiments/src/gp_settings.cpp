#include "gpilqg/experiments/gp_settings.hpp"

#include <fmt/format.h>

#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {
namespace {

int integer_at_least(const TomlFields& f, const std::string& path, int minimum, int fallback) {
  const long value = f.integer(path, fallback);
  if (value < minimum) f.fail(path, fmt::format("is {}; expected >= {}", value, minimum));
  if (value > 1'000'000'000) f.fail(path, fmt::format("is {}; expected <= 1000000000", value));
  return static_cast<int>(value);
}

}  // namespace

GpSettings read_gp_settings(const TomlFields& f, const GpSettings& defaults) {
  f.only_keys("gp", {"backend", "exact_points", "inducing", "frequencies", "restarts", "max_evaluations"});
  GpSettings s = defaults;
  s.backend = f.string("gp.backend", defaults.backend);
  s.backend_settings.exact_points = integer_at_least(f, "gp.exact_points", 2, defaults.backend_settings.exact_points);
  s.backend_settings.inducing = integer_at_least(f, "gp.inducing", 1, defaults.backend_settings.inducing);
  s.backend_settings.frequencies = integer_at_least(f, "gp.frequencies", 1, defaults.backend_settings.frequencies);
  try {
    (void)gp::make_backend(s.backend, s.backend_settings);
  } catch (const std::invalid_argument& e) {
    f.fail("gp.backend", e.what());
  }
  s.restarts = integer_at_least(f, "gp.restarts", 0, defaults.restarts);
  s.max_evaluations = integer_at_least(f, "gp.max_evaluations", 1, defaults.max_evaluations);
  return s;
}

}  // namespace gpilqg
