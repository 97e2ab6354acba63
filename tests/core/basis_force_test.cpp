// Forces users declare without C++ (basis_terms.hpp, basis_force.hpp): every basis function and
// products of two against central differences of Q (dQ/dx and dQ/du), the systems' generalised
// coordinates, the parser's texts and errors, the declaration's errors, and the model description
// with user effects (candidates, adding, building, describing).

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "acrobot.hpp"
#include "gpilqg/core/basis_force.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// Every basis function, then products (with u, with tanh, of the two-piece qdot*abs(qdot), squares).
const std::vector<std::string> kTerms = {"qdot", "tanh(qdot/v0)", "qdot*abs(qdot)", "q", "q^2", "q^3", "sin(q)",
                                         "cos(q)", "u", "1", "q*qdot", "u*qdot", "tanh(qdot/v0)*q^2",
                                         "qdot*abs(qdot)*cos(q)", "sin(q)*u", "u*u", "q^3*1"};

BasisForceDeclaration declaration(std::string coordinate, std::vector<std::string> terms) {
  BasisForceDeclaration d;
  d.name = "mine";
  d.coordinate = std::move(coordinate);
  d.terms = std::move(terms);
  return d;
}

/// Q(x, u) of `effect` at `theta` (k_Q entries).
Vector force_at(const BasisForceEffect& effect, int k, const Vector& x, const Vector& u, const Vector& theta) {
  Vector Q = Vector::Zero(k);
  effect.add_force(x, u, theta, Q, nullptr, nullptr);
  return Q;
}

void expect_derivatives_match_central_differences(const Dynamics& system, const BasisForceDeclaration& d,
                                                  double velocity_scale) {
  const BasisForceEffect effect(system, d);
  const int n = system.state_dim(), m = system.control_dim();
  const int k = static_cast<int>(dynamic_cast<const GeneralisedForceInput&>(system).generalised_forces().size());
  const Vector theta = test::random_vector(static_cast<int>(d.terms.size()), -2.0, 2.0, 3);
  for (unsigned seed = 1; seed <= 12; ++seed) {
    // Velocities also on the steep part of the tanh (|qdot| < v0) and through qdot = 0.
    Vector x = test::random_vector(n, -2.0, 2.0, seed);
    x(effect.coordinate().velocity) *= seed % 2 == 0 ? velocity_scale : 1.0;
    const Vector u = test::random_vector(m, -3.0, 3.0, 50 + seed);
    Vector Q = Vector::Zero(k);
    Matrix dQ_dx = Matrix::Zero(k, n), dQ_du = Matrix::Zero(k, m);
    effect.add_force(x, u, theta, Q, &dQ_dx, &dQ_du);
    EXPECT_TRUE(test::matrices_near(Q, force_at(effect, k, x, u, theta), 0.0));
    const Matrix fx = test::numeric_jacobian([&](const Vector& xs) { return force_at(effect, k, xs, u, theta); }, x, test::kFdStep);
    const Matrix fu = test::numeric_jacobian([&](const Vector& us) { return force_at(effect, k, x, us, theta); }, u, test::kFdStep);
    EXPECT_TRUE(test::matrices_near(dQ_dx, fx, 1e-6, 1e-6)) << "seed " << seed << "\n" << dQ_dx << "\n" << fx;
    EXPECT_TRUE(test::matrices_near(dQ_du, fu, 1e-6, 1e-6)) << "seed " << seed << "\n" << dQ_du << "\n" << fu;
    // Only the coordinate's component carries a force.
    for (int i = 0; i < k; ++i) EXPECT_EQ(i == effect.coordinate().component ? 0.0 : Q(i), 0.0) << "component " << i;
  }
}

TEST(BasisForce, EveryTermAndProductMatchesCentralDifferences) {
  const DynamicsPtr cartpole = make_system("cartpole");
  for (const std::string& term : kTerms) {
    SCOPED_TRACE(term);
    for (const char* coordinate : {"x", "theta"})
      expect_derivatives_match_central_differences(*cartpole, declaration(coordinate, {term}), 0.02);
  }
  // All terms at once, and a small v0.
  BasisForceDeclaration all = declaration("theta", kTerms);
  all.v0 = 0.01;
  expect_derivatives_match_central_differences(*cartpole, all, 0.01);
}

TEST(BasisForce, SeveralControlsAreNamedAndDifferentiated) {
  const DynamicsPtr quadrotor = make_system("quadrotor");
  expect_derivatives_match_central_differences(
      *quadrotor, declaration("pz", {"u:u1", "u:u2*u:u3", "u:u4*qdot", "qdot*abs(qdot)", "q*u:u1"}), 0.02);
  expect_derivatives_match_central_differences(*quadrotor, declaration("tau_y", {"sin(q)*u:u2", "tanh(qdot/v0)"}), 0.02);
}

