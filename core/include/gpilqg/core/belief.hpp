#pragma once
/// @file belief.hpp
/// Gaussian beliefs over the state and deterministic belief dynamics (Pan and Theodorou, "Probabilistic
/// Differential Dynamic Programming", NIPS 2014): the belief v = (mu, Sigma) of x ~ N(mu, Sigma) moves
/// as v' = F(v, u). PDDP runs DDP on v; a GP with exact moment matching provides F (gp implements it).
///
/// Packing: v = [mu; vech(Sigma)], n + n(n+1)/2 entries, vech stacking the lower triangle column by
/// column (Sigma_00, Sigma_10, ..., Sigma_n-1,0, Sigma_11, ...). Derivatives with respect to the packed
/// entries treat Sigma as symmetric: moving packed entry (i, j), i != j, moves Sigma_ij and Sigma_ji.

#include <memory>

#include "gpilqg/core/types.hpp"
#include "gpilqg/core/workspace.hpp"

namespace gpilqg {

/// Number of packed belief entries for n states: n + n(n+1)/2 (cart-pole 14, quadrotor 90).
int belief_dim(int n);
/// Index of Sigma_ij (either order) inside vech(Sigma).
int vech_index(int n, int i, int j);
/// [mu; vech(Sigma)] into v (belief_dim(n) entries).
void pack_belief(const VectorCRef& mu, const MatrixCRef& Sigma, VectorRef v);
/// v into mu (n) and the symmetric Sigma (n x n).
void unpack_belief(const VectorCRef& v, int n, Vector& mu, Matrix& Sigma);

/// Jacobians of one belief step with respect to the packed belief and the control:
/// d v' / d v (belief_dim x belief_dim) and d v' / d u (belief_dim x m).
struct BeliefJacobians {
  Matrix dv;
  Matrix du;
};

/// Deterministic belief dynamics v' = F(v, u) at step dt.
/// The scratch space of one caller of a BeliefStepModel (the model/data split of step_model.hpp).
struct BeliefWorkspace {
  virtual ~BeliefWorkspace() = default;
};

class BeliefStepModel {
 public:
  virtual ~BeliefStepModel() = default;
  /// A workspace for this model's propagations (the default is empty).
  virtual std::unique_ptr<BeliefWorkspace> make_workspace() const { return std::make_unique<BeliefWorkspace>(); }
  virtual int state_dim() const = 0;
  virtual int control_dim() const = 0;
  virtual double dt() const = 0;
  /// Propagates the packed belief; fills the Jacobians when not null. Never returns NaN: a belief that
  /// cannot be propagated (non-finite input) throws std::invalid_argument.
  virtual void propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next,
                         BeliefJacobians* jacobians = nullptr) const = 0;
  /// The same with the caller's workspace (from make_workspace()); the default calls the form without.
  virtual void propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next, BeliefJacobians* jacobians,
                         BeliefWorkspace&) const {
    propagate(v, u, v_next, jacobians);
  }
};

}  // namespace gpilqg
