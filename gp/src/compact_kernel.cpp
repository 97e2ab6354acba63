#include "compact_kernel.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace gpilqg::gp::detail {

WendlandKernel::WendlandKernel(const VectorCRef& parameters, int input_dim) {
  const Hyperparameters h = Hyperparameters::unpack(parameters, input_dim);
  inverse_lengthscales_ = (-h.log_lengthscales.array()).exp().matrix();
  inverse_squared_lengthscales_ = inverse_lengthscales_.array().square().matrix();
  signal_variance_ = h.signal_variance();
  exponent_ = input_dim / 2 + 2;
}

double support_scale_for_neighbours(const Matrix& inputs, const Vector& spreads, int neighbours) {
  const Eigen::Index n = inputs.rows();
  if (n < 2) return 1.0;
  const Eigen::Index k = std::clamp<Eigen::Index>(neighbours, 1, n - 1);
  const Eigen::Index samples = std::min<Eigen::Index>(n, 512);
  const Matrix scaled = inputs * spreads.cwiseInverse().asDiagonal();
  std::vector<double> distances(static_cast<std::size_t>(n - 1));
  std::vector<double> radii;
  radii.reserve(static_cast<std::size_t>(samples));
  for (Eigen::Index s = 0; s < samples; ++s) {
    const Eigen::Index i = s * n / samples;
    std::size_t m = 0;
    for (Eigen::Index other = 0; other < n; ++other)
      if (other != i) distances[m++] = (scaled.row(other) - scaled.row(i)).squaredNorm();
    std::nth_element(distances.begin(), distances.begin() + (k - 1), distances.end());
    radii.push_back(std::sqrt(distances[static_cast<std::size_t>(k - 1)]));
  }
  std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2), radii.end());
  const double median = radii[radii.size() / 2];
  // Just beyond the k-th neighbour, so that it lies inside the support; 1 for degenerate inputs.
  return median > 0.0 && std::isfinite(median) ? 1.01 * median : 1.0;
}

}  // namespace gpilqg::gp::detail
