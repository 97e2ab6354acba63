#pragma once
/// @file name_list.hpp
/// Lists of names (columns, attributes) for error messages, bounded in length whatever the input:
/// a header of 200000 columns must not make a message of megabytes.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace gpilqg::name_list {

/// The most names an error message lists before "... and N more".
inline constexpr std::size_t kMaxListedNames = 10;
/// The most characters of one name an error message shows before "...".
inline constexpr std::size_t kMaxNameChars = 40;

/// `name` in single quotes, cut to kMaxNameChars characters followed by "..." when longer.
std::string quoted(std::string_view name);

/// The first kMaxListedNames names, each quoted(), joined with ", ", then ", ... and N more" when
/// there are more, e.g. "'a', 'b', ... and 3 more".
std::string quoted_list(const std::vector<std::string>& names);
std::string quoted_list(const std::vector<std::string_view>& names);

/// The same with `separator` and the names unquoted (but cut like quoted()), e.g. for a header line
/// "episode,t,x,... and 7 more".
std::string plain_list(const std::vector<std::string>& names, std::string_view separator);
std::string plain_list(const std::vector<std::string_view>& names, std::string_view separator);

}  // namespace gpilqg::name_list
