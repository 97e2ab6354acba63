#include "gpilqg/core/effect_library.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/system_registry.hpp"

namespace gpilqg {

namespace {

std::string joined_names(const std::vector<LibraryEffect>& library) {
  std::string out;
  for (const auto& e : library) out += (out.empty() ? "" : ", ") + e.name;
  return out;
}

bool in_library(std::string_view system, std::string_view name) {
  for (const LibraryEffect& e : effect_library(system))
    if (e.name == name) return true;
  return false;
}

}  // namespace

LibraryEffect user_effect_entry(std::string_view system, const BasisForceDeclaration& declaration) {
  for (const LibraryEffect& e : effect_library(system))
    if (e.name == declaration.name)
      throw DeclarationError("name", -1, fmt::format("'{}' is the name of the library effect '{}' ({}) of system '{}'; "
                                                     "expected a name of its own",
                                                     declaration.name, e.name, e.formula, system));
  const SystemEntryPtr entry = find_system(system);
  const DynamicsPtr probe = entry->build(Preset::Simulator, {}, {});
  auto force = std::make_shared<const BasisForceEffect>(*probe, declaration);
  LibraryEffect out;
  out.name = force->name();
  out.kind = EffectKind::Force;
  out.parameters = force->parameters();
  out.formula = force->formula();
  out.linear = true;
  out.force = std::move(force);
  return out;
}

const BasisForceDeclaration* user_declaration(const LibraryEffect& effect) {
  const auto* basis = dynamic_cast<const BasisForceEffect*>(effect.force.get());
  return basis == nullptr ? nullptr : &basis->declaration();
}

LibraryEffect with_smoothing(const LibraryEffect& effect, double v0) {
  if (!effect.smoothing)
    throw std::invalid_argument(fmt::format("effect '{}' has no smoothing velocity v0; only Coulomb friction has one",
                                            effect.name));
  if (!(v0 > 0.0) || !std::isfinite(v0))
    throw std::invalid_argument(fmt::format("effect '{}': smoothing velocity v0 = {}; expected a finite v0 > 0",
                                            effect.name, v0));
  LibraryEffect out = effect;
  out.force = effect.smoothing->at(v0);
  out.formula = out.force->formula();
  out.smoothing->width = v0;
  return out;
}

namespace {

/// `effect` at the smoothing velocity `model` gives it, if any.
LibraryEffect as_in_model(const LibraryEffect& effect, const ModelSpec& model) {
  const auto it = model.smoothing.find(effect.name);
  if (!effect.smoothing || it == model.smoothing.end() || it->second == effect.smoothing->width) return effect;
  return with_smoothing(effect, it->second);
}

}  // namespace

std::vector<LibraryEffect> candidate_effects(const ModelSpec& model) {
  std::vector<LibraryEffect> out;
  for (const LibraryEffect& e : effect_library(model.system)) out.push_back(as_in_model(e, model));
  out.insert(out.end(), model.user_effects.begin(), model.user_effects.end());
  return out;
}

std::string candidate_names(const ModelSpec& model) { return joined_names(candidate_effects(model)); }

ModelSpec with_parameter(const ModelSpec& model, const std::string& name, double value) {
  for (const LibraryEffect& e : effect_library(model.system))
    if (e.kind == EffectKind::Recalibration && e.recalibrated == name) return model.with(e, Vector::Constant(1, value));
  ModelSpec out = model;
  out.parameters[name] = value;
  return out;
}

LibraryEffect find_candidate(const ModelSpec& model, std::string_view name) {
  for (const LibraryEffect& e : effect_library(model.system))
    if (e.name == name) return as_in_model(e, model);
  for (const LibraryEffect& e : model.user_effects)
    if (e.name == name) return e;
  throw std::invalid_argument(fmt::format("unknown effect '{}' for system '{}'; expected one of: {}", name, model.system,
                                          candidate_names(model)));
}

const std::vector<LibraryEffect>& effect_library(std::string_view system) {
  // Entries live as long as the process-wide registry, so the reference stays valid.
  return find_system(system)->effects;
}

std::string effect_names(std::string_view system) { return joined_names(effect_library(system)); }

const LibraryEffect& find_effect(std::string_view system, std::string_view name) {
  const auto& library = effect_library(system);
  for (const auto& e : library)
    if (e.name == name) return e;
  throw std::invalid_argument(fmt::format("unknown effect '{}' for system '{}'; expected one of: {}", name, system,
                                          joined_names(library)));
}

DynamicsPtr ModelSpec::build(const ActuatorNoise& noise) const {
  DynamicsPtr base = make_system(system, preset, parameters);
  if (actuator_gain == 1.0 && forces.empty()) {
    if (noise.column_count() == 0) return base;
    return make_system(system, preset, parameters, noise);
  }
  std::vector<AppliedEffect> applied;
  for (const auto& [name, values] : forces) {
    const LibraryEffect e = find_candidate(*this, name);
    if (e.kind != EffectKind::Force)
      throw std::invalid_argument("effect '" + name + "' is not a force; set it through the gain or the parameters");
    applied.push_back({e.force, values});
  }
  auto model = std::make_shared<EffectDynamics>(std::move(base), actuator_gain, std::move(applied));
  model->set_noise_model(noise);
  return model;
}

Vector ModelSpec::current_values(const LibraryEffect& effect) const {
  switch (effect.kind) {
    case EffectKind::Force:
      for (const auto& [name, values] : forces)
        if (name == effect.name) return values;
      return Vector::Zero(static_cast<Eigen::Index>(effect.parameters.size()));
    case EffectKind::ActuatorGain:
      return Vector::Constant(1, actuator_gain);
    case EffectKind::InputDelay:
      return Vector::Constant(1, input_delay);
    case EffectKind::Recalibration:
      for (const Parameter& p : make_system(system, preset, parameters)->parameters())
        if (p.name == effect.recalibrated) return Vector::Constant(1, p.value);
      break;
  }
  throw std::invalid_argument("effect '" + effect.name + "' does not apply to system '" + system + "'");
}

ModelSpec ModelSpec::with(const LibraryEffect& effect, const VectorCRef& values) const {
  const auto expected = static_cast<Eigen::Index>(effect.parameters.size());
  if (values.size() != expected)
    throw std::invalid_argument(fmt::format("effect '{}' takes {} value(s); got {}", effect.name, expected, values.size()));
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const EffectParameter& p = effect.parameters[static_cast<std::size_t>(i)];
    if (!std::isfinite(values(i)) || values(i) < p.lowest() || values(i) > p.highest())
      throw std::invalid_argument(fmt::format("effect '{}': {} = {}; expected a finite value in [{:.6g}, {:.6g}] {}",
                                              effect.name, p.name, values(i), p.lowest(), p.highest(), p.unit));
  }
  ModelSpec out = *this;
  switch (effect.kind) {
    case EffectKind::Force: {
      bool replaced = false;
      for (auto& [name, v] : out.forces)
        if (name == effect.name) {
          v = values;
          replaced = true;
        }
      if (!replaced) out.forces.emplace_back(effect.name, values);
      if (effect.smoothing) out.smoothing[effect.name] = effect.smoothing->width;
      if (!in_library(system, effect.name)) {
        // A user effect: the model carries its declaration (the latest one of its name).
        auto same = std::find_if(out.user_effects.begin(), out.user_effects.end(),
                                 [&](const LibraryEffect& e) { return e.name == effect.name; });
        if (same == out.user_effects.end()) out.user_effects.push_back(effect);
        else *same = effect;
      }
      break;
    }
    case EffectKind::ActuatorGain:
      out.actuator_gain = values(0);
      break;
    case EffectKind::Recalibration:
      out.parameters[effect.recalibrated] = values(0);
      break;
    case EffectKind::InputDelay:
      out.input_delay = values(0);
      break;
  }
  return out;
}

