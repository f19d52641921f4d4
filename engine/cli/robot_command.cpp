#include "cli/robot_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <vector>

#include "common/angles.hpp"
#include "model/chain_plane.hpp"
#include "robot/urdf.hpp"
#include "study/study.hpp"

namespace ks::cli {

namespace {

using V3 = Eigen::Vector3d;

/// What the command shows: the chain in its base frame and what the engine makes of it.
struct RobotView {
  std::string name;
  std::string origin;    ///< where the chain comes from, for people
  std::string dynamics;  ///< "closed_form" (the seed's 3R) or "recursive"
  Chain chain;           ///< base frame
  std::optional<ChainPlane> plane;
  bool gravity_default = false;  ///< URDF: no gravity given, base -z taken
  std::string task;              ///< the task space the redundancy is counted for
  int task_rows = 0;
};

// ---- numbers ----

/// v with 12 significant digits for people (tiny roundoff of rotated frames shown as 0).
std::string num(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::abs(v) < 1e-14) v = 0.0;
  char b[40];
  std::snprintf(b, sizeof b, "%.12g", v);
  return b;
}
std::string vec(const V3& v) { return "(" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + ")"; }

/// v as JSON: 17 significant digits (reads back as the same double), null when not finite.
std::string jnum(double v) {
  if (!std::isfinite(v)) return "null";
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}
std::string jstr(std::string_view s) {
  std::string o = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\', o += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", c);
      o += b;
    } else o += c;
  }
  return o + "\"";
}
template <class V>
std::string jarr(const V& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + jnum(v[i]);
  return s + "]";
}
std::string jmat(const Eigen::Matrix3d& m) {
  return "[" + jarr(V3(m.row(0))) + ", " + jarr(V3(m.row(1))) + ", " + jarr(V3(m.row(2))) + "]";
}
/// {"value": ..., "unit": ...}: every quantity carries its unit ("" for directions).
std::string q(const std::string& value, std::string_view unit) { return "{\"value\": " + value + ", \"unit\": " + jstr(unit) + "}"; }

// ---- the chain in its base frame at q = 0 ----

struct JointAtZero {
  Frame frame;  ///< joint frame, base frame
  V3 axis, com;
  Eigen::Matrix3d inertia;  ///< about the centre of mass, base frame axes
};
std::vector<JointAtZero> at_zero(const Chain& c) {
  std::vector<JointAtZero> out;
  Frame f;
  for (const ChainJoint& j : c.joints) {
    f = f * j.origin;
    out.push_back({f, f.R * j.axis, f.R * j.com + f.p, f.R * j.inertia * f.R.transpose()});
  }
  return out;
}
V3 tip_at_zero(const Chain& c) {
  Frame f;
  for (const ChainJoint& j : c.joints) f = f * j.origin;
  return (f * c.tip).p;
}
bool revolute(const ChainJoint& j) { return j.type == JointType::revolute; }

// ---- sources ----

std::optional<V3> parse_gravity(const std::string& text) {
  V3 g;
  std::istringstream in(text);
  for (int i = 0; i < 3; ++i) {
    if (i > 0 && in.get() != ',') return std::nullopt;
    if (!(in >> g[i]) || !std::isfinite(g[i])) return std::nullopt;
  }
  return in.peek() == std::char_traits<char>::eof() ? std::optional<V3>(g) : std::nullopt;
}

RobotView from_study(const Study& s) {
  RobotView v;
  v.plane = s.plane;
  if (s.base_chain) {
    v.chain = *s.base_chain;
    v.dynamics = "recursive";
    v.origin = s.robot_format == "urdf" ? "[robot] of " + s.file + ": URDF " + s.robot_file
               : s.robot_format != "dh" ? "[robot] of " + s.file + ": an n-link planar arm"
               : s.robot_file.empty()   ? "[robot] of " + s.file + ": a DH table"
                                        : "[robot] of " + s.file + ": DH table " + s.robot_file;
  } else {
    v.chain = *s.robot_chain();
    v.dynamics = "closed_form";
    v.origin = "[robot] of " + s.file + ": the seed's 3R (closed-form dynamics; physical inertia shown)";
  }
  v.name = v.chain.name;
  const bool planar = s.plane.has_value();
  v.task_rows = (planar ? 2 : 3) + (s.task.orientation.empty() ? 0 : 1) + (s.task.hold_orientation ? 3 : 0);
  v.task = std::string(planar ? "planar_" : "spatial_") + (s.task.pose() ? "pose" : "position");
  v.gravity_default = s.gravity_defaulted;
  return v;
}

