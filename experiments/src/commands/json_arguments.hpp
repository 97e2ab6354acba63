#pragma once
/// @file json_arguments.hpp
/// Names in JSON output must be valid UTF-8 (core/utf8.hpp). A command asked for `--json` echoes
/// its arguments (file names above all) into the document, so an argument that is not UTF-8 is
/// refused before the command does any work; log column names are checked where a log is read
/// (read_raw_log).

#include <CLI/CLI.hpp>

namespace gpilqg::cli {

/// Throws InputError naming the first argument of the parsed command chain under `app` that is not
/// valid UTF-8, when that command was given `--json`: "FILE 'log\xff.csv': is not valid UTF-8;
/// expected UTF-8 names with --json (JSON output holds only UTF-8 text)".
void check_json_arguments(const CLI::App& app);

}  // namespace gpilqg::cli
