#pragma once
/// @file free_run.hpp
/// Free-run simulation (k = infinity) of whole episodes, the simulation fit of MATLAB's `compare`:
/// start from the measured initial state x_0 of the episode and roll the model over the whole episode
/// with the applied controls, never resetting to a measured state,
///
///   x^_0 = x_0,   x^_{t+1} = phi(x^_t, u^_t),   t = 0 .. T - 2,
///
/// where u^ = controls(u), u the episode's measured controls (T x m). The fit of state i,
///
///   fit_i = 100 (1 - |y - y^| / |y - mean(y)|)       (fit_percent, residual_analysis.hpp),
///
/// runs over the predicted samples t = 1 .. T - 1 (x_0 is given, not predicted): 100 is a perfect
/// simulation, 0 no better than the measured mean, and it is negative when the simulation drifts
/// further than that.
///
/// Divergence. When a predicted state diverges (prediction_diverged: not finite or beyond 1e12), the
/// simulation of that episode stops there: `diverged` is true, `steps` counts the predictions before
/// it, `predicted` holds x^_0 .. x^_steps only, and the fit runs over t = 1 .. steps (0 when steps is
/// 0). So every number is finite, and a diverged fit is always reported with its flag: it scores the
/// part of the episode the model survived, and it is not comparable with a fit over the whole episode.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg::diagnosis {

/// Where the controls a free run applies come from: the episode's measured controls (T x m) in, the
/// applied controls (T x m, row t applied from sample t to t + 1) out. This is the one place a
/// model's input path (an input delay, say) enters the simulation.
using ControlSource = std::function<Matrix(const MatrixCRef& measured)>;

/// The measured controls as they are (the default ControlSource).
Matrix measured_controls(const MatrixCRef& measured);

/// One model to simulate: its name in the report ("sim", "sim+effect", "sim+GP"), its step
/// x' = phi(x, u) (a gp::ResidualModel for sim + GP mean) and its control source.
struct FreeRunModel {
  std::string name;
  std::shared_ptr<const StepModel> step;
  ControlSource controls = measured_controls;
};

/// One model's simulation of one episode.
struct FreeRunTrajectory {
  std::string model;
  Matrix predicted;       ///< (steps + 1) x n: x^_0 (= x_0) .. x^_steps
  int steps = 0;          ///< predictions made: T - 1, or fewer when diverged
  bool diverged = false;
  Vector fit_percent;     ///< n, over t = 1 .. steps
};

/// The free runs of one episode.
struct FreeRunEpisode {
  int index = 0;          ///< index in MeasurementSet::episodes
  long id = 0;            ///< Episode::id
  Vector t;               ///< T sample times
  Matrix measured;        ///< T x n
  std::vector<FreeRunTrajectory> models;  ///< in the order of the models given
};

/// Simulates one model over one episode (length >= 1). Throws std::invalid_argument when the control
/// source returns a matrix of another shape than the measured controls, or the model's dimensions
/// differ from the episode's.
FreeRunTrajectory free_run(const FreeRunModel& model, const Episode& episode);

/// Every model over each of `episodes` (indices into set.episodes); episodes shorter than 2 samples
/// are left out (nothing to predict).
std::vector<FreeRunEpisode> free_run(const MeasurementSet& set, const std::vector<int>& episodes,
                                     const std::vector<FreeRunModel>& models);

}  // namespace gpilqg::diagnosis
