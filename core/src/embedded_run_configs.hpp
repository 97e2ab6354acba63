#pragma once
/// The embedded default configs of `gpilqg run` (generated from experiments/configs/run_*.toml).

namespace gpilqg::embedded {
extern const char* const kRunCartpoleToml;
extern const char* const kRunQuadrotorToml;
}  // namespace gpilqg::embedded
