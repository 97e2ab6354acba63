/// The `gpilqg` command-line program. Subcommands are registered from src/commands/; see
/// `gpilqg --help` and docs/command-line.md for the fixed names.
///
/// `--plugin LIB.so` (repeatable) belongs to the program, not to one command: every subcommand falls
/// through to it, so it may stand before or after the command's name. The plugins are loaded after
/// the command line is parsed and before the command runs; a plugin that cannot be used is bad input
/// (exit 2, plugin.hpp).

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <optional>
#include <iostream>
#include <string>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "commands/commands.hpp"
#include "commands/json_arguments.hpp"
#include "commands/output_options.hpp"
#include "gpilqg/core/plugin.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/blas_library.hpp"

namespace {

/// The first word of the command line that is neither an option nor the value of --plugin: what
/// the user meant as the command's name; empty when there is none.
std::string first_word(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--plugin") {
      ++i;
      continue;
    }
    if (!word.empty() && word[0] != '-') return word;
  }
  return "";
}

/// The names of the commands, e.g. "data, solve, simulate".
std::vector<std::string> command_names(CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(command->get_name());
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  // Under a file-size limit (ulimit -f, RLIMIT_FSIZE) a write past the limit raises SIGXFSZ, whose
  // default action kills the process without a message and leaves the temporary of an atomic write
  // behind. Ignored, the write(2) fails with EFBIG instead, and the atomic write reports it
  // ("<file>: not written: writing failed (File too large)"), removes its temporary and keeps the
  // previous file. The program ignores it here, not the library: a signal's disposition belongs to
  // the process, and a program embedding the library chooses its own (Python already ignores
  // SIGXFSZ at start-up, so the Python module gets the same messages).
  std::signal(SIGXFSZ, SIG_IGN);
  // OpenBLAS chose its kernels when it loaded; on a processor it does not know it falls back to SSE3
  // kernels five times slower than the AVX-512 ones (gp/blas_library.hpp). The program then starts
  // itself again with OPENBLAS_CORETYPE naming the right ones: the same command, the same process
  // (execv keeps the process id, so MPI and a waiting parent see nothing), once, since the variable
  // is set the second time. If the new start fails the program carries on with the kernels it has.
  if (const std::optional<std::string> core = gpilqg::gp::better_openblas_coretype()) {
    setenv("OPENBLAS_CORETYPE", core->c_str(), 1);
    execv("/proc/self/exe", argv);
  }
  CLI::App app{"gpilqg: data-driven robust optimal control (GP-corrected simulators, Robust-iLQG)",
               "gpilqg"};
  app.require_subcommand(1);
  std::vector<std::string> plugins;
  app.add_option("--plugin", plugins,
                 "Load the systems of a plugin (a shared library built against gpilqg) before the command; "
                 "repeatable, allowed after the command's name")
      ->type_name("LIB.so")
      ->allow_extra_args(false);
  app.set_version_flag("--version", [] {
    return "gpilqg " GPILQG_VERSION_STRING "\nBLAS: " + gpilqg::gp::blas_library();
  });
  app.fallthrough();  // inherited by the subcommands added below
  gpilqg::cli::CommandAction action;
  gpilqg::cli::add_data_command(app, action);
  gpilqg::cli::add_solve_command(app, action);
  gpilqg::cli::add_simulate_command(app, action);
  gpilqg::cli::add_diagnose_command(app, action);
  gpilqg::cli::add_run_command(app, action);
  gpilqg::cli::add_sweep_command(app, action);
  gpilqg::cli::add_merge_command(app, action);
  gpilqg::cli::add_profile_command(app, action);
  gpilqg::cli::add_plan_command(app, action);
  gpilqg::cli::add_rollout_command(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const std::string word = first_word(argc, argv);
    const std::vector<std::string> names = command_names(app);
    const bool known = std::find(names.begin(), names.end(), word) != names.end();
    if (app.get_subcommands().empty() && !known)
      std::cerr << "error: " << (word.empty() ? "no command given" : "unknown command '" + word + "'")
                << "; expected one of: " << joined(names) << "\n(run with --help for usage)\n";
    else
      std::cerr << "error: " << e.what() << "\n(run with --help for usage)\n";
    return gpilqg::kExitBadInput;
  }
  if (!action) {
    std::cerr << "error: no command given\n" << app.help();
    return gpilqg::kExitBadInput;
  }
  return gpilqg::run_reporting_errors(
      [&] {
        gpilqg::cli::check_json_arguments(app);
        std::vector<gpilqg::cli::CommandInput> inputs;
        for (const auto& plugin : plugins) inputs.push_back({"--plugin", plugin});
        gpilqg::cli::set_program_inputs(std::move(inputs));
        gpilqg::load_plugins(plugins);
        return action();
      },
      std::cerr);
}
