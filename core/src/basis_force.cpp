#include "gpilqg/core/basis_force.hpp"

#include <cctype>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "gpilqg/core/limits.hpp"

namespace gpilqg {

bool valid_declared_name(const std::string& name) {
  if (name.empty() || std::isalpha(static_cast<unsigned char>(name[0])) == 0) return false;
  for (char c : name)
    if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '_') return false;
  return true;
}

namespace {

/// True when `unit` needs parentheses after a '/': a space or a '/' outside parentheses ("m/s",
/// "N m/s"; not "m^3" or "(m/s)^2").
bool compound_unit(const std::string& unit) {
  int depth = 0;
  for (char c : unit) {
    if (c == '(') ++depth;
    else if (c == ')') --depth;
    else if (depth == 0 && (c == ' ' || c == '/')) return true;
  }
  return false;
}

}  // namespace

BasisForceEffect::BasisForceEffect(const Dynamics& system, BasisForceDeclaration declaration)
    : declaration_(std::move(declaration)) {
  const BasisForceDeclaration& d = declaration_;
  if (!valid_declared_name(d.name))
    throw DeclarationError("name", -1, fmt::format("'{}' is not a valid effect name; expected a letter, then letters, "
                                                   "digits and '_' (e.g. \"cart_spring\")",
                                                   d.name));
  try {
    coordinate_ = find_coordinate(system, d.coordinate);
  } catch (const std::invalid_argument& e) {
    throw DeclarationError("coordinate", -1, e.what());
  }
  const auto& controls = system.controls();
  if (d.terms.empty())
    throw DeclarationError("terms", -1, fmt::format("is empty; expected at least one term of the basis {}", basis_list(controls)));
  if (static_cast<long>(d.terms.size()) > limits::kMaxBasisTerms)
    throw DeclarationError("terms", -1, fmt::format("has {} terms; expected at most {} (the limit of one effect)",
                                                    d.terms.size(), limits::kMaxBasisTerms));
  for (std::size_t k = 0; k < d.terms.size(); ++k) {
    try {
      terms_.push_back(parse_basis_term(d.terms[k], controls));
    } catch (const std::invalid_argument& e) {
      throw DeclarationError("terms", static_cast<int>(k), e.what());
    }
    for (std::size_t i = 0; i < k; ++i)
      if (same_basis_term(terms_[i], terms_[k]))
        throw DeclarationError("terms", static_cast<int>(k),
                               fmt::format("term '{}' is the same function as '{}'; expected each term once",
                                           d.terms[k], d.terms[i]));
    declaration_.terms[k] = basis_term_text(terms_[k], controls);
  }
  const std::size_t K = terms_.size();
  if (!d.parameters.empty() && d.parameters.size() != K)
    throw DeclarationError("parameters", -1, fmt::format("has {} name(s) for {} term(s); expected one name per term, "
                                                         "or none for c1, c2, ...",
                                                         d.parameters.size(), K));
  if (!d.units.empty() && d.units.size() != K)
    throw DeclarationError("units", -1, fmt::format("has {} unit(s) for {} term(s); expected one unit per term, or none "
                                                    "for the units derived from the force and the term",
                                                    d.units.size(), K));
  bool uses_tanh = false;
  for (const BasisTerm& t : terms_) uses_tanh = uses_tanh || has_factor(t, BasisFunction::TanhVelocity);
  if (d.v0) {
    if (!uses_tanh)
      throw DeclarationError("v0", -1, "is given but no term uses tanh(qdot/v0); expected no v0, or a tanh(qdot/v0) term");
    if (!(std::isfinite(*d.v0) && *d.v0 > 0.0))
      throw DeclarationError("v0", -1, fmt::format("is {}; expected a finite scale > 0 of tanh(qdot/v0) [{}]", *d.v0,
                                                   system.states()[static_cast<std::size_t>(coordinate_.velocity)].unit));
    v0_ = *d.v0;
  }

  const Quantity& force = dynamic_cast<const GeneralisedForceInput&>(system).generalised_forces()
                              [static_cast<std::size_t>(coordinate_.component)];
  const Quantity& q = system.states()[static_cast<std::size_t>(coordinate_.position)];
  const Quantity& q_dot = system.states()[static_cast<std::size_t>(coordinate_.velocity)];
  formula_ = force.name + " =";
  for (std::size_t k = 0; k < K; ++k) {
    EffectParameter p;
    p.name = d.parameters.empty() ? fmt::format("c{}", k + 1) : d.parameters[k];
    if (!valid_declared_name(p.name))
      throw DeclarationError("parameters", static_cast<int>(k),
                             fmt::format("'{}' is not a valid parameter name; expected a letter, then letters, digits "
                                         "and '_' (e.g. \"k3\")",
                                         p.name));
    for (std::size_t i = 0; i < k; ++i)
      if (parameters_[i].name == p.name)
        throw DeclarationError("parameters", static_cast<int>(k),
                               fmt::format("'{}' names two terms ('{}' and '{}'); expected a different name per term",
                                           p.name, d.terms[i], d.terms[k]));
    if (!d.units.empty()) {
      p.unit = d.units[k];
    } else {
      const std::string unit = basis_term_unit(terms_[k], q.unit, q_dot.unit, controls);
      p.unit = unit.empty() ? force.unit : force.unit + "/" + (compound_unit(unit) ? "(" + unit + ")" : unit);
    }
    p.scale = 1.0;
    parameters_.push_back(std::move(p));
    const bool constant = terms_[k].factors.size() == 1 && terms_[k].factors[0].function == BasisFunction::One;
    formula_ += fmt::format("{} {}", k == 0 ? "" : " +", parameters_[k].name);
    if (!constant) formula_ += " " + basis_term_formula(terms_[k], q.name, q_dot.name, controls, v0_);
    for (const BasisFactor& f : terms_[k].factors) depends_on_input_ = depends_on_input_ || f.function == BasisFunction::Control;
  }
  force_dim_ = static_cast<int>(dynamic_cast<const GeneralisedForceInput&>(system).generalised_forces().size());
  state_dim_ = system.state_dim();
  control_dim_ = system.control_dim();
}