TEST(BasisForce, ValueIsTheSumOfTheTerms) {
  const DynamicsPtr cartpole = make_system("cartpole");
  BasisForceDeclaration d = declaration("x", {"q^3", "u*qdot", "tanh(qdot/v0)", "1"});
  d.v0 = 0.1;
  const BasisForceEffect effect(*cartpole, d);
  const Vector x = (Vector(4) << 0.5, -0.2, 1.0, 0.3).finished();
  const Vector u = Vector::Constant(1, 2.0);
  const Vector theta = (Vector(4) << -40.0, 0.5, 1.5, 0.25).finished();
  const Vector Q = force_at(effect, 2, x, u, theta);
  EXPECT_NEAR(Q(0), -40.0 * 0.125 + 0.5 * 2.0 * -0.2 + 1.5 * std::tanh(-2.0) + 0.25, 1e-14);
  EXPECT_EQ(Q(1), 0.0);
  EXPECT_TRUE(effect.depends_on_input());
  EXPECT_TRUE(effect.linear_in_parameters());
  EXPECT_FALSE(BasisForceEffect(*cartpole, declaration("x", {"q^3"})).depends_on_input());
}

TEST(BasisForce, NamesFormulaAndUnits) {
  const DynamicsPtr cartpole = make_system("cartpole");
  BasisForceDeclaration d = declaration("x", {"q^3", "qdot", "qdot*abs(qdot)", "u * qdot", "tanh(qdot/v0)", "1"});
  const BasisForceEffect effect(*cartpole, d);
  EXPECT_EQ(effect.formula(),
            "Q_x = c1 x^3 + c2 x_dot + c3 x_dot*abs(x_dot) + c4 force*x_dot + c5 tanh(x_dot/0.05) + c6");
  std::vector<std::string> names, units;
  for (const auto& p : effect.parameters()) {
    names.push_back(p.name);
    units.push_back(p.unit);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"c1", "c2", "c3", "c4", "c5", "c6"}));
  EXPECT_EQ(units, (std::vector<std::string>{"N/m^3", "N/(m/s)", "N/(m/s)^2", "N/(N m/s)", "N", "N"}));
  // The declaration keeps the terms in the text the parser reads back.
  EXPECT_EQ(effect.declaration().terms[3], "u*qdot");
  d.parameters = {"k3", "b", "cd", "g", "mu", "F"};
  d.units = {"N/m^3", "N s/m", "N s^2/m^2", "s/m", "N", "N"};
  const BasisForceEffect named(*cartpole, d);
  EXPECT_EQ(named.parameters()[0].name, "k3");
  EXPECT_EQ(named.parameters()[1].unit, "N s/m");
  EXPECT_EQ(named.formula(), "Q_x = k3 x^3 + b x_dot + cd x_dot*abs(x_dot) + g force*x_dot + mu tanh(x_dot/0.05) + F");
}

TEST(GeneralisedCoordinates, OfEverySystemKind) {
  const auto names = [](const Dynamics& system) {
    std::vector<std::string> out;
    for (const auto& c : generalised_coordinates(system))
      out.push_back(c.name + "/" + c.force + "/" + system.states()[static_cast<std::size_t>(c.position)].name + "/" +
                    system.states()[static_cast<std::size_t>(c.velocity)].name);
    return out;
  };
  EXPECT_EQ(names(*make_system("cartpole")), (std::vector<std::string>{"x/Q_x/x/x_dot", "theta/Q_theta/theta/theta_dot"}));
  EXPECT_EQ(names(*make_system("quadrotor")),
            (std::vector<std::string>{"px/F_x/px/vx", "py/F_y/py/vy", "pz/F_z/pz/vz", "rx/tau_x/rx/wx",
                                      "ry/tau_y/ry/wy", "rz/tau_z/rz/wz"}));
  EXPECT_EQ(names(acrobot::Acrobot()),
            (std::vector<std::string>{"theta1/Q_theta1/theta1/theta1_dot", "theta2/Q_theta2/theta2/theta2_dot"}));
  const std::string arm = (test::source_dir() / "data" / "two_link_arm.xml").string();
  EXPECT_EQ(names(*make_system(arm)),
            (std::vector<std::string>{"shoulder/Q_shoulder/shoulder/shoulder_dot", "elbow/Q_elbow/elbow/elbow_dot"}));
  EXPECT_EQ(find_coordinate(*make_system("cartpole"), "Q_theta").name, "theta");
}

