// [robot]: the seed's closed-form 3R (the default), an n-link planar arm, or a URDF robot.
//   l, m, b, g, inertia               the seed's 3R (3 links; closed-form dynamics)
//   l, m (n values), b | lc + I,      an n-link planar arm (2 <= n <= 8; recursive dynamics; with
//   limits, g, dynamics = "recursive"   3 links only when one of lc, I, limits or dynamics asks for it)
//   urdf, base, tip, gravity          a URDF robot's chain from link `base` to link `tip`
//   dh, gravity                       a standard DH table (robot_dh.cpp)
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "model/chain_dynamics.hpp"
#include "robot/urdf.hpp"
#include "study/parser.hpp"

namespace ks {

RobotShape Study::robot_shape() const {
  RobotShape r = chain ? RobotShape::of(*chain) : RobotShape{};
  r.pose_task = task.pose();
  return r;
}

std::shared_ptr<const Chain> Study::robot_chain() const {
  if (chain) return chain;
  std::vector<PlanarLink> links(3);
  for (int i = 0; i < 3; ++i) links[i] = {robot.l[i], robot.m[i], robot.lc[i], robot.I[i]};
  return std::make_shared<const Chain>(planar_chain(links, robot.g, "seed3r"));
}

namespace study_parse {

std::optional<std::vector<double>> Parser::get_joint_numbers(const toml::table& t, std::string_view key,
                                                             std::size_t count, std::string_view what,
                                                             std::string_view unit) {
  const std::string want = count > 0 ? std::to_string(count) + " numbers [" + std::string(unit) + "] (one per link)"
                                     : "2 to " + std::to_string(kMaxJoints) + " numbers [" + std::string(unit) +
                                           "] (one per link)";
  return count > 0 ? get_numbers(t, key, count, count, what, want)
                   : get_numbers(t, key, 2, std::size_t(kMaxJoints), what, want);
}

void Parser::parse_robot(const toml::table& root, Study& s) {
  s.robot = PlanarArm3::seed();
  s.robot_b = 0.1;
  const toml::node* n = root.get("robot");
  if (!n) return;
  const auto* t = n->as_table();
  if (!t) {
    error(*n, "'robot' is " + type_name(*n) + "; expected a [robot] table");
    return;
  }
  check_keys(*t, {"l", "m", "b", "lc", "I", "limits", "g", "inertia", "dynamics", "urdf", "base", "tip", "gravity", "dh"},
             "[robot]");
  if (t->get("urdf") && t->get("dh"))
    error(*t->get("urdf"), "urdf and dh both given; expected one robot description: urdf = \"FILE\" or dh (a DH table)");
  else if (t->get("dh")) parse_dh_robot(*t, s);
  else if (t->get("urdf")) parse_urdf_robot(*t, s);
  else parse_planar_robot(*t, s);
}

void Parser::parse_planar_robot(const toml::table& t, Study& s) {
  for (const char* k : {"base", "tip"})
    if (const toml::node* n = t.get(k))
      error(*n, std::string(k) + " is a key of URDF robots; expected it with urdf = \"FILE\" (planar arms take g)");
  if (const toml::node* n = t.get("gravity"))
    error(*n, "gravity is a key of URDF and DH robots; expected it with urdf = \"FILE\" or dh (planar arms take g)");
  std::vector<double> l{1, 1, 1}, m{5, 2, 1};
  bool ok = true;
  if (auto v = get_joint_numbers(t, "l", 0, "robot l", "m")) {
    l = *v;
    if (*std::min_element(l.begin(), l.end()) <= 0) error(*t.get("l"), "a link length is <= 0; expected lengths > 0 [m]"), ok = false;
  } else if (t.get("l")) ok = false;
  const std::size_t links = l.size();
  if (auto v = get_joint_numbers(t, "m", links, "robot m", "kg")) {
    m = *v;
    if (*std::min_element(m.begin(), m.end()) <= 0) error(*t.get("m"), "a link mass is <= 0; expected masses > 0 [kg]"), ok = false;
  } else if (t.get("m")) ok = false;
  else if (links != 3) error(*t.get("l"), "l has " + std::to_string(links) + " links but m is not given; expected m = [...] (" +
                                             std::to_string(links) + " masses [kg])"), ok = false;
  double b = 0.1, g = 9.81;
  if (auto v = get_number(t, "b", "robot b")) {
    if (*v < 0) error(*t.get("b"), "b = " + fmt(*v) + "; expected b >= 0 [m]"), ok = false;
    else b = *v;
  }
  if (auto v = get_number(t, "g", "robot g")) g = *v;
  std::optional<std::vector<double>> lc, I;
  if ((lc = get_joint_numbers(t, "lc", links, "robot lc", "m")))
    for (std::size_t i = 0; i < links; ++i)
      if (!((*lc)[i] >= 0 && (*lc)[i] <= l[i])) {
        error(*t.get("lc")->as_array()->get(i), "lc = " + fmt((*lc)[i]) + "; expected 0 <= lc <= l = " + fmt(l[i]) + " [m]");
        ok = false;
      }
  if ((I = get_joint_numbers(t, "I", links, "robot I", "kg m^2")))
    for (std::size_t i = 0; i < links; ++i)
      if (!((*I)[i] >= 0)) error(*t.get("I")->as_array()->get(i), "I = " + fmt((*I)[i]) + "; expected I >= 0 [kg m^2]"), ok = false;
  if ((t.get("lc") || t.get("I")) && t.get("b"))
    error(*t.get("b"), "b and lc/I both given; expected b (uniform bars) or lc and I"), ok = false;
  std::vector<std::pair<double, double>> limits(links, {-INFINITY, INFINITY});
  if (const toml::node* ln = t.get("limits")) {
    const auto* a = ln->as_array();
    if (!a || a->size() != links) {
      error(*ln, "limits is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*ln)) + "; expected " +
                     std::to_string(links) + " [lower, upper] pairs [deg]");
      ok = false;
    } else {
      for (std::size_t i = 0; i < links; ++i) {
        const auto* p = a->get(i)->as_array();
        std::optional<double> lo, hi;
        if (p && p->size() == 2) lo = get_number(*p->get(0), "lower limit"), hi = get_number(*p->get(1), "upper limit");
        else error(*a->get(i), "a joint's limits are " + (p ? "an array of " + std::to_string(p->size()) : type_name(*a->get(i))) +
                                   "; expected [lower, upper] [deg]");
        if (lo && hi && !(*lo < *hi)) error(*a->get(i), "limits [" + fmt(*lo) + ", " + fmt(*hi) + "]; expected lower < upper [deg]");
        if (!lo || !hi || !(*lo < *hi)) {
          ok = false;
          continue;
        }
        limits[i] = {*lo * kDeg, *hi * kDeg};
      }
    }
  }
  InertiaForm form = InertiaForm::physical;
  if (auto v = get_string(t, "inertia", "inertia")) {
    if (!parse(*v, form))
      error(*t.get("inertia"), "unknown inertia '" + *v + "'; expected one of " + join(inertia_names()) +
                                   suggest(*v, inertia_names()));
  }
  bool recursive = links != 3 || lc || I || t.get("limits");
  if (auto v = get_string(t, "dynamics", "dynamics")) {
    if (*v == "recursive") recursive = true;
    else if (*v != "closed_form")
      error(*t.get("dynamics"), "unknown dynamics '" + *v + "'; expected \"closed_form\" (the seed's 3R) or \"recursive\"" +
                                    suggest(*v, {"closed_form", "recursive"}));
    else if (recursive)
      error(*t.get("dynamics"), "dynamics = \"closed_form\" is the seed's 3-link arm without lc, I or limits; expected "
                                "\"recursive\" for this arm");
  }
  if (recursive && t.get("inertia") && form != InertiaForm::physical)
    error(*t.get("inertia"), "inertia = \"" + std::string(to_string(form)) + "\" is a closed form of the seed's 3R; "
                             "expected no inertia key for an arm with recursive dynamics (its M(q) is the physical one)");
  if (!ok) return;
  if (!recursive) {
    std::array<double, 3> l3{l[0], l[1], l[2]}, m3{m[0], m[1], m[2]};
    s.robot = PlanarArm3::bars(l3, m3, b, g);
    s.robot.inertia_form = form;
    s.robot_b = b;
    return;
  }
  std::vector<PlanarLink> pl = planar_bars(l, m, b);
  for (std::size_t i = 0; i < links; ++i) {
    if (lc) pl[i].lc = (*lc)[i];
    if (I) pl[i].I = (*I)[i];
    else if (lc) pl[i].I = m[i] * (l[i] * l[i] + b * b) / 12.0;
    pl[i].lower = limits[i].first;
    pl[i].upper = limits[i].second;
  }
  auto chain = std::make_shared<Chain>(planar_chain(pl, g, "planar" + std::to_string(links) + "r"));
  std::string why;
  if (!chain->IsValid(&why)) {
    error(*t.get("l"), "the arm is not a valid chain: " + why + "; expected positive masses and inertias");
    return;
  }
  s.chain = std::move(chain);
}

void Parser::parse_urdf_robot(const toml::table& t, Study& s) {
  for (const char* k : {"l", "m", "b", "lc", "I", "limits", "g", "inertia"})
    if (const toml::node* n = t.get(k))
      error(*n, std::string(k) + " describes a planar arm; expected no " + k + " with urdf (the URDF file gives the robot)");
  if (const toml::node* n = t.get("dynamics"); n && !(n->as_string() && n->as_string()->get() == "recursive"))
    error(*n, "a URDF robot's dynamics are recursive; expected dynamics = \"recursive\" or no dynamics key");
  const auto file = get_string(t, "urdf", "urdf");
  const auto base = get_string(t, "base", "base link");
  const auto tip = get_string(t, "tip", "tip link");
  if (!t.get("base")) error(*t.get("urdf"), "a URDF robot without base; expected base = \"LINK\" (the chain's fixed link)");
  if (!t.get("tip")) error(*t.get("urdf"), "a URDF robot without tip; expected tip = \"LINK\" (the chain's last link)");
  std::optional<Eigen::Vector3d> gravity;
  if (auto v = get_numbers(t, "gravity", 3, "gravity")) gravity = Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
  if (!file || !base || !tip) return;
  const toml::node& at = *t.get("urdf");
  std::filesystem::path path(*file);
  if (path.is_relative() && !file_.empty() && file_.front() != '<')
    path = std::filesystem::path(file_).parent_path() / path;
  std::ostringstream text;
  if (options_.robot_text) {
    text << *options_.robot_text;
  } else {
    std::ifstream in(path, std::ios::binary);
    if (!in || std::filesystem::is_directory(path)) {
      error(at, "cannot read the URDF file '" + path.string() + "'; expected a readable URDF file (relative paths "
                "start at the study file's folder)");
      return;
    }
    text << in.rdbuf();
  }
  try {
    // gravity: as given, else base -z (URDF's z up; check_gravity_given refuses it for a trajectory
    // study when the chain's plane is not vertical)
    Chain c = parse_urdf(text.str(), *base, *tip, gravity.value_or(Eigen::Vector3d(0, 0, -9.81)), path.string());
    if (!gravity) robot_without_gravity_ = &at, robot_without_gravity_kind_ = "URDF";
    c.prepare();
    s.chain = std::make_shared<const Chain>(std::move(c));
    s.robot_file = *file;
    s.robot_text = text.str();
    s.robot_format = "urdf";
  } catch (const UrdfError& e) {
    // an unknown link at its key, anything else at urdf; the URDF's file and line lead the message
    std::string what = e.message, hint;
    if (const auto dym = what.find("; did you mean"); dym != std::string::npos) hint = what.substr(dym), what.resize(dym);
    const toml::node* where = &at;
    std::string expected = "a URDF chain of revolute, continuous or prismatic joints with mass";
    if (what.starts_with("unknown base link")) where = t.get("base"), expected = "a link of the URDF";
    else if (what.starts_with("unknown tip link")) where = t.get("tip"), expected = "a link of the URDF";
    error(*where, "URDF " + e.file + (e.line > 0 ? ":" + std::to_string(e.line) : std::string()) +
                      (e.line > 0 && e.column > 0 ? ":" + std::to_string(e.column) : std::string()) + ": " + what +
                      "; expected " + expected + hint);
  }
}

}  // namespace study_parse
}  // namespace ks
