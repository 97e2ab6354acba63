/// The UTF-8 check of a `--json` command's arguments (json_arguments.hpp).

#include "json_arguments.hpp"

#include <fmt/format.h>

#include <set>

#include "gpilqg/core/utf8.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::cli {

namespace {

std::set<const CLI::Option*>& marked() {
  static std::set<const CLI::Option*> options;
  return options;
}

/// The option of `command` that asks for JSON text ("--json", or a marked one), or "".
std::string json_option(const CLI::App& command) {
  for (const CLI::Option* option : command.get_options())
    if (option->count() > 0 && (option->get_name() == "--json" || marked().count(option) > 0)) return option->get_name();
  return {};
}

void check_command(const CLI::App& command) {
  if (const std::string json = json_option(command); !json.empty())
    for (const CLI::Option* option : command.get_options())
      for (const std::string& value : option->results())
        if (!is_valid_utf8(value))
          throw InputError(fmt::format("{} '{}': is not valid UTF-8; expected UTF-8 names with {} (JSON output "
                                       "holds only UTF-8 text)",
                                       option->get_name(), escaped_bytes(value), json));
  for (const CLI::App* sub : command.get_subcommands()) check_command(*sub);
}

}  // namespace

CLI::Option* writes_json(CLI::Option* option) {
  marked().insert(option);
  return option;
}

void check_json_arguments(const CLI::App& app) { check_command(app); }

}  // namespace gpilqg::cli
