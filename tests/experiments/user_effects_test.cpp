// Effects a user declares in the model file ([[user_effects]], docs/diagnosis.md "Your own effects"):
// a hidden cubic spring on the cart, Q_x = -k x^3, outside the library, is found and fitted once the
// user declares "q^3" on the coordinate x; `diagnose --model --json`, `--add` and `--write-model` treat
// it like a library effect; the model file round-trips; every mistake in a declaration is an error
// naming the file, the line and the field, with the valid choices.

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "diagnosis_support.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The hidden spring's stiffness [N/m^3]: Q_x = -k x^3 (the cart moves up to about 1 m in these data).
constexpr double kSpring = 30.0;

const std::string kDeclaration =
    "[[user_effects]]\n"
    "name = \"cart_spring\"\n"
    "coordinate = \"x\"\n"
    "terms = [\"q^3\"]\n"
    "parameters = [\"k3\"]\n";

LibraryEffect cart_spring() {
  BasisForceDeclaration d;
  d.name = "cart_spring";
  d.coordinate = "x";
  d.terms = {"q^3"};
  d.parameters = {"k3"};
  return user_effect_entry("cartpole", d);
}

/// Cart-pole data with the hidden spring (the sign convention Q = +theta b: k3 = -k).
MeasurementSet spring_data(std::uint64_t seed) {
  const ModelSpec world = ModelSpec{}.with(cart_spring(), Vector::Constant(1, -kSpring));
  return test::hidden_effect_data(world.build(test::actuator_noise(1, 0.02)), seed);
}

using test::quote;

TEST(UserEffects, ADeclaredCubicSpringIsRankedFirstAndFitted) {
  for (std::uint64_t seed : {11u, 22u, 33u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const MeasurementSet data = spring_data(seed);
    double x_max = 0.0;
    for (const auto& e : data.episodes) x_max = std::max(x_max, e.x.col(0).cwiseAbs().maxCoeff());
    EXPECT_GT(x_max, 0.5) << "the spring needs cart excursions to show";
    diagnosis::DiagnosisOptions o = test::fast_options("cartpole");
    o.model.user_effects.push_back(cart_spring());
    const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, o);
    ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
    ASSERT_FALSE(r.ranking.empty());
    const diagnosis::EffectFit& first = r.ranking[0].fit;
    EXPECT_EQ(first.effect, "cart_spring") << r.verdict.reason;
    EXPECT_EQ(r.verdict.effect->effect, "cart_spring");
    EXPECT_NEAR(first.estimate(0), -kSpring, 0.15 * kSpring);
    EXPECT_GT(first.explained, 0.3);
    std::cout << "seed " << seed << ": |x| <= " << x_max << " m, k3 = " << first.estimate(0) << " [" << first.ci_low(0)
              << ", " << first.ci_high(0) << "] (true " << -kSpring << "), explains " << 100.0 * first.explained
              << "%\n";
    // The proposed model carries the declaration and the fitted value.
    ASSERT_EQ(r.model_next.forces.size(), 1u);
    EXPECT_EQ(r.model_next.forces[0].first, "cart_spring");
    EXPECT_EQ(r.model_next.user_effects.size(), 1u);
  }
}

