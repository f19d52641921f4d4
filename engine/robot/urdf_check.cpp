// Strict checks of a URDF text before urdfdom reads it: urdfdom converts numbers leniently (a unit
// suffix or "inf" is logged and the element dropped, the link left massless) and follows parent
// links without a cycle check; both are refused here, located by tinyxml's line numbers.
#include "robot/urdf_check.hpp"

#include <tinyxml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string_view>
#include <vector>

#include "robot/urdf_error.hpp"

namespace ks::urdf_check {

namespace {

struct NumberAttr {
  const char* name;
  int count;         // how many numbers the attribute holds
  const char* unit;  // for the message
};

struct NumberElement {
  const char* parent;  // the element it must be a child of ("" = any)
  const char* tag;
  std::vector<NumberAttr> attrs;
};

// The numeric attributes urdfdom converts, by element.
const std::vector<NumberElement>& number_elements() {
  static const std::vector<NumberElement> table = {
      {"", "origin", {{"xyz", 3, "m"}, {"rpy", 3, "rad"}}},
      {"inertial", "mass", {{"value", 1, "kg"}}},
      {"inertial", "inertia",
       {{"ixx", 1, "kg m^2"}, {"ixy", 1, "kg m^2"}, {"ixz", 1, "kg m^2"}, {"iyy", 1, "kg m^2"}, {"iyz", 1, "kg m^2"},
        {"izz", 1, "kg m^2"}}},
      {"joint", "axis", {{"xyz", 3, "a direction"}}},
      {"joint", "limit", {{"lower", 1, "rad or m"}, {"upper", 1, "rad or m"}, {"velocity", 1, "rad/s or m/s"},
                          {"effort", 1, "N m or N"}}},
      {"joint", "dynamics", {{"damping", 1, ""}, {"friction", 1, ""}}},
      {"joint", "mimic", {{"multiplier", 1, ""}, {"offset", 1, ""}}},
      {"joint", "safety_controller", {{"soft_lower_limit", 1, ""}, {"soft_upper_limit", 1, ""}, {"k_position", 1, ""},
                                      {"k_velocity", 1, ""}}},
      {"joint", "calibration", {{"rising", 1, ""}, {"falling", 1, ""}}},
      {"geometry", "box", {{"size", 3, "m"}}},
      {"geometry", "cylinder", {{"radius", 1, "m"}, {"length", 1, "m"}}},
      {"geometry", "sphere", {{"radius", 1, "m"}}},
      {"geometry", "mesh", {{"scale", 3, ""}}},
  };
  return table;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// Why `text` is not `count` whitespace-separated finite numbers; "" when it is.
std::string number_problem(std::string_view text, int count) {
  int found = 0;
  std::size_t i = 0;
  while (true) {
    while (i < text.size() && is_space(text[i])) ++i;
    if (i == text.size()) break;
    std::size_t end = i;
    while (end < text.size() && !is_space(text[end])) ++end;
    std::string_view token = text.substr(i, end - i);
    i = end;
    ++found;
    std::string_view digits = token;
    if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-') digits.remove_prefix(1);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (ec == std::errc::result_out_of_range) return "'" + std::string(token) + "' is out of range";
    if (ec != std::errc() || ptr != digits.data() + digits.size()) {
      if (ec == std::errc() && ptr != digits.data())
        return "'" + std::string(token) + "' is a number followed by '" +
               std::string(digits.substr(static_cast<std::size_t>(ptr - digits.data()))) +
               "' (units are not part of URDF numbers)";
      return "'" + std::string(token) + "' is not a number";
    }
    if (!std::isfinite(v)) return "'" + std::string(token) + "' is not finite";
  }
  if (found != count)
    return "'" + std::string(text) + "' holds " + std::to_string(found) + (found == 1 ? " number" : " numbers");
  return "";
}

// Throws at the first byte that is not part of a well-formed UTF-8 sequence, or a NUL: tinyxml 2.6
// steps over a UTF-8 sequence by its lead byte's length, past the end of a text cut inside one.
void check_utf8(const std::string& xml, const std::string& file) {
  int line = 1;
  for (std::size_t i = 0; i < xml.size();) {
    const auto c = static_cast<unsigned char>(xml[i]);
    const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = n > 0 && c != 0 && i + n <= xml.size();
    for (std::size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(xml[i + k]) & 0xC0) == 0x80;
    if (!ok) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02X", c);
      throw UrdfError(file, line, std::string("byte ") + hex + (c == 0 ? " (NUL)" : " does not start a complete UTF-8 character") +
                                      "; expected a UTF-8 text");
    }
    if (c == '\n') ++line;
    i += n;
  }
}

// Throws at the first start tag nested deeper than kMaxElementDepth: tinyxml (and urdfdom after it)
// descend one call per level, and a text nested tens of thousands deep overflows the stack (and takes
// time quadratic in the depth before that). A scan of the markup only: comments, CDATA sections,
// processing instructions and declarations are stepped over, quoted attribute values may hold '>';
// whether the text is well-formed is tinyxml's to say.
void check_depth(const std::string& xml, const std::string& file) {
  const auto skip_past = [&](std::size_t from, std::string_view end) {
    const std::size_t at = xml.find(end, from);
    return at == std::string::npos ? xml.size() : at + end.size();
  };
  int depth = 0;
  for (std::size_t i = xml.find('<'); i < xml.size(); i = xml.find('<', i)) {
    const std::string_view rest = std::string_view(xml).substr(i);
    if (rest.starts_with("<!--")) {
      i = skip_past(i + 4, "-->");
    } else if (rest.starts_with("<![CDATA[")) {
      i = skip_past(i + 9, "]]>");
    } else if (rest.starts_with("<?")) {
      i = skip_past(i + 2, "?>");
    } else if (rest.starts_with("<!")) {  // <!DOCTYPE ...> with an internal subset in [ ]
      const std::size_t bracket = xml.find_first_of("[>", i);
      i = bracket != std::string::npos && xml[bracket] == '[' ? skip_past(skip_past(bracket, "]"), ">")
                                                               : skip_past(i, ">");
    } else if (rest.starts_with("</")) {
      --depth;
      i = skip_past(i, ">");
    } else {  // a start tag: up to its '>' outside quotes; "/>" closes it at once
      std::size_t k = i + 1;
      char quote = 0;
      for (; k < xml.size() && (quote || xml[k] != '>'); ++k)
        if (quote ? xml[k] == quote : xml[k] == '"' || xml[k] == '\'') quote = quote ? 0 : xml[k];
      const bool empty = k < xml.size() && xml[k - 1] == '/';
      if (!empty && ++depth > kMaxElementDepth) {
        const std::size_t line_start = xml.rfind('\n', i) == std::string::npos ? 0 : xml.rfind('\n', i) + 1;
        int column = 1;  // in characters: UTF-8 continuation bytes do not count
        for (std::size_t c = line_start; c < i; ++c) column += (static_cast<unsigned char>(xml[c]) & 0xC0) != 0x80;
        const int line = 1 + static_cast<int>(std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(i), '\n'));
        std::size_t name_end = i + 1;
        while (name_end < xml.size() && !is_space(xml[name_end]) && xml[name_end] != '>' && xml[name_end] != '/')
          ++name_end;
        throw UrdfError(file, line,
                        "element <" + xml.substr(i + 1, std::min<std::size_t>(name_end - i - 1, 40)) +
                            "> is nested " + std::to_string(depth) + " elements deep; expected at most " +
                            std::to_string(kMaxElementDepth) + " levels of nesting (a URDF robot needs about 5)",
                        column);
      }
      i = k < xml.size() ? k + 1 : xml.size();
    }
  }
}

class Checker {
 public:
  explicit Checker(const std::string& file) : file_(file) {}

