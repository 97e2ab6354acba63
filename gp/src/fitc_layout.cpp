/// The FITC jitter rule's validation and the packed parameter layout (fitc.hpp).

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitc.hpp"

namespace gpilqg::gp {

void FitcJitter::validate() const {
  if (!std::isfinite(value) || value < 0.0)
    throw std::invalid_argument("FitcJitter::value = " + std::to_string(value) +
                                "; expected finite and >= 0");
}

FitcLayout FitcLayout::from_size(int size, int input_dim) {
  const int extras = size - input_dim - 2;
  if (input_dim < 1 || extras < input_dim || extras % input_dim != 0)
    throw std::invalid_argument("FITC parameter vector of " + std::to_string(size) + " entries for " +
                                std::to_string(input_dim) +
                                " inputs; expected D + 2 + M D = " + std::to_string(input_dim + 2) +
                                " + M * " + std::to_string(input_dim) + " with M >= 1");
  return FitcLayout{input_dim, extras / input_dim};
}

Vector FitcLayout::pack(const VectorCRef& hyper, const MatrixCRef& inducing_inputs) const {
  if (hyper.size() != input_dim + 2 || inducing_inputs.rows() != inducing ||
      inducing_inputs.cols() != input_dim)
    throw std::invalid_argument(
        "FitcLayout::pack: expected " + std::to_string(input_dim + 2) + " hyperparameters and " +
        std::to_string(inducing) + " x " + std::to_string(input_dim) + " pseudo-inputs, got " +
        std::to_string(hyper.size()) + " and " + std::to_string(inducing_inputs.rows()) + " x " +
        std::to_string(inducing_inputs.cols()));
  Vector theta(size());
  theta.head(input_dim + 2) = hyper;
  theta.tail(inducing * input_dim) = inducing_inputs.reshaped();
  return theta;
}

Matrix FitcLayout::inducing_inputs(const VectorCRef& theta) const {
  if (theta.size() != size())
    throw std::invalid_argument("FitcLayout: parameter vector has " + std::to_string(theta.size()) +
                                " entries, expected " + std::to_string(size()));
  return theta.tail(inducing * input_dim).reshaped(inducing, input_dim);
}

}  // namespace gpilqg::gp
