/// The packed SSGP parameter layout (ssgp.hpp).

#include <stdexcept>
#include <string>

#include "gpilqg/gp/ssgp.hpp"

namespace gpilqg::gp {

Vector SsgpLayout::pack(const VectorCRef& hyper, const MatrixCRef& spectral_points) const {
  if (hyper.size() != input_dim + 2 || spectral_points.rows() != frequencies ||
      spectral_points.cols() != input_dim)
    throw std::invalid_argument(
        "SsgpLayout::pack: expected " + std::to_string(input_dim + 2) + " hyperparameters and " +
        std::to_string(frequencies) + " x " + std::to_string(input_dim) + " spectral points, got " +
        std::to_string(hyper.size()) + " and " + std::to_string(spectral_points.rows()) + " x " +
        std::to_string(spectral_points.cols()));
  Vector theta(size());
  theta.head(input_dim + 2) = hyper;
  theta.tail(frequencies * input_dim) = spectral_points.reshaped();
  return theta;
}

Matrix SsgpLayout::spectral_points(const VectorCRef& theta) const {
  if (theta.size() != size())
    throw std::invalid_argument("SsgpLayout: parameter vector has " + std::to_string(theta.size()) +
                                " entries, expected " + std::to_string(size()));
  return theta.tail(frequencies * input_dim).reshaped(frequencies, input_dim);
}

SsgpLayout SsgpLayout::from_size(int size, int input_dim) {
  const int extras = size - input_dim - 2;
  if (input_dim < 1 || extras < input_dim || extras % input_dim != 0)
    throw std::invalid_argument("SSGP parameter vector of " + std::to_string(size) + " entries for " +
                                std::to_string(input_dim) +
                                " inputs; expected D + 2 + m D = " + std::to_string(input_dim + 2) +
                                " + m * " + std::to_string(input_dim) + " with m >= 1");
  return SsgpLayout{input_dim, extras / input_dim};
}

}  // namespace gpilqg::gp
