#include "gpilqg/control/ddp_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "gpilqg/control/box_qp.hpp"

namespace gpilqg {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Runs `stage` and adds its wall time to `seconds`.
template <class Stage>
void timed(double& seconds, Stage&& stage) {
  const auto start = Clock::now();
  stage();
  seconds += seconds_since(start);
}

/// Columns c_i = sqrt(dt) F^(i) (and G^(j)) with their derivatives, as the Q-expansion uses them.
void scale_columns(DiffusionColumns& d, double factor) {
  d.columns *= factor;
  for (auto& m : d.d_dx) m *= factor;
  for (auto& m : d.d_du) m *= factor;
}

}  // namespace

/// Every per-step buffer of one problem shape (n, m, T, p + q diffusion columns).
struct DdpWorkspace {
  int n = -1, m = -1, T = -1;

  AffinePolicy policy;         ///< x_bar, u_bar (the current nominal), k, K, limits
  Matrix x_new, u_new;         ///< the line-search candidate
  std::vector<StepJacobians> jac;
  std::vector<StepJacobians> jac_new;  ///< the candidate's, when the model's are nearly free
  std::vector<CostDerivatives> cost;       ///< T stages + the terminal at index T
  std::vector<DiffusionColumns> noise;     ///< sqrt(dt) F at each step (iLQG, Robust-iLQG)
  std::vector<DiffusionColumns> uncertainty;  ///< sqrt(dt) G at each step (Robust-iLQG)
  std::vector<Matrix> S;                   ///< V_xx at t = 0..T from the last backward pass
  Matrix gradient;                         ///< dM/du_t (m x T) from the last backward pass
  DiffusionColumns candidate_columns;      ///< columns at a line-search candidate (no derivatives)

  // Backward-pass temporaries.
  Vector Vx, Qx, Qu, Sc, p, p_next, dx, grad;
  Matrix Vxx, Qxx, Quu, Qux, Quu_reg, Qux_reg, SA, SB, S_reg, Sc_x;
  Eigen::LLT<Matrix> llt;
  BoxQpResult qp;
  Matrix free_rows;  ///< feedback rows of the free controls (box-limited problems)
  Vector lower, upper, qp_warm, step_lower, step_upper, Quu_k;

  void resize(int n_, int m_, int T_) {
    if (n_ == n && m_ == m && T_ == T) return;
    n = n_;
    m = m_;
    T = T_;
    policy.x_bar.setZero(n, T + 1);
    policy.u_bar.setZero(m, T);
    policy.k.setZero(m, T);
    policy.K.assign(static_cast<std::size_t>(T), Matrix::Zero(m, n));
    x_new.setZero(n, T + 1);
    u_new.setZero(m, T);
    jac.resize(static_cast<std::size_t>(T));
    for (auto& j : jac) j.resize(n, m);
    jac_new.resize(static_cast<std::size_t>(T));
    for (auto& j : jac_new) j.resize(n, m);
    cost.resize(static_cast<std::size_t>(T + 1));
    for (auto& c : cost) c.resize(n, m);
    noise.resize(static_cast<std::size_t>(T));
    uncertainty.resize(static_cast<std::size_t>(T));
    S.assign(static_cast<std::size_t>(T + 1), Matrix::Zero(n, n));
    gradient.setZero(m, T);
    for (Vector* v : {&Vx, &Qx, &Sc, &p, &p_next, &dx}) v->setZero(n);
    for (Vector* v : {&Qu, &grad, &lower, &upper, &qp_warm, &step_lower, &step_upper, &Quu_k}) v->setZero(m);
    for (Matrix* a : {&Vxx, &Qxx, &SA, &S_reg, &Sc_x}) a->setZero(n, n);
    for (Matrix* a : {&Quu, &Quu_reg}) a->setZero(m, m);
    for (Matrix* a : {&Qux, &Qux_reg}) a->setZero(m, n);
    SB.setZero(n, m);
  }
};

DdpSolver::DdpSolver(DdpOptions options) : options_(options), ws_(std::make_unique<DdpWorkspace>()) {
  options_.validate();
}
DdpSolver::~DdpSolver() = default;
DdpSolver::DdpSolver(DdpSolver&&) noexcept = default;
DdpSolver& DdpSolver::operator=(DdpSolver&&) noexcept = default;

