#pragma once
/// @file basis_force.hpp
/// A force a user declares without writing C++ (the model file's [[user_effects]], docs/diagnosis.md):
/// a generalised force on one coordinate c of the system, linear in its parameters over the basis of
/// basis_terms.hpp,
///
///   Q_c(x, u; theta) = sum_k theta_k b_k(q, q_dot, u),   q = x(position), q_dot = x(velocity)
///
/// (the other components of Q are zero), with the exact derivatives
///
///   dQ_c/dq = sum_k theta_k db_k/dq,   dQ_c/dq_dot = sum_k theta_k db_k/dq_dot,
///   dQ_c/du_j = sum_k theta_k db_k/du_j,
///
/// each db_k by the product rule over its (at most two) factors. tests/core/basis_force_test.cpp checks
/// them against central differences for every basis function and for products.

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpilqg/core/basis_terms.hpp"
#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/generalised_forces.hpp"

namespace gpilqg {

/// The scale v0 of tanh(q_dot / v0) when a declaration gives none: the library's Coulomb width [m/s or rad/s].
inline constexpr double kDefaultTanhScale = 0.05;

/// What a user declares: one [[user_effects]] entry of a model file.
struct BasisForceDeclaration {
  std::string name;                     ///< the effect's name: a letter, then letters, digits and '_'
  std::string coordinate;               ///< a generalised coordinate (find_coordinate), e.g. "x", "Q_x"
  std::vector<std::string> terms;       ///< basis terms (parse_basis_term), at least one, no two the same
  std::vector<std::string> parameters;  ///< one name per term; empty: c1, c2, ...
  std::vector<std::string> units;       ///< one unit per term; empty: the force's unit over the term's
  std::optional<double> v0;             ///< tanh's scale, > 0; only with a tanh(qdot/v0) term (default 0.05)

  friend bool operator==(const BasisForceDeclaration&, const BasisForceDeclaration&) = default;
};

/// A declaration that cannot be used: `field()` is the declaration's field at fault ("name",
/// "coordinate", "terms", "parameters", "units" or "v0") and `index()` the entry of an array field
/// (-1 for the field as a whole), so a file reader can name the line.
class DeclarationError : public std::invalid_argument {
 public:
  DeclarationError(std::string field, int index, const std::string& what)
      : std::invalid_argument(what), field_(std::move(field)), index_(index) {}
  const std::string& field() const { return field_; }
  int index() const { return index_; }

 private:
  std::string field_;
  int index_;
};

class BasisForceEffect final : public ForceEffect {
 public:
  /// The declared force on `system` (any system with a generalised-force map; the preset does not
  /// matter). Throws DeclarationError for an invalid name, an unknown coordinate (listing the valid
  /// ones), no terms, an unknown or repeated term or a product of more than two factors (listing the
  /// basis), parameter names or units that are not one per term, repeated or not names, and a v0
  /// that is not finite and > 0 or given without a tanh term.
  BasisForceEffect(const Dynamics& system, BasisForceDeclaration declaration);

  const std::string& name() const override { return declaration_.name; }
  const std::vector<EffectParameter>& parameters() const override { return parameters_; }
  /// E.g. "Q_x = k3 x^3" or "Q_theta = c1 theta_dot + c2 tanh(theta_dot/0.05)".
  const std::string& formula() const override { return formula_; }
  bool depends_on_input() const override { return depends_on_input_; }
  bool linear_in_parameters() const override { return true; }
  /// Adds Q (k_Q entries, only the coordinate's component), dQ/dx (k_Q x n) and dQ/du (k_Q x m).
  void add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q, Matrix* dQ_dx,
                 Matrix* dQ_du) const override;

  /// The declaration as given, with each term in the text parse_basis_term reads back
  /// (basis_term_text): declaring it again gives the same effect.
  const BasisForceDeclaration& declaration() const { return declaration_; }
  const GeneralisedCoordinate& coordinate() const { return coordinate_; }
  const std::vector<BasisTerm>& terms() const { return terms_; }
  double v0() const { return v0_; }

 private:
  BasisForceDeclaration declaration_;
  GeneralisedCoordinate coordinate_;
  std::vector<BasisTerm> terms_;
  std::vector<EffectParameter> parameters_;
  std::string formula_;
  double v0_ = kDefaultTanhScale;
  int force_dim_ = 0, state_dim_ = 0, control_dim_ = 0;
  bool depends_on_input_ = false;
};

/// True when `name` can name an effect or a parameter of a declaration: a letter, then letters,
/// digits and '_' (a bare TOML key and a JSON key that needs no escaping).
bool valid_declared_name(const std::string& name);

}  // namespace gpilqg
