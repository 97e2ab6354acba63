/// The conditioned compact GP: the neighbour grid, the sparse factor and alpha; prediction with input
/// gradients through sparse solves over the elimination-tree reach (compact.hpp).

#include <algorithm>
#include <stdexcept>
#include <string>

#include "compact_internal.hpp"
#include "conditioned_gp.hpp"
#include "parallel.hpp"
#include "sparse_factor.hpp"

namespace gpilqg::gp::detail {

namespace {

class CompactFittedGp final : public ConditionedGp {
 public:
  CompactFittedGp(TrainingSet data, const VectorCRef& parameters, const JitterSchedule& jitter,
                  const CompactOptions& options)
      : ConditionedGp(std::move(data), parameters),
        threads_(options.threads),
        kernel_((check_compact_parameters(parameters, data_.input_dim(), "CompactBackend::condition"), parameters),
                data_.input_dim()),
        grid_(data_.inputs, kernel_.inverse_lengthscales()) {
    const int d = data_.input_dim();
    const double noise_variance = std::exp(2.0 * parameters_(d + 1));
    CholmodFactorizer factorizer;
    CompactSystem system;
    build_compact_system(data_.inputs, kernel_, grid_, noise_variance, jitter, options, factorizer, system);
    const auto n = std::to_string(data_.size());
    if (system.outcome.over_budget)
      throw std::runtime_error("CompactBackend::condition: the kernel matrix or its Cholesky factor on " + n +
                               " points would have " + std::to_string(system.outcome.factor_nonzeros) +
                               " nonzeros, more than CompactOptions::max_factor_nonzeros = " +
                               std::to_string(options.max_factor_nonzeros) + " (shorter length-scales or a larger budget)");
    if (system.outcome.status == FactorStatus::Failed)
      throw std::runtime_error("CompactBackend::condition: K is not positive definite even with jitter " +
                               std::to_string(system.outcome.jitter) + " on " + n + " points (CHOLMOD)");
    report_.status = system.outcome.status;
    report_.jitter = system.outcome.jitter;
    report_.negative_log_marginal_likelihood = compact_nlml(system.factor, data_.targets, alpha_);
    factor_ = system.factor.simplicial();
  }

  std::string_view backend_name() const override { return "compact"; }

  /// Workspace use (sizes fixed by N and D, so no allocation after the first query):
  ///   cross   3N + D: k(x_s, z) | g(r_s) | w_s for the support points s = 0 .. |S|-1 | scaled z
  ///   weighted, extra  N each: the sparse solve's forward and backward values (kept zero)
  ///   indices 3N: marks | support (original indices) | reach.
  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int d = input_dim();
    check_query(z, "CompactGp");
    const int n = data_.size();
    PredictionWorkspace& ws = out.workspace;
    if (ws.cross.size() != 3 * n + d) ws.cross.resize(3 * n + d);
    if (ws.weighted.size() != n) ws.weighted.setZero(n);
    if (ws.extra.size() != n) ws.extra.setZero(n);
    if (ws.indices.size() != 3 * static_cast<std::size_t>(n)) ws.indices.assign(3 * static_cast<std::size_t>(n), 0);
    double* k = ws.cross.data();
    double* slope = k + n;
    double* w = k + 2 * static_cast<std::ptrdiff_t>(n);
    int* support = ws.indices.data() + n;
    int count = 0;
    grid_.for_each_neighbour(z, k + 3 * static_cast<std::ptrdiff_t>(n), [&](int i, double r2) {
      support[count] = i;
      k[count] = kernel_.value(r2);
      slope[count] = kernel_.slope(r2);
      ++count;
    });
    out.mean = 0.0;
    for (int s = 0; s < count; ++s) out.mean += k[s] * alpha_(support[s]);
    if (request.gradients) {
      out.mean_gradient.resize(d);
      input_gradient(z, support, slope, count, [&](int s) { return alpha_(support[s]); }, out.mean_gradient);
      out.mean_gradient = -out.mean_gradient;
    }
    if (!request.variance) return;
    const SparseSolveScratch scratch{ws.weighted.data(), ws.extra.data(), ws.indices.data(),
                                     ws.indices.data() + 2 * static_cast<std::ptrdiff_t>(n)};
    const double explained =
        sparse_quadratic_form(factor_, support, k, count, scratch, request.gradients ? w : nullptr);
    out.variance = std::max(kernel_.signal_variance() - explained, 0.0);
    if (request.gradients) {
      out.variance_gradient.resize(d);
      input_gradient(z, support, slope, count, [&](int s) { return w[s]; }, out.variance_gradient);
      out.variance_gradient *= 2.0;
    }
  }

  /// Rows split over CompactOptions::threads, one Prediction (workspace) per worker.
  void predict(const MatrixCRef& points, Vector& mean, Vector& variance) const override {
    if (points.cols() != input_dim())
      throw std::invalid_argument("CompactGp::predict: points have " + std::to_string(points.cols()) +
                                  " columns; expected " + std::to_string(input_dim()));
    const Eigen::Index total = points.rows();
    mean.resize(total);
    variance.resize(total);
    const int max_workers = static_cast<int>(std::min<Eigen::Index>(total / 64 + 1, threads_));
    run_workers(threads_, max_workers, [&](int worker, int workers) {
      Prediction p;
      for (Eigen::Index i = total * worker / workers; i < total * (worker + 1) / workers; ++i) {
        predict(points.row(i).transpose(), p, PredictionRequest{true, false});
        mean(i) = p.mean;
        variance(i) = p.variance;
      }
    });
  }

 private:
  /// out_d = (1/l_d^2) sum_s c_s g(r_s) (z_d - x_sd)  (= -sum_s c_s dk_s/dz_d).
  template <class Coefficient>
  void input_gradient(const VectorCRef& z, const int* support, const double* slope, int count,
                      Coefficient&& coefficient, Vector& out) const {
    out.setZero();
    for (int s = 0; s < count; ++s) {
      const double c = coefficient(s) * slope[s];
      for (int dim = 0; dim < input_dim(); ++dim) out(dim) += c * (z(dim) - data_.inputs(support[s], dim));
    }
    out.array() *= kernel_.inverse_squared_lengthscales().array();
  }

  int threads_;
  WendlandKernel kernel_;
  NeighbourGrid grid_;
  SimplicialFactor factor_;
  Vector alpha_;
};

}  // namespace

std::unique_ptr<FittedGp> make_compact_fitted_gp(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter, const CompactOptions& compact) {
  return std::make_unique<CompactFittedGp>(std::move(data), parameters, jitter, compact);
}

}  // namespace gpilqg::gp::detail
