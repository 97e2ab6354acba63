#include "gpilqg/control/box_qp.hpp"

#include <cmath>

namespace gpilqg {

bool usable(BoxQpStatus status) {
  return status != BoxQpStatus::NotPositiveDefinite;
}

namespace {

/// 0.5 x'Hx + g'x, with H x written into `Hx` (no allocation once sized).
double objective(const Matrix& H, const Vector& g, const Vector& x, Vector& Hx) {
  Hx.noalias() = H * x;
  return 0.5 * x.dot(Hx) + g.dot(x);
}

/// Free: not at a bound with the gradient pointing out of the box.
void update_free_set(const Vector& x, const Vector& gradient, const Vector& lower, const Vector& upper,
                     BoxQpResult& out) {
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const bool at_lower = x(i) <= lower(i) && gradient(i) > 0.0;
    const bool at_upper = x(i) >= upper(i) && gradient(i) < 0.0;
    out.free(i) = !(at_lower || at_upper);
  }
}

/// Factors H on the free set; false when it is not positive definite.
bool factor_free_block(const Matrix& H, BoxQpResult& out) {
  const int n_free = static_cast<int>(out.free.count());
  out.free_index.resize(n_free);
  for (int i = 0, k = 0; i < out.free.size(); ++i)
    if (out.free(i)) out.free_index(k++) = i;
  Matrix& Hff = out.scratch.free_block;
  Hff.resize(n_free, n_free);
  for (int a = 0; a < n_free; ++a)
    for (int b = 0; b < n_free; ++b) Hff(a, b) = H(out.free_index(a), out.free_index(b));
  out.free_factor.compute(Hff);
  return out.free_factor.info() == Eigen::Success;
}

}  // namespace

void solve_box_qp(const Matrix& H, const Vector& g, const Vector& lower, const Vector& upper,
                  const Vector& x0, BoxQpResult& out, const BoxQpOptions& options) {
  const Eigen::Index n = g.size();
  out.x = x0.cwiseMax(lower).cwiseMin(upper);
  out.free.setConstant(n, true);
  out.iterations = 0;
  out.status = BoxQpStatus::MaxIterations;

  auto& sc = out.scratch;
  double value = objective(H, g, out.x, sc.Hx);
  auto& previous_free = sc.previous_free;
  Vector& gradient = sc.gradient;
  Vector& search = sc.search;
  Vector& candidate = sc.candidate;
  gradient.resize(n);
  search.resize(n);
  candidate.resize(n);

  for (int iter = 0; iter < options.max_iterations; ++iter) {
    out.iterations = iter + 1;
    gradient.noalias() = H * out.x;
    gradient += g;

    update_free_set(out.x, gradient, lower, upper, out);
    if (!out.free.any()) {
      out.free_index.resize(0);
      out.status = BoxQpStatus::AllClamped;
      return;
    }
    if (iter == 0 || out.free != previous_free) {
      if (!factor_free_block(H, out)) {
        out.status = BoxQpStatus::NotPositiveDefinite;
        return;
      }
    }
    previous_free = out.free;

    double free_gradient_norm2 = 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (out.free(i)) free_gradient_norm2 += gradient(i) * gradient(i);
    if (std::sqrt(free_gradient_norm2) < options.gradient_tolerance) {
      out.status = BoxQpStatus::Converged;
      return;
    }

    // Newton step on the free block with the clamped variables held: the free part of the minimiser
    // of the model is -H_ff^-1 (g + H_fc x_c)_f, so the search direction is that minus x_f.
    sc.x_clamped = out.x;
    for (Eigen::Index i = 0; i < n; ++i)
      if (out.free(i)) sc.x_clamped(i) = 0.0;
    sc.grad_clamped = g;
    sc.grad_clamped.noalias() += H * sc.x_clamped;
    const int n_free = static_cast<int>(out.free_index.size());
    sc.rhs.resize(n_free);
    for (int a = 0; a < n_free; ++a) sc.rhs(a) = -sc.grad_clamped(out.free_index(a));
    sc.newton = sc.rhs;
    out.free_factor.solveInPlace(sc.newton);
    search.setZero();
    for (int a = 0; a < n_free; ++a) search(out.free_index(a)) = sc.newton(a) - out.x(out.free_index(a));

    const double slope = search.dot(gradient);
    if (slope >= 0.0) {  // no descent left: at the optimum up to round-off
      out.status = BoxQpStatus::Converged;
      return;
    }

    // Armijo search along the projected path.
    double step = 1.0;
    double new_value = value;
    bool accepted = false;
    while (step >= options.min_step) {
      candidate = (out.x + step * search).cwiseMax(lower).cwiseMin(upper);
      new_value = objective(H, g, candidate, sc.Hx);
      if ((new_value - value) / (step * slope) > options.armijo) {
        accepted = true;
        break;
      }
      step *= options.step_factor;
    }
    if (!accepted) {
      out.status = BoxQpStatus::LineSearchFailed;
      return;
    }
    out.x = candidate;
    const double improvement = value - new_value;
    value = new_value;
    if (improvement < options.improvement_tolerance * std::abs(value)) {
      // Refresh the free set and factor at the final point so the caller's feedback uses them.
      gradient.noalias() = H * out.x;
      gradient += g;
      update_free_set(out.x, gradient, lower, upper, out);
      if (out.free.any() && !factor_free_block(H, out)) {
        out.status = BoxQpStatus::NotPositiveDefinite;
        return;
      }
      if (!out.free.any()) out.free_index.resize(0);
      out.status = BoxQpStatus::SmallImprovement;
      return;
    }
  }
}

}  // namespace gpilqg
