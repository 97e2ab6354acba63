#include "gpilqg/core/systems.hpp"

#include "gpilqg/core/system_registry.hpp"

namespace gpilqg {

std::optional<Preset> parse_preset(std::string_view name) {
  if (name == "sim") return Preset::Simulator;
  if (name == "real") return Preset::RealWorld;
  return std::nullopt;
}

std::string_view to_string(Preset preset) { return preset == Preset::Simulator ? "sim" : "real"; }

std::vector<std::string> system_names() { return SystemRegistry::instance().names(); }

DynamicsPtr make_system(std::string_view name, Preset preset, const std::map<std::string, double>& overrides,
                        const ActuatorNoise& noise) {
  return find_system(name)->build(preset, overrides, noise);
}

SystemSignature system_signature(std::string_view name) { return make_system(name)->signature(); }

std::string signature_mismatch(const SystemSignature& a, const SystemSignature& b) {
  const auto list = [](const std::vector<Quantity>& q) {
    std::string out;
    for (const auto& name : names_of(q)) out += (out.empty() ? "" : ", ") + name;
    return out;
  };
  if (names_of(a.states) == names_of(b.states) && names_of(a.controls) == names_of(b.controls)) return "";
  return "'" + b.name + "' has states [" + list(b.states) + "] and controls [" + list(b.controls) + "], but '" + a.name +
         "' has states [" + list(a.states) + "] and controls [" + list(a.controls) + "]";
}

}  // namespace gpilqg
