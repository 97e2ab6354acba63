#pragma once
/// @file mujoco_model_numbers.hpp
/// The check of every number of a compiled MuJoCo model. MuJoCo 2.2 reads a NaN or an infinity in a
/// model file (MJCF or URDF) with a warning only ("XML contains a 'NaN'"), and takes a negative joint
/// damping, armature or friction loss without a word; a simulation of such a model runs and writes
/// garbage with exit 0 (a NaN joint axis made an arm spin at 30 rad/s in 0.02 s). Refused at load, naming
/// the element: every real number of the model (mjModel's arrays and mjOption's) must be finite, and a
/// joint's damping, armature and friction loss must be >= 0 (MuJoCo itself refuses a limited joint
/// whose range does not increase).

#include <optional>
#include <string>

#include <mujoco/mujoco.h>

namespace gpilqg {

/// The first number of `m` that breaks the rules above, as "<what>; expected <what>", e.g. "joint
/// 'shoulder': jnt_axis is (nan, 1, 0); expected finite numbers (MuJoCo reads a NaN or an infinity in
/// the file with a warning only)"; nothing when every number holds.
std::optional<std::string> model_number_problem(const mjModel* m);

/// Copies every real number of `from` into `to` where both models have the array at the same size (the
/// bodies, joints, degrees of freedom, geoms, ... of one model compiled twice), then recomputes `to`'s
/// constants at qpos0 (mj_setConst). A URDF reaches gpilqg through MuJoCo's MJCF writer, which keeps 6
/// significant digits (a mass of 1.23456789 became 1.23457), turns an integral value beyond 2^31 into
/// -2147483648 and drops a NaN axis for the default one; the model compiled from the URDF itself holds
/// the file's numbers, and they are what the converted model (with gpilqg's motors) must simulate.
void copy_real_numbers(const mjModel* from, mjModel* to);

}  // namespace gpilqg
