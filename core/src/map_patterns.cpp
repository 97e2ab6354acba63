/// Patterns of an import map (map_patterns.hpp): parsing, matching a name, and expanding the
/// patterns of [states] and [controls] over a system's names.

#include "gpilqg/core/map_patterns.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg {

namespace {

constexpr std::string_view kPlaceholder = "{i}";

/// A piece of a column template: literal text, or the placeholder with its offset (none: the
/// digits as written).
struct ColumnPiece {
  std::string text;
  bool placeholder = false;
  std::optional<long> offset;
};

bool all_digits(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

/// A column template read into pieces, or the problem with it.
struct ColumnTemplate {
  std::vector<ColumnPiece> pieces;
  std::string problem;  ///< empty when the template is well formed
};

ColumnTemplate parse_column(const std::string& column) {
  std::vector<ColumnPiece> pieces;
  const auto failed = [](std::string problem) { return ColumnTemplate{{}, std::move(problem)}; };
  std::size_t at = 0;
  while (at < column.size()) {
    const std::size_t open = column.find_first_of("{}", at);
    if (open == std::string::npos) {
      pieces.push_back({column.substr(at), false, std::nullopt});
      break;
    }
    if (open > at) pieces.push_back({column.substr(at, open - at), false, std::nullopt});
    const std::size_t close = column.find('}', open);
    if (column[open] == '}' || close == std::string::npos)
      return failed(fmt::format("the column '{}' has an unmatched brace", column));
    const std::string inside = column.substr(open + 1, close - open - 1);
    ColumnPiece piece{"", true, std::nullopt};
    if (inside != "i") {
      const std::string number = inside.size() > 2 ? inside.substr(2) : "";
      if (inside.size() < 3 || inside[0] != 'i' || (inside[1] != '+' && inside[1] != '-') || !all_digits(number) ||
          number.size() > 9)
        return failed(fmt::format("'{{{}}}' in the column '{}' is not a placeholder; expected {{i}}, {{i+K}} or {{i-K}}",
                                  inside, column));
      piece.offset = (inside[1] == '-' ? -1 : 1) * std::stol(number);
    }
    pieces.push_back(piece);
    at = close + 1;
  }
  if (std::none_of(pieces.begin(), pieces.end(), [](const ColumnPiece& p) { return p.placeholder; }))
    return failed(fmt::format("the column '{}' has no placeholder, so every name would read the same column", column));
  return {pieces, ""};
}

/// The digits that the target pattern's {i} stands for in `name`, or nullopt when it does not match.
std::optional<std::string> matched_digits(const std::string& target, const std::string& name) {
  const std::size_t at = target.find(kPlaceholder);
  const std::string prefix = target.substr(0, at), suffix = target.substr(at + kPlaceholder.size());
  if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix))
    return std::nullopt;
  std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  if (!all_digits(digits)) return std::nullopt;
  return digits;
}

[[noreturn]] void pattern_error(const ColumnMapping& pattern, const std::string& problem, const std::string& expected) {
  throw DataError(pattern.origin.file, pattern.origin.location(), fmt::format("field '{}': {}", pattern.origin.field, problem),
                  expected);
}

/// The patterns of one section expanded over `names` into `mappings` (after its explicit entries).
void expand_section(const std::vector<ColumnMapping>& patterns, const std::vector<Quantity>& names, const char* kind,
                    const std::string& system, std::vector<ColumnMapping>& mappings) {
  const std::size_t explicit_count = mappings.size();
  std::vector<bool> matched(patterns.size(), false);
  for (const Quantity& q : names) {
    const bool explicit_entry = std::any_of(mappings.begin(), mappings.begin() + static_cast<long>(explicit_count),
                                            [&](const ColumnMapping& m) { return m.target == q.name; });
    const ColumnMapping* chosen = nullptr;
    for (std::size_t p = 0; p < patterns.size(); ++p) {
      if (!matched_digits(patterns[p].target, q.name)) continue;
      matched[p] = true;
      if (explicit_entry) continue;
      if (chosen != nullptr)
        pattern_error(patterns[p],
                      fmt::format("{} '{}' is matched by this pattern '{}' and by '{}' ({})", kind, q.name, patterns[p].target,
                                  chosen->target, chosen->origin.location()),
                      fmt::format("one pattern per {}, or an explicit line for '{}', which wins over the patterns", kind, q.name));
      chosen = &patterns[p];
    }
    if (chosen == nullptr) continue;
    ColumnMapping mapping = *chosen;
    mapping.target = q.name;
    mapping.column = *pattern_column(*chosen, q.name);
    mapping.pattern = fmt::format("'{}' = '{}'", chosen->target, chosen->column);
    mappings.push_back(std::move(mapping));
  }
  for (std::size_t p = 0; p < patterns.size(); ++p)
    if (!matched[p])
      pattern_error(patterns[p], fmt::format("the pattern '{}' matches no {} of {}", patterns[p].target, kind, system),
                    fmt::format("a pattern whose {{i}} (a whole number) makes it one of the {}s: {}", kind,
                                fmt::join(names_of(names), ", ")));
}

}  // namespace

bool is_pattern(const std::string& target) { return target.find_first_of("{}") != std::string::npos; }

std::optional<std::string> pattern_syntax_problem(const std::string& target, const std::string& column) {
  const std::size_t at = target.find(kPlaceholder);
  if (at == std::string::npos || target.find_first_of("{}", at + kPlaceholder.size()) != std::string::npos ||
      target.find_first_of("{}") != at)
    return fmt::format("the pattern '{}' must hold the placeholder {{i}} exactly once, and no other brace", target);
  const ColumnTemplate parsed = parse_column(column);
  if (!parsed.problem.empty()) return parsed.problem;
  return std::nullopt;
}

std::optional<std::string> pattern_column(const ColumnMapping& pattern, const std::string& name) {
  const auto digits = matched_digits(pattern.target, name);
  if (!digits) return std::nullopt;
  const ColumnTemplate parsed = parse_column(pattern.column);
  std::string column;
  for (const ColumnPiece& piece : parsed.pieces) {
    if (!piece.placeholder) {
      column += piece.text;
    } else if (!piece.offset) {
      column += *digits;
    } else {
      if (digits->size() > 15)
        pattern_error(pattern, fmt::format("the number {} in '{}' is too long for an offset", *digits, name),
                      "at most 15 digits");
      const long value = std::stol(*digits) + *piece.offset;
      if (value < 0)
        pattern_error(pattern, fmt::format("for '{}' the column '{}' gives the number {}", name, pattern.column, value),
                      "an offset that keeps every number >= 0");
      column += std::to_string(value);
    }
  }
  return column;
}

LogMap expand_patterns(const LogMap& map, const SystemSignature& system) {
  LogMap out = map;
  expand_section(map.state_patterns, system.states, "state", system.name, out.states);
  expand_section(map.control_patterns, system.controls, "control", system.name, out.controls);
  out.state_patterns.clear();
  out.control_patterns.clear();
  return out;
}

}  // namespace gpilqg