  [[noreturn]] void fail(const TiXmlElement& at, const std::string& message) const {
    throw UrdfError(file_, at.Row(), message);
  }
  [[noreturn]] void fail_at_column(const TiXmlElement& at, const std::string& message) const {
    throw UrdfError(file_, at.Row(), message, at.Column());
  }

  // The number attributes of `e` and of its descendants; `owner` names the link or joint.
  void check_numbers(const TiXmlElement& e, const char* parent, const std::string& owner) const {
    for (const NumberElement& spec : number_elements()) {
      if (std::strcmp(spec.tag, e.Value()) != 0 || (*spec.parent && std::strcmp(spec.parent, parent) != 0)) continue;
      for (const NumberAttr& a : spec.attrs) {
        const char* value = e.Attribute(a.name);
        if (!value) continue;
        const std::string why = number_problem(value, a.count);
        if (why.empty()) continue;
        std::string expected = a.count == 1 ? "a finite number" : std::to_string(a.count) + " finite numbers";
        if (*a.unit) expected += std::string(" [") + a.unit + "]";
        fail(e, owner + ": <" + spec.tag + " " + a.name + "=\"" + value + "\">: " + why + "; expected " + expected);
      }
    }
    for (const TiXmlElement* c = e.FirstChildElement(); c; c = c->NextSiblingElement()) check_numbers(*c, e.Value(), owner);
  }

