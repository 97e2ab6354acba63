#include "urdf_actuators.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/limits.hpp"

namespace gpilqg::urdf {
namespace {

/// One start or end tag of the XML text, with its attributes (entities decoded).
struct Tag {
  std::string name;
  std::map<std::string, std::string> attributes;
  long line = 1;             ///< of its '<' in the text
  bool closing = false;       ///< </name>
  bool self_closing = false;  ///< <name ... />
};

std::string decode_entities(const std::string& s) {
  static const std::pair<const char*, char> entities[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    bool replaced = false;
    if (s[i] == '&')
      for (const auto& [entity, c] : entities)
        if (s.compare(i, std::char_traits<char>::length(entity), entity) == 0) {
          out += c;
          i += std::char_traits<char>::length(entity);
          replaced = true;
          break;
        }
    if (!replaced) out += s[i++];
  }
  return out;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/// The tags of the text in order, skipping comments, processing instructions, declarations and CDATA.
std::vector<Tag> tags(const std::string& text, const std::string& path) {
  std::vector<Tag> out;
  const auto fail = [&](std::size_t at, const std::string& what) {
    const long line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(std::min(at, text.size())), '\n');
    throw std::invalid_argument(fmt::format("{}: line {}: {}; expected a well-formed URDF (XML)", path, line, what));
  };
  std::size_t i = 0;
  while ((i = text.find('<', i)) != std::string::npos) {
    const auto skip_to = [&](const char* end) {
      const std::size_t e = text.find(end, i);
      if (e == std::string::npos) fail(i, fmt::format("no closing '{}'", end));
      i = e + std::char_traits<char>::length(end);
    };
    if (text.compare(i, 4, "<!--") == 0) { skip_to("-->"); continue; }
    if (text.compare(i, 9, "<![CDATA[") == 0) { skip_to("]]>"); continue; }
    if (text.compare(i, 2, "<?") == 0) { skip_to("?>"); continue; }
    if (text.compare(i, 2, "<!") == 0) { skip_to(">"); continue; }
    Tag tag;
    tag.line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(i), '\n');
    std::size_t p = i + 1;
    if (p < text.size() && text[p] == '/') {
      tag.closing = true;
      ++p;
    }
    const std::size_t name_start = p;
    while (p < text.size() && !is_space(text[p]) && text[p] != '>' && text[p] != '/') ++p;
    tag.name = text.substr(name_start, p - name_start);
    if (tag.name.empty()) fail(i, "a tag without a name");
    for (;;) {
      while (p < text.size() && is_space(text[p])) ++p;
      if (p >= text.size()) fail(i, fmt::format("the tag <{}> is not closed", tag.name));
      if (text[p] == '>') { ++p; break; }
      if (text.compare(p, 2, "/>") == 0) { tag.self_closing = true; p += 2; break; }
      const std::size_t key_start = p;
      while (p < text.size() && !is_space(text[p]) && text[p] != '=' && text[p] != '>' && text[p] != '/') ++p;
      const std::string key = text.substr(key_start, p - key_start);
      while (p < text.size() && is_space(text[p])) ++p;
      if (key.empty() || p >= text.size() || text[p] != '=')
        fail(p, fmt::format("a malformed attribute in <{}>", tag.name));
      ++p;
      while (p < text.size() && is_space(text[p])) ++p;
      if (p >= text.size() || (text[p] != '"' && text[p] != '\''))
        fail(p, fmt::format("attribute '{}' of <{}> has no quoted value", key, tag.name));
      const char quote = text[p++];
      const std::size_t end = text.find(quote, p);
      if (end == std::string::npos) fail(p, fmt::format("attribute '{}' of <{}> is not closed", key, tag.name));
      tag.attributes[key] = decode_entities(text.substr(p, end - p));
      p = end + 1;
    }
    out.push_back(std::move(tag));
    i = p;
  }
  return out;
}

bool actuated_type(const std::string& type) {
  return type == "revolute" || type == "continuous" || type == "prismatic";
}

/// The URDF joint types the MuJoCo system takes (a floating joint it refuses later, by its own rule).
bool known_type(const std::string& type) { return actuated_type(type) || type == "fixed" || type == "floating"; }

/// A number of the file: finite, nothing after it but spaces; nullopt otherwise.
std::optional<double> finite_number(const std::string& s) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(s.c_str(), &end);
  std::string rest(end == nullptr ? "" : end);
  while (!rest.empty() && is_space(rest.back())) rest.pop_back();
  if (s.empty() || !rest.empty() || errno != 0 || !std::isfinite(value)) return std::nullopt;
  return value;
}

