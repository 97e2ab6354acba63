#pragma once
/// @file velocity_scales.hpp
/// Scales of the effect library taken from the data, not from a constant: the smoothing velocity of
/// Coulomb friction, Q = -tau tanh(qdot / v0).
///
/// A slide joint may move at 0.01 m/s and a wheel at 50 rad/s, so no single v0 suits every
/// coordinate: 0.05 m/s turns the friction of the slow slide into a viscous term, and 0.05 rad/s is a
/// sign function at the wheel's speeds. How sharp the switch at qdot = 0 looks in the data depends on
/// the friction itself (a constraint is a true sign function, a lubricated contact is smoother) and
/// on the noise of the measured velocity, which blurs the sign of small velocities. So v0 is fitted:
/// with s the RMS of the coordinate's measured velocity about 0 on the training rows,
///
///   v0 = argmin over f in {0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2} of min_{tau, b} S(tau, b, f s),
///
/// S the weighted training objective of the fit under the criterion (effect_fit.hpp) with the
/// Coulomb friction and a viscous friction b qdot of the same coordinate beside it, both profiled
/// out by linear least squares (each is linear in its level), refined by the vertex of the parabola
/// through the best grid point and its neighbours in log v0. The viscous term is there because v0 is
/// the width of the switch at qdot = 0, not the slope at speed: fitted alone on a joint with viscous
/// and dry friction (as every robot joint has), the Coulomb term takes the top of the grid, a
/// saturating viscous friction, and a search that starts from it no longer sees the two terms
/// (subset_search.hpp screens with these widths until a set fits its own). Its column is the same
/// effect at a width of a thousand times the rms speed, where tanh is linear over the data. The grid
/// spans the data's own scale, two decades below its RMS speed; above 0.2 s the tanh is nearly linear
/// over the data and the term is viscous friction, which the library has. A coordinate whose measured
/// velocity is 0 throughout keeps the library's default (kDefaultCoulombWidth). The value is reported
/// with the effect (`v0 = ...`) and written into model files, so a model keeps the smoothing it was
/// fitted with.

#include <map>
#include <string>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// The grid of v0 / RMS(qdot) (see the file comment).
inline constexpr double kSmoothingGrid[] = {0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2};

/// tau tanh(qdot / V) = (tau / V) qdot to 2e-4 for |qdot| below V / 50: at V a thousand times the rms
/// speed a Coulomb effect is the viscous friction of its coordinate (to 2e-4 up to 20 times the rms
/// speed), from the same machinery under every criterion and for every system.
inline constexpr double kViscousWidth = 1e3;

/// `coulomb` at kViscousWidth times `rms` (the rms speed of its coordinate): the viscous friction of
/// the coordinate, as a force of its own name ("<name> (viscous)", no smoothing), to be fitted beside
/// a Coulomb term and never reported as an effect.
LibraryEffect viscous_twin(const LibraryEffect& coulomb, double rms);

/// The RMS of state `velocity` over the training rows of `data` (0 when there are none).
double training_rms(const Transitions& data, int velocity);

/// context.model with a fitted smoothing velocity (see the file comment) for every Coulomb candidate
/// that the model neither has as a force nor gives a v0 already. Needs the context's data, weights
/// and residual (that of context.model).
ModelSpec with_fitted_smoothing(const FitContext& context);

/// The smoothing velocities of the Coulomb effects of the joint fit `fit` (its effect and those it
/// refitted), fitted again inside the set: for each in turn, the same grid and parabola, the objective
/// being the training objective of the linearised joint fit of the whole set (linearised_fits.hpp)
/// around context.model, with a viscous friction (viscous_twin) beside each Coulomb member, as when
/// it was fitted alone: v0 is the switch's width, not a slope the set leaves to it. A v0 fitted alone
/// is biased by what the other effects do (on a cart with Coulomb friction and a constant force, v0
/// alone came out at 0.6 times its value); the set's v0 is not. The set's columns are computed
/// context.threads at once. Effect name -> v0.
std::map<std::string, double> joint_smoothing(const FitContext& context, const EffectFit& fit);

}  // namespace gpilqg::diagnosis
