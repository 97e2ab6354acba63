#include "gpilqg/gp/gp_belief_dynamics.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/moment_matching.hpp"
#include "parallel.hpp"

namespace gpilqg::gp {

GpBeliefDynamics::GpBeliefDynamics(int n, int m, double dt, std::shared_ptr<const MomentMatcher> matcher)
    : n_(n), m_(m), dt_(dt), matcher_(std::move(matcher)) {
  if (n < 1 || m < 0) throw std::invalid_argument("GpBeliefDynamics: need n >= 1 and m >= 0");
  if (!std::isfinite(dt) || dt <= 0.0) throw std::invalid_argument("GpBeliefDynamics: dt must be > 0");
  if (!matcher_) throw std::invalid_argument("GpBeliefDynamics: the matcher is null");
  if (matcher_->output_dim() != n || matcher_->input_dim() != n + m)
    throw std::invalid_argument("GpBeliefDynamics: the matcher has " + std::to_string(matcher_->output_dim()) +
                                " outputs over " + std::to_string(matcher_->input_dim()) + " inputs; expected " +
                                std::to_string(n) + " over " + std::to_string(n + m) + " (z = [x; u] -> dx)");
}

void GpBeliefDynamics::set_threads(int threads) {
  if (threads < 1) throw std::invalid_argument("GpBeliefDynamics::set_threads: threads is " + std::to_string(threads) + ", need >= 1");
  threads_ = threads;
}

GpBeliefDynamics GpBeliefDynamics::condition(int n, int m, double dt, const Matrix& inputs, const Matrix& increments,
                                             const std::vector<Vector>& hyperparameters) {
  const int D = n + m;
  if (inputs.cols() != D || increments.cols() != n || increments.rows() != inputs.rows())
    throw std::invalid_argument("GpBeliefDynamics::condition: inputs must be N x (n+m) and increments N x n");
  if (static_cast<int>(hyperparameters.size()) != n)
    throw std::invalid_argument("GpBeliefDynamics::condition: " + std::to_string(hyperparameters.size()) +
                                " hyperparameter vectors; expected one per state (" + std::to_string(n) + ")");
  std::vector<SeArdOutput> outputs;
  for (int a = 0; a < n; ++a) {
    const Vector& h = hyperparameters[static_cast<std::size_t>(a)];
    if (h.size() != D + 2)
      throw std::invalid_argument("GpBeliefDynamics::condition: hyperparameters[" + std::to_string(a) + "] has " +
                                  std::to_string(h.size()) + " entries; expected D + 2 = " + std::to_string(D + 2));
    outputs.push_back(condition_se_ard_output(inputs, increments.col(a), h.head(D), h(D), h(D + 1)));
  }
  return GpBeliefDynamics(n, m, dt, std::make_shared<const SeArdMomentMatcher>(inputs, std::move(outputs)));
}

GpBeliefDynamics GpBeliefDynamics::fit(int n, int m, double dt, const Matrix& inputs, const Matrix& increments,
                                       const GpBackend& backend, const FitOptions& options,
                                       std::vector<FitSummary>* summaries, int threads) {
  require_moment_matching(backend.name(), "GpBeliefDynamics::fit");
  if (threads < 1) throw std::invalid_argument("GpBeliefDynamics::fit: threads is " + std::to_string(threads) + ", need >= 1");
  if (increments.cols() != n || increments.rows() != inputs.rows())
    throw std::invalid_argument("GpBeliefDynamics::fit: increments must be N x n with N = rows of inputs");
  std::vector<std::unique_ptr<FittedGp>> models(static_cast<std::size_t>(n));
  std::vector<FitSummary> fit_summaries(static_cast<std::size_t>(n));
  detail::run_indexed(n, threads, [&](int a) {
    FitResult fitted = backend.fit(TrainingSet{inputs, increments.col(a)}, options);
    models[static_cast<std::size_t>(a)] = std::move(fitted.model);
    fit_summaries[static_cast<std::size_t>(a)] = std::move(fitted.summary);
  });
  std::vector<const FittedGp*> outputs;
  for (const auto& model : models) outputs.push_back(model.get());
  if (summaries) summaries->insert(summaries->end(), fit_summaries.begin(), fit_summaries.end());
  GpBeliefDynamics dynamics(n, m, dt, moment_matcher_for(outputs));
  dynamics.set_threads(threads);
  return dynamics;
}

namespace {

/// The caller's scratch for GpBeliefDynamics::propagate.
struct GpBeliefWorkspace final : BeliefWorkspace {
  Vector mu, mu_z;
  Matrix Sigma, Sigma_z, Sigma_next;
  MomentMatch mm;
};

}  // namespace

std::unique_ptr<BeliefWorkspace> GpBeliefDynamics::make_workspace() const {
  return std::make_unique<GpBeliefWorkspace>();
}

void GpBeliefDynamics::propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next,
                                 BeliefJacobians* jacobians) const {
  const auto workspace = make_workspace();
  propagate(v, u, v_next, jacobians, *workspace);
}