void DdpSolver::set_options(DdpOptions options) {
  options.validate();
  options_ = options;
}

namespace {

/// The state of one solve: the problem, the options, the workspace and the bookkeeping of the
/// regularisation schedule. Kept out of the header so the public type stays small.
class Engine {
 public:
  Engine(const DdpProblem& problem, const DdpOptions& options, DdpWorkspace& ws)
      : pb_(problem), opt_(options), ws_(ws), model_(*problem.model), cost_(*problem.cost),
        model_ws_(problem.model->make_workspace()), cost_ws_(problem.cost->make_workspace()) {}

  DdpResult run(const Matrix& initial_controls);

 private:
  bool uses_noise() const { return opt_.variant != DdpVariant::ILQR; }
  bool uses_uncertainty() const { return opt_.variant == DdpVariant::RobustILQG; }

  /// Rolls out `policy` with feed-forward scale alpha into (x_out, u_out); returns the merit with the
  /// stored S (trace terms included for iLQG variants), or +inf when the rollout diverges.
  double forward(double alpha, Matrix& x_out, Matrix& u_out);
  /// Derivatives of model, cost and diffusion columns along the nominal trajectory; nothing when
  /// they are already those of the nominal (derivatives_current_).
  void differentiate();
  /// The candidate (x_new, u_new) becomes the nominal, with its model Jacobians when forward()
  /// computed them.
  void accept_candidate();
  /// One backward pass with regularisation lambda. False when a Q_uu block is not positive definite.
  bool backward(double lambda);
  /// The regularisation schedule of Tassa, Erez and Todorov (IROS 2012, sec. II-F), with
  /// lambda_0 = DdpOptions::lambda_factor: after a failure
  ///   dlambda <- max(dlambda lambda_0, lambda_0),   lambda <- max(lambda dlambda, lambda_min).
  void increase_lambda();
  /// After a success: dlambda <- min(dlambda / lambda_0, 1 / lambda_0), lambda <- lambda dlambda,
  /// and lambda <- 0 once it falls below lambda_min (no regularisation at all).
  void decrease_lambda();
  /// sum_i 0.5 c_i' S c_i for the columns at one step.
  static double trace_term(const DiffusionColumns& d, const Matrix& S, Vector& Sc);

  // The stages of run(), in the order the algorithm takes them.

  /// Sizes the workspace for the problem, sets the control bounds (infinite where the problem has
  /// none), zeros the policy and the stored S = V_xx, and resets the schedule to
  /// lambda = lambda_initial, dlambda = 1.
  void prepare();
  /// The initial rollout: the initial controls clamped to [u_min, u_max], open loop (K = 0, k = 0,
  /// u_bar = the controls), into the candidate (x_new, u_new). Returns its cost (S = 0, so no trace
  /// terms), +inf when it diverges.
  double initial_rollout(const Matrix& initial_controls);
  /// The result of a diverged initial rollout: costs +inf (DdpResult's contract); the states reached
  /// (the last one repeated) and the clamped initial controls, open loop; no value Hessians.
  DdpResult diverged_result(double merit, Clock::time_point start) const;
  /// The regularised backward pass: backward(lambda) at the current lambda, raising lambda
  /// (increase_lambda) after each failure until every Q_uu block is positive definite or
  /// lambda > lambda_max. Records lambda, the failures and the projected gradient norm; false when
  /// the limit was passed.
  bool regularised_backward(DdpIteration& record);
  /// Termination after the backward pass: RegularizationLimit when it failed at lambda_max,
  /// GradientNorm when the projected gradient is small, |g|_inf < gradient_tolerance.
  std::optional<DdpTermination> backward_termination(bool backward_ok) const;

