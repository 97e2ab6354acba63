/// `gpilqg merge PART.h5... --out F.h5 [--plots DIR] [--no-plots]`: result files of `gpilqg run` for
/// disjoint seeds or algorithms joined into one (run_merge.hpp), figures drawn as `gpilqg run` draws them.

#include <iostream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "commands.hpp"
#include "output_options.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_merge.hpp"

namespace gpilqg::cli {
namespace {

struct MergeArguments {
  std::vector<std::string> parts;
  std::string out;
  std::string plots;
  bool no_plots = false;
};

int merge_command(const MergeArguments& a) {
  const std::filesystem::path out = a.out;
  std::vector<CommandInput> inputs;
  for (const auto& part : a.parts) inputs.push_back({"PART", part});
  check_output_file_option("--out", out, {"merge writes an HDF5 result file", kHdf5Extensions}, inputs);
  if (!a.no_plots) check_output_folder_option("--plots", a.plots);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  const MergeSummary summary = merge_run_results(std::vector<std::filesystem::path>(a.parts.begin(), a.parts.end()), out);

  std::cout << fmt::format("merged {} files: {} seed(s) ({})\n", summary.parts, summary.seeds.size(), fmt::join(summary.seeds, ", "));
  for (const MergedTask& task : summary.tasks)
    std::cout << fmt::format("  {}: {} ({} data rows)\n", task.name, fmt::join(task.algorithms, ", "), task.data_rows);
  print_result_and_draw_figures("plot_run.py", out, a.plots, a.no_plots);
  return kExitSuccess;
}

}  // namespace

void add_merge_command(CLI::App& app, CommandAction& action) {
  auto args = std::make_shared<MergeArguments>();
  auto* cmd = app.add_subcommand("merge", "Join result files of `gpilqg run` for disjoint seeds (e.g. one cluster job per "
                                          "seed) or algorithms into one result file; figures as PNG");
  cmd->add_option("PART", args->parts, "result files of `gpilqg run` (two or more) of the same system and config")
      ->required()
      ->type_name("PART.h5");
  cmd->add_option("--out", args->out, "the merged result file")->required();
  cmd->add_option("--plots", args->plots, "folder for the PNG figures (default: beside the result)");
  cmd->add_flag("--no-plots", args->no_plots, "write the result only");
  cmd->callback([&action, args] { action = [args] { return merge_command(*args); }; });
}

}  // namespace gpilqg::cli
