// Standard DH table to Chain (see dh.hpp).
#include "robot/dh.hpp"

#include <cmath>

namespace ks {

namespace {

Frame rot_z(double t) {
  Frame f;
  const double c = std::cos(t), s = std::sin(t);
  f.R << c, -s, 0, s, c, 0, 0, 0, 1;
  return f;
}

Frame rot_x(double t) {
  Frame f;
  const double c = std::cos(t), s = std::sin(t);
  f.R << 1, 0, 0, 0, c, -s, 0, s, c;
  return f;
}

Frame move(double x, double y, double z) {
  Frame f;
  f.p = Eigen::Vector3d(x, y, z);
  return f;
}

/// Add a body of mass m [kg], centre of mass com and inertia I about it (the joint frame's axes,
/// kg m^2) to the body joint j moves: the combined mass, centre of mass and inertia about it
/// (parallel-axis theorem).
void add_body(ChainJoint& j, double m, const Eigen::Vector3d& com, const Eigen::Matrix3d& I) {
  const double total = j.mass + m;
  if (!(total > 0.0)) return;
  const Eigen::Vector3d c = (j.mass * j.com + m * com) / total;
  const auto shift = [&](double mass, const Eigen::Vector3d& at) {  // a point mass's inertia about c
    const Eigen::Vector3d r = at - c;
    return (mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose())).eval();
  };
  const Eigen::Matrix3d sum = j.inertia + shift(j.mass, j.com) + I + shift(m, com);
  j.inertia = 0.5 * (sum + sum.transpose());
  j.com = c;
  j.mass = total;
}

}  // namespace

Frame dh_frame(double a, double alpha, double d, double theta) {
  return rot_z(theta) * move(0, 0, d) * move(a, 0, 0) * rot_x(alpha);
}

Chain dh_chain(const std::vector<DhLink>& links, const Eigen::Vector3d& gravity, std::string name, std::string source) {
  Chain c;
  c.name = std::move(name);
  c.source = std::move(source);
  c.gravity = gravity;
  Frame before;  // the rest of the previous row: this joint's frame starts there (identity: frame 0)
  for (std::size_t i = 0; i < links.size(); ++i) {
    const DhLink& l = links[i];
    if (l.fixed) {
      const Frame row = before * dh_frame(l.a, l.alpha, l.d, l.theta);  // frame i in the last joint's frame
      if (!c.joints.empty()) add_body(c.joints.back(), l.mass, row.R * l.com + row.p, row.R * l.inertia * row.R.transpose());
      before = row;
      continue;
    }
    const bool prismatic = l.type == JointType::prismatic;
    ChainJoint j;
    j.name = l.name.empty() ? "joint" + std::to_string(i + 1) : l.name;
    j.type = l.type;
    j.axis = Eigen::Vector3d::UnitZ();
    // the joint's own motion commutes with Rz(theta) and Tz(d): both are about and along its axis
    j.origin = before * rot_z(l.theta);
    if (prismatic) j.origin = j.origin * move(0, 0, l.d);
    const Frame rest = (prismatic ? Frame{} : move(0, 0, l.d)) * move(l.a, 0, 0) * rot_x(l.alpha);  // frame i in the joint frame
    j.mass = l.mass;
    j.com = rest.R * l.com + rest.p;
    j.inertia = rest.R * l.inertia * rest.R.transpose();
    j.inertia = (0.5 * (j.inertia + j.inertia.transpose())).eval();
    j.lower = l.lower;
    j.upper = l.upper;
    j.velocity = l.velocity;
    j.effort = l.effort;
    c.joints.push_back(std::move(j));
    before = rest;
  }
  c.tip = before;
  c.prepare();
  return c;
}

}  // namespace ks