/// The message of the std::invalid_argument `f` throws ("" when it does not throw).
template <class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(BasisTerms, ParseAndWriteBack) {
  const std::vector<Quantity> one = {{"force", "N"}};
  for (const std::string& term : kTerms) EXPECT_EQ(basis_term_text(parse_basis_term(term, one), one), term);
  EXPECT_EQ(parse_basis_term("qdot*abs(qdot)*q", one).factors.size(), 2u);
  EXPECT_EQ(parse_basis_term(" q *  qdot ", one).factors.size(), 2u);
  EXPECT_EQ(basis_term_text(parse_basis_term("u:force", one), one), "u");
  EXPECT_TRUE(same_basis_term(parse_basis_term("q*qdot", one), parse_basis_term("qdot*q", one)));
  EXPECT_FALSE(same_basis_term(parse_basis_term("q*qdot", one), parse_basis_term("q", one)));
}

TEST(BasisTerms, ErrorsNameTheTermAndListTheBasis) {
  const std::vector<Quantity> one = {{"force", "N"}};
  const std::vector<Quantity> four = {{"u1", "N"}, {"u2", "N"}, {"u3", "N"}, {"u4", "N"}};
  const std::string unknown = message_of([&] { parse_basis_term("q^4", one); });
  EXPECT_NE(unknown.find("term 'q^4': unknown factor 'q^4'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("qdot, tanh(qdot/v0), qdot*abs(qdot), q, q^2, q^3, sin(q), cos(q), u, 1"), std::string::npos) << unknown;
  const std::string three = message_of([&] { parse_basis_term("q*q*qdot", one); });
  EXPECT_NE(three.find("term 'q*q*qdot' is a product of 3 factors; expected at most two"), std::string::npos) << three;
  const std::string empty = message_of([&] { parse_basis_term("q*", one); });
  EXPECT_NE(empty.find("an empty factor"), std::string::npos) << empty;
  const std::string ambiguous = message_of([&] { parse_basis_term("u*qdot", four); });
  EXPECT_NE(ambiguous.find("'u' is ambiguous with 4 controls; expected one of: u:u1, u:u2, u:u3, u:u4"), std::string::npos)
      << ambiguous;
  const std::string control = message_of([&] { parse_basis_term("u:thrust", four); });
  EXPECT_NE(control.find("unknown control 'thrust'; expected one of: u:u1, u:u2"), std::string::npos) << control;
  EXPECT_NE(message_of([&] { parse_basis_term("abs(qdot)", one); }).find("unknown factor 'abs(qdot)'"), std::string::npos);
}

/// The field, the entry and the message of the DeclarationError `f` throws.
template <class F>
std::string declaration_error(F&& f) {
  try {
    f();
  } catch (const DeclarationError& e) {
    return e.field() + "[" + std::to_string(e.index()) + "]: " + e.what();
  }
  return "no error";
}

TEST(BasisForce, DeclarationErrorsNameTheFieldAndTheChoices) {
  const DynamicsPtr cartpole = make_system("cartpole");
  const auto error = [&](const BasisForceDeclaration& d) {
    return declaration_error([&] { BasisForceEffect(*cartpole, d); });
  };
  BasisForceDeclaration d = declaration("y", {"q"});
  EXPECT_EQ(error(d), "coordinate[-1]: unknown coordinate 'y' of system 'cartpole'; expected one of: x (Q_x), "
                      "theta (Q_theta) (a coordinate or, in parentheses, the force acting on it)");
  d = declaration("x", {"q", "q^5"});
  EXPECT_NE(error(d).find("terms[1]: term 'q^5': unknown factor 'q^5'"), std::string::npos) << error(d);
  d = declaration("x", {"q*qdot*u"});
  EXPECT_NE(error(d).find("terms[0]: term 'q*qdot*u' is a product of 3 factors"), std::string::npos) << error(d);
  d = declaration("x", {"q*qdot", "qdot*q"});
  EXPECT_NE(error(d).find("terms[1]: term 'qdot*q' is the same function as 'q*qdot'"), std::string::npos) << error(d);
  d = declaration("x", {});
  EXPECT_NE(error(d).find("terms[-1]: is empty"), std::string::npos) << error(d);
  d = declaration("x", {"q", "qdot"});
  d.parameters = {"k"};
  EXPECT_NE(error(d).find("parameters[-1]: has 1 name(s) for 2 term(s)"), std::string::npos) << error(d);
  d.parameters = {"k", "k"};
  EXPECT_NE(error(d).find("parameters[1]: 'k' names two terms"), std::string::npos) << error(d);
  d.parameters = {"k", "2b"};
  EXPECT_NE(error(d).find("parameters[1]: '2b' is not a valid parameter name"), std::string::npos) << error(d);
  d.parameters.clear();
  d.units = {"N/m"};
  EXPECT_NE(error(d).find("units[-1]: has 1 unit(s) for 2 term(s)"), std::string::npos) << error(d);
  d = declaration("x", {"tanh(qdot/v0)"});
  d.v0 = 0.0;
  EXPECT_NE(error(d).find("v0[-1]: is 0; expected a finite scale > 0 of tanh(qdot/v0) [m/s]"), std::string::npos) << error(d);
  d.v0 = -1.0;
  EXPECT_NE(error(d).find("v0[-1]: is -1"), std::string::npos) << error(d);
  d = declaration("x", {"q"});
  d.v0 = 0.1;
  EXPECT_NE(error(d).find("v0[-1]: is given but no term uses tanh(qdot/v0)"), std::string::npos) << error(d);
  d = declaration("x", {"q"});
  d.name = "cart spring";
  EXPECT_NE(error(d).find("name[-1]: 'cart spring' is not a valid effect name"), std::string::npos) << error(d);
  // A library name is taken: the message names the library effect and its formula.
  d.name = "cart_viscous_friction";
  EXPECT_EQ(declaration_error([&] { user_effect_entry("cartpole", d); }),
            "name[-1]: 'cart_viscous_friction' is the name of the library effect 'cart_viscous_friction' "
            "(Q_x = -b x_dot) of system 'cartpole'; expected a name of its own");
}

TEST(UserEffects, AreCandidatesThatModelsAddBuildAndDescribe) {
  BasisForceDeclaration d = declaration("x", {"q^3"});
  d.name = "cart_spring";
  d.parameters = {"k3"};
  const LibraryEffect spring = user_effect_entry("cartpole", d);
  EXPECT_EQ(spring.kind, EffectKind::Force);
  EXPECT_TRUE(spring.linear);
  ASSERT_NE(user_declaration(spring), nullptr);
  EXPECT_EQ(user_declaration(spring)->coordinate, "x");
  EXPECT_EQ(user_declaration(find_effect("cartpole", "cart_viscous_friction")), nullptr);

  ModelSpec declared;
  declared.user_effects.push_back(spring);
  const std::vector<LibraryEffect> candidates = candidate_effects(declared);
  ASSERT_EQ(candidates.size(), effect_library("cartpole").size() + 1);
  EXPECT_EQ(candidates.back().name, "cart_spring");
  EXPECT_EQ(find_candidate(declared, "cart_spring").formula, "Q_x = k3 x^3");
  EXPECT_EQ(find_candidate(declared, "cart_viscous_friction").name, "cart_viscous_friction");
  const std::string unknown = message_of([&] { find_candidate(declared, "spring"); });
  EXPECT_NE(unknown.find("unknown effect 'spring' for system 'cartpole'; expected one of: cart_viscous_friction"),
            std::string::npos) << unknown;
  EXPECT_NE(unknown.find("constant_force:theta, cart_spring"), std::string::npos) << unknown;
  EXPECT_TRUE(declared.describe().empty());
  EXPECT_TRUE(declared.current_values(spring).isZero());

  // Adding it to a model that does not declare it declares it; the built model has the force.
  const ModelSpec model = ModelSpec{}.with(spring, Vector::Constant(1, -30.0));
  ASSERT_EQ(model.user_effects.size(), 1u);
  EXPECT_EQ(model.current_values(spring)(0), -30.0);
  EXPECT_EQ(model.describe(), (std::vector<std::string>{"cart_spring: k3 = -30 N/m^3"}));
  const DynamicsPtr built = model.build();
  const DynamicsPtr bare = ModelSpec{}.build();
  const Vector x = (Vector(4) << 0.5, 0.0, 0.0, 0.0).finished();
  const Vector u = Vector::Zero(1);
  // The spring enters as W(x) Q with Q = (-30 x^3, 0).
  Matrix W;
  dynamic_cast<const GeneralisedForceInput&>(*bare).generalised_force_map(x, W, nullptr);
  EXPECT_TRUE(test::matrices_near(built->f(x, u) - bare->f(x, u), W.col(0) * (-30.0 * 0.125), 1e-12, 1e-12));
  EXPECT_EQ(model.with(spring, Vector::Constant(1, -20.0)).user_effects.size(), 1u);
}

}  // namespace
}  // namespace gpilqg
