#pragma once
/// @file utf8.hpp
/// Names that reach JSON output (file names, log column names, task names) must be valid UTF-8:
/// JSON text is Unicode, and a name of other bytes cannot be written into it. These two functions
/// are the one test of that rule and the one way such a name is shown in an error message.

#include <string>
#include <string_view>

namespace gpilqg {

/// True when `text` is well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates, at most
/// U+10FFFF).
bool is_valid_utf8(std::string_view text);

/// `text` with every byte outside printable ASCII, and the backslash, written as \xNN, so that an
/// error message about a name shows its exact bytes and is itself plain ASCII: "log\xff.csv".
std::string escaped_bytes(std::string_view text);

}  // namespace gpilqg