void BasisForceEffect::add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q,
                                 Matrix* dQ_dx, Matrix* dQ_du) const {
  if (Q.size() != force_dim_ || x.size() != state_dim_ || u.size() != control_dim_ ||
      theta.size() != static_cast<Eigen::Index>(terms_.size()))
    throw std::invalid_argument(fmt::format("BasisForceEffect '{}': Q, x, u, theta have {}, {}, {}, {} entries; "
                                            "expected {}, {}, {}, {}",
                                            name(), Q.size(), x.size(), u.size(), theta.size(), force_dim_, state_dim_,
                                            control_dim_, terms_.size()));
  const int c = coordinate_.component;
  const double q = x(coordinate_.position), q_dot = x(coordinate_.velocity);
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    const double t = theta(static_cast<Eigen::Index>(k));
    const auto& factors = terms_[k].factors;
    // b = f_1 f_2 (f_2 = 1 for a single factor); db = f_1' f_2 + f_1 f_2'.
    const FactorValue f1 = evaluate_factor(factors[0], q, q_dot, u, v0_);
    const FactorValue f2 = factors.size() > 1 ? evaluate_factor(factors[1], q, q_dot, u, v0_) : FactorValue{};
    Q(c) += t * f1.value * f2.value;
    if (dQ_dx != nullptr) {
      (*dQ_dx)(c, coordinate_.position) += t * (f1.d_q * f2.value + f1.value * f2.d_q);
      (*dQ_dx)(c, coordinate_.velocity) += t * (f1.d_qdot * f2.value + f1.value * f2.d_qdot);
    }
    if (dQ_du != nullptr) {
      if (factors[0].function == BasisFunction::Control) (*dQ_du)(c, factors[0].control) += t * f1.d_u * f2.value;
      if (factors.size() > 1 && factors[1].function == BasisFunction::Control)
        (*dQ_du)(c, factors[1].control) += t * f1.value * f2.d_u;
    }
  }
}

}  // namespace gpilqg
