/// The `gpilqg` command-line program. Subcommands are registered from src/commands/; see
/// `gpilqg --help` and DESIGN.md section 8 for the fixed names.

#include <iostream>

#include <CLI/CLI.hpp>

#include "commands/commands.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{"gpilqg: data-driven robust optimal control (GP-corrected simulators, Robust-iLQG)",
               "gpilqg"};
  app.require_subcommand(1);
  gpilqg::cli::CommandAction action;
  gpilqg::cli::add_data_command(app, action);
  gpilqg::cli::add_solve_command(app, action);
  gpilqg::cli::add_simulate_command(app, action);
  gpilqg::cli::add_diagnose_command(app, action);
  gpilqg::cli::add_run_command(app, action);
  gpilqg::cli::add_profile_command(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << "\n(run with --help for usage)\n";
    return gpilqg::kExitBadInput;
  }
  if (!action) {
    std::cerr << "error: no command given\n" << app.help();
    return gpilqg::kExitBadInput;
  }
  return gpilqg::run_reporting_errors(action, std::cerr);
}
