// The building blocks of the inverse-dynamics residual: the zero-phase acceleration estimate with its
// window chosen from the data (derivative_window.hpp, accelerations.hpp) and the generalised-force
// residual of a model (generalised_force_residual.hpp). Each is checked against something
// independent: analytic derivatives of polynomials and sinusoids (and the error of every window of
// the grid against the true derivative, to judge the rule's choice), the cart-pole's textbook
// inverse dynamics written out here, MuJoCo's own inverse dynamics (mj_inverse), and the hidden
// friction of a simulated world, written out here.

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>

#include <Eigen/Dense>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/savitzky_golay.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/criteria/criterion_context.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"
#include "gpilqg/experiments/diagnosis/student_t.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

using namespace diagnosis;

/// Transitions of episodes given as sampled states (T x n each) and controls (T x m each), every
/// episode at step dt: the rows x_t -> x_{t+1} of make_transitions.
Transitions transitions_of(const std::vector<Matrix>& states, const std::vector<Matrix>& controls, double dt) {
  Transitions out;
  Eigen::Index rows = 0;
  for (const Matrix& x : states) rows += x.rows() - 1;
  const Eigen::Index n = states.front().cols(), m = controls.front().cols();
  out.x.resize(rows, n);
  out.u.resize(rows, m);
  out.x_next.resize(rows, n);
  out.t.resize(rows);
  Eigen::Index row = 0;
  for (std::size_t e = 0; e < states.size(); ++e) {
    const Eigen::Index steps = states[e].rows() - 1;
    out.x.middleRows(row, steps) = states[e].topRows(steps);
    out.x_next.middleRows(row, steps) = states[e].bottomRows(steps);
    out.u.middleRows(row, steps) = controls[e].topRows(steps);
    for (Eigen::Index s = 0; s < steps; ++s) {
      out.t(row + s) = static_cast<double>(s) * dt;
      out.episode.push_back(static_cast<int>(e));
      out.heldout.push_back(false);
    }
    row += steps;
  }
  return out;
}

/// One state column sampled from `signal` at T samples of step dt, plus white noise of std `noise`.
Matrix sampled(const std::function<double(double)>& signal, int T, double dt, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Matrix x(T, 1);
  for (int i = 0; i < T; ++i) x(i, 0) = signal(i * dt) + noise * gauss(rng);
  return x;
}

// --- The acceleration estimate -------------------------------------------------------------------

TEST(InverseDynamicsAccelerations, ExactForPolynomialsOfTheFilterOrderAtEverySampleIncludingTheEnds) {
  for (const int order : {2, 3}) {
    // v(t) = 0.3 - 1.2 t + 0.7 t^2 (+ 0.9 t^3 for order 3): qdd = -1.2 + 1.4 t (+ 2.7 t^2), two episodes.
    const double cubic = order == 3 ? 0.9 : 0.0;
    const auto v = [&](double t) { return 0.3 - 1.2 * t + 0.7 * t * t + cubic * t * t * t; };
    const auto a = [&](double t) { return -1.2 + 1.4 * t + 3.0 * cubic * t * t; };
    const double dt = 0.01;
    const Transitions data = transitions_of({sampled(v, 150, dt, 0.0, 1), sampled(v, 90, dt, 0.0, 2)},
                                            {Matrix::Zero(150, 1), Matrix::Zero(90, 1)}, dt);
    const AccelerationEstimate estimate = estimate_accelerations(data, {0}, dt, order);
    ASSERT_EQ(estimate.qdd.rows(), data.size());
    for (int r = 0; r < data.size(); ++r) EXPECT_NEAR(estimate.qdd(r, 0), a(data.t(r)), 1e-8) << "order " << order << " row " << r;
  }
}

// Parallel filtering (accelerations.hpp): the acceleration estimate is a weighted mean of the
// acceleration over its window, and filtered_controls applies the same weights to the controls. A
// second derivation: velocities integrated exactly from random controls, v1' = u1 and
// v2' = u1 - 2 u2, continuous (piecewise linear: each step's increment is dt times the mean of its
// ends) or held (each step's increment is dt times its first control). The estimate of both columns
// (one window for both) must be G times the filtered controls at every row, the ends included.
TEST(InverseDynamicsAccelerations, ParallelFilteringSeesTheControlsAsTheEstimateSeesTheAcceleration) {
  const double dt = 0.002;
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const ControlHold hold : {ControlHold::Continuous, ControlHold::ZeroOrder}) {
    std::vector<Matrix> states, controls;
    for (const int T : {400, 260}) {
      Matrix u(T, 2), x(T, 2);
      for (int s = 0; s < T; ++s) u.row(s) << std::sin(0.05 * s) + 0.3 * gauss(rng), 0.5 * gauss(rng);
      u.row(T - 1) = u.row(T - 2);  // no control after the last row: the filter holds the last one
      x.row(0) << 0.4, -0.2;
      for (int s = 0; s + 1 < T; ++s) {
        const Eigen::RowVector2d mean = hold == ControlHold::Continuous ? Eigen::RowVector2d(0.5 * (u.row(s) + u.row(s + 1)))
                                                                        : Eigen::RowVector2d(u.row(s));
        x(s + 1, 0) = x(s, 0) + dt * mean(0);
        x(s + 1, 1) = x(s, 1) + dt * (mean(0) - 2.0 * mean(1));
      }
      states.push_back(x);
      controls.push_back(u);
    }
    const Transitions data = transitions_of(states, controls, dt);
    for (const int window : {5, 21, 61}) {
      // The estimate of both columns with this window, episode by episode (the rows of one episode
      // and its last x_next are its samples).
      const SavitzkyGolayDerivative filter(window, 2);
      Matrix qdd(data.size(), 2);
      for (std::size_t e = 0, row = 0; e < states.size(); ++e) {
        const auto rows = static_cast<Eigen::Index>(states[e].rows() - 1);
        for (int j = 0; j < 2; ++j) qdd.col(j).segment(static_cast<Eigen::Index>(row), rows) =
            filter.differentiate(states[e].col(j), dt).head(rows);
        row += static_cast<std::size_t>(rows);
      }
      const Matrix filtered = filtered_controls(data, data.u, {window, 2, 1}, hold);
      for (int r = 0; r < data.size(); ++r) {
        EXPECT_NEAR(qdd(r, 0), filtered(r, 0), 1e-8) << "window " << window << " row " << r;
        EXPECT_NEAR(qdd(r, 1), filtered(r, 0) - 2.0 * filtered(r, 1), 1e-8) << "window " << window << " row " << r;
      }
      // Not trivially so: the filtered controls are far from the controls themselves.
      EXPECT_GT((filtered - data.u).cwiseAbs().maxCoeff(), 0.3) << window;
      for (int p = 0; p < window; ++p) EXPECT_NEAR(acceleration_weights(filter, p, hold).sum(), 1.0, 1e-12);
    }
  }
}

// The same from positions (accelerations.hpp, derivative 2): a position q' = v, v' = u integrated
// exactly from random controls, continuous (linear within each step: v gains dt (u_s + u_{s+1}) / 2, q
// gains dt v_s + dt^2 (u_s / 3 + u_{s+1} / 6)) or held (v gains dt u_s, q gains dt v_s + dt^2 u_s / 2),
// with only the positions measured. The velocity estimated from the position makes the estimate
// differentiate the position twice, and that estimate must be the controls seen through the
// second derivative's weights at every row, the ends included; the weights of the first derivative
// (the velocity's filter) differ from it by far more.
TEST(InverseDynamicsAccelerations, ParallelFilteringOfPositionsSeesTheControlsAsTheirSecondDerivativeSees) {
  const double dt = 0.001;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const ControlHold hold : {ControlHold::Continuous, ControlHold::ZeroOrder}) {
    std::vector<Matrix> states, controls;
    for (const int T : {500, 300}) {
      Matrix u(T, 1), x(T, 2);
      for (int s = 0; s < T; ++s) u(s, 0) = (s < T / 3 ? 0.0 : 40.0) + std::sin(0.03 * s) + 0.5 * gauss(rng);  // a step
      u.row(T - 1) = u.row(T - 2);  // no control after the last row: the filter holds the last one
      x.row(0) << 0.1, 0.0;
      for (int s = 0; s + 1 < T; ++s) {
        const bool held = hold == ControlHold::ZeroOrder;
        x(s + 1, 1) = x(s, 1) + dt * (held ? u(s, 0) : 0.5 * (u(s, 0) + u(s + 1, 0)));
        x(s + 1, 0) = x(s, 0) + dt * x(s, 1) +
                      dt * dt * (held ? 0.5 * u(s, 0) : u(s, 0) / 3.0 + u(s + 1, 0) / 6.0);
      }
      states.push_back(x);
      controls.push_back(u);
    }
    Transitions data = transitions_of(states, controls, dt);
    data.position_of = {-1, 0};  // the velocity (column 1) estimated from its position (column 0)
    for (const int window : {5, 31}) {
      const AccelerationFilter filter{window, 2, 2};
      const SavitzkyGolayDerivative second(window, 2, 2);
      Vector qdd(data.size());
      for (std::size_t e = 0, row = 0; e < states.size(); ++e) {
        const auto rows = static_cast<Eigen::Index>(states[e].rows() - 1);
        qdd.segment(static_cast<Eigen::Index>(row), rows) = second.differentiate(states[e].col(0), dt).head(rows);
        row += static_cast<std::size_t>(rows);
      }
      const Matrix filtered = filtered_controls(data, data.u, filter, hold);
      const Matrix of_velocities = filtered_controls(data, data.u, {window, 2, 1}, hold);
      for (int r = 0; r < data.size(); ++r) EXPECT_NEAR(qdd(r), filtered(r, 0), 1e-6) << "window " << window << " row " << r;
      EXPECT_GT((of_velocities - filtered).cwiseAbs().maxCoeff(), 1.0) << window;
      for (int p = 0; p < window; ++p) EXPECT_NEAR(acceleration_weights(second, p, hold).sum(), 1.0, 1e-12);
    }
    // estimate_accelerations takes the positions by itself, and its estimate is the same.
    const AccelerationEstimate estimate = estimate_accelerations(data, {1}, dt);
    EXPECT_EQ(estimate.derivative, 2);
    EXPECT_EQ(estimate.differentiated_states, std::vector<int>{0});
    const Matrix filtered = filtered_controls(data, data.u, estimate.filter(), hold);
    EXPECT_LT((estimate.qdd.col(0) - filtered.col(0)).cwiseAbs().maxCoeff(), 1e-6);
  }
}