  struct LineSearchOutcome {
    bool accepted = false;
    double merit = 0.0;  ///< the accepted candidate's merit (the last one tried when none was)
  };
  /// The line search over the feed-forward scale alpha (Tassa, Erez and Todorov 2012). The steps are
  /// alpha_s = 10^(-3 s / (S - 1)), s = 0..S-1 (S = line_search_steps; alpha = 1 when S = 1). For
  /// each, with dV1 = sum_t k_t' Q_u and dV2 = sum_t 0.5 k_t' Q_uu k_t from the backward pass, the
  /// quadratic model expects the reduction
  ///   expected(alpha) = -(alpha dV1 + alpha^2 dV2),
  /// and the candidate is accepted, Armijo-like, when its merit is finite and the ratio
  ///   z = (J - J(alpha)) / expected(alpha)  >  min_reduction_ratio
  /// (z = +1 or -1 by the sign of the actual reduction when expected <= 0). Records the trials and,
  /// for an accepted step, alpha and both reductions. The accepted candidate is left in
  /// (x_new, u_new).
  LineSearchOutcome line_search(double merit, DdpIteration& record);
  /// Termination after an accepted step: the cost changed by at most
  /// cost_tolerance max(|J|, 1e-12) (J the merit before the step). CostChange when the trajectory is
  /// stationary (ddp_summary.hpp's stationary()), else Stalled: a tiny accepted step with a huge or
  /// non-finite gradient is a stall of the line search, not a minimum.
  std::optional<DdpTermination> cost_change_termination(double merit, double new_merit,
                                                        double actual_reduction) const;
  /// Termination after a rejected line search (lambda already raised): lambda > lambda_max.
  std::optional<DdpTermination> rejection_termination() const;
  /// Termination by the budgets, checked in this order after every iteration: the wall time
  /// (elapsed > max_seconds), the caller (on_iteration(last) returns false), the iteration count
  /// (iteration == max_iterations).
  std::optional<DdpTermination> budget_termination(Clock::time_point start, const DdpIteration& last,
                                                   int iteration) const;
  /// Derivatives and one more backward pass at the returned trajectory, for its gains, value
  /// Hessians and expected cost: lambda = 0 first, then lambda <- max(10 lambda, lambda_min) while
  /// the pass fails and lambda <= lambda_max. False when none worked.
  bool final_backward(DdpTimings& timings);
  /// When no final backward pass works (non-finite or hopelessly indefinite derivatives at the
  /// returned trajectory), what the failed pass left is partial: an open-loop policy, the nominal
  /// cost summed directly, the larger of it and `merit` (the last accepted iterate's) as the expected
  /// cost, no value Hessians and the last recorded gradient norm.
  void open_loop_fallback(double merit, DdpSummary& summary);
  /// The returned trajectory, policy (gains of the final backward pass, k = 0), costs, value Hessians
  /// and gradient, and the summary's final values.
  void finish(double merit, Clock::time_point start, DdpResult& result);

  const DdpProblem& pb_;
  const DdpOptions& opt_;
  DdpWorkspace& ws_;
  const StepModel& model_;
  const Cost& cost_;
  std::unique_ptr<StepWorkspace> model_ws_;  ///< the model's scratch for this solve (model/data split)
  std::unique_ptr<CostWorkspace> cost_ws_;   ///< the cost's scratch for this solve