void GpBeliefDynamics::propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next,
                                 BeliefJacobians* jacobians, BeliefWorkspace& workspace) const {
  const int n = n_, m = m_, D = n + m, nb = belief_dim(n);
  if (v.size() != nb || u.size() != m || v_next.size() != nb)
    throw std::invalid_argument("GpBeliefDynamics::propagate: belief has " + std::to_string(v.size()) +
                                " entries, control " + std::to_string(u.size()) + "; expected " +
                                std::to_string(nb) + " and " + std::to_string(m));
  // The caller's buffers: this model is const and shared, and propagate must not allocate per step.
  auto& ws = workspace_as<GpBeliefWorkspace>(workspace);
  Vector &mu = ws.mu, &mu_z = ws.mu_z;
  Matrix &Sigma = ws.Sigma, &Sigma_z = ws.Sigma_z, &Sigma_next = ws.Sigma_next;
  MomentMatch& mm = ws.mm;
  mm.threads = threads_;
  unpack_belief(v, n, mu, Sigma);
  mu_z.resize(D);
  mu_z.head(n) = mu;
  mu_z.tail(m) = u;
  Sigma_z.setZero(D, D);
  Sigma_z.topLeftCorner(n, n) = Sigma;
  matcher_->propagate(mu_z, Sigma_z, mm, jacobians ? MomentDerivatives::All : MomentDerivatives::None);

  const Matrix& C = mm.cross_covariance;  // D x n
  Sigma_next = Sigma + mm.covariance;
  Sigma_next += C.topRows(n) + C.topRows(n).transpose();
  pack_belief(mu + mm.mean, Sigma_next, v_next);
  if (!jacobians) return;

  // d/dtheta of the outputs for theta in (mu_k, u_k, packed Sigma_ij):
  //   mu'_a          = mu_a + M_a
  //   Sigma'_ab      = Sigma_ab + S_ab + C_ab + C_ba
  jacobians->dv.setZero(nb, nb);
  jacobians->du.setZero(nb, m);
  // A column of derivatives with respect to one input coordinate, written into `column` (nb).
  auto fill = [&](auto dM, auto dS, auto dC, auto column) {
    for (int a = 0; a < n; ++a) column(a) += dM(a);
    for (int b = 0; b < n; ++b)
      for (int a = b; a < n; ++a) column(n + vech_index(n, a, b)) += dS(a + n * b) + dC(a + D * b) + dC(b + D * a);
  };
  for (int k = 0; k < D; ++k) {
    auto column = k < n ? jacobians->dv.col(k) : jacobians->du.col(k - n);
    fill(mm.dmean_dmu.col(k), mm.dcovariance_dmu.col(k), mm.dcross_dmu.col(k), column);
    if (k < n) column(k) += 1.0;  // mu' = mu + M
  }
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      auto column = jacobians->dv.col(n + vech_index(n, i, j));
      // A packed entry moves Sigma_ij and Sigma_ji together.
      fill(mm.dmean_dsigma.col(i + D * j), mm.dcovariance_dsigma.col(i + D * j), mm.dcross_dsigma.col(i + D * j), column);
      if (i != j)
        fill(mm.dmean_dsigma.col(j + D * i), mm.dcovariance_dsigma.col(j + D * i), mm.dcross_dsigma.col(j + D * i), column);
      column(n + vech_index(n, i, j)) += 1.0;  // Sigma' = Sigma + ...
    }
}

}  // namespace gpilqg::gp