// standstill_rows against a direct count: a velocity at rest (creeping at 0.1% of the motion's rms
// speed), a move, a reversal through 0 and rest again; a row stands still exactly when every sample of
// its window (centred, or the first / last window at the ends) is within 1% of the rms speed. The
// rests' inner rows are marked, a window that reaches one moving sample is not, and neither is the
// reversal, whose velocity passes 0 within the window.
TEST(InverseDynamicsAccelerations, StandstillIsWhereTheWholeWindowRests) {
  const double dt = 0.001;
  const int T = 801, window = 21;
  Matrix x(T, 2);
  for (int s = 0; s < T; ++s) {
    double v = 0.001 * std::sin(0.7 * s);  // rest, creeping
    if (s >= 200 && s < 400) v = std::sin(M_PI * (s - 200) / 200.0);
    if (s >= 400 && s < 600) v = std::sin(2.0 * M_PI * (s - 400) / 200.0);
    x(s, 1) = v;
    x(s, 0) = s == 0 ? 0.0 : x(s - 1, 0) + dt * v;
  }
  const Transitions data = transitions_of({x}, {Matrix::Zero(T, 1)}, dt);
  const auto still = standstill_rows(data, {1}, {window, 2, 2});
  const double band = kStandstillSpeed * std::sqrt(x.col(1).squaredNorm() / T);
  ASSERT_GT(band, 0.001) << "the creep must be inside the band for this case";
  int marked = 0;
  for (int t = 0; t < data.size(); ++t) {
    const int start = std::clamp(t - window / 2, 0, T - window);
    bool rests = true;
    for (int j = start; j < start + window; ++j) rests = rests && std::abs(x(j, 1)) <= band;
    EXPECT_EQ(still(t, 0), rests) << "row " << t;
    marked += rests ? 1 : 0;
  }
  EXPECT_TRUE(still(50, 0));
  EXPECT_TRUE(still(700, 0));
  EXPECT_FALSE(still(195, 0));  // its window reaches the move's first samples
  EXPECT_FALSE(still(300, 0));
  EXPECT_FALSE(still(500, 0));  // the reversal
  EXPECT_GT(marked, 350);
  // No filter, no standstill.
  EXPECT_EQ(standstill_rows(data, {1}, {0, 2, 2}).count(), 0);
}

// The GP of the remainder test learns the equations the criterion has. A residual that is sin(3 x) where
// the coordinate moves and zero where the criterion leaves it out (every third row of a slow stretch,
// as a standstill is): with the left-out entries passed, the GP is not trained on those zeros, its mean
// there is exactly 0 (target - mean adds nothing to a score), and at the other rows it is the sine; a
// GP trained on every row, the zeros included, is pulled towards them.
TEST(InverseDynamicsRemainder, TheGpOfWhatIsLeftIsNotTrainedOnTheRowsLeftOut) {
  const int T = 241;
  Matrix x(T, 2);
  for (int s = 0; s < T; ++s) x.row(s) << -1.0 + 2.0 * s / (T - 1), 0.0;
  const Transitions data = transitions_of({x}, {Matrix::Zero(T, 1)}, 0.01);
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> left_out =
      Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(data.size(), 1, false);
  Matrix target(data.size(), 1);
  for (int t = 0; t < data.size(); ++t) {
    left_out(t, 0) = data.x(t, 0) > 0.0 && t % 3 != 0;
    target(t, 0) = left_out(t, 0) ? 0.0 : std::sin(3.0 * data.x(t, 0));
  }
  GpSettings settings;
  settings.points = 200;
  const Matrix masked = gp_column_means(data, target, settings, &left_out);
  const Matrix every_row = gp_column_means(data, target, settings);
  double error_masked = 0.0, error_every_row = 0.0;
  for (int t = 0; t < data.size(); ++t) {
    if (left_out(t, 0)) {
      EXPECT_EQ(masked(t, 0), 0.0) << "row " << t;
      continue;
    }
    error_masked = std::max(error_masked, std::abs(masked(t, 0) - target(t, 0)));
    error_every_row = std::max(error_every_row, std::abs(every_row(t, 0) - target(t, 0)));
  }
  EXPECT_LT(error_masked, 0.05);
  EXPECT_GT(error_every_row, 0.2);  // the zeros beside x > 0 drag the mean from the sine there
}

// Every column is differentiated with one window, the widest of the columns' own choices: a noisy
// column beside a clean one sets it for both.
TEST(InverseDynamicsAccelerations, EveryColumnTakesTheWidestWindow) {
  const double dt = 0.01;
  const auto v = [](double t) { return std::sin(1.3 * t); };
  Matrix x(400, 2);
  x.col(0) = sampled(v, 400, dt, 0.0, 1);
  x.col(1) = sampled(v, 400, dt, 0.02, 2);
  const Transitions data = transitions_of({x}, {Matrix::Zero(400, 1)}, dt);
  const AccelerationEstimate estimate = estimate_accelerations(data, {0, 1}, dt);
  ASSERT_EQ(estimate.windows.size(), 2u);
  EXPECT_LT(estimate.windows[0].window, estimate.windows[1].window);
  EXPECT_EQ(estimate.window, estimate.windows[1].window);
  const Vector clean = SavitzkyGolayDerivative(estimate.window, 2).differentiate(x.col(0), dt);
  EXPECT_MATRIX_NEAR(estimate.qdd.col(0), clean.head(data.size()), 1e-12);
}

TEST(InverseDynamicsAccelerations, ZeroLagOnANoisySinusoidWhereACausalWindowWouldLag) {
  // v = sin(omega t) at 100 Hz with noise 1% of the amplitude: the rule takes a long window, over which
  // a causal (one-sided) fit would lag by about h dt, a phase of omega h dt. The centred fit's estimate,
  // projected on cos and sin over the interior samples, has no sin part beyond the noise.
  const double dt = 0.01, omega = 2.0 * M_PI * 0.5;
  const int T = 2001;
  const Transitions data = transitions_of({sampled([&](double t) { return std::sin(omega * t); }, T, dt, 0.01, 3)},
                                          {Matrix::Zero(T, 1)}, dt);
  const AccelerationEstimate estimate = estimate_accelerations(data, {0}, dt);
  const int h = estimate.windows[0].window / 2;
  EXPECT_GT(omega * h * dt, 0.1) << "window " << estimate.windows[0].window << ": too short to show a lag";
  Matrix basis(data.size() - 2 * h, 2);
  Vector y(basis.rows());
  for (Eigen::Index r = 0; r < basis.rows(); ++r) {
    const double t = data.t(r + h);
    basis(r, 0) = std::cos(omega * t);
    basis(r, 1) = std::sin(omega * t);
    y(r) = estimate.qdd(r + h, 0);
  }
  const Vector ab = basis.colPivHouseholderQr().solve(y);
  const double phase = std::atan2(-ab(1), ab(0));  // the estimate is |a| cos(omega t - phase)
  EXPECT_LT(std::abs(phase), 0.01) << "window " << estimate.windows[0].window;
  // The amplitude: the frequency response of the antisymmetric weights, sum_j c_j sin(omega j dt) / dt,
  // slightly below omega (the bias the window rule accepts for less noise).
  const SavitzkyGolayDerivative filter(estimate.windows[0].window, 2);
  const Vector& c = filter.weights(h);
  double response = 0.0;
  for (int j = -h; j <= h; ++j) response += c(j + h) * std::sin(omega * j * dt) / dt;
  EXPECT_NEAR(ab(0), response, 0.002 * omega);
  std::printf("window %d: phase %.2e rad (a causal window: %.2f rad), amplitude %.4f, response %.4f, omega %.4f\n",
              estimate.windows[0].window, phase, omega * h * dt, ab(0), response, omega);
}

/// The mean squared error of the derivative of `signal` against `derivative` over the interior
/// samples at least `margin` from the ends, for a window w of order 2.
double actual_mse(const Vector& samples, const std::function<double(double)>& derivative, double dt, int window,
                  int margin) {
  const Vector d = SavitzkyGolayDerivative(window, 2).differentiate(samples, dt);
  double sum = 0.0;
  for (Eigen::Index i = margin; i + margin < samples.size(); ++i) sum += std::pow(d(i) - derivative(i * dt), 2);
  return sum / static_cast<double>(samples.size() - 2 * margin);
}

struct WindowCase {
  double frequency;  ///< [Hz] of the slower component
  double noise;      ///< std of the white noise on the samples
  double dt;
};

struct WindowOutcome {
  DerivativeWindow chosen;
  double chosen_mse = 0.0;  ///< its true mean squared error
  double best_mse = 0.0;    ///< the least true mean squared error of any window from 3 to 301
  int best_window = 0;
};

/// A velocity of two incommensurate sinusoids over 10 s: the rule's choice and, against the true
/// derivative, its error and that of the best window in hindsight.
WindowOutcome window_for(const WindowCase& c) {
  const double w1 = 2.0 * M_PI * c.frequency, w2 = 2.7 * w1;
  const auto v = [&](double t) { return std::sin(w1 * t) + 0.5 * std::sin(w2 * t + 1.0); };
  const auto a = [&](double t) { return w1 * std::cos(w1 * t) + 0.5 * w2 * std::cos(w2 * t + 1.0); };
  const int T = static_cast<int>(std::lround(10.0 / c.dt)) + 1;
  const Vector y = sampled(v, T, c.dt, c.noise, 11).col(0);
  WindowOutcome out;
  out.chosen = choose_derivative_window({y}, c.dt);
  const int margin = 150;
  out.chosen_mse = actual_mse(y, a, c.dt, out.chosen.window, margin);
  out.best_mse = std::numeric_limits<double>::infinity();
  for (int h = 1; h <= margin; h += std::max(1, h / 10)) {  // every window to 21, then 10% apart
    const int w = 2 * h + 1;
    const double mse = actual_mse(y, a, c.dt, w, margin);
    if (mse < out.best_mse) {
      out.best_mse = mse;
      out.best_window = w;
    }
  }
  return out;
}