std::vector<std::string> ModelSpec::describe() const {
  std::vector<std::string> lines;
  for (const auto& [name, value] : parameters) {
    const LibraryEffect* effect = nullptr;
    for (const LibraryEffect& e : effect_library(system))
      if (e.kind == EffectKind::Recalibration && e.recalibrated == name) effect = &e;
    if (effect == nullptr) throw std::invalid_argument(fmt::format("system '{}' has no parameter '{}' to recalibrate", system, name));
    lines.push_back(fmt::format("{}: {} = {:.6g} {}", effect->name, name, value, effect->parameters[0].unit));
  }
  if (actuator_gain != 1.0) lines.push_back(fmt::format("actuator_gain: k = {:.6g}", actuator_gain));
  if (input_delay != 0.0) lines.push_back(fmt::format("input_delay: d = {:.6g} steps", input_delay));
  for (const auto& [name, values] : forces) {
    const LibraryEffect e = find_candidate(*this, name);
    std::string text = name + ":";
    for (std::size_t i = 0; i < e.parameters.size(); ++i)
      text += fmt::format(" {} = {:.6g} {}", e.parameters[i].name, values(static_cast<Eigen::Index>(i)), e.parameters[i].unit);
    if (e.smoothing) text += fmt::format(" (v0 = {:.4g})", e.smoothing->width);
    lines.push_back(text);
  }
  return lines;
}

}  // namespace gpilqg
