#pragma once
/// @file gp_belief_dynamics.hpp
/// PDDP's learned dynamics (Pan and Theodorou, NIPS 2014): n independent GPs, one per state dimension,
/// on z = [x; u] -> dx = x' - x, learned from data only (no simulator in the mean). Under a Gaussian
/// belief x ~ N(mu, Sigma) and a known control u, the input is z ~ N([mu; u], blkdiag(Sigma, 0)), and
/// exact moment matching (a MomentMatcher, moment_matcher.hpp: the SE-ARD GP of the exact and FITC
/// backends, or SSGP's trigonometric features) gives M = E[dx], S = Cov[dx] and C = Cov[z, dx], so
///
///   mu'    = mu + M
///   Sigma' = Sigma + S + C_x + C_x'        (C_x = Cov[x, dx], the first n rows of C)
///
/// a deterministic belief step v' = F(v, u) with analytic Jacobians by the chain rule through M, S and
/// C (the packed-covariance convention of core/belief.hpp).

#include <memory>
#include <vector>

#include "gpilqg/core/belief.hpp"
#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp {

class GpBeliefDynamics final : public BeliefStepModel {
 public:
  /// `matcher` must have n outputs (the increments of x) over D = n + m inputs. Throws
  /// std::invalid_argument otherwise (or when it is null).
  GpBeliefDynamics(int n, int m, double dt, std::shared_ptr<const MomentMatcher> matcher);

  /// Conditions the n GPs on shared inputs (N x (n+m), rows z = [x; u]) and increments (N x n, rows
  /// x' - x), with per-output hyperparameters [log l (n+m); log sf; log sn].
  static GpBeliefDynamics condition(int n, int m, double dt, const Matrix& inputs, const Matrix& increments,
                                    const std::vector<Vector>& hyperparameters);

  /// Fits the n GPs by maximum likelihood with `backend`, one output at a time, then builds the
  /// moment matcher of the fitted models (moment_matcher_for, fitted_moment_matcher.hpp): "exact"
  /// (the outputs share one subsample: the same seed for every output), "fitc" (each output its own
  /// pseudo-inputs) or "ssgp" (each output its own frequencies). Any other backend ("compact": the
  /// Wendland kernel has no closed-form Gaussian expectation) is rejected with std::invalid_argument
  /// before anything is fitted. `summaries` receives one fit summary per output when not null.
  /// `threads` (>= 1): the outputs are fitted concurrently on that many threads, and the model's
  /// belief step gets them too (set_threads); the results do not depend on it.
  static GpBeliefDynamics fit(int n, int m, double dt, const Matrix& inputs, const Matrix& increments,
                              const GpBackend& backend, const FitOptions& options = {},
                              std::vector<FitSummary>* summaries = nullptr, int threads = 1);

  int state_dim() const override { return n_; }
  int control_dim() const override { return m_; }
  double dt() const override { return dt_; }
  void propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next,
                 BeliefJacobians* jacobians = nullptr) const override;
  /// Holds the unpacked belief and the moment match (with its derivatives), so a caller that keeps it
  /// does not allocate per step.
  std::unique_ptr<BeliefWorkspace> make_workspace() const override;
  void propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next, BeliefJacobians* jacobians,
                 BeliefWorkspace& workspace) const override;

  const MomentMatcher& matcher() const { return *matcher_; }

  /// Threads one belief step may use (MomentMatch::threads, >= 1; default 1): the SE-ARD matcher
  /// shares its output pairs among them. The results are the same for any value. Throws
  /// std::invalid_argument when threads < 1.
  void set_threads(int threads);
  int threads() const { return threads_; }

 private:
  int n_, m_;
  double dt_;
  int threads_ = 1;
  std::shared_ptr<const MomentMatcher> matcher_;  ///< immutable, shared by copies of this model
};

}  // namespace gpilqg::gp
