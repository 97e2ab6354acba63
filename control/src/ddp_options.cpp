#include "gpilqg/control/ddp_options.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

std::optional<DdpVariant> parse_variant(std::string_view name) {
  if (name == "ilqr") return DdpVariant::ILQR;
  if (name == "ilqg") return DdpVariant::ILQG;
  if (name == "robust_ilqg") return DdpVariant::RobustILQG;
  return std::nullopt;
}

std::string_view to_string(DdpVariant variant) {
  switch (variant) {
    case DdpVariant::ILQR: return "ilqr";
    case DdpVariant::ILQG: return "ilqg";
    case DdpVariant::RobustILQG: return "robust_ilqg";
  }
  return "?";
}

std::optional<RegularizationTarget> parse_regularization(std::string_view name) {
  if (name == "control") return RegularizationTarget::ControlHessian;
  if (name == "value") return RegularizationTarget::ValueHessian;
  return std::nullopt;
}

std::string_view to_string(RegularizationTarget target) {
  return target == RegularizationTarget::ControlHessian ? "control" : "value";
}

namespace {

void require(bool ok, const char* field, double value, const char* expected) {
  if (!ok)
    throw std::invalid_argument(std::string("solver option '") + field + "' = " + std::to_string(value) +
                                "; expected " + expected);
}

}  // namespace

void DdpOptions::validate() const {
  require(max_iterations >= 1, "max_iterations", max_iterations, ">= 1");
  require(std::isfinite(max_seconds) && max_seconds > 0.0, "max_seconds", max_seconds, "a finite value > 0");
  require(std::isfinite(cost_tolerance) && cost_tolerance >= 0.0, "cost_tolerance", cost_tolerance, ">= 0");
  require(std::isfinite(gradient_tolerance) && gradient_tolerance >= 0.0, "gradient_tolerance",
          gradient_tolerance, ">= 0");
  require(std::isfinite(lambda_initial) && lambda_initial >= 0.0, "lambda_initial", lambda_initial, ">= 0");
  require(std::isfinite(lambda_factor) && lambda_factor > 1.0, "lambda_factor", lambda_factor, "> 1");
  require(std::isfinite(lambda_min) && lambda_min > 0.0, "lambda_min", lambda_min, "> 0");
  require(std::isfinite(lambda_max) && lambda_max > lambda_min, "lambda_max", lambda_max, "> lambda_min");
  require(line_search_steps >= 1, "line_search_steps", line_search_steps, ">= 1");
  require(std::isfinite(min_reduction_ratio) && min_reduction_ratio >= 0.0 && min_reduction_ratio < 1.0,
          "min_reduction_ratio", min_reduction_ratio, "in [0, 1)");
}

}  // namespace gpilqg
