#include "gpilqg/gp/fit.hpp"

#include "gpilqg/gp/hyperparameters.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <nlopt.hpp>

namespace gpilqg::gp {

namespace {

/// The bridge between NLopt and an objective: counts evaluations, remembers the best point seen and
/// shields NLopt from failed evaluations (see fit.hpp).
struct ObjectiveBridge {
  MarginalLikelihoodObjective* objective = nullptr;
  Vector theta;     // reused buffers
  Vector gradient;
  int evaluations = 0;
  int jittered = 0;
  int failed = 0;
  double max_jitter = 0.0;
  double best_value = std::numeric_limits<double>::infinity();
  Vector best_theta;
  // The last evaluation with a gradient: the fitter evaluates each start before NLopt does, and
  // NLopt's first request at that point is answered from here instead of evaluating it twice.
  std::vector<double> last_x;
  std::vector<double> last_gradient;
  double last_value = 0.0;

  /// The nlml at x (the failure value of fit.hpp for a failed evaluation) and, when `grad` is not
  /// empty, its gradient.
  double operator()(const std::vector<double>& x, std::vector<double>& grad) {
    if (!grad.empty() && x == last_x) {
      grad = last_gradient;
      return last_value;
    }
    const double value = evaluate(x, grad);
    if (!grad.empty()) {
      last_x = x;
      last_gradient = grad;
      last_value = value;
    }
    return value;
  }

  /// NLopt's objective: its variables z are the parameters in units of `step` (first_step_unit).
  static double call(const std::vector<double>& z, std::vector<double>& grad, void* self) {
    ObjectiveBridge& bridge = *static_cast<ObjectiveBridge*>(self);
    bridge.parameters.resize(z.size());
    for (std::size_t i = 0; i < z.size(); ++i) bridge.parameters[i] = bridge.step * z[i];
    const double value = bridge(bridge.parameters, grad);
    for (double& g : grad) g *= bridge.step;
    return value;
  }
  double step = 1.0;
  std::vector<double> parameters;  // reused buffer of call

