#include "urdf_actuators.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

namespace gpilqg::urdf {
namespace {

/// One start or end tag of the XML text, with its attributes (entities decoded).
struct Tag {
  std::string name;
  std::map<std::string, std::string> attributes;
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
    const int level = depth + 1;
    if (level == 2 && t.name == "joint") {
      Joint j;
      const auto name = t.attributes.find("name");
      const auto type = t.attributes.find("type");
      if (name == t.attributes.end() || name->second.empty())
        throw std::invalid_argument(fmt::format("{}: joint {} has no name; every joint needs one", path, out.size()));
      j.name = name->second;
      j.type = type == t.attributes.end() ? "" : type->second;
      out.push_back(j);
      in_joint = !t.self_closing;
    } else if (level == 3 && in_joint && t.name == "limit") {
      const auto effort = t.attributes.find("effort");
      if (effort != t.attributes.end()) {
        const std::string& s = effort->second;
        char* end = nullptr;
        errno = 0;
        const double value = std::strtod(s.c_str(), &end);
        std::string rest(end == nullptr ? "" : end);
        while (!rest.empty() && is_space(rest.back())) rest.pop_back();
        if (s.empty() || !rest.empty() || errno != 0 || !std::isfinite(value) || value < 0.0)
          throw std::invalid_argument(fmt::format(
              "{}: joint '{}': <limit effort=\"{}\">; expected a finite number >= 0 (the motor's bound, N m or N; "
              "0 leaves the joint without a motor)",
              path, out.back().name, s));
        out.back().effort = value;
      }
    }
    if (!t.self_closing) ++depth;
  }
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
    const std::string motor = name + "_motor";
    for (const std::string& other : model_joints)
      if (other == motor)
        throw std::invalid_argument(
            fmt::format("{}: joint '{}' would get the motor '{}', the name of another joint; rename one of them", path,
                        name, motor));
    std::string escaped;
    for (const char c : name) {
      if (c == '"') escaped += "&quot;";
      else if (c == '&') escaped += "&amp;";
      else if (c == '<') escaped += "&lt;";
      else escaped += c;
    }
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

}  // namespace gpilqg::urdf
