#pragma once
/// @file box_qp.hpp
/// Box-constrained quadratic programme solved by projected Newton (Bertsekas 1982; the control-limited
/// DDP of Tassa, Mansard and Todorov, ICRA 2014, sec. III):
///
///   minimise  0.5 x' H x + g' x   subject to   lower <= x <= upper.
///
/// Each iteration splits the variables into clamped ones (at a bound with the gradient pushing outwards)
/// and free ones, takes a Newton step on the free block with the Cholesky factor of H_ff, and runs an
/// Armijo search along the projection of that step onto the box. The DDP backward pass uses the result
/// for the feed-forward k and the factor of H_ff for the feedback rows of the free controls; rows of
/// clamped controls get zero feedback.

#include <Eigen/Cholesky>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

enum class BoxQpStatus {
  Converged,           ///< the free-subspace gradient fell below the tolerance
  AllClamped,          ///< every variable sits at a bound with the gradient pushing out
  SmallImprovement,    ///< the relative improvement of the last step fell below the tolerance
  MaxIterations,       ///< the iteration cap was reached (the result is feasible, not optimal)
  NotPositiveDefinite, ///< H_ff has no Cholesky factor: the caller must regularise
  LineSearchFailed,    ///< no step decreased the objective (numerical trouble; the result is feasible)
};

/// True for the statuses after which the solution can be used.
bool usable(BoxQpStatus status);

struct BoxQpOptions {
  int max_iterations = 100;             ///< cap on projected-Newton iterations
  double gradient_tolerance = 1e-8;     ///< stop when |grad_free| < this
  double improvement_tolerance = 1e-8;  ///< stop when the relative improvement of a step < this
  double min_step = 1e-22;              ///< the Armijo search gives up below this step length
  double step_factor = 0.6;             ///< Armijo backtracking factor
  double armijo = 0.1;                  ///< sufficient-decrease constant
};

/// Result and reusable storage. Keep one per DDP time step (or per problem) so repeated solves
/// reuse the factorisation buffers.
struct BoxQpResult {
  Vector x;                         ///< the minimiser (always inside the box)
  Eigen::Matrix<bool, Eigen::Dynamic, 1> free;  ///< true for variables not clamped at the solution
  Eigen::LLT<Matrix> free_factor;   ///< Cholesky factor of H restricted to the free variables
  Eigen::VectorXi free_index;       ///< indices of the free variables, in order
  BoxQpStatus status = BoxQpStatus::Converged;
  int iterations = 0;

  /// Scratch of the iterations, kept here so repeated solves of one size do not allocate (only the
  /// free-block factor is refactored, and reallocated when the number of free variables changes).
  struct Scratch {
    Vector gradient, search, candidate, x_clamped, grad_clamped, rhs, newton, Hx;
    Matrix free_block;
    Eigen::Matrix<bool, Eigen::Dynamic, 1> previous_free;
  } scratch;
};

/// Solves the box QP from the warm start x0 (projected onto the box first). H must be symmetric;
/// lower <= upper elementwise (infinite bounds allowed). The result is written into `out`.
void solve_box_qp(const Matrix& H, const Vector& g, const Vector& lower, const Vector& upper,
                  const Vector& x0, BoxQpResult& out, const BoxQpOptions& options = {});

}  // namespace gpilqg
