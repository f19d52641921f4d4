// [robot] dh: a robot given by its standard Denavit–Hartenberg table (robot/dh.hpp), written in the
// study ([[robot.dh]] tables) or in a robot file (dh = "robots/puma560.toml": [[dh]] tables, gravity,
// name). One row per joint:
//   a [m], alpha [deg], d [m], theta [deg], type ("revolute" | "prismatic"), mass [kg],
//   com = [x, y, z] [m, link frame], inertia = { ixx, iyy, izz, ixy = 0, ixz = 0, iyz = 0 }
//   [kg m^2, about the centre of mass, link frame axes], limits = { lower, upper, velocity, effort }
//   (optional each: deg, deg/s, Nm for revolute joints; m, m/s, N for prismatic ones), name.
// The rows are read by a DhReader over the text they are written in, so that their errors carry that
// text's file, line and column; the study parser adds them to its own.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/angles.hpp"
#include "robot/dh.hpp"
#include "robot/inertia_check.hpp"
#include "study/parser.hpp"

namespace ks::study_parse {

namespace {

const std::vector<std::string> kRowKeys{"name", "type", "a", "alpha", "d", "theta", "mass", "com", "inertia", "limits"};
const std::vector<std::string> kInertiaKeys{"ixx", "iyy", "izz", "ixy", "ixz", "iyz"};
const std::vector<std::string> kLimitKeys{"lower", "upper", "velocity", "effort"};
const std::vector<std::string> kTypes{"revolute", "prismatic", "fixed"};

/// Reads DH rows from one TOML text (the study's or a robot file's), collecting located diagnostics.
class DhReader : public ParserCore {
 public:
  DhReader(std::string file, std::string_view text) : ParserCore(std::move(file), text) {}

  std::vector<StudyDiagnostic>& diagnostics() { return diags_; }
  void report(const toml::node& n, std::string msg) { error(n, std::move(msg)); }
  void report(const toml::source_region& r, std::string msg) { error(r, std::move(msg)); }
  void report(Pos p, std::string msg) { error(p, std::move(msg)); }
  void keys(const toml::table& t, const std::vector<std::string>& allowed, std::string_view where) {
    check_keys(t, allowed, where);
  }
  std::optional<std::vector<double>> numbers(const toml::table& t, std::string_view key, std::string_view what) {
    return get_numbers(t, key, 3, what);
  }
  std::optional<std::string> string(const toml::table& t, std::string_view key, std::string_view what) {
    return get_string(t, key, what);
  }

  /// The rows of `dh` (written as `key`: "[[robot.dh]]" or "[[dh]]"); nullopt after reporting.
  std::optional<std::vector<DhLink>> rows(const toml::node& dh, const std::string& key) {
    const auto* a = dh.as_array();
    if (!a || a->empty() || a->size() > std::size_t(kMaxJoints)) {
      error(dh, "dh is " + (a ? "an array of " + std::to_string(a->size()) : type_name(dh)) + "; expected 1 to " +
                    std::to_string(kMaxJoints) + " DH rows (" + key + " tables, one per joint) or a robot file name");
      return std::nullopt;
    }
    const std::size_t before = diags_.size();
    std::vector<DhLink> links;
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& n = *a->get(i);
      const auto* t = n.as_table();
      if (!t) {
        error(n, "dh row " + std::to_string(i + 1) + " is " + type_name(n) + "; expected a table of " + join(kRowKeys));
        continue;
      }
      links.push_back(row(*t, "dh row " + std::to_string(i + 1)));
    }
    if (diags_.size() > before) return std::nullopt;
    if (std::all_of(links.begin(), links.end(), [](const DhLink& l) { return l.fixed; })) {
      error(dh, "every DH row is fixed; expected at least one revolute or prismatic row (a joint)");
      return std::nullopt;
    }
    return links;
  }

 private:
  // A number the row must have: reported when missing or wrong.
  std::optional<double> required(const toml::table& t, const std::string& key, const std::string& what,
                                 const std::string& unit) {
    if (!t.get(key)) {
      error(t.source(), what + " has no '" + key + "'; expected " + key + " = " + unit);
      return std::nullopt;
    }
    return get_number(t, key, what + " " + key);
  }