/// The numeric attributes of URDF elements that MuJoCo reads, with their number of values. MuJoCo takes
/// a NaN or an infinity with a warning only and then drops some (a NaN rpy becomes no rotation) or
/// carries others into the simulation.
struct NumericAttribute {
  const char* element;
  const char* attribute;
  int count;
};

constexpr NumericAttribute kNumericAttributes[] = {
    {"origin", "xyz", 3},       {"origin", "rpy", 3},        {"axis", "xyz", 3},         {"mass", "value", 1},
    {"inertia", "ixx", 1},      {"inertia", "ixy", 1},       {"inertia", "ixz", 1},      {"inertia", "iyy", 1},
    {"inertia", "iyz", 1},      {"inertia", "izz", 1},       {"limit", "lower", 1},      {"limit", "upper", 1},
    {"limit", "velocity", 1},   {"dynamics", "damping", 1},  {"dynamics", "friction", 1}, {"box", "size", 3},
    {"cylinder", "radius", 1},  {"cylinder", "length", 1},   {"sphere", "radius", 1},    {"mesh", "scale", 3},
};

/// Checks every numeric attribute of `t` that MuJoCo reads (kNumericAttributes): `count` finite numbers
/// separated by spaces, and a joint's damping and friction >= 0 (a negative one adds energy).
void check_numbers(const Tag& t, const std::string& path) {
  for (const NumericAttribute& a : kNumericAttributes) {
    if (t.name != a.element) continue;
    const auto found = t.attributes.find(a.attribute);
    if (found == t.attributes.end()) continue;
    std::vector<std::string> words;
    std::size_t p = 0;
    const std::string& text = found->second;
    while (p < text.size()) {
      while (p < text.size() && is_space(text[p])) ++p;
      const std::size_t start = p;
      while (p < text.size() && !is_space(text[p])) ++p;
      if (p > start) words.push_back(text.substr(start, p - start));
    }
    bool ok = static_cast<int>(words.size()) == a.count;
    for (const std::string& w : words) ok = ok && finite_number(w).has_value();
    if (!ok)
      throw std::invalid_argument(fmt::format("{}: line {}: <{} {}=\"{}\">; expected {} finite number{}", path, t.line,
                                              a.element, a.attribute, text, a.count, a.count == 1 ? "" : "s"));
    if (t.name == "dynamics" && *finite_number(words.front()) < 0.0)
      throw std::invalid_argument(fmt::format(
          "{}: line {}: <dynamics {}=\"{}\">; expected a value >= 0 (a negative one adds energy: the joint would speed "
          "itself up)",
          path, t.line, a.attribute, text));
  }
  if (t.name == "limit" && t.attributes.contains("lower") && t.attributes.contains("upper") &&
      *finite_number(t.attributes.at("lower")) > *finite_number(t.attributes.at("upper")))
    throw std::invalid_argument(fmt::format("{}: line {}: <limit lower=\"{}\" upper=\"{}\">; expected lower <= upper "
                                            "(MuJoCo would drop the limits without a word)",
                                            path, t.line, t.attributes.at("lower"), t.attributes.at("upper")));
}

/// The name with the characters XML attribute values cannot hold escaped.
std::string xml_escaped(const std::string& name) {
  std::string escaped;
  for (const char c : name) {
    if (c == '"') escaped += "&quot;";
    else if (c == '&') escaped += "&amp;";
    else if (c == '<') escaped += "&lt;";
    else escaped += c;
  }
  return escaped;
}

