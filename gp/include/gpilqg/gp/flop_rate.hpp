#pragma once
/// @file flop_rate.hpp
/// The speed of this machine for the GP backends' dense linear algebra, measured, for cost models
/// that turn flop counts into seconds (`gpilqg profile --time-budget`).
///
/// What is timed is one exact-GP evaluation's dense work at n = kFlopRateSize (dense_cholesky.hpp):
/// the Cholesky factor of an SPD n x n matrix (n^3/3 flops), then the inverse from it (L^-1 and
/// L^-T L^-1, 2 n^3/3): n^3 flops in all. The rate is n^3 over the fastest of two runs (the first also
/// warms the caches and the threads), so a busy machine makes it lower, never higher.

namespace gpilqg::gp {

/// Matrix size of the measurement: 1024^3 = 1.07e9 flops, about 0.05 s per run at 20 GFLOP/s.
inline constexpr int kFlopRateSize = 1024;

/// Flops per second of the dense linear algebra with `threads` threads (>= 1; the exact backend's
/// ExactGpOptions::threads). Measured on the first call per thread count in this process (about
/// 0.1-0.2 s), then cached; thread-safe. Throws std::invalid_argument when threads < 1.
double dense_flop_rate(int threads = 1);

/// One measurement, not cached (what dense_flop_rate caches).
double measure_dense_flop_rate(int threads);

}  // namespace gpilqg::gp
