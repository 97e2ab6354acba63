#include "gpilqg/core/basis_terms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace gpilqg {

namespace {

/// The factors' texts, in the order of BasisFunction (Control handled apart).
constexpr std::pair<BasisFunction, std::string_view> kTexts[] = {
    {BasisFunction::Velocity, "qdot"},
    {BasisFunction::TanhVelocity, "tanh(qdot/v0)"},
    {BasisFunction::SignedSquareVelocity, "qdot*abs(qdot)"},
    {BasisFunction::Position, "q"},
    {BasisFunction::PositionSquared, "q^2"},
    {BasisFunction::PositionCubed, "q^3"},
    {BasisFunction::Sine, "sin(q)"},
    {BasisFunction::Cosine, "cos(q)"},
    {BasisFunction::One, "1"},
};

std::string control_text(int j, const std::vector<Quantity>& controls) {
  return controls.size() == 1 ? std::string("u") : "u:" + controls[static_cast<std::size_t>(j)].name;
}

std::string control_names(const std::vector<Quantity>& controls) {
  std::string out;
  for (const Quantity& c : controls) out += (out.empty() ? "u:" : ", u:") + c.name;
  return out;
}

/// The factor written `text` (no whitespace), or nothing when it is not one; throws for "u" with
/// several controls and an unknown "u:<name>".
std::optional<BasisFactor> parse_factor(std::string_view text, std::string_view term,
                                        const std::vector<Quantity>& controls) {
  for (const auto& [function, name] : kTexts)
    if (text == name) return BasisFactor{function, -1};
  if (text == "u") {
    if (controls.size() == 1) return BasisFactor{BasisFunction::Control, 0};
    if (controls.empty()) throw std::invalid_argument(fmt::format("term '{}': the system has no controls", term));
    throw std::invalid_argument(fmt::format("term '{}': 'u' is ambiguous with {} controls; expected one of: {}", term,
                                            controls.size(), control_names(controls)));
  }
  if (text.substr(0, 2) == "u:" && text.find('*') == std::string_view::npos) {
    const std::string name(text.substr(2));
    const int j = index_of(controls, name);
    if (j < 0)
      throw std::invalid_argument(fmt::format("term '{}': unknown control '{}'; expected one of: {}", term, name,
                                              control_names(controls)));
    return BasisFactor{BasisFunction::Control, j};
  }
  return std::nullopt;
}

std::string power(const std::string& unit, int n) {
  if (unit.empty()) return unit;
  const bool compound = unit.find_first_of(" /*^") != std::string::npos;
  return (compound ? "(" + unit + ")" : unit) + "^" + std::to_string(n);
}

std::string factor_unit(const BasisFactor& f, const std::string& q, const std::string& q_dot,
                        const std::vector<Quantity>& controls) {
  switch (f.function) {
    case BasisFunction::Velocity: return q_dot;
    case BasisFunction::SignedSquareVelocity: return power(q_dot, 2);
    case BasisFunction::Position: return q;
    case BasisFunction::PositionSquared: return power(q, 2);
    case BasisFunction::PositionCubed: return power(q, 3);
    case BasisFunction::Control: return controls[static_cast<std::size_t>(f.control)].unit;
    case BasisFunction::TanhVelocity:
    case BasisFunction::Sine:
    case BasisFunction::Cosine:
    case BasisFunction::One: return "";
  }
  return "";
}

std::string factor_formula(const BasisFactor& f, const std::string& q, const std::string& q_dot,
                           const std::vector<Quantity>& controls, double v0) {
  switch (f.function) {
    case BasisFunction::Velocity: return q_dot;
    case BasisFunction::TanhVelocity: return fmt::format("tanh({}/{:g})", q_dot, v0);
    case BasisFunction::SignedSquareVelocity: return fmt::format("{}*abs({})", q_dot, q_dot);
    case BasisFunction::Position: return q;
    case BasisFunction::PositionSquared: return q + "^2";
    case BasisFunction::PositionCubed: return q + "^3";
    case BasisFunction::Sine: return "sin(" + q + ")";
    case BasisFunction::Cosine: return "cos(" + q + ")";
    case BasisFunction::Control: return controls[static_cast<std::size_t>(f.control)].name;
    case BasisFunction::One: return "1";
  }
  return "";
}

}  // namespace

FactorValue evaluate_factor(const BasisFactor& factor, double q, double q_dot, const VectorCRef& u, double v0) {
  FactorValue f;
  switch (factor.function) {
    case BasisFunction::Velocity:
      f.value = q_dot;
      f.d_qdot = 1.0;
      break;
    case BasisFunction::TanhVelocity: {
      const double t = std::tanh(q_dot / v0);
      f.value = t;
      f.d_qdot = (1.0 - t * t) / v0;
      break;
    }
    case BasisFunction::SignedSquareVelocity:
      f.value = q_dot * std::abs(q_dot);
      f.d_qdot = 2.0 * std::abs(q_dot);
      break;
    case BasisFunction::Position:
      f.value = q;
      f.d_q = 1.0;
      break;
    case BasisFunction::PositionSquared:
      f.value = q * q;
      f.d_q = 2.0 * q;
      break;
    case BasisFunction::PositionCubed:
      f.value = q * q * q;
      f.d_q = 3.0 * q * q;
      break;
    case BasisFunction::Sine:
      f.value = std::sin(q);
      f.d_q = std::cos(q);
      break;
    case BasisFunction::Cosine:
      f.value = std::cos(q);
      f.d_q = -std::sin(q);
      break;
    case BasisFunction::Control:
      f.value = u(factor.control);
      f.d_u = 1.0;
      break;
    case BasisFunction::One:
      break;
  }
  return f;
}