 private:
  double evaluate(const std::vector<double>& x, std::vector<double>& grad) {
    theta = Eigen::Map<const Vector>(x.data(), static_cast<Eigen::Index>(x.size()));
    const NlmlEvaluation e = objective->evaluate(theta, grad.empty() ? nullptr : &gradient);
    ++evaluations;
    if (e.status == FactorStatus::JitterAdded) ++jittered;
    max_jitter = std::max(max_jitter, e.jitter);
    if (e.status == FactorStatus::Failed || !std::isfinite(e.value)) {
      ++failed;
      std::fill(grad.begin(), grad.end(), 0.0);
      const double reference = std::isfinite(best_value) ? std::abs(best_value) : 1.0;
      return 1e10 * (1.0 + reference);
    }
    if (!grad.empty()) std::copy(gradient.data(), gradient.data() + gradient.size(), grad.begin());
    if (e.value < best_value) {
      best_value = e.value;
      best_theta = theta;
    }
    return e.value;
  }
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<double> to_std(const Vector& v) { return {v.data(), v.data() + v.size()}; }

/// The unit of NLopt's variables for a start whose gradient there is g0: the power of two nearest to
/// 1 / sqrt(max(1, |g0|_inf)). L-BFGS's first iteration is a steepest-descent step whose first trial
/// is the unit step in the optimiser's variables, -step g0 in its variables, i.e. -step^2 g0 in the
/// parameters: with this unit no parameter moves by more than about 1 (a factor of e in a
/// log-parametrised quantity), instead of by |g0|_inf, which grows with N (the nlml is a sum over the
/// data) and sends the first trial far outside the region the line search then backtracks into.
/// Later steps use the curvature L-BFGS has measured. A power of two keeps parameters = step x
/// variables exact, and xtol_rel and ftol_rel are relative, so the stopping rules do not change.
double first_step_unit(const std::vector<double>& g0) {
  double largest = 1.0;
  for (const double g : g0) largest = std::max(largest, std::abs(g));
  return std::isfinite(largest) ? std::exp2(-std::round(0.5 * std::log2(largest))) : 1.0;
}

std::vector<double> in_units(const Vector& v, double step) { return to_std(v / step); }

Vector clip(const Vector& theta, const ParameterBounds& b) {
  return theta.cwiseMax(b.lower).cwiseMin(b.upper);
}

}  // namespace

ParameterFit fit_parameters(MarginalLikelihoodObjective& objective, const FitOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  options.validate();
  const int p = objective.parameter_count();
  const int shared = Hyperparameters::count(objective.input_dim());
  if (options.warm_start.size() != 0 && options.warm_start.size() != p && options.warm_start.size() < shared)
    throw std::invalid_argument("fit_parameters: warm start has " + std::to_string(options.warm_start.size()) +
                                " entries; expected the backend's " + std::to_string(p) + " parameters, or at least the " +
                                std::to_string(shared) + " shared hyperparameters");
  const ParameterBounds bounds = objective.bounds();

  std::vector<Vector> starts;
  const Vector initial = clip(objective.initial_parameters(), bounds);
  if (options.warm_start.size() == p) {
    starts.push_back(clip(options.warm_start, bounds));
  } else if (options.warm_start.size() != 0) {
    // A previous fit with another number of backend-specific parameters (FITC's pseudo-inputs when
    // it had fewer points than inducing inputs): its kernel hyperparameters, this data's extras.
    Vector start = initial;
    start.head(shared) = options.warm_start.head(shared);
    starts.push_back(clip(start, bounds));
  }
  starts.push_back(initial);
  if (options.optimise) {
    std::mt19937_64 rng(options.seed);
    for (int r = 0; r < options.restarts; ++r) starts.push_back(clip(objective.restart_parameters(initial, rng), bounds));
  }

  ObjectiveBridge bridge;
  bridge.objective = &objective;
  ParameterFit out;
  FitSummary& s = out.summary;
  s.parameters = p;

  // With optimisation, with its gradient: NLopt's first evaluation of the first start is this one.
  std::vector<double> first_gradient(options.optimise ? static_cast<std::size_t>(p) : 0);
  s.initial_nlml = bridge(to_std(starts.front()), first_gradient);
  if (!options.optimise) {
    out.parameters = starts.front();
    s.starts = 1;
    s.termination = FitTermination::NotOptimised;
  } else {
    double best_of_starts = std::numeric_limits<double>::infinity();
    bool any_start_worked = false;
    bool out_of_time = false;
    std::size_t begun = 0;
    for (std::size_t k = 0; k < starts.size(); ++k) {
      if (options.max_seconds > 0.0 && seconds_since(start_time) >= options.max_seconds) {
        out_of_time = true;  // no start begins once the time is used up
        break;
      }
      ++begun;
      // The start's gradient (NLopt's first evaluation, served from the bridge) sets its unit.
      std::vector<double> gradient_at_start = first_gradient;
      if (k > 0) bridge(to_std(starts[k]), gradient_at_start);
      bridge.step = first_step_unit(gradient_at_start);
      nlopt::opt opt(nlopt::LD_LBFGS, static_cast<unsigned>(p));
      opt.set_lower_bounds(in_units(bounds.lower, bridge.step));
      opt.set_upper_bounds(in_units(bounds.upper, bridge.step));
      opt.set_min_objective(&ObjectiveBridge::call, &bridge);
      opt.set_maxeval(options.max_evaluations);
      opt.set_ftol_rel(options.relative_tolerance);
      opt.set_xtol_rel(options.parameter_tolerance);
      if (options.max_seconds > 0.0)  // the time left after the start's evaluation (for NLopt 0 is no limit)
        opt.set_maxtime(std::max(options.max_seconds - seconds_since(start_time), 1e-9));
      std::vector<double> x = in_units(starts[k], bridge.step);
      double value = 0.0;
      FitTermination termination = FitTermination::Converged;
      bool worked = true;
      try {
        const nlopt::result r = opt.optimize(x, value);
        if (r == nlopt::MAXEVAL_REACHED) termination = FitTermination::MaxEvaluations;
        if (r == nlopt::MAXTIME_REACHED) {
          termination = FitTermination::TimeLimit;
          out_of_time = true;
        }
      } catch (const nlopt::roundoff_limited&) {
        // L-BFGS stops this way when it cannot improve further at the working precision, typically
        // at the optimum; the best point seen is kept.
      } catch (const std::exception&) {
        worked = false;
      }
      any_start_worked = any_start_worked || worked;
      // The best point of this start is the best seen so far if it improved on the earlier starts.
      if (bridge.best_value < best_of_starts) {
        best_of_starts = bridge.best_value;
        s.best_start = static_cast<int>(k);
        s.termination = worked ? termination : FitTermination::OptimiserError;
      }
    }
    s.starts = static_cast<int>(begun);
    if (!any_start_worked) s.termination = FitTermination::OptimiserError;
    if (out_of_time) s.termination = FitTermination::TimeLimit;
    out.parameters = bridge.best_theta.size() == p ? bridge.best_theta : starts.front();
  }
  s.nlml = std::isfinite(bridge.best_value) ? bridge.best_value : s.initial_nlml;
  s.evaluations = bridge.evaluations;
  s.jittered_evaluations = bridge.jittered;
  s.failed_evaluations = bridge.failed;
  s.max_jitter = bridge.max_jitter;
  s.seconds = seconds_since(start_time);
  return out;
}

}  // namespace gpilqg::gp
