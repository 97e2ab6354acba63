#pragma once
/// @file output_options.hpp
/// What every command does with its output options (--out, --plots, --write-model) before any
/// computation: a path that cannot be written is bad input (InputError, exit 2) now rather than an
/// error after minutes of work, and temporary files left beside the target by an interrupted earlier
/// write (atomic_file.hpp) are removed and named on stderr.

#include <filesystem>
#include <string>
#include <vector>

#include "gpilqg/core/output_path.hpp"

namespace gpilqg::cli {

/// A file a command reads (output_path.hpp).
using CommandInput = NamedInput;

/// Checks, in this order, and throws InputError "<option> <file>: <problem>" at the first problem:
///  1. output_file_problem (output_path.hpp): what is at the path, its folder, its name's length;
///  2. the same file as one of `inputs` or of the program's inputs (same_file, e.g.
///     `data import log.csv --out log.csv`): writing it would replace the input. "... is the same file
///     as <name> <input>, an input of the command; expected a file that is not one of its inputs";
///  3. output_extension_problem against `format` (what the command writes there and the names that
///     format takes): "--out p.csv: plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5".
/// An empty path (option not given) passes. Every output option of a fixed format goes through here.
void check_output_file_option(const std::string& option, const std::filesystem::path& file, const OutputFormat& format,
                              const std::vector<CommandInput>& inputs = {});

/// {"--system", system} when `system` is a model file (is_model_file_name), else an empty input.
CommandInput system_input(const std::string& system, const std::string& name = "--system");

/// The inputs of the program itself, checked by every check_output_file_option: the --plugin libraries.
void set_program_inputs(std::vector<CommandInput> inputs);

/// Checks `folder` with output_folder_problem; an empty path passes.
void check_output_folder_option(const std::string& option, const std::filesystem::path& folder);

/// Where the figures of the result file `result` go: the --plots folder `plots` when given, else the
/// result's own folder.
std::filesystem::path figures_folder(const std::filesystem::path& result, const std::string& plots);

/// The end of a command that wrote a result file: prints "results: FILE", then (unless `no_plots`)
/// draws its figures with `script` (plot_script.hpp) into figures_folder(result, plots) and prints
/// "figures: DIR".
void print_result_and_draw_figures(const std::string& script, const std::filesystem::path& result,
                                   const std::string& plots, bool no_plots);

/// Removes the temporaries of interrupted writes in `folder` (stale_temporaries_in), naming them on stderr.
void remove_stale_temporaries_in(const std::filesystem::path& folder);

}  // namespace gpilqg::cli