TEST(InverseDynamicsAccelerations, WindowRuleIsNearTheBestWindowInHindsightAndFollowsNoiseSpeedAndRate) {
  const WindowOutcome base = window_for({1.0, 0.01, 0.01});
  const WindowOutcome noisier = window_for({1.0, 0.05, 0.01});
  const WindowOutcome faster = window_for({3.0, 0.01, 0.01});
  const WindowOutcome fast_rate = window_for({1.0, 0.01, 0.001});
  const WindowOutcome clean = window_for({1.0, 0.0, 0.01});
  for (const WindowOutcome* o : {&base, &noisier, &faster, &fast_rate, &clean}) {
    std::printf("window %3d (%.3f s), sigma_hat %.3e, estimated rms %.4g, true rms %.4g; best window %3d, rms %.4g; "
                "mse ratio %.4f\n", o->chosen.window, o->chosen.window * (o == &fast_rate ? 0.001 : 0.01),
                o->chosen.noise_std, std::sqrt(o->chosen.risk), std::sqrt(o->chosen_mse), o->best_window,
                std::sqrt(o->best_mse), o->chosen_mse / o->best_mse);
    // Near the optimum: the true mean squared error within 1.1 times the best window's.
    EXPECT_LE(o->chosen_mse, 1.1 * o->best_mse) << "window " << o->chosen.window << ", best " << o->best_window;
  }
  EXPECT_GT(noisier.chosen.window, base.chosen.window);
  EXPECT_LT(faster.chosen.window, base.chosen.window);
  EXPECT_LT(clean.chosen.window, base.chosen.window);
  // The same signal and noise per sample at 1 kHz: theory (derivative_window.hpp) says a span 10^(1/7)
  // = 1.39 times shorter; roughly the same time, and ten times the samples' rate does not mean ten
  // times the samples.
  const double span_100 = (base.chosen.window - 1) * 0.01, span_1000 = (fast_rate.chosen.window - 1) * 0.001;
  EXPECT_GT(span_100 / span_1000, 1.0);
  EXPECT_LT(span_100 / span_1000, 2.0);
  // The noise estimate from differences, against the noise put in.
  EXPECT_NEAR(base.chosen.noise_std, 0.01, 0.001);
  EXPECT_NEAR(noisier.chosen.noise_std, 0.05, 0.005);
}