  // A revolute or prismatic joint's <limit>: lower <= upper, and lower < upper when both are given;
  // the omitted bounds into `omitted`.
  void check_limit(const TiXmlElement& joint, LimitsOmitted& omitted) const {
    const char* type = joint.Attribute("type");
    const char* name = joint.Attribute("name");
    if (!type || !name || (std::strcmp(type, "revolute") != 0 && std::strcmp(type, "prismatic") != 0)) return;
    const TiXmlElement* limit = joint.FirstChildElement("limit");
    if (!limit) return;  // urdfdom says a revolute or prismatic joint needs one
    const char* lower = limit->Attribute("lower");
    const char* upper = limit->Attribute("upper");
    if (!lower) omitted.lower.insert(name);
    if (!upper) omitted.upper.insert(name);
    if (!lower || !upper) return;
    const double lo = std::strtod(lower, nullptr), up = std::strtod(upper, nullptr);  // (checked numbers)
    const std::string at = "joint '" + std::string(name) + "': <limit lower=\"" + lower + "\" upper=\"" + upper + "\">: ";
    const char* unit = std::strcmp(type, "revolute") == 0 ? "rad" : "m";
    if (lo > up)
      fail_at_column(*limit, at + "lower > upper; expected lower <= upper [" + unit + "]");
    if (lo == up)
      fail_at_column(*limit, at + "lower = upper, a " + type + " joint that cannot move; expected lower < upper [" + unit +
                       "] (omit both for a joint without position limits, or make the joint fixed)");
  }

  struct Edge {
    std::string joint, parent;
    const TiXmlElement* at;
  };

  void check_graph(const TiXmlElement& robot) const {
    std::map<std::string, Edge> parent_of;  // child link -> the joint attaching it
    for (const TiXmlElement* j = robot.FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
      const TiXmlElement* p = j->FirstChildElement("parent");
      const TiXmlElement* c = j->FirstChildElement("child");
      const char* name = j->Attribute("name");
      if (!p || !c || !name || !p->Attribute("link") || !c->Attribute("link")) continue;  // urdfdom reports these
      const std::string child = c->Attribute("link"), parent = p->Attribute("link");
      if (child == parent)
        fail(*j, "joint '" + std::string(name) + "' attaches link '" + child +
                     "' to itself: a kinematic loop; expected a tree of links (closed chains cannot be simulated)");
      const auto [it, fresh] = parent_of.emplace(child, Edge{name, parent, j});
      if (!fresh)
        fail(*j, "link '" + child + "' is the child of joint '" + it->second.joint + "' (line " +
                     std::to_string(it->second.at->Row()) + ") and of joint '" + name +
                     "': a kinematic loop; expected a tree of links, each the child of one joint (closed chains "
                     "cannot be simulated)");
    }
    // each link's ancestors: a walk up that meets a link of the same walk is a cycle
    std::map<std::string, int> state;  // 1: on the current walk, 2: known to reach a root
    for (const auto& [start, edge] : parent_of) {
      std::vector<std::string> walk;
      std::string link = start;
      while (state[link] == 0) {
        state[link] = 1;
        walk.push_back(link);
        const auto up = parent_of.find(link);
        if (up == parent_of.end()) break;
        link = up->second.parent;
      }
      if (state[link] == 1 && parent_of.count(link)) {
        std::string joints;
        const TiXmlElement* first = parent_of.at(link).at;
        std::string l = link;
        do {
          const Edge& e = parent_of.at(l);
          joints += (joints.empty() ? "'" : ", '") + e.joint + "'";
          if (e.at->Row() < first->Row()) first = e.at;
          l = e.parent;
        } while (l != link);
        fail(*first, "the joints " + joints + " form a cycle (link '" + link +
                         "' is its own ancestor): a kinematic loop; expected a tree of links (closed chains cannot "
                         "be simulated)");
      }
      for (const std::string& w : walk) state[w] = 2;
    }
  }

 private:
  std::string file_;
};

}  // namespace

LimitsOmitted check_text(const std::string& xml, const std::string& file) {
  check_utf8(xml, file);
  check_depth(xml, file);
  TiXmlDocument doc;  // urdfdom's own XML parser; its errors carry a line
  doc.Parse(xml.c_str());
  if (doc.Error()) throw UrdfError(file, doc.ErrorRow(), std::string("XML parse error: ") + doc.ErrorDesc());
  LimitsOmitted omitted;
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (!robot) return omitted;  // urdfdom says so
  const Checker check(file);
  for (const TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const bool link = std::strcmp(e->Value(), "link") == 0;
    if (!link && std::strcmp(e->Value(), "joint") != 0) continue;
    const char* name = e->Attribute("name");
    check.check_numbers(*e, "robot", std::string(link ? "link '" : "joint '") + (name ? name : "") + "'");
    if (!link) check.check_limit(*e, omitted);
  }
  check.check_graph(*robot);
  return omitted;
}

}  // namespace ks::urdf_check
