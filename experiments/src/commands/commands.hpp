#pragma once
/// @file commands.hpp
/// Each subcommand of the `gpilqg` program registers itself on the CLI11 application and, when the
/// user selects it, stores the action to run in `action`. main() runs that action under
/// run_reporting_errors, so every command shares one exit-status contract.

#include <functional>

#include <CLI/CLI.hpp>

namespace gpilqg::cli {

using CommandAction = std::function<int()>;

/// The help text of every --system option (docs/command-line.md#what-every-command-shares).
inline constexpr const char* kSystemHelp =
    "System: cartpole, quadrotor, a MuJoCo model file (.xml or .urdf) or a system registered by a --plugin";

/// `gpilqg data info FILE --system NAME [--json]`
void add_data_command(CLI::App& app, CommandAction& action);

/// `gpilqg solve CONFIG.toml [--json]`
void add_solve_command(CLI::App& app, CommandAction& action);

/// `gpilqg simulate --system NAME --out FILE [...]`
void add_simulate_command(CLI::App& app, CommandAction& action);

/// `gpilqg diagnose --system NAME --data FILE [--model F.toml] [--add EFFECT[=VALUE]]... [...]`
void add_diagnose_command(CLI::App& app, CommandAction& action);

/// `gpilqg run SYSTEM [--config F] [--seeds N] [--iterations K] [--backends LIST] [--out F.h5] [--plots DIR]`
void add_run_command(CLI::App& app, CommandAction& action);

/// `gpilqg sweep SWEEP.toml [--out F.h5] [--plots DIR] [--resume]`
void add_sweep_command(CLI::App& app, CommandAction& action);

/// `gpilqg merge PART.h5... --out F.h5 [--plots DIR] [--no-plots]`
void add_merge_command(CLI::App& app, CommandAction& action);

/// `gpilqg profile DATA --backends LIST [--sizes LIST] [--json] [--out F.h5] [--plots DIR]`
void add_profile_command(CLI::App& app, CommandAction& action);

/// `gpilqg plan CONFIG.toml [--data FILE]... [--previous POLICY.h5] --out POLICY.h5 [--seed S] [--json]`
void add_plan_command(CLI::App& app, CommandAction& action);

/// `gpilqg rollout --system NAME --policy POLICY.h5 --out LOG.csv|LOG.h5 [...]`
void add_rollout_command(CLI::App& app, CommandAction& action);

}  // namespace gpilqg::cli
