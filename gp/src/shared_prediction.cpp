#include "shared_prediction.hpp"

#include <atomic>

namespace gpilqg::gp::detail {

namespace {

std::uint64_t next_id() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

}  // namespace

std::shared_ptr<const SharedExactPrediction> SharedExactPrediction::make(
    const std::vector<std::shared_ptr<const FittedGp>>& outputs) {
  std::vector<const ExactPredictor*> predictors;
  for (const auto& output : outputs) {
    const ExactPredictor* p = output ? exact_predictor(*output) : nullptr;
    if (p == nullptr) return nullptr;
    const Matrix& first = predictors.empty() ? p->inputs() : predictors.front()->inputs();
    if (&p->inputs() != &first &&
        (p->inputs().rows() != first.rows() || p->inputs().cols() != first.cols() || p->inputs() != first))
      return nullptr;
    predictors.push_back(p);
  }
  if (predictors.empty()) return nullptr;
  return std::shared_ptr<const SharedExactPrediction>(new SharedExactPrediction(outputs, std::move(predictors)));
}

SharedExactPrediction::SharedExactPrediction(std::vector<std::shared_ptr<const FittedGp>> outputs,
                                             std::vector<const ExactPredictor*> predictors)
    : outputs_(std::move(outputs)), predictors_(std::move(predictors)), id_(next_id()) {}

SharedExactPrediction::Cache& SharedExactPrediction::at(const VectorCRef& z, Cache& cache) const {
  if (cache.id == id_ && cache.z.size() == z.size() && cache.z == z) return cache;
  cache.id = 0;  // invalid until complete (an exception below leaves no stale entry)
  const Matrix& x = predictors_.front()->inputs();
  ExactPredictor::squared_differences(x, z, cache.squared);
  cache.cross.resize(x.rows(), static_cast<Eigen::Index>(predictors_.size()));
  for (std::size_t a = 0; a < predictors_.size(); ++a)
    predictors_[a]->cross(z, &cache.squared, cache.cross.col(static_cast<Eigen::Index>(a)));
  cache.z = z;
  cache.id = id_;
  return cache;
}

template <class Stage>
void SharedExactPrediction::each_output(const VectorCRef& z, Vector& values, Matrix* gradient, Cache& cache,
                                        Stage&& stage) const {
  Cache& c = at(z, cache);
  const auto n = static_cast<Eigen::Index>(predictors_.size());
  values.resize(n);
  if (gradient != nullptr) gradient->resize(n, z.size());
  for (Eigen::Index a = 0; a < n; ++a) {
    values(a) = stage(*predictors_[static_cast<std::size_t>(a)], c, c.cross.col(a), gradient ? &c.gradient : nullptr);
    if (gradient != nullptr) gradient->row(a) = c.gradient.transpose();
  }
}

void SharedExactPrediction::means(const VectorCRef& z, Vector& mean, Matrix* gradient, Cache& cache) const {
  each_output(z, mean, gradient, cache, [&z](const ExactPredictor& p, Cache& c, const auto& k, Vector* g) {
    return p.mean(z, k, g, c.scratch);
  });
}

void SharedExactPrediction::variances(const VectorCRef& z, Vector& variance, Matrix* gradient, Cache& cache) const {
  each_output(z, variance, gradient, cache, [&z](const ExactPredictor& p, Cache& c, const auto& k, Vector* g) {
    return p.variance(z, k, g, c.weighted, c.scratch);
  });
}

}  // namespace gpilqg::gp::detail