TEST(InverseDynamicsAccelerations, ShortEpisodesAndWrongStepsAreClearErrors) {
  const double dt = 0.01;
  const auto v = [](double t) { return t; };
  const Transitions data = transitions_of({sampled(v, 50, dt, 0.0, 1), sampled(v, 4, dt, 0.0, 2)},
                                          {Matrix::Zero(50, 1), Matrix::Zero(4, 1)}, dt);
  try {
    estimate_accelerations(data, {0}, dt);
    ADD_FAILURE() << "expected a DataProblem";
  } catch (const diagnosis::DataProblem& e) {  // the data's, named with its file
    EXPECT_NE(std::string(e.what()).find("episode 1 (rows 49 to 51) has 4 consecutive samples"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("needs at least 5"), std::string::npos) << e.what();
  }
  const Transitions long_enough = transitions_of({sampled(v, 50, dt, 0.0, 1)}, {Matrix::Zero(50, 1)}, dt);
  EXPECT_THROW(estimate_accelerations(long_enough, {0}, 0.02), diagnosis::DataProblem);  // t says 0.01
  try {  // no column 1: the caller's mistake, not the data's
    estimate_accelerations(long_enough, {1}, dt);
    ADD_FAILURE() << "a velocity column outside the state was accepted";
  } catch (const diagnosis::DataProblem& e) {
    ADD_FAILURE() << "the caller's mistake blamed on the data: " << e.what();
  } catch (const std::invalid_argument&) {
  }
}

// --- The residual on the cart-pole, against its textbook inverse dynamics ------------------------

/// M(q) qdd - h(q, qdot, k u) of the cart-pole written out (Tedrake, Underactuated Robotics, ch. 3;
/// theta = 0 hanging): (mc + mp) x_dd + mp l c th_dd - mp l s th_d^2 = k u + Q_x and
/// mp l c x_dd + mp l^2 th_dd + mp g l s = Q_theta, solved for Q.
Vector cartpole_inverse_dynamics(const Vector& x, const Vector& qdd, double u, double mc, double mp, double l, double k) {
  const double g = 9.81, s = std::sin(x(2)), c = std::cos(x(2));
  Vector Q(2);
  Q(0) = (mc + mp) * qdd(0) + mp * l * c * qdd(1) - mp * l * s * x(3) * x(3) - k * u;
  Q(1) = mp * l * c * qdd(0) + mp * l * l * qdd(1) + mp * g * l * s;
  return Q;
}

TEST(InverseDynamicsResidual, CartPoleMatchesTheClosedFormWithTheModelsParametersGainAndDelay) {
  // Random states, accelerations and controls in two episodes. The model: the simulator preset
  // (cart 1 kg, pole 1 kg, length 1 m, CartPoleParameters::simulator()) with the pole recalibrated to
  // 1.3 m, an actuator gain of 0.8 and an input delay of one control period, so the force at row t is
  // 0.8 u_{t-1} (u_0 at an episode's first row).
  const int T = 40;
  std::vector<Matrix> states, controls;
  for (unsigned e = 0; e < 2; ++e) {
    Matrix x(T, 4), u(T, 1);
    for (int i = 0; i < T; ++i) {
      x.row(i) = test::random_vector(4, -3.0, 3.0, 100 * e + i).transpose();
      u(i, 0) = test::random_vector(1, -10.0, 10.0, 7000 + 100 * e + i)(0);
    }
    states.push_back(x);
    controls.push_back(u);
  }
  const Transitions data = transitions_of(states, controls, 0.02);
  Matrix qdd(data.size(), 2);
  for (int r = 0; r < data.size(); ++r) qdd.row(r) = test::random_vector(2, -20.0, 20.0, 9000 + r).transpose();

  ModelSpec model;
  model.system = "cartpole";
  model.parameters["pole_length"] = 1.3;
  model.actuator_gain = 0.8;
  model.input_delay = 1.0;
  const DynamicsPtr built = model.build();
  const ForceComponents components = force_components(*built);
  ASSERT_EQ(components.forces.size(), 2u);
  EXPECT_EQ(components.forces[0].name, "Q_x");
  EXPECT_EQ(components.forces[0].unit, "N");
  EXPECT_EQ(components.forces[1].name, "Q_theta");
  EXPECT_EQ(components.forces[1].unit, "N m");
  EXPECT_EQ(components.velocity_states(), (std::vector<int>{1, 3}));

  std::vector<int> rows(static_cast<std::size_t>(data.size()));
  for (int r = 0; r < data.size(); ++r) rows[static_cast<std::size_t>(r)] = data.size() - 1 - r;  // any order
  const Matrix r = generalised_force_residual(model, data, qdd, rows);
  ASSERT_EQ(r.rows(), data.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int t = rows[i];
    const bool first = t == 0 || data.episode[static_cast<std::size_t>(t)] != data.episode[static_cast<std::size_t>(t - 1)];
    const double u = data.u(first ? t : t - 1, 0);
    const Vector expected = cartpole_inverse_dynamics(data.x.row(t).transpose(), qdd.row(t).transpose(), u, 1.0, 1.0, 1.3, 0.8);
    EXPECT_MATRIX_NEAR(r.row(static_cast<Eigen::Index>(i)).transpose(), expected, 1e-9 * (1.0 + expected.norm()));
  }
}

// --- The residual of a MuJoCo model, against mj_inverse ------------------------------------------

std::string arm_path() { return (test::source_dir() / "data" / "two_link_arm.xml").string(); }

/// MuJoCo's inverse dynamics as a second implementation: qfrc_inverse (M qacc + bias - passive) minus
/// the actuator forces of ctrl = u, from the file itself.
Vector mujoco_force_residual(const Vector& x, const Vector& qdd, const Vector& u) {
  char error[512] = "";
  mjModel* m = mj_loadXML(arm_path().c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  for (int i = 0; i < m->nv; ++i) {
    d->qpos[i] = x(i);
    d->qvel[i] = x(m->nv + i);
  }
  for (int a = 0; a < m->nu; ++a) d->ctrl[a] = u(a);
  mj_forward(m, d);  // the actuator forces of ctrl
  Vector actuator(m->nv);
  for (int i = 0; i < m->nv; ++i) actuator(i) = d->qfrc_actuator[i];
  for (int i = 0; i < m->nv; ++i) d->qacc[i] = qdd(i);
  mj_inverse(m, d);
  Vector r(m->nv);
  for (int i = 0; i < m->nv; ++i) r(i) = d->qfrc_inverse[i] - actuator(i);
  mj_deleteData(d);
  mj_deleteModel(m);
  return r;
}

TEST(InverseDynamicsResidual, MujocoArmMatchesMjInverseAndAnEffectInTheModelIsSubtracted) {
  const int T = 30;
  Matrix x(T, 4), u(T, 2);
  for (int i = 0; i < T; ++i) {
    x.row(i) = test::random_vector(4, -2.0, 2.0, 300 + i).transpose();
    u.row(i) = test::random_vector(2, -3.0, 3.0, 600 + i).transpose();
  }
  const Transitions data = transitions_of({x}, {u}, 0.01);
  Matrix qdd(data.size(), 2);
  for (int r = 0; r < data.size(); ++r) qdd.row(r) = test::random_vector(2, -30.0, 30.0, 900 + r).transpose();

  ModelSpec bare;
  bare.system = arm_path();
  ModelSpec damped = bare;  // the model already has 0.3 N m s/rad of damping on the shoulder
  damped.forces.push_back({"joint_viscous_damping:shoulder", Vector::Constant(1, 0.3)});
  const std::vector<int> rows = [&] {
    std::vector<int> all;
    for (int r = 0; r < data.size(); ++r) all.push_back(r);
    return all;
  }();
  const Matrix r_bare = generalised_force_residual(bare, data, qdd, rows);
  const Matrix r_damped = generalised_force_residual(damped, data, qdd, rows);
  EXPECT_EQ(names_of(force_components(*bare.build()).forces), (std::vector<std::string>{"Q_shoulder", "Q_elbow"}));
  for (int t = 0; t < data.size(); ++t) {
    const Vector expected = mujoco_force_residual(data.x.row(t).transpose(), qdd.row(t).transpose(), data.u.row(t).transpose());
    EXPECT_MATRIX_NEAR(r_bare.row(t).transpose(), expected, 1e-8 * (1.0 + expected.norm()));
    // The model's own damping force -0.3 shoulder_dot is no longer missing.
    Vector damping = Vector::Zero(2);
    damping(0) = -0.3 * data.x(t, 2);
    EXPECT_MATRIX_NEAR(r_damped.row(t).transpose(), (expected - damping).eval(), 1e-8 * (1.0 + expected.norm()));
  }
}

/// r_t = W_v^-1 (qdd_t - f_v(x_t, u_t)) written out: the model's forward dynamics and its generalised-force
/// map, solved per row (generalised_force_residual.hpp's definition).
Matrix solved_force_residual(const Dynamics& model, const Transitions& data, const Matrix& qdd) {
  const Dynamics& owner = force_map_system(model);
  const auto& map = dynamic_cast<const GeneralisedForceInput&>(owner);
  const std::vector<int> velocity = force_components(model).velocity_states();
  const auto k = static_cast<Eigen::Index>(velocity.size());
  Matrix out(data.size(), k);
  Vector xdot(model.state_dim());
  Matrix W;
  for (int t = 0; t < data.size(); ++t) {
    const Vector x = data.x.row(t).transpose();
    model.evaluate(x, data.u.row(t).transpose(), xdot);
    map.generalised_force_map(x, W, nullptr);
    Matrix W_v(k, k);
    Vector e(k);
    for (Eigen::Index c = 0; c < k; ++c) {
      W_v.row(c) = W.row(velocity[static_cast<std::size_t>(c)]);
      e(c) = qdd(t, c) - xdot(velocity[static_cast<std::size_t>(c)]);
    }
    out.row(t) = W_v.fullPivLu().solve(e).transpose();
  }
  return out;
}

// MuJoCo's direct inverse dynamics (MujocoSystem::inverse_dynamics, no factorisation) is the solved
// forward dynamics' residual to rounding, with an actuator gain, a force at a body, Coulomb friction and
// recalibrated masses, armature and damping, and with the constraint rows of frictionloss (whose forces
// the forward solver gives).
TEST(InverseDynamicsResidual, DirectMujocoInverseDynamicsIsTheSolvedForwardDynamics) {
  const int T = 40;
  Matrix x(T, 4), u(T, 2);
  for (int i = 0; i < T; ++i) {
    x.row(i) = test::random_vector(4, -2.0, 2.0, 1300 + i).transpose();
    u.row(i) = test::random_vector(2, -3.0, 3.0, 1600 + i).transpose();
  }
  const Transitions data = transitions_of({x}, {u}, 0.01);
  Matrix qdd(data.size(), 2);
  for (int r = 0; r < data.size(); ++r) qdd.row(r) = test::random_vector(2, -30.0, 30.0, 1900 + r).transpose();
  std::vector<int> rows;
  for (int r = 0; r < data.size(); ++r) rows.push_back(r);

  ModelSpec bare;
  bare.system = arm_path();
  ModelSpec decorated = bare;
  decorated.actuator_gain = 1.3;
  decorated.parameters = {{"forearm.mass", 0.9}, {"elbow.armature", 0.02}, {"shoulder.damping", 0.2}};
  decorated.forces.push_back({"joint_coulomb_friction:elbow", Vector::Constant(1, 0.4)});
  decorated.forces.push_back({"external_force_x:forearm", Vector::Constant(1, 1.5)});
  ModelSpec friction_loss = bare;
  friction_loss.parameters = {{"elbow.frictionloss", 0.3}};
  for (const ModelSpec* model : {&bare, &decorated, &friction_loss}) {
    const DynamicsPtr system = model->build();
    const Matrix direct = generalised_force_residual(*system, data, data.u, qdd, rows);
    const Matrix solved = solved_force_residual(*system, data, qdd);
    for (int t = 0; t < data.size(); ++t)
      EXPECT_MATRIX_NEAR(direct.row(t).transpose(), solved.row(t).transpose(), 1e-9 * (1.0 + solved.row(t).norm()));
    const auto& owner = dynamic_cast<const GeneralisedForceInput&>(force_map_system(*system));
    const auto workspace = force_map_system(*system).make_workspace();
    Vector inertial(2), forces(2);
    EXPECT_TRUE(owner.inverse_dynamics_parts(data.x.row(0).transpose(), data.u.row(0).transpose(),
                                             qdd.row(0).transpose(), inertial, forces, *workspace));
  }
}

/// A system without a generalised-force map: xdot = u.
class Integrator1D final : public Dynamics {
 public:
  const std::string& name() const override { return name_; }
  const std::vector<Quantity>& states() const override { return states_; }
  const std::vector<Quantity>& controls() const override { return controls_; }
  std::vector<Parameter> parameters() const override { return {}; }
  void evaluate(const VectorCRef&, const VectorCRef& u, VectorRef xdot, DynamicsJacobians*) const override {
    xdot(0) = u(0);
  }

 private:
  std::string name_ = "integrator";
  std::vector<Quantity> states_{{"p", "m"}};
  std::vector<Quantity> controls_{{"v", "m/s"}};
};

TEST(InverseDynamicsResidual, BadInputIsAClearError) {
  const Integrator1D plain;
  try {
    force_components(plain);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("system 'integrator' has no generalised-force map"), std::string::npos)
        << e.what();
  }
  const Transitions data = transitions_of({Matrix::Zero(5, 4)}, {Matrix::Zero(5, 1)}, 0.02);
  ModelSpec cartpole;
  EXPECT_THROW(generalised_force_residual(cartpole, data, Matrix::Zero(4, 1), {0}), std::invalid_argument);  // 1 column
  EXPECT_THROW(generalised_force_residual(cartpole, data, Matrix::Zero(4, 2), {4}), std::invalid_argument);  // no row 4
}

// --- A world with hidden friction: the residual is the friction ----------------------------------

constexpr double kShoulderDamping = 0.4;  // N m s/rad, hidden from the model
constexpr double kElbowFriction = 0.3;    // N m, hidden from the model
constexpr double kElbowSmoothing = 0.1;   // rad/s, v0 of the elbow's tanh

/// The hidden forces written out: -b shoulder_dot on the shoulder, -tau tanh(elbow_dot / v0) on the elbow.
Vector hidden_force(const Vector& x) {
  return (Vector(2) << -kShoulderDamping * x(2), -kElbowFriction * std::tanh(x(3) / kElbowSmoothing)).finished();
}

/// Smooth joint torques [N m]: sums of sinusoids, so the true acceleration has no jumps.
Vector torque(double t, int episode) {
  const double p = 0.7 * episode;
  return (Vector(2) << 1.5 * std::sin(2 * M_PI * 0.6 * t + p) + 0.6 * std::sin(2 * M_PI * 1.7 * t),
          0.6 * std::sin(2 * M_PI * 0.9 * t + 1.0 + p) + 0.3 * std::sin(2 * M_PI * 2.3 * t))
      .finished();
}

/// The world (the arm with the hidden forces) integrated by RK4 at dt / 10 with the torques at the stage
/// times, sampled at dt: noise-free states and the torques at the samples.
void simulate_world(const Dynamics& world, double dt, int T, int episode, Matrix& x, Matrix& u) {
  const int substeps = 10;
  const double h = dt / substeps;
  x.resize(T, 4);
  u.resize(T, 2);
  Vector s = (Vector(4) << 0.3 * episode - 0.4, 0.2, 0.5, -0.3).finished();
  const auto workspace = world.make_workspace();
  Vector k1(4), k2(4), k3(4), k4(4);
  const auto f = [&](const Vector& state, double t, Vector& xdot) {
    world.evaluate(state, torque(t, episode), xdot, nullptr, *workspace);
  };
  for (int i = 0; i < T; ++i) {
    x.row(i) = s.transpose();
    u.row(i) = torque(i * dt, episode).transpose();
    for (int j = 0; j < substeps; ++j) {
      const double t = i * dt + j * h;
      f(s, t, k1);
      f(s + 0.5 * h * k1, t + 0.5 * h, k2);
      f(s + 0.5 * h * k2, t + 0.5 * h, k3);
      f(s + h * k3, t + h, k4);
      s += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
  }
}

/// The arm with a timestep of 2 ms, the step of the world's records: the model to simulate at their step.
std::string arm_2ms_path() {
  static const std::string path = [] {
    std::string text = test::read_text(arm_path());
    const auto at = text.find("timestep=\"0.01\"");
    EXPECT_NE(at, std::string::npos);
    text.replace(at, std::string("timestep=\"0.01\"").size(), "timestep=\"0.002\"");
    return test::write_text(test::temporary_dir("arm_2ms") / "two_link_arm_2ms.xml", text).string();
  }();
  return path;
}

/// The arm as the model and the world with the hidden forces.
struct HiddenFrictionWorld {
  ModelSpec model;
  DynamicsPtr world;
  std::vector<Matrix> states, controls;  ///< five episodes of 3 s at 500 Hz
  double dt = 0.002;  ///< the elbow's friction turns within v0 = 0.1 rad/s, a few milliseconds at these speeds
};

const HiddenFrictionWorld& hidden_friction_world() {
  static const HiddenFrictionWorld w = [] {
    HiddenFrictionWorld w;
    w.model.system = arm_path();
    ModelSpec world = w.model;
    world.forces.push_back({"joint_viscous_damping:shoulder", Vector::Constant(1, kShoulderDamping)});
    world.forces.push_back({"joint_coulomb_friction:elbow", Vector::Constant(1, kElbowFriction)});
    world.smoothing["joint_coulomb_friction:elbow"] = kElbowSmoothing;
    w.world = world.build();
    for (int e = 0; e < 5; ++e) {
      Matrix x, u;
      simulate_world(*w.world, w.dt, 1501, e, x, u);
      w.states.push_back(x);
      w.controls.push_back(u);
    }
    return w;
  }();
  return w;
}

/// IDIM-LS on the residual: b and tau by linear least squares, each on its own joint's column.
Vector friction_by_least_squares(const Transitions& data, const Matrix& r) {
  const Vector shoulder_basis = -data.x.col(2);
  const Vector elbow_basis = -(data.x.col(3) / kElbowSmoothing).array().tanh().matrix();
  return (Vector(2) << shoulder_basis.dot(r.col(0)) / shoulder_basis.squaredNorm(),
          elbow_basis.dot(r.col(1)) / elbow_basis.squaredNorm())
      .finished();
}

TEST(InverseDynamicsResidual, NoiseFreeWorldWithHiddenFrictionGivesTheFrictionAsResidual) {
  const HiddenFrictionWorld& w = hidden_friction_world();
  const ModelSpec& model = w.model;
  const Transitions data = transitions_of(w.states, w.controls, w.dt);
  const std::vector<int> rows = data.rows(false);

  // With the world's true accelerations the residual is the hidden force, exactly.
  Matrix true_qdd(data.size(), 2);
  for (int t = 0; t < data.size(); ++t) {
    const Vector xdot = w.world->f(data.x.row(t).transpose(), data.u.row(t).transpose());
    true_qdd.row(t) = xdot.tail(2).transpose();
  }
  const Matrix exact = generalised_force_residual(model, data, true_qdd, rows);
  Matrix hidden(data.size(), 2);
  for (int t = 0; t < data.size(); ++t) hidden.row(t) = hidden_force(data.x.row(t).transpose()).transpose();
  EXPECT_MATRIX_NEAR(exact, hidden, 1e-9);

  // With the estimated accelerations: the hidden force within the estimate's error.
  const AccelerationEstimate estimate =
      estimate_accelerations(data, force_components(*model.build()).velocity_states(), w.dt);
  const Matrix r = generalised_force_residual(model, data, estimate.qdd, rows);
  const Vector error_rms = ((r - hidden).colwise().squaredNorm() / data.size()).cwiseSqrt().transpose();
  const Vector hidden_rms = (hidden.colwise().squaredNorm() / data.size()).cwiseSqrt().transpose();
  const Vector qdd_error_rms = ((estimate.qdd - true_qdd).colwise().squaredNorm() / data.size()).cwiseSqrt().transpose();
  std::printf("windows %d, %d; acceleration error rms %.3g, %.3g rad/s^2; force error rms %.3g, %.3g of %.3g, %.3g N m\n",
              estimate.windows[0].window, estimate.windows[1].window, qdd_error_rms(0), qdd_error_rms(1), error_rms(0),
              error_rms(1), hidden_rms(0), hidden_rms(1));
  EXPECT_LT(error_rms(0), 0.02 * hidden_rms(0));
  EXPECT_LT(error_rms(1), 0.02 * hidden_rms(1));

  // IDIM-LS on the residual: the friction parameters by linear least squares, each on its own joint.
  const Vector theta = friction_by_least_squares(data, r);
  const double b = theta(0), tau = theta(1);
  std::printf("least squares on the residual: b = %.4f (true %.4f), tau = %.4f (true %.4f)\n", b, kShoulderDamping, tau,
              kElbowFriction);
  EXPECT_NEAR(b, kShoulderDamping, 0.01 * kShoulderDamping);
  EXPECT_NEAR(tau, kElbowFriction, 0.01 * kElbowFriction);
}

/// The world's states with white noise of 0.02 rad/s on the velocities and 1e-4 rad on the angles.
std::vector<Matrix> noisy_states(const HiddenFrictionWorld& w, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Matrix> noisy = w.states;
  for (Matrix& x : noisy)
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      for (Eigen::Index j = 0; j < 4; ++j) x(i, j) += (j < 2 ? 1e-4 : 0.02) * gauss(rng);
  return noisy;
}

TEST(InverseDynamicsResidual, NoisyVelocitiesGiveTheFrictionByLeastSquaresOnTheResidual) {
  // The same record with white noise of 0.02 rad/s on the measured velocities (and 1e-4 rad on the
  // angles): the window rule smooths, and least squares on the residual finds the hidden friction.
  const HiddenFrictionWorld& w = hidden_friction_world();
  const Transitions data = transitions_of(noisy_states(w, 5), w.controls, w.dt);
  const AccelerationEstimate estimate =
      estimate_accelerations(data, force_components(*w.model.build()).velocity_states(), w.dt);
  const Matrix r = generalised_force_residual(w.model, data, estimate.qdd, data.rows(false));
  const Vector theta = friction_by_least_squares(data, r);
  std::printf("windows %d, %d (sigma_hat %.4f, %.4f rad/s); b = %.4f (true %.4f), tau = %.4f (true %.4f)\n",
              estimate.windows[0].window, estimate.windows[1].window, estimate.windows[0].noise_std,
              estimate.windows[1].noise_std, theta(0), kShoulderDamping, theta(1), kElbowFriction);
  EXPECT_NEAR(estimate.windows[0].noise_std, 0.02, 0.002);
  EXPECT_NEAR(estimate.windows[1].noise_std, 0.02, 0.002);
  EXPECT_GT(estimate.windows[0].window, 3);
  EXPECT_NEAR(theta(0), kShoulderDamping, 0.05 * kShoulderDamping);
  EXPECT_NEAR(theta(1), kElbowFriction, 0.05 * kElbowFriction);
}

// --- Fits of forces linear in their parameters: least squares on the residual --------------------------

/// The hidden-friction world's record with noise on the measured states, its third episode held out.
const Transitions& friction_fit_data() {
  static const Transitions data = [] {
    const HiddenFrictionWorld& w = hidden_friction_world();
    Transitions out = transitions_of(noisy_states(w, 11), w.controls, w.dt);
    for (std::size_t t = 0; t < out.episode.size(); ++t) out.heldout[t] = out.episode[t] == 2;
    return out;
  }();
  return data;
}

/// The inverse-dynamics fit context of the arm (the model without friction) on that record.
const FitContext& friction_fit_context() {
  static const FitContext context = [] {
    FitContext c;
    c.data = &friction_fit_data();
    c.model = hidden_friction_world().model;
    c.dt = hidden_friction_world().dt;
    return criterion_context(c, FitCriterion::InverseDynamics, 1);
  }();
  return context;
}

// IDIM-WLS: each joint's equations are weighted by 1 / sigma_i^2, sigma_i = max(noise_i, left_i), the
// white noise of its residual and the rms the model as given leaves of it on the training rows. The same
// record twice, with white noise of 1e-3 and 0.1 N m added to the shoulder's torque: weighted by the
// noise alone, the quiet record would give the shoulder at least 9 times the weight of the loud one
// (the quiet one's noise is mostly the acceleration estimate's, 0.02 N m), though its model (without
// the hidden damping of 0.4 N m s/rad) is wrong by far more than either noise. By what the model
// leaves, its weight hardly moves.
TEST(InverseDynamicsWeights, AJointsWeightFollowsWhatTheModelLeavesNotHowQuietItsSensorIs) {
  const HiddenFrictionWorld& w = hidden_friction_world();
  struct Weights {
    Vector weight, noise, left;
  };
  const auto weights_with_shoulder_noise = [&](double torque_noise) {
    std::vector<Matrix> controls = w.controls;
    std::mt19937 rng(3);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (Matrix& u : controls)
      for (Eigen::Index t = 0; t < u.rows(); ++t) u(t, 0) += torque_noise * gauss(rng);
    Transitions data = transitions_of(noisy_states(w, 11), controls, w.dt);
    for (std::size_t t = 0; t < data.episode.size(); ++t) data.heldout[t] = data.episode[t] == 2;
    FitContext base;
    base.data = &data;
    base.model = w.model;  // the shoulder's damping is missing, the elbow's friction is there
    base.model.forces.push_back({"joint_coulomb_friction:elbow", Vector::Constant(1, kElbowFriction)});
    base.model.smoothing["joint_coulomb_friction:elbow"] = kElbowSmoothing;
    base.dt = w.dt;
    const FitContext c = criterion_context(base, FitCriterion::InverseDynamics, 1);
    const InverseDynamicsCriterion& criterion = *c.criterion->inverse_dynamics();
    const std::vector<int> training = data.rows(false);
    for (Eigen::Index i = 0; i < 2; ++i) {
      double square = 0.0;
      for (int t : training) square += c.residual(t, i) * c.residual(t, i);
      const double left = std::sqrt(square / static_cast<double>(training.size()));
      EXPECT_NEAR(criterion.left()(i), left, 1e-12 * left);
      const double sigma = std::max(criterion.noise()(i), left);
      EXPECT_NEAR(c.weights(i) * sigma * sigma, 1.0, 1e-12);
    }
    std::printf("shoulder torque noise %.0e N m: noise [%.3g, %.3g], left [%.3g, %.3g] N m, weights [%.4g, %.4g]\n",
                torque_noise, criterion.noise()(0), criterion.noise()(1), criterion.left()(0), criterion.left()(1),
                c.weights(0), c.weights(1));
    return Weights{c.weights, criterion.noise(), criterion.left()};
  };
  const Weights quiet = weights_with_shoulder_noise(1e-3), loud = weights_with_shoulder_noise(0.1);
  // The estimate sees the sensor's noise ...
  EXPECT_GT(loud.noise(0), 0.8 * 0.1);
  EXPECT_GT(loud.noise(0), 3.0 * quiet.noise(0));
  // ... but the missing damping leaves far more of the shoulder's torque than either noise, and sets its weight.
  EXPECT_GT(quiet.left(0), 3.0 * loud.noise(0));
  EXPECT_NEAR(loud.weight(0) / quiet.weight(0), 1.0, 0.05);
}

// Each criterion is one object (criteria/criterion.hpp) that the fits take row by row and the report
// and the starts of every fit take whole: its rows for a fit must be its residual, weighted, for any
// model (here the arm with a damping it was not made for), under each of the three criteria, with the
// simulation's estimated starts and the filtered controls of inverse dynamics included.
TEST(Criteria, EachCriterionsWeightedRowsAreItsResidualWeightedForAnyModel) {
  const Transitions& data = friction_fit_data();
  FitContext base;
  base.data = &data;
  base.model.system = arm_2ms_path();  // the state criteria step the model at the records' step
  base.dt = hidden_friction_world().dt;
  base.weights = Vector::Constant(4, 1.0);
  base.weights << 1e8, 1e8, 1e2, 1e2;  // positions 1e-4 rad, velocities 0.1 rad/s
  base.residual = criterion_residual(base.model, base);  // a context's default criterion: one-step
  const ModelSpec other = base.model.with(find_candidate(base.model, "joint_viscous_damping:elbow"), Vector::Constant(1, 0.3));
  const std::vector<int> rows = all_rows(data);
  for (const auto& [criterion, window] : {std::pair{FitCriterion::OneStep, 1}, std::pair{FitCriterion::Simulation, 50},
                                          std::pair{FitCriterion::InverseDynamics, 1}}) {
    const FitContext c = criterion_context(base, criterion, window);
    EXPECT_EQ(c.criterion->kind(), criterion);
    EXPECT_EQ(c.criterion->window(), window);
    // The context's residual is the criterion's residual of its own model.
    EXPECT_LT((c.residual - c.criterion->residual(c.model, c)).norm(), 1e-12 * (1.0 + c.residual.norm()));
    const Matrix r = c.criterion->residual(other, c);
    const Vector weighted = c.criterion->weighted_residual(other, c, rows);
    const auto k = static_cast<Eigen::Index>(c.weights.size());
    ASSERT_EQ(r.cols(), k);
    ASSERT_EQ(weighted.size(), r.rows() * k);
    Vector expected(weighted.size());
    for (Eigen::Index t = 0; t < r.rows(); ++t)
      expected.segment(t * k, k) = c.weights.cwiseSqrt().cwiseProduct(r.row(t).transpose());
    std::printf("%s: |sqrt(w) r| = %.6g, difference %.3g\n", c.criterion->name().c_str(), expected.norm(),
                (weighted - expected).norm());
    EXPECT_GT(expected.norm(), 0.0);
    EXPECT_LT((weighted - expected).norm(), 1e-9 * expected.norm()) << c.criterion->name();
  }
  // Only inverse dynamics rules out the gains (its residual is homogeneous in them and the inertias).
  const std::vector<LibraryEffect> candidates = candidate_effects(base.model);
  EXPECT_TRUE(criterion_context(base, FitCriterion::OneStep, 1).criterion->unidentifiable(candidates).empty());
  const std::vector<std::string> gains =
      criterion_context(base, FitCriterion::InverseDynamics, 1).criterion->unidentifiable(candidates);
  EXPECT_FALSE(gains.empty());
  for (const std::string& name : gains)
    EXPECT_TRUE(name.starts_with("actuator_gain:") || name.ends_with(".gear") || name.ends_with(".gain")) << name;
}

/// The weighted least-squares fit of the residual r0 on the regressor X (both stacked over the rows,
/// weighted), the iid 95% half-width s sqrt((X'X)^-1) widened to the delete-one-episode jackknife,
/// computed here directly: what fit_effect and fit_jointly must give for forces linear in theta.
struct LeastSquaresFit {
  Vector theta, half;
};

LeastSquaresFit least_squares_fit(const Matrix& X, const Vector& r0, const std::vector<int>& episode_of_block,
                                  Eigen::Index k) {
  const Eigen::Index p = X.cols();
  LeastSquaresFit out;
  out.theta = X.colPivHouseholderQr().solve(r0);
  const double s2 = (r0 - X * out.theta).squaredNorm() / static_cast<double>(X.rows() - p);
  Vector variance = s2 * (X.transpose() * X).inverse().diagonal();
  const std::set<int> episodes(episode_of_block.begin(), episode_of_block.end());
  std::vector<Vector> replicates;
  for (int episode : episodes) {
    std::vector<Eigen::Index> keep;
    for (std::size_t b = 0; b < episode_of_block.size(); ++b)
      if (episode_of_block[b] != episode)
        for (Eigen::Index i = 0; i < k; ++i) keep.push_back(static_cast<Eigen::Index>(b) * k + i);
    const Matrix Xe = X(keep, Eigen::all);
    const Vector re = r0(keep);
    replicates.push_back(Xe.colPivHouseholderQr().solve(re));
  }
  Vector mean = Vector::Zero(p);
  for (const Vector& t : replicates) mean += t / static_cast<double>(replicates.size());
  Vector jack = Vector::Zero(p);
  for (const Vector& t : replicates) jack += (t - mean).cwiseAbs2();
  const auto R = static_cast<double>(replicates.size());
  jack *= (R - 1.0) / R;
  // The normal quantile, or Student's on R - 1 degrees of freedom where the jackknife is the larger
  // (student_t.hpp, checked against the table in its own test).
  out.half.resize(p);
  for (Eigen::Index j = 0; j < p; ++j)
    out.half(j) = jack(j) > variance(j) ? student_t_quantile(0.975, R - 1.0) * std::sqrt(jack(j))
                                        : 1.96 * std::sqrt(variance(j));
  return out;
}

// For forces linear in their parameters the fit is one least-squares solve of the model's residual on
// the forces' regressor (affine_force_residual.hpp). Checked against that solve done here: on the
// forces' formulas (viscous damping: g = -qdot on its joint), and on regressors and residuals of the
// rebuilt model (r(0) - r(1) of a force at a body's centre of mass), alone and jointly; the held-out
// share against the rebuilt model's residuals; a force the data cannot see is not identifiable.
TEST(InverseDynamicsFit, LinearForcesFitAsLeastSquaresOfTheResidualOnTheirRegressor) {
  const Transitions& data = friction_fit_data();
  const FitContext& c = friction_fit_context();
  const std::vector<int> training = data.rows(false), heldout = data.rows(true);
  const Eigen::Index k = 2;
  std::vector<int> episode_of_block;
  for (int t : training) episode_of_block.push_back(data.episode[static_cast<std::size_t>(t)]);
  const Vector r0 = weighted_residual_of(c.model, c, training);
  const auto regressor_of = [&](const LibraryEffect& effect, const std::vector<int>& rows) {
    // The rebuilt model's residual is affine in theta: its difference between 0 and 1 is the column.
    return Vector(weighted_residual_of(c.model, c, rows) -
                  weighted_residual_of(c.model.with(effect, Vector::Ones(1)), c, rows));
  };

  // Viscous damping on the shoulder: the column is sqrt(w_0) (-shoulder_dot) on component 0, seen
  // through the acceleration estimate's weights as the residual sees every force (parallel filtering).
  const LibraryEffect viscous = find_candidate(c.model, "joint_viscous_damping:shoulder");
  const int window = c.criterion->inverse_dynamics()->acceleration_window();
  ASSERT_GT(window, 1);
  const Matrix seen = filtered_at(data, data.x.col(2), training, {window, 2, 1});
  Matrix X = Matrix::Zero(r0.size(), 1);
  for (std::size_t i = 0; i < training.size(); ++i)
    X(static_cast<Eigen::Index>(i) * k, 0) = -std::sqrt(c.weights(0)) * seen(static_cast<Eigen::Index>(i), 0);
  const LeastSquaresFit expected = least_squares_fit(X, r0, episode_of_block, k);
  const EffectFit fit = fit_effect(viscous, c);
  std::printf("viscous: %.6f [%.6f, %.6f]; least squares %.6f +- %.6f\n", fit.estimate(0), fit.ci_low(0),
              fit.ci_high(0), expected.theta(0), expected.half(0));
  ASSERT_TRUE(fit.identifiable) << fit.not_identifiable;
  EXPECT_NEAR(fit.estimate(0), expected.theta(0), 1e-9 * std::abs(expected.theta(0)));
  EXPECT_NEAR(fit.linear_estimate(0), expected.theta(0), 1e-9 * std::abs(expected.theta(0)));
  EXPECT_NEAR(fit.ci_high(0) - fit.estimate(0), expected.half(0), 1e-6 * expected.half(0));
  EXPECT_NEAR(fit.estimate(0), kShoulderDamping, 0.05 * kShoulderDamping);
  // The objective and the held-out share are the rebuilt model's.
  const ModelSpec fitted = c.model.with(viscous, fit.estimate);
  const double after = weighted_residual_of(fitted, c, training).squaredNorm();
  EXPECT_NEAR(fit.training_objective_after, after, 1e-9 * after);
  const double before_h = weighted_residual_of(c.model, c, heldout).squaredNorm();
  const double after_h = weighted_residual_of(fitted, c, heldout).squaredNorm();
  EXPECT_NEAR(fit.explained, 1.0 - after_h / before_h, 1e-9);
  EXPECT_GT(fit.explained, 0.1);

  // A force along x at the forearm's centre of mass (its regressor is the body's Jacobian), jointly
  // with the shoulder's damping: two columns, the joint estimate and interval of each.
  const LibraryEffect push = find_candidate(c.model, "external_force_x:forearm");
  X.conservativeResize(Eigen::NoChange, 2);
  X.col(1) = regressor_of(push, training);
  const LeastSquaresFit both = least_squares_fit(X, r0, episode_of_block, k);
  const EffectFit joint = fit_jointly(push, {{&viscous, Vector::Zero(1)}}, c);
  ASSERT_EQ(joint.refitted.size(), 1u);
  std::printf("jointly: force %.6f (least squares %.6f), damping %.6f (least squares %.6f)\n", joint.estimate(0),
              both.theta(1), joint.refitted[0].estimate(0), both.theta(0));
  EXPECT_NEAR(joint.estimate(0), both.theta(1), 1e-9 * std::max(1.0, std::abs(both.theta(1))));
  EXPECT_NEAR(joint.refitted[0].estimate(0), both.theta(0), 1e-9 * std::abs(both.theta(0)));
  EXPECT_NEAR(joint.ci_high(0) - joint.estimate(0), both.half(1), 1e-6 * both.half(1));
  EXPECT_NEAR(joint.refitted[0].ci_high(0) - joint.refitted[0].estimate(0), both.half(0), 1e-6 * both.half(0));

  // A force along the hinges' axis y moves no joint: its regressor is zero, so it is not identifiable
  // (and nothing is NaN).
  const EffectFit blind = fit_effect(find_candidate(c.model, "external_force_y:forearm"), c);
  EXPECT_FALSE(blind.identifiable);
  EXPECT_EQ(blind.not_identifiable, "it does not change the predictions") << "its regressor is not exactly zero";
  EXPECT_EQ(blind.explained, 0.0);
  EXPECT_TRUE(blind.estimate.allFinite());
}

// A recalibration fitted jointly with a force linear in its parameter: the force's column of the
// regressor is its basis, the recalibration's a central difference. The estimate is the minimum of the
// rebuilt model's training objective: moving either parameter by 1% of itself raises it.
TEST(InverseDynamicsFit, RecalibrationWithALinearForceEndsAtTheRebuiltModelsMinimum) {
  const FitContext& c = friction_fit_context();
  const std::vector<int> training = friction_fit_data().rows(false);
  const LibraryEffect mass = find_candidate(c.model, "param:forearm.mass");
  const LibraryEffect coulomb = find_candidate(c.model, "joint_coulomb_friction:elbow");
  const EffectFit fit = fit_jointly(mass, {{&coulomb, Vector::Zero(1)}}, c);
  ASSERT_TRUE(fit.identifiable) << fit.not_identifiable;
  ASSERT_EQ(fit.refitted.size(), 1u);
  const auto objective = [&](double m, double tau) {
    return weighted_residual_of(c.model.with(mass, Vector::Constant(1, m)).with(coulomb, Vector::Constant(1, tau)), c,
                                training)
        .squaredNorm();
  };
  const double m = fit.estimate(0), tau = fit.refitted[0].estimate(0);
  const double at = objective(m, tau);
  std::printf("forearm mass %.5f kg, elbow Coulomb friction %.5f N m; objective %.6g\n", m, tau, at);
  EXPECT_NEAR(fit.training_objective_after, at, 1e-9 * at);
  EXPECT_NEAR(tau, kElbowFriction, 0.1 * kElbowFriction);
  for (const double step : {-0.01, 0.01}) {
    EXPECT_GT(objective(m * (1.0 + step), tau), at) << step;
    EXPECT_GT(objective(m, tau * (1.0 + step)), at) << step;
  }
}

// --- IDIM-IV: instruments from the simulated model --------------------------------------------------

/// One noisy record of the hidden-friction world (velocity noise `velocity_noise`, episode 2 held out)
/// with its least-squares and instrumental-variable inverse-dynamics contexts.
struct NoisyRecord {
  std::shared_ptr<Transitions> data;
  FitContext base, ls, iv;
};

NoisyRecord noisy_record(double velocity_noise, unsigned seed) {
  const HiddenFrictionWorld& w = hidden_friction_world();
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Matrix> noisy = w.states;
  for (Matrix& x : noisy)
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      for (Eigen::Index j = 0; j < 4; ++j) x(i, j) += (j < 2 ? 1e-4 : velocity_noise) * gauss(rng);
  NoisyRecord record;
  record.data = std::make_shared<Transitions>(transitions_of(noisy, w.controls, w.dt));
  Transitions& data = *record.data;
  for (std::size_t t = 0; t < data.episode.size(); ++t) data.heldout[t] = data.episode[t] == 2;
  record.base.data = &data;
  record.base.model.system = arm_2ms_path();  // the instruments simulate the model at the records' step
  record.base.dt = w.dt;
  record.ls = criterion_context(record.base, FitCriterion::InverseDynamics, 1);
  record.iv = record.ls;
  record.iv.criterion = record.ls.criterion->inverse_dynamics()->with_instruments(record.ls);
  return record;
}

/// The least-squares and the instrumental-variable fit of the shoulder's viscous damping on one noisy
/// record of the hidden-friction world, and the IV estimate in closed form from its instruments.
struct DampingFits {
  EffectFit ls, iv;
  double iv_closed_form = 0.0;
  long instrumented = 0, training = 0;
};

DampingFits fit_damping_both_ways(double velocity_noise, unsigned seed) {
  const NoisyRecord record = noisy_record(velocity_noise, seed);
  const Transitions& data = *record.data;
  const FitContext &base = record.base, &ls = record.ls, &iv = record.iv;
  const Instruments& z = *iv.criterion->inverse_dynamics()->instruments();
  EXPECT_EQ(z.window, 4 * (ls.criterion->inverse_dynamics()->reach() + 1));
  EXPECT_EQ(z.restarts, 0);

  const LibraryEffect viscous = find_candidate(base.model, "joint_viscous_damping:shoulder");
  DampingFits out{fit_effect(viscous, ls), fit_effect(viscous, iv)};
  // Z = -sqrt(w_0) qdot_simulated on component 0 (0 on rows without an instrument), J the same with
  // the measured velocity seen through the acceleration estimate's weights (parallel filtering):
  // theta = Z'r0 / Z'J on the training rows.
  const std::vector<int> training = data.rows(false);
  const Vector r0 = weighted_residual_of(base.model, ls, training);
  const Matrix seen = filtered_at(data, data.x.col(2), training, ls.criterion->inverse_dynamics()->acceleration_filter());
  double zr = 0.0, zj = 0.0;
  for (std::size_t k = 0; k < training.size(); ++k) {
    const int t = training[k];
    if (!z.instrumented[static_cast<std::size_t>(t)]) continue;
    const double zt = -std::sqrt(ls.weights(0)) * z.data.x(t, 2);
    zr += zt * r0(static_cast<Eigen::Index>(k) * 2);
    zj += zt * -std::sqrt(ls.weights(0)) * seen(static_cast<Eigen::Index>(k), 0);
    ++out.instrumented;
  }
  out.iv_closed_form = zr / zj;
  out.training = static_cast<long>(training.size());
  return out;
}

// Velocities measured with noise of 0.5 rad/s. Least squares on the force residual regresses on the
// noisy velocity seen through the acceleration estimate's weights m (parallel filtering), so its
// viscous damping shrinks by the errors-in-variables factor
//
//   lambda = S / (S + n sigma^2 |m|^2),   S = sum_t (m * qdot_clean)_t^2 over the n training rows,
//
// the filter's share of the noise being sigma^2 |m|^2 per row: lambda = 0.9986 here, where least squares
// on the unfiltered velocity (var(qdot) / (var(qdot) + sigma^2)) came out more than 5% low. The instrumental-variable
// fit (instrumental_variables.hpp) takes the velocity of the model simulated over short windows as the
// instrument, which the noise does not enter. Over four noise draws (a Monte Carlo of the bias): the
// IV estimate is the closed form Z'r / Z'J of its instruments on every draw, its mean is the world's
// damping within 2.5% and its interval holds the world's value on at least 3 of 4 draws; least
// squares' mean is the world's damping times lambda within 2.5%.
TEST(InverseDynamicsFit, InstrumentsFromTheSimulatedModelRemoveTheNoiseBiasOfLeastSquares) {
  double ls_mean = 0.0, iv_mean = 0.0;
  int ls_holds = 0, iv_holds = 0;
  constexpr int kDraws = 4;
  for (unsigned seed = 1; seed <= kDraws; ++seed) {
    const DampingFits f = fit_damping_both_ways(0.5, seed);
    std::printf("draw %u: least squares %.4f [%.4f, %.4f]; IV %.4f [%.4f, %.4f] (closed form %.4f), %ld of %ld rows "
                "instrumented; world %.4f\n",
                seed, f.ls.estimate(0), f.ls.ci_low(0), f.ls.ci_high(0), f.iv.estimate(0), f.iv.ci_low(0),
                f.iv.ci_high(0), f.iv_closed_form, f.instrumented, f.training, kShoulderDamping);
    ASSERT_TRUE(f.ls.identifiable) << f.ls.not_identifiable;
    ASSERT_TRUE(f.iv.identifiable) << f.iv.not_identifiable;
    EXPECT_NEAR(f.iv.estimate(0), f.iv_closed_form, 1e-9 * std::abs(f.iv_closed_form));
    EXPECT_GT(f.instrumented, f.training * 9 / 10);
    ls_mean += f.ls.estimate(0) / kDraws;
    iv_mean += f.iv.estimate(0) / kDraws;
    ls_holds += f.ls.ci_low(0) <= kShoulderDamping && kShoulderDamping <= f.ls.ci_high(0);
    iv_holds += f.iv.ci_low(0) <= kShoulderDamping && kShoulderDamping <= f.iv.ci_high(0);
  }
  // lambda on the noise-free record, with the window the criterion chose on the first draw.
  const NoisyRecord first = noisy_record(0.5, 1);
  const int window = first.ls.criterion->inverse_dynamics()->acceleration_window();
  const HiddenFrictionWorld& w = hidden_friction_world();
  const Transitions clean = transitions_of(w.states, w.controls, w.dt);
  std::vector<int> training;
  for (int t = 0; t < clean.size(); ++t)
    if (clean.episode[static_cast<std::size_t>(t)] != 2) training.push_back(t);
  const double S = filtered_at(clean, clean.x.col(2), training, {window, 2, 1}).squaredNorm();
  const double m2 = acceleration_weights(SavitzkyGolayDerivative(window, 2), window / 2, ControlHold::Continuous).squaredNorm();
  const double lambda = S / (S + static_cast<double>(training.size()) * 0.25 * m2);
  std::printf("means: least squares %.4f (lambda %.4f: expected %.4f), IV %.4f; intervals holding the world's value: "
              "%d and %d of %d\n", ls_mean, lambda, lambda * kShoulderDamping, iv_mean, ls_holds, iv_holds, kDraws);
  EXPECT_NEAR(iv_mean, kShoulderDamping, 0.025 * kShoulderDamping);
  EXPECT_GE(iv_holds, 3);
  EXPECT_NEAR(ls_mean, lambda * kShoulderDamping, 0.025 * kShoulderDamping);
}

// The subset search screens with the estimator it then fits with (linearised_fits.hpp): in a context
// with instruments, what the linearised fit of a force linear in its parameters leaves on the training
// rows is what the exact IV fit leaves (fit_effect: its training objective), not what least squares
// leaves, which is less (least squares minimises it; the IV estimate does not).
TEST(InverseDynamicsFit, TheSubsetScreeningFitsWithTheInstruments) {
  const NoisyRecord record = noisy_record(0.5, 1);
  const LibraryEffect viscous = find_candidate(record.base.model, "joint_viscous_damping:shoulder");
  const EffectFit ls = fit_effect(viscous, record.ls), iv = fit_effect(viscous, record.iv);
  const LinearisedFits screened_ls(record.ls, {ls}, {}), screened_iv(record.iv, {iv}, {});
  std::printf("training residual left: IV %.8g (exact %.8g), least squares %.8g (exact %.8g)\n",
              screened_iv.training_left({0}), iv.training_objective_after, screened_ls.training_left({0}),
              ls.training_objective_after);
  EXPECT_NEAR(screened_iv.training_left({0}), iv.training_objective_after, 1e-9 * iv.training_objective_after);
  EXPECT_NEAR(screened_ls.training_left({0}), ls.training_objective_after, 1e-9 * ls.training_objective_after);
  EXPECT_GT(iv.training_objective_after, ls.training_objective_after * (1.0 + 1e-6));
}

// Parameters of the model whose residual is affine in them (a mass with its inertia, an armature, a
// damping, a stiffness, alone or with a linear force) are fitted in the closed form from probes of the
// model; the fit is the rebuilt model's at every theta (the general path) to rounding. Frictionloss
// (MuJoCo's dry friction, a constraint of the forward solver) is not affine: both paths are the
// rebuilt model's and agree exactly.
TEST(InverseDynamicsFit, ProbedClosedFormIsTheRebuiltModelsFit) {
  const FitContext& closed = friction_fit_context();
  FitContext rebuilt = closed;
  rebuilt.probe_affine = false;
  const LibraryEffect coulomb = find_candidate(closed.model, "joint_coulomb_friction:elbow");
  for (const char* name : {"param:forearm.mass", "param:upper_arm.mass", "param:elbow.armature", "param:shoulder.damping",
                           "param:elbow.stiffness", "param:elbow.frictionloss"}) {
    const LibraryEffect effect = find_candidate(closed.model, name);
    for (const bool with_force : {false, true}) {
      const std::vector<RefitEffect> refit =
          with_force ? std::vector<RefitEffect>{{&coulomb, Vector::Zero(1)}} : std::vector<RefitEffect>{};
      const EffectFit a = fit_jointly(effect, refit, closed), b = fit_jointly(effect, refit, rebuilt);
      std::printf("%s%s: %.8g [%.6g, %.6g] (rebuilt %.8g [%.6g, %.6g]), explained %.6f (%.6f)\n", name,
                  with_force ? " with elbow Coulomb" : "", a.estimate(0), a.ci_low(0), a.ci_high(0), b.estimate(0),
                  b.ci_low(0), b.ci_high(0), a.explained, b.explained);
      ASSERT_EQ(a.identifiable, b.identifiable) << name;
      const double scale = std::max(1e-3, std::abs(b.estimate(0)));
      EXPECT_NEAR(a.estimate(0), b.estimate(0), 1e-7 * scale) << name;
      EXPECT_NEAR(a.ci_high(0) - a.ci_low(0), b.ci_high(0) - b.ci_low(0), 1e-5 * (b.ci_high(0) - b.ci_low(0))) << name;
      EXPECT_NEAR(a.explained, b.explained, 1e-9) << name;
      EXPECT_NEAR(a.training_objective_after, b.training_objective_after, 1e-9 * b.training_objective_after) << name;
      if (with_force) {
        ASSERT_EQ(a.refitted.size(), 1u);
        EXPECT_NEAR(a.refitted[0].estimate(0), b.refitted[0].estimate(0), 1e-7 * std::abs(b.refitted[0].estimate(0)));
      }
    }
  }
}

// A set that the closed form does not hold (frictionloss, a constraint of MuJoCo's forward solver, is
// not affine in its level; nor is an input delay) is fitted on the rebuilt model, its regressor by
// central differences whose evaluations FitContext::threads run at once (set_residual.hpp): with two
// threads every member's estimate and interval and the scores are those of one thread, to the bit.
TEST(InverseDynamicsFit, ASetsModelEvaluatedOnTwoThreadsGivesTheSameFit) {
  const FitContext& one = friction_fit_context();
  FitContext two = one;
  two.threads = 2;
  const std::vector<std::vector<const char*>> sets = {
      {"param:elbow.frictionloss", "param:shoulder.damping", "param:elbow.armature"},
      {"param:shoulder.damping", "input_delay", "param:upper_arm.mass", "joint_coulomb_friction:elbow"},
  };
  for (const std::vector<const char*>& names : sets) {
    std::vector<LibraryEffect> effects;
    for (const char* name : names) effects.push_back(find_candidate(one.model, name));
    std::vector<RefitEffect> refit;
    for (std::size_t i = 1; i < effects.size(); ++i) refit.push_back({&effects[i], one.model.current_values(effects[i])});
    const EffectFit a = fit_jointly(effects[0], refit, one), b = fit_jointly(effects[0], refit, two);
    ASSERT_EQ(a.refitted.size(), b.refitted.size());
    std::vector<EffectValues> ma{own_values(a)}, mb{own_values(b)};
    ma.insert(ma.end(), a.refitted.begin(), a.refitted.end());
    mb.insert(mb.end(), b.refitted.begin(), b.refitted.end());
    for (std::size_t m = 0; m < ma.size(); ++m) {
      std::printf("%s: %.10g [%.8g, %.8g] (two threads %.10g [%.8g, %.8g])\n", ma[m].effect.c_str(), ma[m].estimate(0),
                  ma[m].ci_low(0), ma[m].ci_high(0), mb[m].estimate(0), mb[m].ci_low(0), mb[m].ci_high(0));
      EXPECT_EQ(ma[m].effect, mb[m].effect);
      EXPECT_EQ(ma[m].estimate, mb[m].estimate) << ma[m].effect;
      EXPECT_EQ(ma[m].ci_low, mb[m].ci_low) << ma[m].effect;
      EXPECT_EQ(ma[m].ci_high, mb[m].ci_high) << ma[m].effect;
    }
    EXPECT_GT(a.evaluations, 1 + 2 * static_cast<int>(names.size())) << "not fitted by differences: " << names[0];
    EXPECT_EQ(a.explained, b.explained) << names[0];
    EXPECT_EQ(a.training_objective_after, b.training_objective_after) << names[0];
  }
}

// --- The whole diagnosis on the inverse-dynamics criterion ------------------------------------------

// The noisy record as a measurement file would hold it, diagnosed with --auto on the inverse-dynamics
// criterion: both hidden frictions are found within 15%, and nothing else is added (no delay, gain,
// armature or mass stands in for them).
TEST(InverseDynamicsDiagnosis, AutoFindsTheHiddenFrictionAndNothingElse) {
  const HiddenFrictionWorld& w = hidden_friction_world();
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  MeasurementSet set;
  set.system = system_signature(w.model.system);
  for (std::size_t e = 0; e < w.states.size(); ++e) {
    Episode episode;
    episode.id = static_cast<long>(e);
    episode.x = w.states[e];
    for (Eigen::Index i = 0; i < episode.x.rows(); ++i)
      for (Eigen::Index j = 0; j < 4; ++j) episode.x(i, j) += (j < 2 ? 1e-4 : 0.02) * gauss(rng);
    episode.u = w.controls[e];
    episode.t = Vector::LinSpaced(episode.x.rows(), 0.0, w.dt * static_cast<double>(episode.x.rows() - 1));
    set.episodes.push_back(std::move(episode));
  }
  // The diagnosis also simulates the model (one-step and k-step predictions, free runs) at the data's
  // step: the same arm with a timestep of 2 ms, whose physics the world was simulated with.
  const std::filesystem::path dir = test::temporary_dir("inverse_dynamics_diagnosis");
  const std::string arm_2ms = arm_2ms_path();
  set.system = system_signature(arm_2ms);
  write_measurements(dir / "record.csv", set);  // to compare the criteria from the command line
  diagnosis::DiagnosisOptions o;
  o.model.system = arm_2ms;
  o.criterion = diagnosis::FitCriterion::InverseDynamics;
  o.auto_select = true;
  o.gp.points = 100;
  o.gp.restarts = 0;
  o.gp.threads = 1;
  o.horizons = {1, 10};
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(set, o);
  EXPECT_EQ(r.channel_names, (std::vector<std::string>{"Q_shoulder", "Q_elbow"}));
  ASSERT_TRUE(r.selection.has_value());
  ASSERT_FALSE(r.selection->steps.empty()) << r.verdict.reason;
  std::map<std::string, double> found;
  const diagnosis::EffectFit& last = r.selection->steps.back().fit;
  found[last.effect] = last.estimate(0);
  for (const diagnosis::EffectValues& v : last.refitted) found[v.effect] = v.estimate(0);
  std::string names;
  for (const auto& [name, value] : found) names += name + " = " + std::to_string(value) + "; ";
  std::printf("found: %s\nverdict: %s (%s)\n", names.c_str(), r.verdict.status.c_str(), r.verdict.reason.c_str());
  SCOPED_TRACE(names + r.selection->stop_reason);
  EXPECT_EQ(found.size(), 2u);
  const double shoulder = found.count("joint_viscous_damping:shoulder") ? found["joint_viscous_damping:shoulder"]
                                                                        : found["param:shoulder.damping"];
  EXPECT_NEAR(shoulder, kShoulderDamping, 0.15 * kShoulderDamping);
  const double elbow = found.count("joint_coulomb_friction:elbow") ? found["joint_coulomb_friction:elbow"]
                                                                   : found["param:elbow.frictionloss"];
  EXPECT_NEAR(elbow, kElbowFriction, 0.15 * kElbowFriction);
  EXPECT_NE(r.verdict.status, "unexplained") << r.verdict.reason;
}

}  // namespace
}  // namespace gpilqg
