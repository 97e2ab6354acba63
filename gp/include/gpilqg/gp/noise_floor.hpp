#pragma once
/// @file noise_floor.hpp
/// The smallest noise a residual GP may fit, from what the sensors and the process noise put into every
/// residual target (ResidualModelOptions::noise_floor).
///
/// A residual target is r = x'_m - phi_sim(x_m, u) (residual_model.hpp), computed from measured states
/// x_m = x + e and x'_m = x' + e' with independent sensor errors e, e' ~ N(0, diag(sigma_o^2)). The
/// world's step is x' = phi_world(x, u) + F xi sqrt(dt) (noise.hpp). To first order in the errors,
///
///   r_i = [phi_world,i(x, u) - phi_sim,i(x, u)]  +  e'_i  -  sum_j A_ij e_j  +  (F xi)_i sqrt(dt),
///
/// with A = d phi_sim / dx at (x_m, u). The bracket is the simulator's error, the GP's latent function;
/// the rest is noise the GP cannot explain, of variance
///
///   v_i(z) = sigma_o,i^2  +  sum_j A_ij(z)^2 sigma_o,j^2  +  dt sum_k F_ik(z)^2.
///
/// The first two terms are the variance of a difference of two measurements (2 sigma_o,i^2 where the
/// step leaves state i nearly unchanged, A ~ I), the third the process noise over one step. The floor
/// is sqrt(min_z v_i(z)) over the training inputs: no measurement can be less noisy than that, so a
/// fitted noise std below it explains sensor noise as signal (an over-fitted, wiggling correction).
/// The process noise is the simulator's own F (the world's is unknown to the learner).

#include "gpilqg/core/step_model.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp {

/// v_i(z) above at every row of `data.inputs`: N x n, row r the variances at z_r (what
/// ResidualData::noise_variance holds when the GPs are given the noise the model already predicts).
/// `observation_std` as below. Throws std::invalid_argument for mismatched sizes or negative /
/// non-finite standard deviations.
Matrix residual_noise_variance(const StepModel& simulator, const ResidualData& data, const VectorCRef& observation_std);

/// sqrt of each column's least value of `noise_variance` (residual_noise_variance): the floor below;
/// zeros for no rows.
Vector least_noise_std(const Matrix& noise_variance);

/// The per-output floor sqrt(min_z v_i(z)) above, one entry per state. `observation_std` has n
/// entries (zeros allowed) or is empty (no sensor noise); the process noise is `simulator.noise` at
/// each row of `data.inputs`. An empty data set gives the floor at no row: zeros. Throws
/// std::invalid_argument for mismatched sizes or negative / non-finite standard deviations.
Vector sensor_noise_floor(const StepModel& simulator, const ResidualData& data, const VectorCRef& observation_std);

}  // namespace gpilqg::gp