std::string basis_list(const std::vector<Quantity>& controls) {
  std::string out;
  for (const auto& [function, name] : kTexts) {
    if (function == BasisFunction::One) out += ", " + (controls.size() == 1 ? std::string("u") : control_names(controls));
    out += (out.empty() ? "" : ", ") + std::string(name);
  }
  return out;
}

BasisTerm parse_basis_term(std::string_view text, const std::vector<Quantity>& controls) {
  std::string s;
  for (char c : text)
    if (c != ' ' && c != '\t') s += c;
  // The pieces between '*'; a factor spans one piece, or two for "qdot*abs(qdot)". fewest[i] is the
  // fewest factors that make up pieces [0, i) (a shortest path over the pieces).
  std::vector<std::string> pieces(1);
  for (char c : s) {
    if (c == '*') pieces.emplace_back();
    else pieces.back() += c;
  }
  const std::size_t n = pieces.size();
  constexpr int kNone = std::numeric_limits<int>::max();
  std::vector<int> fewest(n + 1, kNone);
  std::vector<std::optional<BasisFactor>> last(n + 1);
  std::vector<std::size_t> from(n + 1, 0);
  fewest[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (fewest[i] == kNone) continue;
    std::string joined;
    for (std::size_t j = i; j < std::min(n, i + 2); ++j) {
      joined += (j == i ? "" : "*") + pieces[j];
      const auto factor = parse_factor(joined, text, controls);
      if (factor && fewest[i] + 1 < fewest[j + 1]) {
        fewest[j + 1] = fewest[i] + 1;
        last[j + 1] = factor;
        from[j + 1] = i;
      }
    }
  }
  const std::string expected = fmt::format("expected one of the basis {} or a product a*b of two of them", basis_list(controls));
  if (fewest[n] == kNone) {
    // Name the first piece that no factor explains.
    std::size_t bad = 0;
    while (bad < n && fewest[bad] != kNone) ++bad;
    const std::string& piece = pieces[bad == 0 ? 0 : bad - 1];
    if (piece.empty()) throw std::invalid_argument(fmt::format("term '{}': an empty factor; {}", text, expected));
    throw std::invalid_argument(fmt::format("term '{}': unknown factor '{}'; {}", text, piece, expected));
  }
  if (fewest[n] > 2)
    throw std::invalid_argument(fmt::format("term '{}' is a product of {} factors; expected at most two (a*b), each "
                                            "one of the basis {}",
                                            text, fewest[n], basis_list(controls)));
  BasisTerm term;
  for (std::size_t i = n; i > 0; i = from[i]) term.factors.insert(term.factors.begin(), *last[i]);
  return term;
}

std::string basis_term_text(const BasisTerm& term, const std::vector<Quantity>& controls) {
  std::string out;
  for (const BasisFactor& f : term.factors) {
    out += out.empty() ? "" : "*";
    if (f.function == BasisFunction::Control) {
      out += control_text(f.control, controls);
      continue;
    }
    for (const auto& [function, name] : kTexts)
      if (function == f.function) out += name;
  }
  return out;
}

std::string basis_term_formula(const BasisTerm& term, const std::string& q, const std::string& q_dot,
                               const std::vector<Quantity>& controls, double v0) {
  std::string out;
  for (const BasisFactor& f : term.factors) out += (out.empty() ? "" : "*") + factor_formula(f, q, q_dot, controls, v0);
  return out;
}

std::string basis_term_unit(const BasisTerm& term, const std::string& q_unit, const std::string& q_dot_unit,
                            const std::vector<Quantity>& controls) {
  std::string out;
  for (const BasisFactor& f : term.factors) {
    const std::string unit = factor_unit(f, q_unit, q_dot_unit, controls);
    if (!unit.empty()) out += (out.empty() ? "" : " ") + unit;
  }
  return out;
}

bool same_basis_term(const BasisTerm& a, const BasisTerm& b) {
  const auto key = [](const BasisTerm& t) {
    std::vector<std::pair<int, int>> out;
    for (const BasisFactor& f : t.factors) out.emplace_back(static_cast<int>(f.function), f.control);
    std::sort(out.begin(), out.end());
    return out;
  };
  return key(a) == key(b);
}

bool has_factor(const BasisTerm& term, BasisFunction function) {
  return std::any_of(term.factors.begin(), term.factors.end(),
                     [function](const BasisFactor& f) { return f.function == function; });
}

}  // namespace gpilqg
