#include "gpilqg/gp/training_set.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg::gp {

void refuse_known_noise(const TrainingSet& data, std::string_view backend) {
  if (data.noise_variance.size() > 0)
    throw std::invalid_argument(fmt::format("backend '{}' does not take a known noise variance per point; expected "
                                            "a backend that does ({}), or no known noise variances",
                                            backend, fmt::join(backends_taking_known_noise(), ", ")));
}

TrainingSet TrainingSet::subset(const std::vector<int>& indices) const {
  TrainingSet out;
  out.inputs.resize(static_cast<Eigen::Index>(indices.size()), inputs.cols());
  out.targets.resize(static_cast<Eigen::Index>(indices.size()));
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const int i = indices[k];
    if (i < 0 || i >= size())
      throw std::invalid_argument("TrainingSet::subset: index " + std::to_string(i) + " outside [0, " +
                                  std::to_string(size()) + ")");
    out.inputs.row(static_cast<Eigen::Index>(k)) = inputs.row(i);
    out.targets(static_cast<Eigen::Index>(k)) = targets(i);
  }
  if (noise_variance.size() > 0) {
    out.noise_variance.resize(static_cast<Eigen::Index>(indices.size()));
    for (std::size_t k = 0; k < indices.size(); ++k) out.noise_variance(static_cast<Eigen::Index>(k)) = noise_variance(indices[k]);
  }
  return out;
}

void validate_training_set(const TrainingSet& data, std::string_view who) {
  const std::string prefix = std::string(who) + ": ";
  if (data.inputs.rows() != data.targets.size())
    throw std::invalid_argument(prefix + "inputs have " + std::to_string(data.inputs.rows()) +
                                " rows but there are " + std::to_string(data.targets.size()) +
                                " targets; expected one target per input row");
  if (data.input_dim() == 0)
    throw std::invalid_argument(prefix + "inputs have no columns; expected at least one input dimension");
  if (data.size() < data.input_dim() || data.size() < 2)
    throw std::invalid_argument(prefix + "only " + std::to_string(data.size()) + " points for " +
                                std::to_string(data.input_dim()) +
                                " input dimensions; expected at least as many points as inputs (and 2)");
  for (Eigen::Index i = 0; i < data.inputs.rows(); ++i)
    for (Eigen::Index j = 0; j < data.inputs.cols(); ++j)
      if (!std::isfinite(data.inputs(i, j))) {
        std::ostringstream os;
        os << prefix << "input row " << i << ", column " << j << " is " << data.inputs(i, j)
           << "; expected finite inputs";
        throw std::invalid_argument(os.str());
      }
  if (data.noise_variance.size() != 0 && data.noise_variance.size() != data.targets.size())
    throw std::invalid_argument(prefix + std::to_string(data.noise_variance.size()) + " known noise variances for " +
                                std::to_string(data.targets.size()) + " targets; expected one per target, or none");
  for (Eigen::Index i = 0; i < data.noise_variance.size(); ++i)
    if (!(std::isfinite(data.noise_variance(i)) && data.noise_variance(i) >= 0.0)) {
      std::ostringstream os;
      os << prefix << "known noise variance " << i << " is " << data.noise_variance(i) << "; expected a finite value >= 0";
      throw std::invalid_argument(os.str());
    }
  for (Eigen::Index i = 0; i < data.targets.size(); ++i)
    if (!std::isfinite(data.targets(i))) {
      std::ostringstream os;
      os << prefix << "target " << i << " is " << data.targets(i) << "; expected finite targets";
      throw std::invalid_argument(os.str());
    }
  const double mean = data.targets.mean();
  const double spread = (data.targets.array() - mean).abs().maxCoeff();
  if (!(spread > 1e-14 * std::max(1.0, std::abs(mean)))) {
    std::ostringstream os;
    os << prefix << "all " << data.size() << " targets equal " << mean
       << "; expected targets that vary (a constant has nothing to regress)";
    throw std::invalid_argument(os.str());
  }
}

std::vector<int> uniform_subsample(int size, int count, std::uint64_t seed) {
  std::vector<int> all(static_cast<std::size_t>(std::max(size, 0)));
  std::iota(all.begin(), all.end(), 0);
  if (count >= size) return all;
  if (count < 0) throw std::invalid_argument("uniform_subsample: negative count " + std::to_string(count));
  std::mt19937_64 rng(seed);
  // Partial Fisher-Yates: the first `count` entries become a uniform sample without replacement.
  for (int k = 0; k < count; ++k) {
    std::uniform_int_distribution<int> pick(k, size - 1);
    std::swap(all[static_cast<std::size_t>(k)], all[static_cast<std::size_t>(pick(rng))]);
  }
  all.resize(static_cast<std::size_t>(count));
  std::sort(all.begin(), all.end());
  return all;
}

}  // namespace gpilqg::gp
