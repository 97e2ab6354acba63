#pragma once
/// @file derivative_window.hpp
/// The window of a Savitzky-Golay differentiator (savitzky_golay.hpp) chosen from the data: the one
/// of least estimated mean squared error of the derivative, with the noise and the bias estimated
/// from the signal itself, so that nothing encodes the sampling rate or the speed of one data set.
///
/// Model. Samples y_i = y(i dt) + e_i of a smooth signal with white noise of variance sigma^2. The
/// centred differentiator of window w = 2h + 1 and order p is D_w(i) = (1/dt) sum_{j=-h..h} c^w_j y_{i+j};
/// its mean squared error over the samples is
///
///   R(w) = sigma^2 |c^w|^2 / dt^2  +  mean_i b_w(i)^2,
///
/// noise (sigma times the noise gain G(w) = |c^w| / dt, which falls like h^-3/2) plus squared bias
/// (b_w(i) = E D_w(i) - y'(i dt), which grows like (h dt)^q y^(q+1) with q = p for even p and p + 1 for odd
/// p: a centred fit of odd degree p differentiates exactly to degree p + 1).
///
/// Noise. sigma^2 from difference-based pseudo-residuals (Rice 1984; Gasser, Sroka and
/// Jennen-Steinmetz 1986): the k-th difference Delta^k e of white noise has variance sigma^2 C(2k, k),
/// and that of a smooth signal is about y^(k) dt^k, so
///
///   sigma_hat^2 = min_{k = 2..6} mean_i (Delta^k y_i)^2 / C(2k, k),
///
/// the minimum over k taking the order at which the signal's own differences are smallest (they fall
/// with k as long as the signal varies slowly over a few samples, which a differentiable record must).
/// On noise-free data sigma_hat is the signal's roughness at the sampling step and small.
///
/// Bias, by a reference instead of a pilot derivative. The squared bias is not computed from a pilot
/// estimate of y^(q+1) (which needs a window of its own) but against a reference differentiator
/// D_ref,w of degree p + 2 on the same window (or on its shortest window, p + 3 rounded up to odd, when
/// w is shorter). Its bias is two orders higher in h dt, so with d_i = D_w(i) - D_ref,w(i),
///
///   E mean_i d_i^2 = mean_i (b_w(i) - b_ref(i))^2 + sigma^2 |c^w - c^ref|^2 / dt^2
///
/// (the weights aligned at the centre), and neglecting b_ref,
///
///   R_hat(w) = sigma_hat^2 |c^w|^2 / dt^2 + max(0, mean_i d_i^2 - sigma_hat^2 |c^w - c^ref|^2 / dt^2).
///
/// This is an unbiased risk estimate in the spirit of Stein's (SURE), which Krishnan and Seelamantula
/// (IEEE Trans. Signal Processing 61(2), 2013) use to choose Savitzky-Golay smoothers: a smoother can
/// compare its output with the noisy samples themselves, but a derivative is never observed, so a
/// higher-degree fit over the same samples takes their place and its known extra noise is subtracted
/// (the bias estimate of local polynomial regression from a fit of higher degree). It needs no pilot
/// window and no assumption on which derivative dominates the bias. What it neglects, b_ref, is smaller
/// than b_w by a factor of order (omega h dt)^2 for a sinusoid of frequency omega, so it understates
/// the bias of long windows a little; on two sinusoids with noise, at 100 Hz and 1 kHz, the chosen
/// window's true mean squared error is within 1% of the best window's in hindsight
/// (tests/experiments/inverse_dynamics_test.cpp). A fixed short reference (5 samples) would have
/// almost no bias, but its noise, which grows like 1 / dt, buries the bias at high sampling rates: on
/// that test at 1 kHz it chose 173 samples where 45 were best; on the same window the reference's
/// noise is only a few times that of D_w.
/// The means run over the samples where both filters are centred, pooled over all segments.
///
/// Candidates. Half-widths h = h_min, then h <- max(h + 1, round(1.2 h)) (a geometric grid, 20%
/// apart), from the smallest window above the order (w = 3 for p = 2) up to the shortest segment,
/// stopping once R_hat exceeds 4 times the least value so far (past the optimum the squared bias grows
/// like h^(2q), so the minimum is behind). Ties keep the shorter window. For a signal
/// A sin(omega t) and p = 2 the optimum half-span tau = h dt scales like (sigma^2 dt / (A^2 omega^6))^(1/7):
/// longer for noisier data, shorter for faster signals, and 10^(1/7) = 1.39 times shorter at ten
/// times the sampling rate for the same noise per sample.
///
/// The second derivative (derivative 2: the accelerations from measured positions, accelerations.hpp)
/// is chosen the same way, with dt^2 for dt: R(w) = sigma^2 |c^w|^2 / dt^4 + mean_i b_w(i)^2, the
/// reference of degree p + 2 on the same window.
///
/// Assumptions: white noise on the samples (a velocity computed from encoder positions by
/// differences has correlated noise, for which sigma_hat^2 |c|^2 misstates the noise term), a uniform
/// step, and one window for all segments of the signal.

#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg::diagnosis {

/// The window rule's choice for one signal.
struct DerivativeWindow {
  int window = 0;           ///< w, odd: the centred least-squares fit spans w samples, (w - 1) dt seconds
  int order = 0;            ///< p, the degree of the fitted polynomial
  int derivative = 1;       ///< 1: dy/dt; 2: d^2y/dt^2
  double noise_std = 0.0;   ///< sigma_hat, the estimated noise of the samples (units of y)
  double noise_gain = 0.0;  ///< G(w) = |c^w| / dt^d [1/s^d]: derivative noise per unit sample noise
  double risk = 0.0;        ///< R_hat(w), the estimated mean squared error of the derivative [(units of y / s^d)^2]
  int candidates = 0;       ///< windows whose risk was estimated
};

/// sigma_hat of the white noise on the samples of `segments` (each uniformly sampled, the differences
/// taken within a segment): the minimum over k = 2..6 of mean (Delta^k y)^2 / C(2k, k), pooled over
/// the segments long enough for each k. Throws std::invalid_argument when no segment has 3 samples.
double difference_noise_std(const std::vector<Vector>& segments);

/// The smallest number of samples every segment needs for choose_derivative_window with `order`: the
/// shortest window of the reference differentiator (order + 3, rounded up to an odd number).
int shortest_differentiable_segment(int order);

/// The window of least R_hat (file comment) for the `derivative`-th derivative (1 or 2) of `segments`
/// (each uniformly sampled at `dt`) by Savitzky-Golay fits of degree `order`. Throws
/// std::invalid_argument for dt not finite and positive, a derivative other than 1 or 2, order below
/// the derivative, no segment, or a segment shorter than shortest_differentiable_segment
/// (naming its index in `segments` and its length), or a sample that is not finite.
DerivativeWindow choose_derivative_window(const std::vector<Vector>& segments, double dt, int order = 2,
                                          int derivative = 1);

}  // namespace gpilqg::diagnosis