/// The mimic of joint `j` read from its <mimic> tag `t`.
Mimic read_mimic(const Tag& t, const Joint& j, const std::string& path) {
  Mimic mimic;
  const auto leader = t.attributes.find("joint");
  if (leader == t.attributes.end() || leader->second.empty())
    throw std::invalid_argument(fmt::format("{}: line {}: joint '{}': <mimic> without a joint; expected "
                                            "<mimic joint=\"<the joint it follows>\" multiplier=\"..\" offset=\"..\"/>",
                                            path, t.line, j.name));
  mimic.joint = leader->second;
  for (const auto& [key, field] : {std::pair{"multiplier", &mimic.multiplier}, std::pair{"offset", &mimic.offset}}) {
    const auto a = t.attributes.find(key);
    if (a == t.attributes.end()) continue;
    const std::optional<double> value = finite_number(a->second);
    if (!value)
      throw std::invalid_argument(fmt::format("{}: line {}: joint '{}': <mimic {}=\"{}\">; expected a finite number",
                                              path, t.line, j.name, key, a->second));
    *field = *value;
  }
  return mimic;
}

/// Every <mimic> names another moving joint of the file, one that does not itself mimic.
void check_mimics(const std::vector<Joint>& joints, const std::string& path) {
  for (const Joint& j : joints) {
    if (!j.mimic) continue;
    const auto leader = std::find_if(joints.begin(), joints.end(), [&](const Joint& o) { return o.name == j.mimic->joint; });
    const std::string why = leader == joints.end()        ? "no joint of the file has that name"
                            : leader->name == j.name       ? "a joint cannot follow itself"
                            : !actuated_type(leader->type) ? fmt::format("it is a {} joint", leader->type)
                            : leader->mimic                ? "it mimics another joint itself"
                                                           : "";
    if (!why.empty())
      throw std::invalid_argument(fmt::format("{}: line {}: joint '{}' mimics '{}': {}; expected a revolute, "
                                              "continuous or prismatic joint that moves by itself",
                                              path, j.line, j.name, j.mimic->joint, why));
    if (!actuated_type(j.type))
      throw std::invalid_argument(fmt::format("{}: line {}: joint '{}' is {} and has a <mimic>; only a revolute, "
                                              "continuous or prismatic joint can follow another",
                                              path, j.line, j.name, j.type));
  }
}

}  // namespace

bool is_urdf(const std::string& text) {
  // The first element after the prolog (declaration, comments, processing instructions, DOCTYPE).
  std::size_t i = 0;
  while ((i = text.find('<', i)) != std::string::npos) {
    const char* end = text.compare(i, 4, "<!--") == 0 ? "-->" : text.compare(i, 2, "<?") == 0 ? "?>"
                      : text.compare(i, 2, "<!") == 0 ? ">" : nullptr;
    if (end == nullptr) break;
    const std::size_t e = text.find(end, i);
    if (e == std::string::npos) return false;  // MuJoCo's own parser reports malformed XML
    i = e + std::char_traits<char>::length(end);
  }
  if (i == std::string::npos) return false;
  std::size_t p = i + 1;
  while (p < text.size() && !is_space(text[p]) && text[p] != '>' && text[p] != '/') ++p;
  return text.compare(i + 1, p - i - 1, "robot") == 0 && p - i - 1 == 5;
}

