#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"

#include <fnmatch.h>

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg::diagnosis {

std::vector<std::string> excluded_effects(const std::vector<std::string>& patterns, const ModelSpec& model,
                                          const std::vector<std::string>& add) {
  const std::vector<LibraryEffect> candidates = candidate_effects(model);
  std::vector<std::string> out;
  for (const std::string& pattern : patterns) {
    bool matched = false;
    for (const LibraryEffect& effect : candidates) {
      if (::fnmatch(pattern.c_str(), effect.name.c_str(), 0) != 0) continue;
      matched = true;
      if (std::find(out.begin(), out.end(), effect.name) == out.end()) out.push_back(effect.name);
    }
    if (!matched)
      throw InputError(fmt::format("--exclude '{}': matches no candidate effect; expected a name or a pattern (*, ?) "
                                   "over the candidates: {}",
                                   pattern, candidate_names(model)));
  }
  for (const std::string& name : add)
    if (std::find(out.begin(), out.end(), name) != out.end())
      throw InputError(fmt::format("--add {}: the effect is excluded by --exclude; expected an effect that is not excluded",
                                   name));
  // The candidates' order, whatever the order of the patterns.
  std::vector<std::string> ordered;
  for (const LibraryEffect& effect : candidates)
    if (std::find(out.begin(), out.end(), effect.name) != out.end()) ordered.push_back(effect.name);
  return ordered;
}

std::vector<std::string> included_effects(const std::vector<std::string>& patterns, const ModelSpec& model,
                                          const std::vector<std::string>& excluded) {
  std::vector<std::string> on_request, out;
  for (const LibraryEffect& effect : candidate_effects(model))
    if (effect.on_request) on_request.push_back(effect.name);
  std::vector<bool> included(on_request.size(), false);
  for (const std::string& pattern : patterns) {
    bool matched = false;
    std::vector<std::string> excluded_matches;
    for (std::size_t i = 0; i < on_request.size(); ++i) {
      if (::fnmatch(pattern.c_str(), on_request[i].c_str(), 0) != 0) continue;
      // --exclude wins: `--include 'param:*.second_moment_*' --exclude 'param:link1.*'` leaves link 1 out.
      if (std::find(excluded.begin(), excluded.end(), on_request[i]) != excluded.end()) {
        excluded_matches.push_back(on_request[i]);
      } else {
        matched = true;
        included[i] = true;
      }
    }
    if (!matched && !excluded_matches.empty())
      throw InputError(fmt::format("--include '{}': every effect it names is excluded by --exclude ({}); expected "
                                   "an effect that is not excluded",
                                   pattern, fmt::join(excluded_matches, ", ")));
    if (!matched)
      throw InputError(fmt::format("--include '{}': matches no candidate searched only on request; expected a name or "
                                   "a pattern (*, ?) over: {}",
                                   pattern, on_request.empty() ? std::string("(none for this system)")
                                                               : fmt::format("{}", fmt::join(on_request, ", "))));
  }
  for (std::size_t i = 0; i < on_request.size(); ++i)
    if (included[i]) out.push_back(on_request[i]);
  return out;
}

DiagnosisOptions diagnosis_options(const DiagnoseRequest& o) {
  DiagnosisOptions d;
  if (!o.model_file.empty()) {
    d.model = read_model_file(o.model_file, o.system);
  } else {
    const auto preset = parse_preset(o.preset);
    if (!preset) throw InputError("--preset '" + o.preset + "': expected 'sim' or 'real'");
    d.model.system = o.system;
    d.model.preset = *preset;
  }
  for (const std::string& text : o.add) d.add.push_back(parse_add_option(text, d.model));
  std::vector<std::string> added;
  for (const EffectRequest& e : d.add) added.push_back(e.effect);
  d.exclude = excluded_effects(o.exclude, d.model, added);
  d.include = included_effects(o.include, d.model, d.exclude);
  const auto integrator = parse_integrator(o.integrator);
  if (!integrator) throw InputError("--integrator '" + o.integrator + "': expected 'rk4' or 'euler'");
  d.integrator = *integrator;
  if (!(o.heldout > 0.0 && o.heldout < 1.0))
    throw InputError(fmt::format("--heldout {}: expected a fraction of the episodes (or blocks) in (0, 1)", o.heldout));
  const std::string horizons = fmt::format("{}", fmt::join(o.horizons, ","));
  if (o.horizons.empty()) throw InputError("--horizons: expected at least one horizon k >= 1");
  if (o.horizons.size() > kMaxHorizonCount)
    throw InputError(fmt::format("--horizons {}: {} horizons; expected at most {}", horizons, o.horizons.size(), kMaxHorizonCount));
  for (std::size_t i = 0; i < o.horizons.size(); ++i) {
    if (o.horizons[i] < 1 || o.horizons[i] > limits::kMaxHorizon)
      throw InputError(fmt::format("--horizons {}: {} is not a horizon; expected whole numbers from 1 to {}", horizons,
                                   o.horizons[i], limits::kMaxHorizon));
    for (std::size_t j = 0; j < i; ++j)
      if (o.horizons[j] == o.horizons[i])
        throw InputError(fmt::format("--horizons {}: {} is listed twice; expected distinct horizons", horizons, o.horizons[i]));
  }
  if (o.gp_points < 10) throw InputError(fmt::format("--gp-points {}: expected at least 10", o.gp_points));
  if (o.gp_restarts < 0) throw InputError(fmt::format("--gp-restarts {}: expected >= 0", o.gp_restarts));
  try {
    gp::make_backend(o.backend);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("--backend: ") + e.what());
  }
  const bool chosen_by_data = o.criterion == "auto";
  // inverse-dynamics-iv: the inverse-dynamics criterion in its instrumental-variable form.
  const bool instruments = o.criterion == "inverse-dynamics-iv";
  const auto criterion = chosen_by_data ? std::optional<FitCriterion>(FitCriterion::OneStep)
                         : instruments  ? std::optional<FitCriterion>(FitCriterion::InverseDynamics)
                                        : parse_fit_criterion(o.criterion);
  if (!criterion)
    throw InputError("--criterion '" + o.criterion +
                     "': expected 'auto', 'one-step', 'simulation', 'inverse-dynamics' or 'inverse-dynamics-iv'");
  if (chosen_by_data && o.window)
    throw InputError(fmt::format("--window {}: windows belong to --criterion simulation; with --criterion auto the data "
                                 "choose the criterion and its window", *o.window));
  if (*criterion == FitCriterion::Simulation && !o.window)
    throw InputError("--criterion simulation: expected --window N, the samples per simulation window (e.g. a few "
                     "periods of the slowest motion)");
  if (*criterion != FitCriterion::Simulation && o.window)
    throw InputError(fmt::format("--window {}: windows belong to --criterion simulation; the criterion is {}", *o.window,
                                 fit_criterion_name(*criterion)));
  if (*criterion == FitCriterion::InverseDynamics && !find_system(o.system)->generalised_forces)
    throw InputError(fmt::format("--criterion {}: system '{}' has no generalised-force map, so it has no "
                                 "generalised-force residual; expected 'one-step' or 'simulation'", o.criterion, o.system));
  if (o.window && (*o.window < 1 || *o.window > limits::kMaxHorizon))
    throw InputError(fmt::format("--window {}: expected a whole number of samples from 1 to {}", *o.window, limits::kMaxHorizon));
  d.criterion = *criterion;
  d.choose_criterion = chosen_by_data;
  d.instruments = instruments;
  d.window = o.window ? static_cast<int>(*o.window) : 1;
  d.auto_select = o.auto_select;
  const std::string search = o.search.value_or("subsets");
  if (search == "subsets") d.search = SearchMethod::Subsets;
  else if (search == "forward") d.search = SearchMethod::Forward;
  else throw InputError(fmt::format("--search '{}': expected 'subsets' (every set of up to {} effects) or 'forward'",
                                    search, d.max_subset));
  if (o.search && !o.auto_select)
    throw InputError(fmt::format("--search {}: chooses how --auto searches for a set of effects; expected --auto with "
                                 "it (without --auto each effect is ranked alone)",
                                 search));
  d.heldout_fraction = o.heldout;
  d.horizons = o.horizons;
  d.gp.points = o.gp_points;
  d.gp.restarts = o.gp_restarts;
  d.gp.backend = o.backend;
  d.gp.seed = o.seed;
  return d;
}

}  // namespace gpilqg::diagnosis
