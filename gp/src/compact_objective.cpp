/// The compact backend's negative log marginal likelihood and its exact gradient from the sparse
/// inverse subset (compact.hpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "compact_internal.hpp"

namespace gpilqg::gp::detail {

namespace {

class CompactObjective final : public MarginalLikelihoodObjective {
 public:
  CompactObjective(TrainingSet data, const FitOptions& options, const CompactOptions& compact)
      : data_(std::move(data)),
        compact_(compact),
        min_noise_std_(options.min_noise_std),
        min_noise_ratio_(options.min_noise_ratio),
        jitter_(options.jitter) {
    // initial_hyperparameters with the spreads scaled by support_scale_for_neighbours, so that a point
    // starts with about CompactOptions::initial_neighbours neighbours; the box lets each l_d grow by
    // max_neighbours / initial_neighbours.
    const int d = data_.input_dim();
    Hyperparameters h = initial_hyperparameters(data_);
    const double c = support_scale_for_neighbours(data_.inputs, h.lengthscales(), compact_.initial_neighbours);
    h.log_lengthscales.array() += std::log(c);
    bounds_ = hyperparameter_bounds(data_, min_noise_std_, min_noise_ratio_);
    const double growth = std::log(static_cast<double>(compact_.max_neighbours) / compact_.initial_neighbours);
    bounds_.upper.head(d) = bounds_.upper.head(d).cwiseMin((h.log_lengthscales.array() + growth).matrix());
    bounds_.lower.head(d) = bounds_.lower.head(d).cwiseMin(bounds_.upper.head(d));
    start_ = h.pack().cwiseMax(bounds_.lower).cwiseMin(bounds_.upper);
  }

  int parameter_count() const override { return Hyperparameters::count(data_.input_dim()); }
  int input_dim() const override { return data_.input_dim(); }
  ParameterBounds bounds() const override { return bounds_; }
  Vector initial_parameters() const override { return start_; }

  /// As the default, but the log length-scale offsets are uniform in +-1.2/sqrt(D): the number of
  /// neighbours scales with prod_d l_d, so independent offsets of +-1.5 would change it by up to
  /// e^(1.5 D) (mostly beyond the budget); with 1.2/sqrt(D) the log of that product has a standard
  /// deviation of about 0.7 whatever D.
  Vector restart_parameters(const VectorCRef& initial, std::mt19937_64& rng) const override {
    const int d = input_dim();
    const ParameterBounds b = bounds();
    Vector theta = initial;
    const double width = 1.2 / std::sqrt(static_cast<double>(d));
    std::uniform_real_distribution<double> lengthscale_offset(-width, width), offset(-1.5, 1.5);
    for (int i = 0; i < d; ++i) theta(i) = std::clamp(initial(i) + lengthscale_offset(rng), b.lower(i), b.upper(i));
    for (int i = d; i < d + 2; ++i) theta(i) = std::clamp(initial(i) + offset(rng), b.lower(i), b.upper(i));
    return theta;
  }

  /// With W = Z - alpha alpha' (Z = K^-1 on the pattern of L) and the 0.5 of GPML eq. 5.9 cancelling
  /// the two symmetric halves of each off-diagonal entry:
  ///   d/d log l_d = sum_{i>j in pattern(Kf)} W_ij g(r_ij) (x_id - x_jd)^2 / l_d^2
  ///   d/d log sf  = sum_ij W_ij Kf_ij,   d/d log sn = sn^2 tr(W).
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient) override {
    const int d = data_.input_dim();
    check_compact_parameters(theta, d, "CompactGp objective");
    const WendlandKernel kernel(theta, d);
    const double noise_variance = std::exp(2.0 * theta(d + 1));
    const NeighbourGrid grid(data_.inputs, kernel.inverse_lengthscales());
    build_compact_system(data_.inputs, kernel, grid, noise_variance, jitter_, compact_, factorizer_, system_);
    NlmlEvaluation result{0.0, system_.outcome.status, system_.outcome.jitter};
    if (system_.outcome.status != FactorStatus::Failed) {
      result.value = compact_nlml(system_.factor, data_.targets, alpha_);
      if (gradient != nullptr) accumulate_gradient(kernel, noise_variance, *gradient);
    }
    const bool finite = std::isfinite(result.value) && (gradient == nullptr || gradient->allFinite());
    if (system_.outcome.status == FactorStatus::Failed || !finite) {
      result.value = std::numeric_limits<double>::infinity();
      result.status = FactorStatus::Failed;
      if (gradient != nullptr) gradient->setZero(parameter_count());
    }
    return result;
  }