  DhLink row(const toml::table& t, const std::string& what) {
    check_keys(t, kRowKeys, what);
    DhLink l;
    if (auto v = get_string(t, "name", what + " name")) l.name = *v;
    if (!t.get("type")) {
      error(t.source(), what + " has no 'type'; expected type = \"revolute\", \"prismatic\" or \"fixed\"");
    } else if (auto v = get_string(t, "type", what + " type")) {
      if (*v == "prismatic") l.type = JointType::prismatic;
      else if (*v == "fixed") l.fixed = true;
      else if (*v != "revolute")
        error(*t.get("type"), "unknown joint type '" + *v + "' in " + what + "; expected \"revolute\", \"prismatic\" or "
                              "\"fixed\" (a row without a joint)" + suggest(*v, kTypes));
    }
    const bool prismatic = l.type == JointType::prismatic;
    l.a = required(t, "a", what, "A [m] (along x_i)").value_or(0.0);
    l.alpha = required(t, "alpha", what, "ALPHA [deg] (about x_i)").value_or(0.0) * kDeg;
    l.d = required(t, "d", what, "D [m] (along z_{i-1})").value_or(0.0);
    l.theta = required(t, "theta", what, "THETA [deg] (about z_{i-1}; a revolute joint's offset)").value_or(0.0) * kDeg;
    if (auto m = required(t, "mass", what, "M [kg] (the link's mass)")) {
      if (*m < 0) error(*t.get("mass"), what + ": mass = " + fmt(*m) + " is negative; expected a mass >= 0 [kg]");
      else l.mass = *m;
    }
    if (!t.get("com")) error(t.source(), what + " has no 'com'; expected com = [x, y, z] [m] (the centre of mass, link frame)");
    else if (auto c = get_numbers(t, "com", 3, what + " com")) l.com = Eigen::Vector3d((*c)[0], (*c)[1], (*c)[2]);
    if (!t.get("inertia"))
      error(t.source(), what + " has no 'inertia'; expected inertia = { ixx = .., iyy = .., izz = .. } [kg m^2] "
                               "(about the centre of mass, link frame axes)");
    else read_inertia(*t.get("inertia"), what, l);
    if (const toml::node* n = t.get("limits")) {
      if (l.fixed) error(*n, what + " is fixed (no joint) and has limits; expected no limits on a fixed row");
      else read_limits(*n, what, prismatic, l);
    }
    return l;
  }

  void read_inertia(const toml::node& n, const std::string& what, DhLink& l) {
    const auto* t = n.as_table();
    if (!t) {
      error(n, what + " inertia is " + type_name(n) + "; expected a table { ixx = .., iyy = .., izz = .., ixy = 0, "
                      "ixz = 0, iyz = 0 } [kg m^2]");
      return;
    }
    check_keys(*t, kInertiaKeys, what + " inertia");
    double v[6] = {0, 0, 0, 0, 0, 0};
    bool ok = true;
    for (int k = 0; k < 6; ++k) {
      const std::string& key = kInertiaKeys[std::size_t(k)];
      if (!t->get(key)) {
        if (k < 3) error(n, what + " inertia has no '" + key + "'; expected " + key + " = .. [kg m^2]"), ok = false;
        continue;
      }
      if (auto x = get_number(*t, key, what + " inertia " + key)) v[k] = *x;
      else ok = false;
    }
    if (!ok) return;
    Eigen::Matrix3d I;
    I << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
    if (const std::string why = inertia_problem(I); !why.empty()) {
      error(n, what + ": " + why);
      return;
    }
    l.inertia = I;
  }

  void read_limits(const toml::node& n, const std::string& what, bool prismatic, DhLink& l) {
    const std::string pos = prismatic ? "m" : "deg", vel = prismatic ? "m/s" : "deg/s", eff = prismatic ? "N" : "Nm";
    const auto* t = n.as_table();
    if (!t) {
      error(n, what + " limits is " + type_name(n) + "; expected a table { lower = .., upper = .. [" + pos +
                   "], velocity = .. [" + vel + "], effort = .. [" + eff + "] } (each optional)");
      return;
    }
    check_keys(*t, kLimitKeys, what + " limits");
    const double scale = prismatic ? 1.0 : kDeg;
    const auto lo = get_number(*t, "lower", what + " lower limit"), hi = get_number(*t, "upper", what + " upper limit");
    if (lo && hi && !(*lo < *hi)) {
      error(*t->get("lower"), what + ": limits lower = " + fmt(*lo) + (*lo == *hi ? " = " : " > ") + "upper = " + fmt(*hi) +
                                  "; expected lower < upper [" + pos + "]" + (*lo == *hi ? " (a joint that cannot move)" : ""));
    } else {
      if (lo) l.lower = *lo * scale;
      if (hi) l.upper = *hi * scale;
    }
    for (const auto& [key, unit] : {std::pair{"velocity", vel}, std::pair{"effort", eff}}) {
      const auto v = get_number(*t, key, what + " " + key + " limit");
      if (!v) continue;
      if (!(*v > 0)) {
        error(*t->get(key), what + ": " + key + " limit = " + fmt(*v) + "; expected a limit > 0 [" + unit + "] (or no " + key + " key: none)");
        continue;
      }
      (std::string(key) == "velocity" ? l.velocity : l.effort) = *v * (std::string(key) == "velocity" ? scale : 1.0);
    }
  }
};

}  // namespace

