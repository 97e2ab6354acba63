#pragma once
/// @file noise.hpp
/// Diffusion columns of the stochastic dynamics (paper eq. 1, dx = f dt + F dw) and their derivatives.
///
/// A set of p columns c_i(x, u) in R^n enters the discrete step as sum_i c_i xi_i sqrt(dt) with
/// xi ~ N(0, I_p). The derivatives of each column, dc_i/dx (n x n) and dc_i/du (n x m), are what the
/// paper's appendix calls F^(i)_x and F^(i)_u, used by iLQG and Robust-iLQG in the Q-expansion.

#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// The columns F = [c_1 ... c_p] (n x p) and, when requested, the derivative of every column.
/// Storage is reused across calls: resize() only reallocates when a dimension changes.
struct DiffusionColumns {
  Matrix columns;              ///< n x p: column i is c_i(x, u)
  std::vector<Matrix> d_dx;    ///< p entries, each n x n: d c_i / d x
  std::vector<Matrix> d_du;    ///< p entries, each n x m: d c_i / d u

  /// Sizes the buffers for n states, m controls and p columns; zero-fills everything.
  void resize(int n, int m, int p);
  int count() const { return static_cast<int>(columns.cols()); }
};

/// Noise that enters through the actuators and, optionally, directly on the states:
///
///   F(x, u) = [ sigma_a,j b_j(x, u) | sigma_m,j u_j b_j(x, u) | sigma_x,i e_i ]
///
/// with b_j = df/du_j the j-th input direction of the dynamics. The first block is additive force
/// noise, the second multiplicative (control-dependent) noise as in Todorov and Li (2005), the third
/// additive process noise on state i. Only the entries with a nonzero standard deviation produce a
/// column, so p = (#nonzero sigma_a) + (#nonzero sigma_m) + (#nonzero sigma_x).
struct ActuatorNoise {
  Vector additive_std;        ///< m entries (or empty = none) [units of u per sqrt(s)]
  Vector multiplicative_std;  ///< m entries (or empty = none) [1 / sqrt(s)]
  Vector state_std;           ///< n entries (or empty = none) [units of x per s / sqrt(s)]

  /// Number of columns this noise produces.
  int column_count() const;
  /// Throws std::invalid_argument naming the field when a size does not match (n, m) or a
  /// standard deviation is negative or non-finite.
  void validate(int n, int m) const;
};

}  // namespace gpilqg
