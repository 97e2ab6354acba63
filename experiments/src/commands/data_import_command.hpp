#pragma once
/// @file data_import_command.hpp
/// `gpilqg data import LOG --system NAME --map MAP.toml --out FILE [--json]`, registered under
/// `gpilqg data` by data_command.cpp.

#include "commands.hpp"

namespace gpilqg::cli {

/// Adds the `import` subcommand to the `data` command.
void add_data_import_command(CLI::App& data, CommandAction& action);

}  // namespace gpilqg::cli