std::vector<Joint> read_joints(const std::string& text, const std::string& path) {
  const std::vector<Tag> all = tags(text, path);
  std::vector<Joint> out;
  int depth = 0;           // element depth: <robot> is 1, its <joint> children 2
  bool in_joint = false;   // inside a <joint> child of <robot> (not a <transmission>'s <joint>)
  for (const Tag& t : all) {
    if (t.closing) {
      if (depth == 2 && t.name == "joint") in_joint = false;
      --depth;
      continue;
    }
    check_numbers(t, path);
    const int level = depth + 1;
    if (level == 2 && t.name == "joint") {
      Joint j;
      const auto name = t.attributes.find("name");
      const auto type = t.attributes.find("type");
      if (name == t.attributes.end() || name->second.empty())
        throw std::invalid_argument(fmt::format("{}: joint {} has no name; every joint needs one", path, out.size()));
      j.name = name->second;
      j.type = type == t.attributes.end() ? "" : type->second;
      j.line = t.line;
      if (j.type == "planar")
        throw std::invalid_argument(fmt::format(
            "{}: line {}: joint '{}' is planar; gpilqg supports hinge and slide joints only, and MuJoCo would make "
            "it three joints without motors: write it as two prismatic joints and a revolute one, with links "
            "between them",
            path, t.line, j.name));
      if (!known_type(j.type))
        throw std::invalid_argument(fmt::format(
            "{}: line {}: joint '{}' has type \"{}\"; expected one of revolute, continuous, prismatic, fixed, "
            "floating (URDF's types, in lower case)",
            path, t.line, j.name, j.type));
      out.push_back(j);
      in_joint = !t.self_closing;
    } else if (level == 3 && in_joint && t.name == "limit") {
      const auto effort = t.attributes.find("effort");
      if (effort != t.attributes.end()) {
        const std::optional<double> value = finite_number(effort->second);
        if (!value || *value < 0.0 || *value > limits::kMaxControlBound)
          throw std::invalid_argument(fmt::format(
              "{}: joint '{}': <limit effort=\"{}\">; expected a finite number from 0 to {:g} (the motor's bound, N m or "
              "N; 0 leaves the joint without a motor; no limit: leave effort out)",
              path, out.back().name, effort->second, limits::kMaxControlBound));
        out.back().effort = *value;
      }
    } else if (level == 3 && in_joint && t.name == "mimic") {
      out.back().mimic = read_mimic(t, out.back(), path);
    }
    if (!t.self_closing) ++depth;
  }
  check_mimics(out, path);
  return out;
}

std::string actuator_section(const std::vector<Joint>& joints, const std::vector<std::string>& model_joints,
                             const std::string& path) {
  std::string motors;
  for (const std::string& name : model_joints) {
    const Joint* joint = nullptr;
    for (const Joint& j : joints)
      if (j.name == name) joint = &j;
    if (joint == nullptr || !actuated_type(joint->type)) continue;
    if (joint->effort && *joint->effort == 0.0) continue;  // a passive joint
    if (joint->mimic) continue;                             // held at its leader (equality_section)
    const std::string motor = name + "_motor";
    for (const std::string& other : model_joints)
      if (other == motor)
        throw std::invalid_argument(
            fmt::format("{}: joint '{}' would get the motor '{}', the name of another joint; rename one of them", path,
                        name, motor));
    const std::string escaped = xml_escaped(name);
    if (joint->effort)
      motors += fmt::format("    <motor name=\"{0}_motor\" joint=\"{0}\" gear=\"1\" ctrllimited=\"true\" "
                            "ctrlrange=\"{1:.17g} {2:.17g}\"/>\n",
                            escaped, -*joint->effort, *joint->effort);
    else
      motors +=
          fmt::format("    <motor name=\"{0}_motor\" joint=\"{0}\" gear=\"1\" ctrllimited=\"false\"/>\n", escaped);
  }
  return motors.empty() ? "" : "  <actuator>\n" + motors + "  </actuator>\n";
}

std::string equality_section(const std::vector<Joint>& joints) {
  std::string held;
  for (const Joint& j : joints)
    if (j.mimic)
      held += fmt::format("    <joint joint1=\"{}\" joint2=\"{}\" polycoef=\"{:.17g} {:.17g} 0 0 0\" solimp=\"0.9999 0.9999 0.001\"/>\n",
                          xml_escaped(j.name), xml_escaped(j.mimic->joint), j.mimic->offset, j.mimic->multiplier);
  return held.empty() ? "" : "  <equality>\n" + held + "  </equality>\n";
}

}  // namespace gpilqg::urdf
