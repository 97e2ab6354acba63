#pragma once
/// @file utc_time.hpp
/// The `created` stamp of every file gpilqg writes (results, reports, profiles, policies).

#include <string>

namespace gpilqg {

/// The current time in UTC as ISO 8601 to the second, e.g. "2026-11-24T01:02:03Z".
std::string utc_timestamp();

}  // namespace gpilqg
