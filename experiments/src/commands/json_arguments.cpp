/// The UTF-8 check of a `--json` command's arguments (json_arguments.hpp).

#include "json_arguments.hpp"

#include <fmt/format.h>

#include "gpilqg/core/utf8.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::cli {

namespace {

void check_command(const CLI::App& command) {
  const CLI::Option* json = command.get_option_no_throw("--json");
  if (json != nullptr && json->count() > 0)
    for (const CLI::Option* option : command.get_options())
      for (const std::string& value : option->results())
        if (!is_valid_utf8(value))
          throw InputError(fmt::format("{} '{}': is not valid UTF-8; expected UTF-8 names with --json (JSON output "
                                       "holds only UTF-8 text)",
                                       option->get_name(), escaped_bytes(value)));
  for (const CLI::App* sub : command.get_subcommands()) check_command(*sub);
}

}  // namespace

void check_json_arguments(const CLI::App& app) { check_command(app); }

}  // namespace gpilqg::cli
