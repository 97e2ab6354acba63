#pragma once
/// @file model_slice.hpp
/// The paper's Figure 1 for a learned model: a 1-D slice through the GP-corrected step, with the
/// simulator it corrects, the real world and the measurements near the slice.

#include "gpilqg/core/step_model.hpp"
#include "gpilqg/experiments/transition_data.hpp"

namespace gpilqg {

/// A 1-D picture of the learned model (the paper's Figure 1): one state output of the GP-corrected
/// step against one input z_j, the other inputs held at a measured point z*. With the output's ARD
/// length-scales l as the metric, the slice is chosen so that the picture can be read:
///  - output: the state whose GP has the largest signal variance sf^2;
///  - input j: the most relevant one, the shortest l_j relative to the data's spread in z_j;
///  - z*: the measured input with the most measurements within one length-scale of it in the other
///    inputs, sum_{k != j} ((z_k - z*_k) / l_k)^2 <= 1; those are the measurements drawn;
///  - grid: the data's range in z_j plus kSliceMargin length-scales on each side, where every
///    measurement's covariance with the slice is below sf^2 exp(-kSliceMargin^2 / 2), so the model
///    is back to the simulator with the prior's uncertainty.
/// The measurements are given both as measured (data_y) and as residuals r = x'_output -
/// phi_sim(z)_output at their own inputs (data_residual): the targets the GP was fitted to, which lie
/// around mu along the slice because the other inputs are within one length-scale of z*.
struct ModelSlice {
  int output = 0, input = 0;
  Vector base;          ///< the measured point z* the slice goes through
  Vector length_scales; ///< the output's ARD length-scales l (n + m), the metric of the choices above
  Vector grid;          ///< values of z_input
  Vector simulator;     ///< phi_sim(z)_output: the simulator's next state (the GP's mean function)
  Vector mean;          ///< phi_sim + mu: the corrected model
  Vector std;           ///< sqrt(var): the GP's latent standard deviation
  Vector truth;         ///< the real world's mean next state
  Vector data_z, data_y;  ///< measurements within one length-scale of the slice: z_input and x'_output
  Vector data_residual;   ///< their x'_output - phi_sim(z)_output, at each measurement's own z
};

/// Length-scales beyond the data on each side of a ModelSlice's grid.
inline constexpr double kSliceMargin = 4.0;

/// The model's slice (ModelSlice) through the measured inputs of `data`. Throws std::invalid_argument
/// when `model` is not a gp::ResidualModel or `data` is empty or of other dimensions than the model.
ModelSlice model_slice(const StepModel& world, const StepModel& model, const TransitionData& data);

}  // namespace gpilqg