  double lambda_ = 0.0;
  double dlambda_ = 1.0;
  // Results of the last backward pass.
  double dV1_ = 0.0, dV2_ = 0.0;
  double merit_at_nominal_ = 0.0;   ///< nominal cost + trace terms with the new S
  double nominal_cost_ = 0.0;
  double gradient_norm_ = 0.0;
  /// forward() asks the model for Jacobians (StepModel::jacobians_nearly_free).
  bool jacobians_in_forward_ = false;
  /// ws_.jac hold the nominal's model Jacobians (from the candidate that became the nominal).
  bool model_jacobians_current_ = false;
  /// Everything differentiate() computes is that of the nominal (it did not change since).
  bool derivatives_current_ = false;
};

double Engine::trace_term(const DiffusionColumns& d, const Matrix& S, Vector& Sc) {
  double sum = 0.0;
  for (int i = 0; i < d.count(); ++i) {
    Sc.noalias() = S * d.columns.col(i);
    sum += 0.5 * d.columns.col(i).dot(Sc);
  }
  return sum;
}

double Engine::forward(double alpha, Matrix& x_out, Matrix& u_out) {
  const int T = ws_.T;
  const double sqrt_dt = std::sqrt(model_.dt());
  x_out.col(0) = pb_.x0;
  double merit = 0.0;
  for (int t = 0; t < T; ++t) {
    ws_.policy.control(t, x_out.col(t), u_out.col(t), alpha);
    merit += cost_.stage(t, x_out.col(t), u_out.col(t), nullptr, *cost_ws_);
    if (uses_noise()) {
      const auto& S_next = ws_.S[static_cast<std::size_t>(t + 1)];
      model_.noise(x_out.col(t), u_out.col(t), ws_.candidate_columns, false, *model_ws_);
      ws_.candidate_columns.columns *= sqrt_dt;
      merit += trace_term(ws_.candidate_columns, S_next, ws_.Sc);
      if (uses_uncertainty()) {
        model_.uncertainty(x_out.col(t), u_out.col(t), ws_.candidate_columns, false, *model_ws_);
        ws_.candidate_columns.columns *= sqrt_dt;
        merit += trace_term(ws_.candidate_columns, S_next, ws_.Sc);
      }
    }
    const bool control_finite = u_out.col(t).allFinite();
    StepJacobians* jacobians = jacobians_in_forward_ ? &ws_.jac_new[static_cast<std::size_t>(t)] : nullptr;
    if (control_finite) model_.step(x_out.col(t), u_out.col(t), x_out.col(t + 1), jacobians, *model_ws_);
    if (!control_finite || check_divergence(x_out.col(t + 1)) != RolloutStatus::Completed) {
      // Diverged (rollout.hpp's test, shared with every rollout): keep the candidate free of NaN and
      // inf (the last state within the bound repeated, the nominal controls after it) and reject it.
      for (int s = t + 1; s <= T; ++s) x_out.col(s) = x_out.col(t);
      for (int s = t; s < T; ++s) u_out.col(s) = ws_.policy.u_bar.col(s);
      return std::numeric_limits<double>::infinity();
    }
  }
  merit += cost_.terminal(x_out.col(T), nullptr, *cost_ws_);
  return std::isfinite(merit) ? merit : std::numeric_limits<double>::infinity();
}

void Engine::differentiate() {
  if (derivatives_current_) return;
  const int T = ws_.T;
  const double sqrt_dt = std::sqrt(model_.dt());
  const auto& x = ws_.policy.x_bar;
  const auto& u = ws_.policy.u_bar;
  for (int t = 0; t < T; ++t) {
    const auto ts = static_cast<std::size_t>(t);
    if (!model_jacobians_current_) model_.step(x.col(t), u.col(t), ws_.x_new.col(t + 1), &ws_.jac[ts], *model_ws_);
    cost_.stage(t, x.col(t), u.col(t), &ws_.cost[ts], *cost_ws_);
    if (uses_noise()) {
      model_.noise(x.col(t), u.col(t), ws_.noise[ts], true, *model_ws_);
      scale_columns(ws_.noise[ts], sqrt_dt);
    }
    if (uses_uncertainty()) {
      model_.uncertainty(x.col(t), u.col(t), ws_.uncertainty[ts], true, *model_ws_);
      scale_columns(ws_.uncertainty[ts], sqrt_dt);
    }
  }
  cost_.terminal(x.col(T), &ws_.cost[static_cast<std::size_t>(T)], *cost_ws_);
  model_jacobians_current_ = true;
  derivatives_current_ = true;
}

void Engine::accept_candidate() {
  ws_.policy.x_bar.swap(ws_.x_new);
  ws_.policy.u_bar.swap(ws_.u_new);
  if (jacobians_in_forward_) ws_.jac.swap(ws_.jac_new);
  model_jacobians_current_ = jacobians_in_forward_;
  derivatives_current_ = false;
}

bool Engine::backward(double lambda) {
  auto& w = ws_;
  const int T = w.T, m = w.m;
  const auto& terminal = w.cost[static_cast<std::size_t>(T)];
  w.Vx = terminal.lx;
  w.Vxx = terminal.lxx;
  w.S[static_cast<std::size_t>(T)] = w.Vxx;
  w.p = terminal.lx;  // costate of the merit with S held: p_t = dM/dx_t
  dV1_ = dV2_ = 0.0;
  nominal_cost_ = terminal.value;
  double trace_sum = 0.0;
  gradient_norm_ = 0.0;
  const bool limited = pb_.has_limits();

  for (int t = T - 1; t >= 0; --t) {
    const auto ts = static_cast<std::size_t>(t);
    const Matrix& A = w.jac[ts].A;
    const Matrix& B = w.jac[ts].B;
    const CostDerivatives& l = w.cost[ts];
    const Matrix& S = w.Vxx;  // S' = V'_xx

    // Deterministic part of the expansion.
    w.SA.noalias() = S * A;
    w.SB.noalias() = S * B;
    w.Qx = l.lx;
    w.Qx.noalias() += A.transpose() * w.Vx;
    w.Qu = l.lu;
    w.Qu.noalias() += B.transpose() * w.Vx;
    w.Qxx = l.lxx;
    w.Qxx.noalias() += A.transpose() * w.SA;
    w.Qux = l.lux;
    w.Qux.noalias() += B.transpose() * w.SA;
    w.Quu = l.luu;
    w.Quu.noalias() += B.transpose() * w.SB;
    nominal_cost_ += l.value;

    // Costate of the merit (deterministic part; the diffusion part is added below).
    w.p_next = w.p;
    w.grad = l.lu;
    w.grad.noalias() += B.transpose() * w.p_next;
    w.p = l.lx;
    w.p.noalias() += A.transpose() * w.p_next;

    // The variant's stochastic terms: sums over the diffusion columns (paper, q, Q, g, G, H).
    auto add_columns = [&](const DiffusionColumns& d) {
      for (int i = 0; i < d.count(); ++i) {
        const auto is = static_cast<std::size_t>(i);
        const auto c = d.columns.col(i);
        w.Sc.noalias() = S * c;
        trace_sum += 0.5 * c.dot(w.Sc);
        w.Qx.noalias() += d.d_dx[is].transpose() * w.Sc;
        w.Qu.noalias() += d.d_du[is].transpose() * w.Sc;
        w.p.noalias() += d.d_dx[is].transpose() * w.Sc;
        w.grad.noalias() += d.d_du[is].transpose() * w.Sc;
        w.Sc_x.noalias() = S * d.d_dx[is];
        w.Qxx.noalias() += d.d_dx[is].transpose() * w.Sc_x;
        w.Qux.noalias() += d.d_du[is].transpose() * w.Sc_x;
        w.SB.noalias() = S * d.d_du[is];
        w.Quu.noalias() += d.d_du[is].transpose() * w.SB;
      }
    };
    if (uses_noise()) add_columns(w.noise[ts]);
    if (uses_uncertainty()) add_columns(w.uncertainty[ts]);

    // Regularised blocks that determine the step.
    if (opt_.regularization == RegularizationTarget::ControlHessian) {
      w.Quu_reg = w.Quu;
      w.Quu_reg.diagonal().array() += lambda;
      w.Qux_reg = w.Qux;
    } else {
      w.Quu_reg = w.Quu;
      w.Quu_reg.noalias() += lambda * (B.transpose() * B);
      w.Qux_reg = w.Qux;
      w.Qux_reg.noalias() += lambda * (B.transpose() * A);
    }

    // Projected gradient of the merit with respect to u_t (zero where a bound is active and the
    // gradient pushes outwards).
    w.gradient.col(t) = w.grad;
    const auto u_t = w.policy.u_bar.col(t);
    for (int j = 0; j < m; ++j) {
      double g = w.grad(j);
      if (limited && ((u_t(j) <= w.lower(j) && g > 0.0) || (u_t(j) >= w.upper(j) && g < 0.0))) g = 0.0;
      // A NaN entry counts as infinitely large (std::max would skip it): never "small".
      gradient_norm_ = std::max(gradient_norm_, std::isnan(g) ? std::numeric_limits<double>::infinity() : std::abs(g));
    }

    auto k = w.policy.k.col(t);
    Matrix& K = w.policy.K[ts];
    if (!limited) {
      w.llt.compute(w.Quu_reg);
      if (w.llt.info() != Eigen::Success) return false;
      k = -w.Qu;
      w.llt.solveInPlace(k);
      K = -w.Qux_reg;
      w.llt.solveInPlace(K);
      // Eigen's LLT reports success on a NaN matrix: non-finite derivatives must fail here too.
      if (!k.allFinite() || !K.allFinite()) return false;
    } else {
      // Limits on the step: lower - u_bar <= du <= upper - u_bar, warm-started from the previous k.
      w.qp_warm = k;
      w.step_lower = w.lower - u_t;
      w.step_upper = w.upper - u_t;
      solve_box_qp(w.Quu_reg, w.Qu, w.step_lower, w.step_upper, w.qp_warm, w.qp);
      if (!usable(w.qp.status)) return false;
      k = w.qp.x;
      K.setZero();
      // Feedback for the free controls: K_f = -H_ff^-1 Q_ux,f; clamped rows stay zero.
      const auto& idx = w.qp.free_index;
      if (idx.size() > 0) {
        w.free_rows.resize(idx.size(), w.n);  // no reallocation while the free count is unchanged
        for (Eigen::Index a = 0; a < idx.size(); ++a) w.free_rows.row(a) = -w.Qux_reg.row(idx(a));
        w.qp.free_factor.solveInPlace(w.free_rows);
        for (Eigen::Index a = 0; a < idx.size(); ++a) K.row(idx(a)) = w.free_rows.row(a);
      }
      if (!k.allFinite() || !K.allFinite()) return false;
    }

    // Value update with the unregularised blocks (Tassa et al. 2012, eq. 11).
    dV1_ += k.dot(w.Qu);
    w.Quu_k.noalias() = w.Quu * k;
    dV2_ += 0.5 * k.dot(w.Quu_k);
    w.SB.noalias() = K.transpose() * w.Quu;  // K' Q_uu (n x m), scratch
    w.Vx = w.Qx;
    w.Vx.noalias() += w.SB * k;
    w.Vx.noalias() += K.transpose() * w.Qu;
    w.Vx.noalias() += w.Qux.transpose() * k;
    w.Vxx = w.Qxx;
    w.Vxx.noalias() += w.SB * K;
    w.Vxx.noalias() += K.transpose() * w.Qux;
    w.Vxx.noalias() += w.Qux.transpose() * K;
    w.SA = w.Vxx.transpose();  // symmetrise against round-off
    w.Vxx += w.SA;
    w.Vxx *= 0.5;
    w.S[ts] = w.Vxx;
  }
  merit_at_nominal_ = nominal_cost_ + trace_sum;
  return true;
}

void Engine::increase_lambda() {
  dlambda_ = std::max(dlambda_ * opt_.lambda_factor, opt_.lambda_factor);
  lambda_ = std::max(lambda_ * dlambda_, opt_.lambda_min);
}

void Engine::decrease_lambda() {
  dlambda_ = std::min(dlambda_ / opt_.lambda_factor, 1.0 / opt_.lambda_factor);
  lambda_ = lambda_ * dlambda_;
  if (lambda_ < opt_.lambda_min) lambda_ = 0.0;
}

/// The algorithm: the initial rollout, then iterations of derivatives, regularised backward pass and
/// line search until a termination test holds, then the final backward pass at the returned
/// trajectory.
DdpResult Engine::run(const Matrix& initial_controls) {
  const auto start = Clock::now();
  prepare();
  double merit = initial_rollout(initial_controls);
  if (!std::isfinite(merit)) return diverged_result(merit, start);
  accept_candidate();  // u_bar: the initial controls, as the rollout applied them

  DdpResult result;
  DdpSummary& summary = result.summary;
  summary.initial_cost = merit;
  for (int iter = 1; iter <= opt_.max_iterations; ++iter) {
    DdpIteration record;
    record.iteration = iter;
    timed(summary.timings.derivatives_s, [&] { differentiate(); });
    bool backward_ok = false;
    timed(summary.timings.backward_s, [&] { backward_ok = regularised_backward(record); });
    merit = merit_at_nominal_;  // the current trajectory's merit under the new S
    if (iter == 1) summary.initial_cost = merit;
    if (const auto termination = backward_termination(backward_ok)) {
      record.cost = merit;
      summary.trace.push_back(record);
      summary.termination = *termination;
      break;
    }

    LineSearchOutcome step;
    timed(summary.timings.forward_s, [&] { step = line_search(merit, record); });
    std::optional<DdpTermination> termination;
    if (step.accepted) {
      accept_candidate();
      decrease_lambda();
      record.accepted = true;
      record.cost = step.merit;
      termination = cost_change_termination(merit, step.merit, record.actual_reduction);
      merit = step.merit;
    } else {
      increase_lambda();
      record.cost = merit;
      termination = rejection_termination();
    }
    summary.trace.push_back(record);
    if (!termination) termination = budget_termination(start, summary.trace.back(), iter);
    if (termination) {
      summary.termination = *termination;
      break;
    }
  }
  summary.iterations = static_cast<int>(summary.trace.size());
  finish(merit, start, result);
  return result;
}

void Engine::prepare() {
  auto& w = ws_;
  const int m = model_.control_dim(), T = pb_.horizon;
  w.resize(model_.state_dim(), m, T);
  w.lower = pb_.u_min.size() ? pb_.u_min : Vector::Constant(m, -std::numeric_limits<double>::infinity());
  w.upper = pb_.u_max.size() ? pb_.u_max : Vector::Constant(m, std::numeric_limits<double>::infinity());
  w.policy.u_min = pb_.u_min.size() ? w.lower : Vector();
  w.policy.u_max = pb_.u_max.size() ? w.upper : Vector();
  for (auto& S : w.S) S.setZero();
  for (auto& K : w.policy.K) K.setZero();
  w.policy.k.setZero();
  jacobians_in_forward_ = model_.jacobians_nearly_free();
  model_jacobians_current_ = derivatives_current_ = false;
  lambda_ = opt_.lambda_initial;
  dlambda_ = 1.0;
}

double Engine::initial_rollout(const Matrix& initial_controls) {
  const int T = ws_.T;
  ws_.policy.u_bar = initial_controls.cwiseMax(ws_.lower.replicate(1, T)).cwiseMin(ws_.upper.replicate(1, T));
  ws_.policy.x_bar.setZero();
  return forward(0.0, ws_.x_new, ws_.u_new);
}

DdpResult Engine::diverged_result(double merit, Clock::time_point start) const {
  const auto& w = ws_;
  DdpResult result;
  DdpSummary& summary = result.summary;
  summary.termination = DdpTermination::InitialRolloutDiverged;
  summary.initial_cost = summary.final_cost = merit;
  summary.timings.total_s = seconds_since(start);
  result.trajectory.x = w.x_new;
  result.trajectory.u = w.u_new;
  result.policy = w.policy;
  result.policy.x_bar = w.x_new;
  result.nominal_cost = result.expected_cost = merit;
  result.value_hessians.assign(static_cast<std::size_t>(w.T) + 1, Matrix::Zero(w.n, w.n));
  result.gradient = Matrix::Zero(w.m, w.T);
  return result;
}

bool Engine::regularised_backward(DdpIteration& record) {
  bool ok = false;
  while (!ok) {
    ok = backward(lambda_);
    if (!ok) {
      ++record.backward_failures;
      increase_lambda();
      if (lambda_ > opt_.lambda_max) break;
    }
  }
  record.lambda = lambda_;
  record.gradient_norm = gradient_norm_;
  return ok;
}

std::optional<DdpTermination> Engine::backward_termination(bool backward_ok) const {
  if (!backward_ok) return DdpTermination::RegularizationLimit;
  if (gradient_norm_ < opt_.gradient_tolerance) return DdpTermination::GradientNorm;
  return std::nullopt;
}

Engine::LineSearchOutcome Engine::line_search(double merit, DdpIteration& record) {
  const double log_first = 0.0, log_last = -3.0;
  LineSearchOutcome outcome{false, merit};
  for (int s = 0; s < opt_.line_search_steps && !outcome.accepted; ++s) {
    const double exponent =
        opt_.line_search_steps == 1 ? log_first
                                    : log_first + (log_last - log_first) * s / (opt_.line_search_steps - 1);
    const double alpha = std::pow(10.0, exponent);
    outcome.merit = forward(alpha, ws_.x_new, ws_.u_new);
    ++record.line_search_trials;
    const double expected = -(alpha * dV1_ + alpha * alpha * dV2_);
    const double actual = merit - outcome.merit;
    if (!std::isfinite(outcome.merit)) continue;
    const double ratio = expected > 0.0 ? actual / expected : (actual > 0.0 ? 1.0 : -1.0);
    if (ratio > opt_.min_reduction_ratio) {
      outcome.accepted = true;
      record.step = alpha;
      record.expected_reduction = expected;
      record.actual_reduction = actual;
    }
  }
  return outcome;
}

std::optional<DdpTermination> Engine::cost_change_termination(double merit, double new_merit,
                                                              double actual_reduction) const {
  if (actual_reduction > opt_.cost_tolerance * std::max(std::abs(merit), 1e-12)) return std::nullopt;
  const bool at_minimum = stationary(gradient_norm_, ws_.policy.u_bar.cwiseAbs().maxCoeff(), new_merit);
  return at_minimum ? DdpTermination::CostChange : DdpTermination::Stalled;
}

std::optional<DdpTermination> Engine::rejection_termination() const {
  if (lambda_ > opt_.lambda_max) return DdpTermination::RegularizationLimit;
  return std::nullopt;
}

std::optional<DdpTermination> Engine::budget_termination(Clock::time_point start, const DdpIteration& last,
                                                         int iteration) const {
  if (seconds_since(start) > opt_.max_seconds) return DdpTermination::WallTime;
  if (opt_.on_iteration && !opt_.on_iteration(last)) return DdpTermination::Cancelled;
  if (iteration == opt_.max_iterations) return DdpTermination::MaxIterations;
  return std::nullopt;
}

bool Engine::final_backward(DdpTimings& timings) {
  timed(timings.derivatives_s, [&] { differentiate(); });
  bool ok = false;
  timed(timings.backward_s, [&] {
    double lambda = 0.0;
    ok = backward(lambda);
    while (!ok && lambda <= opt_.lambda_max) {
      lambda = std::max(lambda * 10.0, opt_.lambda_min);
      ok = backward(lambda);
    }
  });
  return ok;
}

void Engine::open_loop_fallback(double merit, DdpSummary& summary) {
  auto& w = ws_;
  const int T = w.T;
  for (auto& K : w.policy.K) K.setZero();
  for (auto& S : w.S) S.setZero();
  w.gradient.setZero();
  nominal_cost_ = cost_.terminal(w.policy.x_bar.col(T), nullptr, *cost_ws_);
  for (int t = 0; t < T; ++t) nominal_cost_ += cost_.stage(t, w.policy.x_bar.col(t), w.policy.u_bar.col(t), nullptr, *cost_ws_);
  merit_at_nominal_ = std::max(merit, nominal_cost_);
  gradient_norm_ = summary.trace.empty() ? 0.0 : summary.trace.back().gradient_norm;
  summary.final_backward_failed = true;
}

void Engine::finish(double merit, Clock::time_point start, DdpResult& result) {
  DdpSummary& summary = result.summary;
  if (!final_backward(summary.timings)) open_loop_fallback(merit, summary);
  summary.final_gradient_norm = gradient_norm_;
  summary.final_cost = merit_at_nominal_;

  result.trajectory.x = ws_.policy.x_bar;
  result.trajectory.u = ws_.policy.u_bar;
  result.policy = ws_.policy;
  result.policy.k.setZero();
  result.nominal_cost = nominal_cost_;
  result.expected_cost = merit_at_nominal_;
  result.value_hessians = ws_.S;
  result.gradient = ws_.gradient;
  summary.timings.total_s = seconds_since(start);
}

}  // namespace

DdpResult DdpSolver::solve(const DdpProblem& problem, const Matrix& initial_controls) {
  problem.validate();
  if (initial_controls.rows() != problem.model->control_dim() || initial_controls.cols() != problem.horizon)
    throw std::invalid_argument("initial controls are " + std::to_string(initial_controls.rows()) + "x" +
                                std::to_string(initial_controls.cols()) + "; expected " +
                                std::to_string(problem.model->control_dim()) + "x" +
                                std::to_string(problem.horizon) + " (m x T)");
  if (!initial_controls.allFinite()) throw std::invalid_argument("initial controls contain non-finite values");
  Engine engine(problem, options_, *ws_);
  return engine.run(initial_controls);
}

}  // namespace gpilqg
