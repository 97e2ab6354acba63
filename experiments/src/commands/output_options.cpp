/// Output options checked before any work; leftovers of interrupted writes removed and named.

#include "output_options.hpp"

#include <iostream>
#include <vector>

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/plot_script.hpp"

namespace gpilqg::cli {

namespace {

void remove_and_name(const std::vector<std::filesystem::path>& stale) {
  for (const auto& file : stale) {
    std::error_code error;
    if (std::filesystem::remove(file, error))
      std::cerr << fmt::format("note: removed {}, a temporary file left by an interrupted write\n", file.string());
    else
      std::cerr << fmt::format("note: {} is a temporary file left by an interrupted write; it could not be removed ({})\n",
                               file.string(), error.message());
  }
}

std::vector<CommandInput>& program_inputs() {
  static std::vector<CommandInput> inputs;
  return inputs;
}

}  // namespace

CommandInput system_input(const std::string& system, const std::string& name) {
  return {name, is_model_file_name(system) ? std::filesystem::path(system) : std::filesystem::path()};
}

void set_program_inputs(std::vector<CommandInput> inputs) { program_inputs() = std::move(inputs); }

void check_output_file_option(const std::string& option, const std::filesystem::path& file, const OutputFormat& format,
                              const std::vector<CommandInput>& inputs) {
  if (file.empty()) return;
  std::vector<CommandInput> all = inputs;
  all.insert(all.end(), program_inputs().begin(), program_inputs().end());
  if (const auto problem = output_problem(file, format, all))
    throw InputError(fmt::format("{} {}: {}", option, file.string(), *problem));
  remove_and_name(stale_temporaries(file));
}

std::filesystem::path figures_folder(const std::filesystem::path& result, const std::string& plots) {
  if (!plots.empty()) return plots;
  return result.has_parent_path() ? result.parent_path() : std::filesystem::path(".");
}

void check_output_folder_option(const std::string& option, const std::filesystem::path& folder) {
  if (folder.empty()) return;
  if (const auto problem = output_folder_problem(folder))
    throw InputError(fmt::format("{} {}: {}", option, folder.string(), *problem));
}

void remove_stale_temporaries_in(const std::filesystem::path& folder) { remove_and_name(stale_temporaries_in(folder)); }

void print_result_and_draw_figures(const std::string& script, const std::filesystem::path& result,
                                   const std::string& plots, bool no_plots) {
  std::cout << fmt::format("\nresults: {}\n", result.string());
  if (no_plots) return;
  const std::filesystem::path folder = figures_folder(result, plots);
  run_plot_script(script, result, folder);
  std::cout << fmt::format("figures: {}\n", folder.string());
}

}  // namespace gpilqg::cli