 private:
  void accumulate_gradient(const WendlandKernel& kernel, double noise_variance, Vector& gradient) {
    const int d = data_.input_dim();
    const std::vector<double> inverse = system_.factor.inverse_subset();
    gather_inverse_on_pattern(inverse);
    gradient.setZero(parameter_count());
    const LowerPattern& p = system_.pattern;
    const Matrix& x = data_.inputs;
    double sum_weighted_kernel = 0.0, trace_w = 0.0;
    for (int j = 0; j < p.size; ++j) {
      const auto first = static_cast<std::size_t>(p.column_start[static_cast<std::size_t>(j)]);
      const double w_jj = inverse_on_pattern_[first] - alpha_(j) * alpha_(j);
      trace_w += w_jj;
      sum_weighted_kernel += w_jj * kernel.signal_variance();
      for (auto q = first + 1; q < static_cast<std::size_t>(p.column_start[static_cast<std::size_t>(j) + 1]); ++q) {
        const int i = p.row[q];
        const double w = inverse_on_pattern_[q] - alpha_(i) * alpha_(j);
        sum_weighted_kernel += 2.0 * w * system_.values[q];
        double r2 = 0.0;
        for (int dim = 0; dim < d; ++dim) {
          const double delta = x(i, dim) - x(j, dim);
          squared_delta_(dim) = delta * delta;
          r2 += squared_delta_(dim) * kernel.inverse_squared_lengthscales()(dim);
        }
        gradient.head(d) += (w * kernel.slope(r2)) * squared_delta_;
      }
    }
    gradient.head(d).array() *= kernel.inverse_squared_lengthscales().array();
    gradient(d) = sum_weighted_kernel;
    gradient(d + 1) = noise_variance * trace_w;
  }

  /// inverse_on_pattern_[q] = Z at the q-th entry of Kf's lower pattern: entry (i, j) sits at
  /// (max, min) of (P i, P j) in L's permuted pattern. Grouped by permuted column (a counting sort),
  /// then one scatter of each supernode's rows: O(nnz(L) + nnz(Kf)).
  void gather_inverse_on_pattern(const std::vector<double>& inverse) {
    const LowerPattern& p = system_.pattern;
    const SupernodalFactor& f = system_.factor;
    const auto n = static_cast<std::size_t>(p.size);
    const std::size_t nnz = p.row.size();
    bucket_start_.assign(n + 1, 0);
    auto permuted = [&](std::size_t q, std::size_t column, int& low, int& high) {
      const int a = f.inverse_permutation[static_cast<std::size_t>(p.row[q])];
      const int b = f.inverse_permutation[column];
      low = std::min(a, b);
      high = std::max(a, b);
    };
    int low = 0, high = 0;
    for (std::size_t j = 0; j < n; ++j)
      for (auto q = static_cast<std::size_t>(p.column_start[j]); q < static_cast<std::size_t>(p.column_start[j + 1]); ++q) {
        permuted(q, j, low, high);
        ++bucket_start_[static_cast<std::size_t>(low) + 1];
      }
    for (std::size_t c = 0; c < n; ++c) bucket_start_[c + 1] += bucket_start_[c];
    bucket_entry_.resize(nnz);
    bucket_row_.resize(nnz);
    fill_.assign(bucket_start_.begin(), bucket_start_.end() - 1);
    for (std::size_t j = 0; j < n; ++j)
      for (auto q = static_cast<std::size_t>(p.column_start[j]); q < static_cast<std::size_t>(p.column_start[j + 1]); ++q) {
        permuted(q, j, low, high);
        const auto slot = static_cast<std::size_t>(fill_[static_cast<std::size_t>(low)]++);
        bucket_entry_[slot] = static_cast<std::int64_t>(q);
        bucket_row_[slot] = high;
      }
    inverse_on_pattern_.resize(nnz);
    relative_.assign(n, -1);
    auto at = [](int i) { return static_cast<std::size_t>(i); };
    for (int s = 0; s < f.supernodes(); ++s) {
      const int first_row = f.row_start[at(s)], height = f.row_start[at(s + 1)] - first_row;
      for (int r = 0; r < height; ++r) relative_[at(f.rows[at(first_row + r)])] = r;
      for (int column = f.first_column[at(s)]; column < f.first_column[at(s + 1)]; ++column) {
        const std::int64_t offset = f.value_start[at(s)] + static_cast<std::int64_t>(column - f.first_column[at(s)]) * height;
        for (auto e = static_cast<std::size_t>(bucket_start_[at(column)]); e < static_cast<std::size_t>(bucket_start_[at(column) + 1]); ++e) {
          const int r = relative_[at(bucket_row_[e])];
          if (r < 0) throw std::logic_error("compact objective: an entry of K lies outside the pattern of its factor");
          inverse_on_pattern_[static_cast<std::size_t>(bucket_entry_[e])] = inverse[static_cast<std::size_t>(offset + r)];
        }
      }
      for (int r = 0; r < height; ++r) relative_[at(f.rows[at(first_row + r)])] = -1;
    }
  }

  TrainingSet data_;
  CompactOptions compact_;
  double min_noise_std_;
  double min_noise_ratio_;
  JitterSchedule jitter_;
  ParameterBounds bounds_;
  Vector start_;
  CholmodFactorizer factorizer_;
  CompactSystem system_;
  Vector alpha_;
  Vector squared_delta_ = Vector::Zero(data_.input_dim());
  std::vector<std::int64_t> bucket_start_, fill_, bucket_entry_;
  std::vector<int> bucket_row_, relative_;
  std::vector<double> inverse_on_pattern_;
};

}  // namespace

std::unique_ptr<MarginalLikelihoodObjective> make_compact_objective(TrainingSet data, const FitOptions& options,
                                                                    const CompactOptions& compact) {
  return std::make_unique<CompactObjective>(std::move(data), options, compact);
}

}  // namespace gpilqg::gp::detail
