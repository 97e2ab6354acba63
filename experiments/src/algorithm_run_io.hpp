#pragma once
/// @file algorithm_run_io.hpp
/// One AlgorithmRun as an HDF5 file and back, bit for bit (the unit of run_checkpoint.hpp):
///
///   /                        attrs name, converged_at, iterations (completed)
///   /data/{x, u, x_next}     (N x n, N x m, N x n); /data/iteration (N)
///   /iter_<k>/policy/{x_bar (n x T+1), u_bar (m x T), k (m x T), K (T x m x n), u_min, u_max}
///   /iter_<k>/{predicted_cost, solve_seconds, variant, data_rows, fit_seconds, rollout_seconds,
///              policy_change, repeated}
///   /iter_<k>/summary/{termination, iterations, initial_cost, final_cost, final_gradient_norm,
///              final_backward_failed}   (the DDP summary without its per-iteration trace)
///   /iter_<k>/evaluation/{mean_cost, costs, example_x, example_u, diverged, seconds}
///   (predicted_cost, initial_cost, final_cost, final_gradient_norm, mean_cost and policy_change are
///   absent where they are +inf: a solve or rollout whose cost or gradient was not finite; every
///   number in the file is finite)
///   /iter_<k>/hyperparameters (outputs x D+2; 0 x 0 without a GP)
///   /iter_<k>/noise_floor (outputs; empty without a GP)
///   /model                   the final residual model (gp_io.hpp layout) when final_model is one
///   /diagnosis/{round, adopted, seconds}   the diagnosis inside the loop (loop_diagnosis.hpp), when
///                            there is one; /diagnosis/round attrs verdict, reason, model (model file text)
///
/// Plan models are code or GPs: on reading, only the last iteration's plan gets a model (the restored
/// residual model, which is also final_model); fixed-model runs set theirs (algorithm_runs.cpp).

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "gpilqg/experiments/algorithm_runs.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg {

/// Writes `run` to a new file `file` (not atomically: the caller renames it into place).
void write_algorithm_run(const std::filesystem::path& file, const AlgorithmRun& run);

/// The simulator a run's last plan was made on, given the run's diagnosis (planning_simulator).
using SimulatorOf = std::function<std::shared_ptr<const StepModel>(const std::optional<LoopDiagnosis>& diagnosis)>;

/// Reads what write_algorithm_run wrote for a run of `system`. The residual model, when present, is
/// rebuilt around simulator_of(the run's diagnosis) with the backend named in the file, made with
/// `settings`. Throws std::runtime_error naming the file and object on a missing or malformed entry.
AlgorithmRun read_algorithm_run(const std::filesystem::path& file, const std::string& system,
                                const SimulatorOf& simulator_of, const gp::BackendSettings& settings);

}  // namespace gpilqg