RobotView from_urdf(const RobotArgs& a, const V3& gravity) {
  RobotView v;
  v.chain = load_urdf(a.file, a.base, a.tip, gravity);
  v.name = v.chain.name;
  v.dynamics = "recursive";
  v.origin = "URDF " + a.file + " from link " + a.base + " to link " + a.tip;
  v.plane = motion_plane(v.chain);
  v.task = v.plane ? "planar_position" : "spatial_position";
  v.task_rows = v.plane ? 2 : 3;
  v.gravity_default = a.gravity.empty();
  return v;
}

// ---- output ----

/// Rows of cells in left-aligned columns, indented by two spaces.
void print_rows(const std::vector<std::vector<std::string>>& rows, std::ostream& os) {
  std::vector<std::size_t> w;
  for (const auto& r : rows)
    for (std::size_t k = 0; k < r.size(); ++k) {
      if (w.size() <= k) w.push_back(0);
      w[k] = std::max(w[k], r[k].size());
    }
  for (const auto& r : rows) {
    std::string line = " ";
    for (std::size_t k = 0; k < r.size(); ++k) line += " " + r[k] + std::string(w[k] - r[k].size(), ' ');
    while (!line.empty() && line.back() == ' ') line.pop_back();
    os << line << '\n';
  }
}

void print_table(const RobotView& v, std::ostream& os) {
  const Chain& c = v.chain;
  const auto z = at_zero(c);
  os << "robot     " << v.name << " (" << v.origin << "); " << v.dynamics << " dynamics\n\n";
  os << "joints (axis and position: base frame at q = 0; limits: deg and deg/s for revolute joints, m and m/s "
        "for prismatic ones; inf: none)\n";
  std::vector<std::vector<std::string>> rows{
      {"#", "name", "type", "axis [-]", "position [m]", "lower", "upper", "velocity", "effort [Nm or N]"}};
  for (int i = 0; i < c.dof(); ++i) {
    const ChainJoint& j = c.joints[i];
    const double k = revolute(j) ? 1.0 / kDeg : 1.0;
    rows.push_back({std::to_string(i + 1), j.name, revolute(j) ? "revolute" : "prismatic", vec(z[i].axis), vec(z[i].frame.p),
                    num(j.lower * k), num(j.upper * k), num(j.velocity * k), num(j.effort)});
  }
  print_rows(rows, os);
  os << "\nbodies (each joint's moving body, fixed links merged; base frame at q = 0)\n";
  rows = {{"#", "mass [kg]", "centre of mass [m]", "inertia about it [kg m^2]: xx yy zz xy xz yz"}};
  double total = 0;
  for (int i = 0; i < c.dof(); ++i) {
    const auto& I = z[i].inertia;
    total += c.joints[i].mass;
    rows.push_back({std::to_string(i + 1), num(c.joints[i].mass), vec(z[i].com),
                    num(I(0, 0)) + " " + num(I(1, 1)) + " " + num(I(2, 2)) + " " + num(I(0, 1)) + " " + num(I(0, 2)) + " " +
                        num(I(1, 2))});
  }
  print_rows(rows, os);
  os << "\ntotal mass  " << num(total) << " kg\n";
  os << "tip         " << vec(tip_at_zero(c)) << " m (base frame, q = 0)\n";
  os << "gravity     " << vec(c.gravity) << " m/s^2 (base frame" << (v.gravity_default ? "; not given: base -z, URDF's z up" : "")
     << ")\n";
  if (v.plane) {
    const ChainPlane& p = *v.plane;
    const Eigen::Vector2d g = p.project(c.gravity);
    os << "motion      planar: plane origin " << vec(p.origin()) << " m, normal " << vec(p.normal()) << ", in-plane axes x "
       << vec(p.e1()) << " and y " << vec(p.e2()) << " (base frame)\n";
    os << "            gravity in the plane (" << num(g.x()) << ", " << num(g.y()) << ") m/s^2, along the normal "
       << num(p.normal().dot(c.gravity)) << " m/s^2 (no joint torque)\n";
    if (v.gravity_default && std::abs(p.normal().z()) > kParallelTol)
      os << "            the plane is not vertical: a trajectory study needs gravity = [gx, gy, gz] given\n";
  } else {
    os << "motion      spatial\n";
  }
  os << "task        " << v.task << ": " << v.task_rows << " rows, " << c.dof() << " joints, redundancy "
     << c.dof() - v.task_rows << '\n';
}

