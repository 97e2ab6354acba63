#pragma once
/// @file hyperparameters.hpp
/// The hyperparameters every GP backend shares, in log space, and how they are laid out in a
/// backend's parameter vector.
///
/// Parameter vector of every backend (GPML's order, hyp.cov then hyp.lik):
///
///   theta = [ log l_1 ... log l_D,  log sf,  log sn,  <backend extras> ]
///            `------- D ---------'  index D  index D+1  index D+2 ...
///
/// l_d are the ARD length-scales, sf the signal standard deviation, sn the noise standard deviation.
/// A backend with more parameters appends them after index D+1 (FITC: the pseudo-inputs, M x D
/// column-major; SSGP: the unscaled spectral points W, m x D column-major), so the shared part is
/// always read the same way and a fitter can treat the vector generically.

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/training_set.hpp"

namespace gpilqg::gp {

struct Hyperparameters {
  Vector log_lengthscales;      ///< D entries, log l_d
  double log_signal_std = 0.0;  ///< log sf
  double log_noise_std = 0.0;   ///< log sn

  int input_dim() const { return static_cast<int>(log_lengthscales.size()); }
  Vector lengthscales() const { return log_lengthscales.array().exp(); }
  double signal_variance() const;  ///< sf^2
  double noise_variance() const;   ///< sn^2

  /// Number of shared entries for D inputs: D + 2.
  static int count(int input_dim) { return input_dim + 2; }
  /// Index of log sf and of log sn in the parameter vector.
  static int signal_index(int input_dim) { return input_dim; }
  static int noise_index(int input_dim) { return input_dim + 1; }

  /// [log l; log sf; log sn].
  Vector pack() const;
  /// Reads the first D + 2 entries of a backend's parameter vector. Throws std::invalid_argument when
  /// the vector is shorter or an entry is not finite.
  static Hyperparameters unpack(const VectorCRef& parameters, int input_dim);

  /// The paper's kernel sf^2 exp(-(zi - zj)' Lambda^-1 (zi - zj)) (no 1/2) in GPML's convention:
  /// Lambda_dd = 2 l_d^2, so l_d = sqrt(Lambda_dd / 2) = 1 / sqrt(2 W_dd) with W = Lambda^-1
  /// (kernel.hpp). `lambda_diagonal` holds Lambda_dd > 0.
  static Hyperparameters from_paper(const VectorCRef& lambda_diagonal, double signal_std, double noise_std);
};

/// Box bounds on a parameter vector (both of the parameter vector's size).
struct ParameterBounds {
  Vector lower;
  Vector upper;
};

/// Data-driven starting values for the shared part (used by every backend's objective):
///   l_d = spread of input d (population std over the points; 1 when that is 0),
///   sf  = std of the targets,  sn = 0.1 sf.
Hyperparameters initial_hyperparameters(const TrainingSet& data);

/// The largest length-scale the box allows, in units of the input's spread. An input the targets do
/// not depend on drives its length-scale up without bound (ARD switches it off), and the optimiser
/// runs it to the top of the box. The box must let it get far enough to be off: at 1e6 spreads the
/// kernel's factor for that input is exp(-(dz / l)^2 / 2) >= 1 - 1e-11 over the data, so it no longer
/// changes a prediction (a box of 1e3 spreads left a factor down to 1 - 1e-5 per such input).
inline constexpr double kMaxLengthscaleOverSpread = 1e6;

/// Data-driven box for the shared part, wide enough never to bind on sensible data:
///   log l_d in [log(1e-3 s_d), log(kMaxLengthscaleOverSpread s_d)] (s_d the input spread),
///   log sf  in [log(1e-3 s_y), log(1e3 s_y)]  (s_y the target std),
///   log sn  in [log(max(min_noise_ratio s_y, min_noise_std)), max(that, log(10 s_y))].
/// The lower end of sn is the floor on the noise variance: it bounds the condition number of
/// K = Kff + sn^2 I by about 1 + N sf^2 / sn^2, so that predictions and their gradients keep their
/// digits even on noise-free (simulated) data. `min_noise_std` is an absolute floor in target units.
ParameterBounds hyperparameter_bounds(const TrainingSet& data, double min_noise_std = 1e-9,
                                      double min_noise_ratio = 1e-4);

}  // namespace gpilqg::gp
