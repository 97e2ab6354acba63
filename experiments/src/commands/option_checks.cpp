/// Numeric option checks: whole numbers and finite numbers within a range (option_checks.hpp).

#include "option_checks.hpp"

#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace gpilqg::cli {

CLI::Validator integer_in(long long min, long long max) {
  const std::string expected = fmt::format("expected a whole number from {} to {}", min, max);
  return CLI::Validator(
      [min, max, expected](std::string& text) -> std::string {
        long long value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (error == std::errc::result_out_of_range || (error == std::errc() && stop == end && (value < min || value > max)))
          return fmt::format("is {}; {}", text, expected);
        if (error != std::errc() || stop != end || text.empty()) return fmt::format("'{}' is not a whole number; {}", text, expected);
        return {};
      },
      fmt::format("INT in [{}, {}]", min, max));
}

CLI::Validator number_in(double min, double max, bool open_min) {
  const std::string range = max == std::numeric_limits<double>::max()
                                ? fmt::format("{} {}", open_min ? ">" : ">=", min)
                                : fmt::format("{} {} and <= {}", open_min ? ">" : ">=", min, max);
  const std::string expected = "expected a finite number " + range;
  return CLI::Validator(
      [min, max, open_min, expected](std::string& text) -> std::string {
        double value = 0.0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (error != std::errc() || stop != end || text.empty()) return fmt::format("'{}' is not a number; {}", text, expected);
        if (!std::isfinite(value) || value < min || value > max || (open_min && value == min))
          return fmt::format("is {}; {}", text, expected);
        return {};
      },
      "NUMBER " + range);
}

}  // namespace gpilqg::cli