void Parser::parse_dh_robot(const toml::table& t, Study& s) {
  for (const char* k : {"l", "m", "b", "lc", "I", "limits", "g", "inertia"})
    if (const toml::node* n = t.get(k))
      error(*n, std::string(k) + " describes a planar arm; expected no " + k + " with dh (the DH table gives the robot)");
  for (const char* k : {"urdf", "base", "tip"})
    if (const toml::node* n = t.get(k))
      error(*n, std::string(k) + " is a key of URDF robots; expected no " + k + " with dh (the DH table gives the chain)");
  if (const toml::node* n = t.get("dynamics"); n && !(n->as_string() && n->as_string()->get() == "recursive"))
    error(*n, "a DH robot's dynamics are recursive; expected dynamics = \"recursive\" or no dynamics key");
  std::optional<Eigen::Vector3d> gravity;
  if (auto v = get_numbers(t, "gravity", 3, "gravity")) gravity = Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
  const toml::node& at = *t.get("dh");

  // the text the rows are written in: the study's own, or a robot file's
  std::string path = file_, text(text_), name = "dh", file_key;
  const bool in_file = at.is_string();
  if (in_file) {
    file_key = at.as_string()->get();
    std::filesystem::path p(file_key);
    if (p.is_relative() && !file_.empty() && file_.front() != '<') p = std::filesystem::path(file_).parent_path() / p;
    path = p.string();
    name = p.stem().string();
    if (options_.robot_text) {
      text = *options_.robot_text;
    } else {
      std::ifstream in(p, std::ios::binary);
      std::error_code ec;
      if (!in || std::filesystem::is_directory(p, ec)) {
        error(at, "cannot read the DH robot file '" + path + "'; expected a readable TOML file of [[dh]] tables "
                  "(relative paths start at the study file's folder)");
        return;
      }
      std::ostringstream ss;
      ss << in.rdbuf();
      text = ss.str();
    }
  }
  DhReader reader(path, text);
  std::optional<std::vector<DhLink>> links;
  toml::table root;  // a robot file's tables
  const toml::node* rows = in_file ? nullptr : &at;
  if (!in_file) {
    links = reader.rows(at, "[[robot.dh]]");
  } else if (const auto h = toml_hazard(text)) {
    reader.report(Pos{h->line, h->column, 1}, "TOML syntax: " + h->message);
  } else {
    try {
      root = toml::parse(text, path);
      reader.keys(root, {"name", "gravity", "dh"}, "the DH robot file");
      if (auto v = reader.string(root, "name", "name")) name = *v;
      if (auto v = reader.numbers(root, "gravity", "gravity"); v && !gravity) gravity = Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
      if ((rows = root.get("dh"))) links = reader.rows(*rows, "[[dh]]");
      else reader.report(Pos{1, 1, 0}, "the DH robot file has no dh; expected [[dh]] tables, one per joint (a, alpha, d, "
                                       "theta, type, mass, com, inertia)");
    } catch (const toml::parse_error& e) {
      reader.report(e.source(), "TOML syntax: " + std::string(e.description()) + "; expected valid TOML (https://toml.io)");
    }
  }
  std::optional<Chain> chain;
  if (links && reader.diagnostics().empty()) {
    chain = dh_chain(*links, gravity.value_or(Eigen::Vector3d(0, 0, -9.81)), name, path);
    std::string why;
    int joint = -1;
    double total = 0.0;
    for (const DhLink& l : *links) total += l.mass;
    if (!(total > 0.0)) why = "the links of the DH table have zero total mass; expected a mass > 0 on some link";
    else if (!chain->IsValid(&why)) why = "not a chain the engine can simulate: " + why;
    else if (!(why = inertia_matrix_problem(*chain, &joint)).empty()) why += "; expected links that move mass";
    if (!why.empty()) {
      std::size_t row = 0;  // the row of chain joint `joint` (fixed rows have none)
      for (int seen = -1; joint >= 0 && row < links->size(); ++row)
        if (!(*links)[row].fixed && ++seen == joint) break;
      reader.report(joint >= 0 && row < links->size() ? *rows->as_array()->get(row) : *rows, why);
      chain.reset();
    }
  }
  for (StudyDiagnostic& d : reader.diagnostics()) {
    if (in_file) {
      note(d, pos_of(at.source()), "the DH robot file named here");
      d.notes.back().file = file_;
    }
    diags_.push_back(std::move(d));
  }
  if (!chain) return;
  if (!gravity) robot_without_gravity_ = &at, robot_without_gravity_kind_ = "DH";
  s.chain = std::make_shared<const Chain>(std::move(*chain));
  s.robot_format = "dh";
  if (in_file) {
    s.robot_file = file_key;
    s.robot_text = text;
  }
}

}  // namespace ks::study_parse
