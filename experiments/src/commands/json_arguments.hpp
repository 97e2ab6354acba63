#pragma once
/// @file json_arguments.hpp
/// Names in JSON output must be valid UTF-8 (core/utf8.hpp). A command asked for `--json`, or for an
/// output that holds a JSON document (`diagnose --out`: its report attribute), echoes its arguments
/// (file names above all) into the document, so an argument that is not UTF-8 is refused before the
/// command does any work; log column names are checked where a log is read (read_raw_log).

#include <CLI/CLI.hpp>

namespace gpilqg::cli {

/// Marks `option` as one whose use writes JSON text (as `--json` does): its command's arguments must
/// then be UTF-8. Returns `option`.
CLI::Option* writes_json(CLI::Option* option);

/// Throws InputError naming the first argument of the parsed command chain under `app` that is not
/// valid UTF-8, when that command was given `--json` or an option marked by writes_json: "FILE 'log\xff.csv': is not valid UTF-8;
/// expected UTF-8 names with --json (JSON output holds only UTF-8 text)".
void check_json_arguments(const CLI::App& app);

}  // namespace gpilqg::cli
