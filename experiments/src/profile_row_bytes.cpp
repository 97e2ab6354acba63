/// ProfileRow as bytes (profile.hpp): JSON whose numbers are the doubles' bit patterns, so every value,
/// NaN included, comes back exactly.

#include <bit>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "gpilqg/experiments/profile.hpp"

namespace gpilqg {
namespace {

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }
double from_bits(const nlohmann::json& j) { return std::bit_cast<double>(j.get<std::uint64_t>()); }

}  // namespace

std::string profile_row_bytes(const ProfileRow& r) {
  nlohmann::json parameters = nlohmann::json::array();
  for (Eigen::Index i = 0; i < r.parameters.size(); ++i) parameters.push_back(bits(r.parameters(i)));
  return nlohmann::json{{"backend", r.backend},
                        {"size", r.size},
                        {"status", r.status},
                        {"reason", r.reason},
                        {"fit_seconds", bits(r.fit_seconds)},
                        {"predict_seconds", bits(r.predict_seconds)},
                        {"smse", bits(r.smse)},
                        {"mnlp", bits(r.mnlp)},
                        {"msll", bits(r.msll)},
                        {"nlml", bits(r.nlml)},
                        {"evaluations", r.evaluations},
                        {"termination", r.termination},
                        {"conditioning", r.conditioning},
                        {"parameters", parameters}}
      .dump();
}

ProfileRow profile_row_from_bytes(const std::string& bytes) {
  const nlohmann::json j = nlohmann::json::parse(bytes);
  ProfileRow r;
  r.backend = j.at("backend").get<std::string>();
  r.size = j.at("size").get<int>();
  r.status = j.at("status").get<std::string>();
  r.reason = j.at("reason").get<std::string>();
  r.fit_seconds = from_bits(j.at("fit_seconds"));
  r.predict_seconds = from_bits(j.at("predict_seconds"));
  r.smse = from_bits(j.at("smse"));
  r.mnlp = from_bits(j.at("mnlp"));
  r.msll = from_bits(j.at("msll"));
  r.nlml = from_bits(j.at("nlml"));
  r.evaluations = j.at("evaluations").get<int>();
  r.termination = j.at("termination").get<std::string>();
  r.conditioning = j.at("conditioning").get<std::string>();
  const auto& parameters = j.at("parameters");
  r.parameters.resize(static_cast<Eigen::Index>(parameters.size()));
  for (std::size_t i = 0; i < parameters.size(); ++i) r.parameters(static_cast<Eigen::Index>(i)) = from_bits(parameters[i]);
  return r;
}

}  // namespace gpilqg
