#pragma once
/// @file criterion.hpp
/// The error the candidate effects are fitted to and scored on, as one object that every step of the
/// diagnosis takes: the fits (effect_fit.hpp), the ranking, the subset search, the verdict and its
/// remainder test, and the report. Three criteria, each the practice of a field of system
/// identification (fit_criterion.hpp names them):
///
///  - one-step (equation error, one_step.hpp): e_t = x_{t+1} - phi(x_t, u_t);
///  - simulation (output error, MATLAB's `oe`/`pem`; simulation.hpp): the state simulated from the
///    estimated start of a window of W samples (simulation_error.hpp, initial_state.hpp);
///  - inverse dynamics (IDIM-LS, Gautier; IDIM-IV, Janot et al.; inverse_dynamics.hpp): the
///    generalised force the model is missing, r_t = W_v(x_t)^-1 (qdd_t - f_v(x_t, u_t)) with qdd_t a
///    zero-phase derivative of the measured velocities (generalised_force_residual.hpp).
///
/// A criterion is made once for its data and the model the effects are added to (make_criterion:
/// it may estimate accelerations, windows' starts or instruments there) and is immutable after: a
/// FitContext holds it by shared pointer, and copies of the context share it.

#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/fit_criterion.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

struct FitContext;                // effect_fit.hpp
struct ResidualGp;                // residual_analysis.hpp
struct GpSettings;                // residual_analysis.hpp
class InverseDynamicsCriterion;   // inverse_dynamics.hpp

/// The one-step residual of a model and the GP fitted to it: the flexible model of the remainder
/// test under the criteria whose channels are the states.
struct OneStepGp {
  const Matrix& residual;  ///< N x n, x_next - phi(x, u) of the model
  const ResidualGp& gp;    ///< the GP of `residual`
};

class Criterion {
 public:
  virtual ~Criterion() = default;

  virtual FitCriterion kind() const = 0;
  /// The --criterion name: "one-step", "simulation", "inverse-dynamics" or "inverse-dynamics-iv".
  virtual std::string name() const { return fit_criterion_name(kind()); }
  /// Rows per window: 1, or W of the simulation criterion. A held-out batch of the significance
  /// test holds whole windows (the errors within one are strongly correlated).
  virtual int window() const { return 1; }

  /// The model's predictions of the next state at every row of c.data (N x n), driven by the measured
  /// controls delayed by model.input_delay: one step from the measured state, or from the window's
  /// start under simulation; `diverged` (when not null) counts the predictions that diverged
  /// (replaced by x_t).
  virtual Matrix predictions(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const;
  /// The residual of `model` at every row of c.data (N x c, c the criterion's channels: the states,
  /// or the generalised-force components under inverse dynamics).
  virtual Matrix residual(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const = 0;
  /// sqrt(w_i) r_{t,i} of `model` stacked over `rows` (index k c + i); `finite` (when not null) turns
  /// false when a prediction diverged (replaced by x_t, so every entry stays finite). Throws
  /// std::invalid_argument when the model does not accept the data (inverse dynamics: a singular
  /// force map, a force that is not finite).
  virtual Vector weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                                   bool* finite = nullptr) const = 0;

  /// The channels whose motion a parameter's scale is measured against (EffectFit::scale), and the
  /// model's own change in channel i at row r: its predicted change of the generalised velocities
  /// x_hat_{r+1} - x_r, or its own generalised force under inverse dynamics.
  virtual std::vector<int> scale_channels(const FitContext& c) const;
  virtual double own_change(const FitContext& c, int row, int channel) const;

  /// Candidates this criterion cannot identify on any data (empty: none), and why.
  virtual std::vector<std::string> unidentifiable(const std::vector<LibraryEffect>& candidates) const;
  virtual std::string unidentifiable_reason() const { return {}; }

  /// What the effects are scored on, for the verdict's sentence ("the one-step residual").
  virtual std::string scored_on() const = 0;
  /// Whether the GP of the one-step residual is this criterion's flexible model: its share of the
  /// residual is then comparable with an effect's (one-step only).
  virtual bool scored_like_the_gp() const { return false; }
  /// Whether flexible_share needs the one-step residual's GP of the model (the states' criteria).
  virtual bool needs_one_step_gp() const { return true; }
  /// What a flexible model removes of what `model` leaves on the held-out rows of c.data under this
  /// criterion, weighted with c.weights: 1 - sum_w (r - r_flexible)^2 / sum_w r^2. `gp` is `model`'s
  /// one-step GP when needs_one_step_gp(); `settings` fit any GP of the criterion's own residual.
  virtual double flexible_share(const ModelSpec& model, const OneStepGp* gp, const FitContext& c,
                                const GpSettings& settings) const = 0;

  /// Where each prediction starts: "measured" (the measured state), "estimated" (simulation from its
  /// windows' estimated starts); empty under inverse dynamics, which predicts no state.
  virtual std::string starts() const { return "measured"; }
  /// The lines of the report's section 3 saying what the residual is (empty: nothing to add).
  virtual std::string description(double /*dt*/, int /*restarts*/) const { return {}; }

  /// Inverse dynamics: this criterion; null for the others (the closed forms of
  /// affine_force_residual.hpp and the instruments hold on its residual only).
  virtual const InverseDynamicsCriterion* inverse_dynamics() const { return nullptr; }
};

/// The one-step criterion, shared (a FitContext's default).
std::shared_ptr<const Criterion> one_step_criterion();

/// 1 - sum_w (r - correction)^2 / sum_w r^2 over the held-out rows of `data` (0 when r is 0).
double weighted_heldout_explained(const Transitions& data, const Matrix& residual, const Matrix& correction,
                                  const Vector& weights);

}  // namespace gpilqg::diagnosis