void print_json(const RobotView& v, std::ostream& os) {
  const Chain& c = v.chain;
  const auto z = at_zero(c);
  os << "{\"robot\": " << jstr(v.name) << ", \"from\": " << jstr(v.origin) << ", \"dynamics\": " << jstr(v.dynamics)
     << ",\n \"joints\": [";
  double total = 0;
  for (int i = 0; i < c.dof(); ++i) {
    const ChainJoint& j = c.joints[i];
    const bool r = revolute(j);
    total += j.mass;
    os << (i ? "," : "") << "\n  {\"name\": " << jstr(j.name) << ", \"type\": " << jstr(r ? "revolute" : "prismatic")
       << ", \"axis\": " << q(jarr(z[i].axis), "") << ", \"position\": " << q(jarr(z[i].frame.p), "m")
       << ",\n   \"lower\": " << q(jnum(j.lower), r ? "rad" : "m") << ", \"upper\": " << q(jnum(j.upper), r ? "rad" : "m")
       << ", \"velocity\": " << q(jnum(j.velocity), r ? "rad/s" : "m/s") << ", \"effort\": " << q(jnum(j.effort), r ? "Nm" : "N")
       << ",\n   \"mass\": " << q(jnum(j.mass), "kg") << ", \"com\": " << q(jarr(z[i].com), "m")
       << ", \"inertia\": " << q(jmat(z[i].inertia), "kg m^2") << "}";
  }
  os << "],\n \"frames\": \"axis, position, com: base frame at q = 0; inertia: about the centre of mass, base frame axes; "
        "limits null: none\",\n";
  os << " \"total_mass\": " << q(jnum(total), "kg") << ",\n \"tip\": " << q(jarr(tip_at_zero(c)), "m")
     << ",\n \"gravity\": " << q(jarr(c.gravity), "m/s^2") << ", \"gravity_default\": " << (v.gravity_default ? "true" : "false")
     << ",\n \"motion\": " << jstr(v.plane ? "planar" : "spatial") << ", \"plane\": ";
  if (v.plane) {
    const ChainPlane& p = *v.plane;
    os << "{\"origin\": " << q(jarr(p.origin()), "m") << ", \"normal\": " << q(jarr(p.normal()), "")
       << ", \"e1\": " << q(jarr(p.e1()), "") << ", \"e2\": " << q(jarr(p.e2()), "")
       << ",\n   \"gravity_in_plane\": " << q(jarr(p.project(c.gravity)), "m/s^2")
       << ", \"gravity_normal\": " << q(jnum(p.normal().dot(c.gravity)), "m/s^2") << "}";
  } else {
    os << "null";
  }
  os << ",\n \"task\": {\"space\": " << jstr(v.task) << ", \"rows\": " << v.task_rows << ", \"joints\": " << c.dof()
     << ", \"redundancy\": " << c.dof() - v.task_rows << "}}\n";
}

/// True when `file` starts with the HDF5 signature (a results file given where a study or URDF is
/// expected).
bool is_hdf5(const std::string& file) {
  static constexpr char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  char head[8] = {};
  std::ifstream in(file, std::ios::binary);
  return in.read(head, sizeof head) && std::equal(head, head + 8, kSignature);
}

bool is_urdf(const std::string& file) {
  const std::string ext = std::filesystem::path(file).extension().string();
  return ext == ".urdf" || ext == ".xml";
}

}  // namespace

int robot_command(const RobotArgs& a, std::ostream& out, std::ostream& err) {
  RobotView v;
  if (is_hdf5(a.file)) {
    err << "kinesweep robot: " << a.file << ": an HDF5 file (a results file?), not a robot description; expected a "
        << "study (TOML) or a URDF file (.urdf, .xml); kinesweep info FILE describes a results file\n";
    return 2;
  }
  if (is_urdf(a.file)) {
    if (a.base.empty() || a.tip.empty()) {
      err << "kinesweep robot: " << a.file << " is a URDF file; expected --base LINK and --tip LINK (the chain's links)\n";
      return 2;
    }
    std::optional<V3> g = V3(0, 0, -9.81);
    if (!a.gravity.empty() && !(g = parse_gravity(a.gravity))) {
      err << "kinesweep robot: --gravity " << a.gravity << ": expected three finite numbers gx,gy,gz [m/s^2]\n";
      return 2;
    }
    try {
      v = from_urdf(a, *g);
    } catch (const UrdfError& e) {
      err << e.what() << '\n';
      return 2;
    }
  } else {
    if (!a.base.empty() || !a.tip.empty() || !a.gravity.empty()) {
      err << "kinesweep robot: --base, --tip and --gravity are for a URDF file; a study names them in [robot]\n";
      return 2;
    }
    try {
      v = from_study(load_study(a.file));
    } catch (const StudyError& e) {
      err << e.what() << '\n';
      return 2;
    }
  }
  if (a.format == "json") print_json(v, out);
  else print_table(v, out);
  return 0;
}

}  // namespace ks::cli
