#pragma once
/// @file basis_terms.hpp
/// The basis of user-declared forces (basis_force.hpp): functions b(q, q_dot, u) of one generalised
/// coordinate q, its velocity q_dot and the controls u, written as text in a model file.
///
/// | text             | b                 | db/dq    | db/dq_dot                  | db/du_j        |
/// |------------------|-------------------|----------|----------------------------|----------------|
/// | `qdot`           | q_dot             | 0        | 1                          | 0              |
/// | `tanh(qdot/v0)`  | tanh(q_dot / v0)  | 0        | (1 - tanh^2(q_dot/v0)) / v0 | 0              |
/// | `qdot*abs(qdot)` | q_dot abs(q_dot)  | 0        | 2 abs(q_dot)               | 0              |
/// | `q`              | q                 | 1        | 0                          | 0              |
/// | `q^2`            | q^2               | 2 q      | 0                          | 0              |
/// | `q^3`            | q^3               | 3 q^2    | 0                          | 0              |
/// | `sin(q)`         | sin q             | cos q    | 0                          | 0              |
/// | `cos(q)`         | cos q             | -sin q   | 0                          | 0              |
/// | `u`, `u:<name>`  | u_j               | 0        | 0                          | 1              |
/// | `1`              | 1                 | 0        | 0                          | 0              |
///
/// A term is one of these factors or the product `a*b` of two, b = f_a f_b, with the product rule
/// db = f_a' f_b + f_a f_b' (so `u*qdot`, `q*qdot`, `qdot*abs(qdot)*q`). `u` is the system's only
/// control; a system with several controls names one, `u:<control>`. u is the commanded control (the
/// data's column), not the applied k u of an actuator gain. Whitespace in the text is ignored.

#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// One factor of a basis term, in the order of the table above.
enum class BasisFunction {
  Velocity,              ///< q_dot
  TanhVelocity,          ///< tanh(q_dot / v0)
  SignedSquareVelocity,  ///< q_dot abs(q_dot)
  Position,              ///< q
  PositionSquared,       ///< q^2
  PositionCubed,         ///< q^3
  Sine,                  ///< sin q
  Cosine,                ///< cos q
  Control,               ///< u_j
  One,                   ///< 1
};

struct BasisFactor {
  BasisFunction function = BasisFunction::One;
  int control = -1;  ///< Control only: j, the index of u_j among the system's controls
};

/// b = f_1 (one factor) or f_1 f_2 (two).
struct BasisTerm {
  std::vector<BasisFactor> factors;
};

/// A factor's value and its partial derivatives at (q, q_dot, u): d_u is d f / d u_control.
struct FactorValue {
  double value = 1.0;
  double d_q = 0.0;
  double d_qdot = 0.0;
  double d_u = 0.0;
};

/// The factor at (q, q_dot, u) with the derivatives of the table; `v0` > 0 is the tanh's scale.
FactorValue evaluate_factor(const BasisFactor& factor, double q, double q_dot, const VectorCRef& u, double v0);

/// The basis as a list for messages, e.g. "qdot, tanh(qdot/v0), ..., u, 1" (with "u:<name>" per control
/// when there are several).
std::string basis_list(const std::vector<Quantity>& controls);

/// Parses a term: one factor of the table, or a product "a*b" of two. Throws std::invalid_argument
/// naming the text and listing the basis for an unknown factor, saying that a product has at most two
/// factors for a longer one, and listing the control names for "u" with several controls or an
/// unknown "u:<name>".
BasisTerm parse_basis_term(std::string_view text, const std::vector<Quantity>& controls);

/// The term's text as parse_basis_term reads it: the factors in their order joined by "*", "u" for the
/// only control, else "u:<name>".
std::string basis_term_text(const BasisTerm& term, const std::vector<Quantity>& controls);

/// The term with the quantities' names, for formulas: e.g. "x^3", "tanh(x_dot/0.05)", "x_dot*force".
std::string basis_term_formula(const BasisTerm& term, const std::string& q, const std::string& q_dot,
                               const std::vector<Quantity>& controls, double v0);

/// The term's unit from the units of q, q_dot and the controls, e.g. "m^3", "(m/s)^2", "m m/s"; empty
/// for a dimensionless term (tanh, sin, cos, 1).
std::string basis_term_unit(const BasisTerm& term, const std::string& q_unit, const std::string& q_dot_unit,
                            const std::vector<Quantity>& controls);

/// True when two terms are the same function (the same factors in any order).
bool same_basis_term(const BasisTerm& a, const BasisTerm& b);

/// True when a factor of `term` is `function`.
bool has_factor(const BasisTerm& term, BasisFunction function);

}  // namespace gpilqg
