// [world]: the fixed obstacles a motion run keeps its links clear of, and the links' capsule radii.
//
//   [world]
//   link_radius = [0.05, 0.05, 0.04]     # m, one per joint (link k: joint k's origin to joint k+1's)
//   obstacles = [
//     { type = "sphere", centre = [0.5, 0.2, 0.3], radius = 0.1 },
//     { type = "box", centre = [x, y, z], half = [hx, hy, hz], rpy = [r, p, y] },   # rpy [deg], optional
//     { type = "capsule", a = [x, y, z], b = [x, y, z], radius = r },
//     { type = "sphere", centre = [1, 0, 0], radius = 0.1, velocity = [0, 0.1, 0] },  # m/s: moving
//   ]
//
// Everything in metres in the robot's base frame (a URDF file's base link; a DH table's frame 0).
#include <Eigen/Geometry>
#include <cmath>

#include "common/angles.hpp"
#include "study/parser.hpp"

namespace ks::study_parse {

namespace {
/// R = Rz(yaw) Ry(pitch) Rx(roll) from roll, pitch, yaw [rad].
Eigen::Matrix3d rpy_rotation(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}
}  // namespace

std::optional<geometry::Obstacle> Parser::parse_obstacle(const toml::node& n, std::size_t index) {
  const std::string what = "[world] obstacles[" + std::to_string(index) + "]";
  const toml::table* t = n.as_table();
  if (!t) {
    error(n, what + " is " + type_name(n) + "; expected an inline table { type = \"sphere\" | \"box\" | \"capsule\", ... }");
    return std::nullopt;
  }
  const auto type = get_string(*t, "type", what + " type");
  if (!type) {
    if (!t->get("type")) error(n, what + " has no type; expected type = \"sphere\", \"box\" or \"capsule\"");
    return std::nullopt;
  }
  const auto point = [&](const char* key) -> std::optional<Vec3> {
    if (!t->get(key)) {
      error(n, what + " (" + *type + ") has no " + key + "; expected " + key + " = [x, y, z] [m]");
      return std::nullopt;
    }
    auto v = get_numbers(*t, key, 3, 3, what + " " + key, "3 numbers [x, y, z] [m]");
    if (v && !(std::isfinite((*v)[0]) && std::isfinite((*v)[1]) && std::isfinite((*v)[2]))) {
      error(*t->get(key), what + " " + key + " is not finite; expected 3 finite numbers [m]");
      return std::nullopt;
    }
    if (!v) return std::nullopt;
    return Vec3((*v)[0], (*v)[1], (*v)[2]);
  };
  const auto radius = [&]() -> std::optional<double> {
    if (!t->get("radius")) {
      error(n, what + " (" + *type + ") has no radius; expected radius = r [m], r >= 0");
      return std::nullopt;
    }
    auto r = get_number(*t, "radius", what + " radius");
    if (r && !(*r >= 0.0 && std::isfinite(*r))) {
      error(*t->get("radius"), what + " radius = " + std::to_string(*r) + "; expected a finite radius >= 0 [m]");
      return std::nullopt;
    }
    return r;
  };
  if (*type == "sphere") {
    check_keys(*t, {"type", "centre", "radius", "velocity"}, what + " (sphere)");
    auto c = point("centre");
    auto r = radius();
    if (!c || !r) return std::nullopt;
    return geometry::Obstacle(geometry::Sphere{*c, *r});
  }
  if (*type == "capsule") {
    check_keys(*t, {"type", "a", "b", "radius", "velocity"}, what + " (capsule)");
    auto a = point("a");
    auto b = point("b");
    auto r = radius();
    if (!a || !b || !r) return std::nullopt;
    return geometry::Obstacle(geometry::Capsule{*a, *b, *r});
  }
  if (*type == "box") {
    check_keys(*t, {"type", "centre", "half", "rpy", "velocity"}, what + " (box)");
    auto c = point("centre");
    auto h = point("half");
    if (h && !(h->array() >= 0.0).all()) {
      error(*t->get("half"), what + " half has a negative extent; expected 3 half-extents >= 0 [m]");
      return std::nullopt;
    }
    Mat3 R = Mat3::Identity();
    if (t->get("rpy")) {
      auto a = get_numbers(*t, "rpy", 3, 3, what + " rpy", "3 angles [roll, pitch, yaw] [deg]");
      if (!a) return std::nullopt;
      R = rpy_rotation((*a)[0] * kDeg, (*a)[1] * kDeg, (*a)[2] * kDeg);
    }
    if (!c || !h) return std::nullopt;
    return geometry::Obstacle(geometry::Box{*c, R, *h});
  }
  error(*t->get("type"), "unknown obstacle type '" + *type + "' in " + what + "; expected \"sphere\", \"box\" or \"capsule\"" +
                             suggest(*type, {"sphere", "box", "capsule"}));
  return std::nullopt;
}

void Parser::parse_world(const toml::table& root, Study& s) {
  const toml::node* wn = root.get("world");
  if (!wn) return;
  const toml::table* w = wn->as_table();
  if (!w) {
    error(*wn, "world is " + type_name(*wn) + "; expected a table [world] with obstacles and link_radius");
    return;
  }
  check_keys(*w, {"obstacles", "link_radius"}, "[world]");
  const int joints = s.robot_shape().joints;
  if (const toml::node* on = w->get("obstacles")) {
    const toml::array* a = on->as_array();
    if (!a) {
      error(*on, "[world] obstacles is " + type_name(*on) + "; expected an array of obstacle tables");
    } else {
      std::vector<Vec3> velocities;
      bool moving = false;
      for (std::size_t i = 0; i < a->size(); ++i) {
        auto o = parse_obstacle(*a->get(i), i);
        if (!o) continue;
        s.world.obstacles.push_back(*o);
        Vec3 v = Vec3::Zero();
        const toml::table* t = a->get(i)->as_table();
        if (t && t->get("velocity")) {
          const std::string what = "[world] obstacles[" + std::to_string(i) + "] velocity";
          auto n = get_numbers(*t, "velocity", 3, 3, what, "3 numbers [vx, vy, vz] [m/s]");
          if (n && std::isfinite((*n)[0]) && std::isfinite((*n)[1]) && std::isfinite((*n)[2])) {
            v = Vec3((*n)[0], (*n)[1], (*n)[2]);
            moving = true;
          } else if (n) {
            error(*t->get("velocity"), what + " is not finite; expected 3 finite numbers [m/s]");
          }
        }
        velocities.push_back(v);
      }
      if (moving) s.world.velocities = velocities;
    }
  }
  if (const toml::node* rn = w->get("link_radius")) {
    const std::string expected = std::to_string(joints) + " radii [m], one per joint of the robot";
    if (auto r = get_numbers(*w, "link_radius", std::size_t(joints), std::size_t(joints), "[world] link_radius", expected)) {
      for (double x : *r)
        if (!(x >= 0.0 && std::isfinite(x))) {
          error(*rn, "[world] link_radius has " + std::to_string(x) + "; expected radii >= 0 [m]");
          return;
        }
      s.world.link_radius = *r;
    }
  } else if (w->get("obstacles")) {
    error(*wn, "[world] has obstacles but no link_radius; expected link_radius = [" + std::to_string(joints) +
                   " radii, m] (the links' capsules)");
  }
}

}  // namespace ks::study_parse
