#pragma once
/// @file prior_mean.hpp
/// Optional prior-mean handling. Every backend is zero-mean on its targets; a GP with prior mean m(z)
/// (the paper's "simulator as the mean function") is the zero-mean GP on r = y - m(X) plus m:
///
///   E[y(z)] = m(z) + k(z)' K^-1 (y - m(X)),   var unchanged        (paper, section on GP; GPML eq. 2.41)
///
/// The residual model does this with the simulator (vector-valued, one output per state); these
/// helpers do it for a scalar m, e.g. the gp_oracle's m(x) = sum_d sin(x_d).

#include <functional>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

/// m(z), and dm/dz into `gradient` (D entries, already sized) when it is not null.
using PriorMean = std::function<double(const VectorCRef& z, Vector* gradient)>;

/// The same inputs with targets y_i - m(x_i).
TrainingSet subtract_prior_mean(const TrainingSet& data, const PriorMean& mean);

/// Adds m(z) (and dm/dz when the prediction has gradients) to a zero-mean prediction at z.
void add_prior_mean(const PriorMean& mean, const VectorCRef& z, Prediction& prediction);

}  // namespace gpilqg::gp
