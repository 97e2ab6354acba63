#pragma once
/// @file belief_space.hpp
/// Probabilistic DDP (Pan and Theodorou, NIPS 2014) on the shared DDP engine: the packed belief
/// v = [mu; vech(Sigma)] becomes the engine's state, the belief dynamics v' = F(v, u) its (deterministic)
/// step model, and the expected cost of the belief its cost. Nothing of the engine is copied.
///
///   E[l(x, u)] = l(mu, u) + 0.5 tr(l_xx Sigma)      for x ~ N(mu, Sigma)
///
/// exact for quadratic costs (the paper's and core/cost.hpp's QuadraticCost), a second-order
/// approximation otherwise (l_xx is then taken as constant in the derivatives). Its derivative with
/// respect to the packed entry (i, j) of Sigma is 0.5 l_xx,ii on the diagonal and l_xx,ij off it.

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/belief.hpp"
#include "gpilqg/core/cost.hpp"

namespace gpilqg {

/// A BeliefStepModel seen by the DDP engine as a StepModel over the packed belief. It has no noise
/// columns: the uncertainty is part of the state.
class BeliefSpaceModel final : public StepModel {
 public:
  explicit BeliefSpaceModel(const BeliefStepModel& belief) : belief_(belief) {}
  int state_dim() const override { return belief_dim(belief_.state_dim()); }
  int control_dim() const override { return belief_.control_dim(); }
  double dt() const override { return belief_.dt(); }
  /// Holds the belief model's workspace and its Jacobians.
  std::unique_ptr<StepWorkspace> make_workspace() const override;
  using StepModel::step;
  void step(const VectorCRef& v, const VectorCRef& u, VectorRef v_next, StepJacobians* jacobians,
            StepWorkspace& workspace) const override;
  /// The moment match dominates a belief step; its derivatives add little (docs/results/pddp.md).
  bool jacobians_nearly_free() const override { return true; }

 private:
  const BeliefStepModel& belief_;
};

/// The expected cost of a belief under a state-space cost (see the file comment).
class BeliefCost final : public Cost {
 public:
  /// `cost` is over n states; the belief cost is over belief_dim(n) entries.
  explicit BeliefCost(const Cost& cost);
  int state_dim() const override { return belief_dim(n_); }
  int control_dim() const override { return cost_.control_dim(); }
  /// Holds the state cost's workspace and the state-space derivatives that the belief ones lift.
  std::unique_ptr<CostWorkspace> make_workspace() const override;
  using Cost::stage;
  using Cost::terminal;
  using Cost::terminal_at;
  double stage(int t, const VectorCRef& v, const VectorCRef& u, CostDerivatives* d,
               CostWorkspace& workspace) const override;
  double terminal(const VectorCRef& v, CostDerivatives* d, CostWorkspace& workspace) const override;
  double terminal_at(int t, const VectorCRef& v, CostDerivatives* d, CostWorkspace& workspace) const override;

 private:
  /// Adds 0.5 tr(l_xx Sigma) to the value and writes the belief-space derivatives from the state ones.
  double lift(double value, const CostDerivatives& state, const VectorCRef& v, CostDerivatives* d,
              bool has_control) const;
  const Cost& cost_;
  int n_;
};

/// A PDDP problem: belief dynamics, a state-space cost, the initial belief N(x0, Sigma0).
struct PddpProblem {
  const BeliefStepModel* model = nullptr;
  const Cost* cost = nullptr;
  Vector x0;
  Matrix Sigma0;  ///< n x n initial covariance (zero: a known start)
  int horizon = 0;
  Vector u_min, u_max;
};

struct PddpResult {
  DdpResult belief;        ///< the engine's result over the packed belief
  Matrix mean;             ///< n x (T+1) predicted state means
  std::vector<Matrix> covariance;  ///< T+1 predicted state covariances
  /// The policy on the real system. It acts with feedback on the measured state: a measurement x is
  /// read as the belief (x, Sigma_bar_t), i.e. the belief deviation (x - mu_bar_t, 0), so
  /// u = u_bar_t + K_t,mu (x - mu_bar_t) with K_t,mu the first n columns of the belief gain.
  AffinePolicy state_policy;
};

/// Solves by DDP over the belief (variant iLQR: the belief dynamics are deterministic).
PddpResult solve_pddp(const PddpProblem& problem, const Matrix& initial_controls, DdpOptions options = {});

}  // namespace gpilqg