TEST(UserEffectsCli, DiagnoseCliFindsAddsAndWritesTheDeclaredEffect) {
  const fs::path dir = test::temporary_dir("user_effects_cli");
  const fs::path data = dir / "spring.csv", model = dir / "user.toml", next = dir / "next.toml";
  write_measurements(data, spring_data(5));
  std::ofstream(model) << "[model]\nsystem = \"cartpole\"\n\n" << kDeclaration;
  const std::string base = "diagnose --system cartpole --data " + quote(data) + " --model " + quote(model) +
                           " --gp-points 100 --gp-restarts 0";
  const auto found = test::run_cli(base + " --json");
  ASSERT_EQ(found.status, 0) << found.err;
  const json j = json::parse(found.out);
  EXPECT_EQ(j["verdict"]["status"], "explained") << j["verdict"];
  EXPECT_EQ(j["verdict"]["effect"], "cart_spring");
  EXPECT_EQ(j["ranking"][0]["effect"], "cart_spring");
  EXPECT_NEAR(j["verdict"]["parameters"]["k3"].get<double>(), -kSpring, 0.15 * kSpring);
  EXPECT_NE(j["model"].get<std::string>().find("[[user_effects]]"), std::string::npos);

  // --add it and write the model for the next round: the declaration and the value come back.
  const auto added = test::run_cli(base + " --add cart_spring --write-model " + quote(next));
  ASSERT_EQ(added.status, 0) << added.err;
  EXPECT_NE(added.out.find("added cart_spring: k3 = "), std::string::npos) << added.out;
  const ModelSpec back = diagnosis::read_model_file(next, "cartpole");
  ASSERT_EQ(back.user_effects.size(), 1u);
  EXPECT_EQ(back.user_effects[0].formula, "Q_x = k3 x^3");
  ASSERT_EQ(back.forces.size(), 1u);
  EXPECT_EQ(back.forces[0].first, "cart_spring");
  EXPECT_NEAR(back.forces[0].second(0), -kSpring, 0.15 * kSpring);

  // --add of a name nobody declared lists the library and the declared effects.
  const auto unknown = test::run_cli(base + " --add cart_springs");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("unknown effect 'cart_springs'"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("constant_force:theta, cart_spring"), std::string::npos) << unknown.err;
}

TEST(UserEffects, ModelFileRoundTrips) {
  const fs::path dir = test::temporary_dir("user_effects_round_trip");
  const fs::path file = dir / "m.toml";
  std::ofstream(file) << "[model]\nsystem = \"cartpole\"\n\n"
                      << kDeclaration
                      << "\n[[user_effects]]\nname = \"pole_drag\"\ncoordinate = \"theta\"\n"
                         "terms = [\"tanh(qdot / v0)\", \"qdot*abs(qdot)\", \"u*qdot\", \"sin(q)*1\"]\n"
                         "units = [\"N m\", \"N m s^2\", \"m s\", \"N m\"]\nv0 = 0.1\n"
                         "\n[effects]\ncart_spring = -35.5\npole_drag = { c1 = 0.25, c2 = 0.0, c3 = -1e-3, c4 = 0.5 }\n";
  const ModelSpec model = diagnosis::read_model_file(file, "cartpole");
  ASSERT_EQ(model.user_effects.size(), 2u);
  EXPECT_EQ(model.user_effects[1].formula,
            "Q_theta = c1 tanh(theta_dot/0.1) + c2 theta_dot*abs(theta_dot) + c3 force*theta_dot + c4 sin(theta)*1");
  EXPECT_EQ(model.user_effects[1].parameters[2].unit, "m s");
  ASSERT_EQ(model.forces.size(), 2u);
  const std::string text = diagnosis::model_file_text(model);
  const fs::path again = dir / "again.toml";
  diagnosis::write_model_file(again, model);
  const ModelSpec back = diagnosis::read_model_file(again, "cartpole");
  EXPECT_EQ(diagnosis::model_file_text(back), text);
  ASSERT_EQ(back.user_effects.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.user_effects[i].name, model.user_effects[i].name);
    EXPECT_EQ(back.user_effects[i].formula, model.user_effects[i].formula);
    EXPECT_EQ(*user_declaration(back.user_effects[i]) == *user_declaration(model.user_effects[i]), true);
  }
  ASSERT_EQ(back.forces.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.forces[i].first, model.forces[i].first);
    EXPECT_EQ(back.forces[i].second, model.forces[i].second);
  }
  // Built, the two are the same system.
  const Vector x = (Vector(4) << 0.3, -0.4, 0.5, 0.6).finished(), u = Vector::Constant(1, 1.5);
  EXPECT_EQ(back.build()->f(x, u), model.build()->f(x, u));
  // A declared but unused effect is written back too: it stays a candidate of the next round.
  ModelSpec declared_only;
  declared_only.user_effects.push_back(cart_spring());
  diagnosis::write_model_file(again, declared_only);
  EXPECT_EQ(diagnosis::read_model_file(again, "cartpole").user_effects.size(), 1u);
}

