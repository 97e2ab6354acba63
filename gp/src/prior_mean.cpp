#include "gpilqg/gp/prior_mean.hpp"

#include <stdexcept>

namespace gpilqg::gp {

TrainingSet subtract_prior_mean(const TrainingSet& data, const PriorMean& mean) {
  if (!mean) throw std::invalid_argument("subtract_prior_mean: empty prior mean");
  TrainingSet out = data;
  for (int i = 0; i < data.size(); ++i) out.targets(i) -= mean(data.inputs.row(i).transpose(), nullptr);
  return out;
}

void add_prior_mean(const PriorMean& mean, const VectorCRef& z, Prediction& prediction) {
  if (!mean) throw std::invalid_argument("add_prior_mean: empty prior mean");
  if (prediction.mean_gradient.size() == z.size()) {
    Vector gradient(z.size());
    prediction.mean += mean(z, &gradient);
    prediction.mean_gradient += gradient;
  } else {
    prediction.mean += mean(z, nullptr);
  }
}

}  // namespace gpilqg::gp