/// The InputError message of reading a model file with `declaration` (one [[user_effects]] entry, its
/// `name` line at line 4), or "" when it reads.
std::string model_error(const std::string& declaration, const std::string& effects = "") {
  const fs::path file = test::temporary_dir("user_effects_errors") / "bad.toml";
  std::ofstream(file) << "[model]\nsystem = \"cartpole\"\n[[user_effects]]\n" << declaration << effects;
  try {
    diagnosis::read_model_file(file, "cartpole");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_contains(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "expected '" << part << "' in:\n" << text;
}

TEST(UserEffects, EachMistakeNamesTheFileLineFieldAndChoices) {
  const std::string name = "name = \"spring\"\n";
  // Unknown term: the term's line and entry, the basis.
  std::string e = model_error(name + "coordinate = \"x\"\nterms = [\"q\",\n  \"q^4\"]\n");
  expect_contains(e, "bad.toml:line 7: field 'user_effects[0].terms[1]': term 'q^4': unknown factor 'q^4'; expected one "
                     "of the basis qdot, tanh(qdot/v0), qdot*abs(qdot), q, q^2, q^3, sin(q), cos(q), u, 1 or a product a*b");
  // Unknown coordinate: the valid ones.
  e = model_error(name + "coordinate = \"y\"\nterms = [\"q\"]\n");
  expect_contains(e, "bad.toml:line 5: field 'user_effects[0].coordinate': unknown coordinate 'y' of system 'cartpole'; "
                     "expected one of: x (Q_x), theta (Q_theta)");
  // A library name: both named.
  e = model_error("name = \"cart_coulomb_friction\"\ncoordinate = \"x\"\nterms = [\"q\"]\n");
  expect_contains(e, "bad.toml:line 4: field 'user_effects[0].name': 'cart_coulomb_friction' is the name of the library "
                     "effect 'cart_coulomb_friction' (Q_x = -mu tanh(x_dot / 0.05))");
  // A product of three.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"q*qdot*u\"]\n");
  expect_contains(e, "bad.toml:line 6: field 'user_effects[0].terms[0]': term 'q*qdot*u' is a product of 3 factors; "
                     "expected at most two");
  // v0 <= 0.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"tanh(qdot/v0)\"]\nv0 = -0.05\n");
  expect_contains(e, "bad.toml:line 7: field 'user_effects[0].v0': is -0.05; expected a finite scale > 0 of tanh(qdot/v0) [m/s]");
  // Parameter names that are not one per term.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"q\", \"q^3\"]\nparameters = [\"k1\"]\n");
  expect_contains(e, "bad.toml:line 7: field 'user_effects[0].parameters': has 1 name(s) for 2 term(s); expected one "
                     "name per term, or none for c1, c2, ...");
  // u on a system with one control is fine; a misspelt control lists the valid ones.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"u:torque\"]\n");
  expect_contains(e, "field 'user_effects[0].terms[0]': term 'u:torque': unknown control 'torque'; expected one of: u:force");
  // Fields: unknown, missing, wrong type.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"q\"]\nscale = 2\n");
  expect_contains(e, "bad.toml:line 7: unknown field 'user_effects[0].scale'; expected one of: name, coordinate, terms, "
                     "parameters, units, v0");
  e = model_error(name + "terms = [\"q\"]\n");
  expect_contains(e, "bad.toml:line 3: field 'user_effects[0]': has no 'coordinate'");
  e = model_error(name + "coordinate = \"x\"\nterms = \"q\"\n");
  expect_contains(e, "bad.toml:line 6: field 'user_effects[0].terms': is not an array");
  e = model_error(name + "coordinate = \"x\"\nterms = [3]\n");
  expect_contains(e, "field 'user_effects[0].terms[0]': is not a string");
  // Declared twice.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"q\"]\n[[user_effects]]\n" + name +
                  "coordinate = \"theta\"\nterms = [\"q\"]\n");
  expect_contains(e, "bad.toml:line 8: field 'user_effects[1].name': 'spring' is declared twice (also user_effects[0])");
  // A value for a parameter the effect does not have.
  e = model_error(name + "coordinate = \"x\"\nterms = [\"q\", \"q^3\"]\n", "[effects]\nspring = 2.0\n");
  expect_contains(e, "field 'effects.spring': expected a table of its parameters (c1, c2)");
  EXPECT_EQ(model_error(name + "coordinate = \"x\"\nterms = [\"q\"]\n", "[effects]\nspring = 2.0\n"), "");
}

}  // namespace
}  // namespace gpilqg
