// motion_plane() and in_plane_frame(): a planar chain in any plane of its base frame.
#include "model/chain_plane.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace ks {

namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

/// Joint i's frame in the base frame at q = 0.
std::vector<Frame> frames_at_zero(const Chain& chain) {
  std::vector<Frame> f;
  Frame acc;
  for (const ChainJoint& j : chain.joints) f.push_back(acc = acc * j.origin);
  return f;
}

/// Chain::planar() of the chain with gravity's z component taken as 0 (it is dropped anyway).
bool in_base_xy(const Chain& chain) {
  Chain c = chain;
  c.gravity.z() = 0.0;
  return c.planar();
}

/// The first base axis, in the order x, y, z and other than `skip`, whose component perpendicular to
/// the unit vectors in `against` is at least 0.5 long; that component, normalised. -1 in `skip`
/// skips none. Some axis always qualifies: the squared projections of x, y, z on a plane sum to 2,
/// and on a line in it to 1.
V3 first_base_axis(const std::vector<V3>& against, int skip, int* chosen) {
  for (int k = 0; k < 3; ++k) {
    if (k == skip) continue;
    V3 w = V3::Unit(k);
    for (const V3& a : against) w -= a.dot(w) * a;
    if (w.norm() >= 0.5) {
      *chosen = k;
      return w.normalized();
    }
  }
  *chosen = -1;  // not reached for unit, orthogonal `against` of 1 or 2 vectors
  return V3::Zero();
}

}  // namespace

Eigen::Vector2d ChainPlane::to_plane(const Eigen::Vector3d& x, double* off) const {
  const V3 d = x - frame.p;
  if (off) *off = normal().dot(d);
  return frame.R.leftCols<2>().transpose() * d;
}

std::optional<ChainPlane> motion_plane(const Chain& chain) {
  if (in_base_xy(chain)) return ChainPlane{};  // R = I, p = 0 exactly
  const std::vector<Frame> f = frames_at_zero(chain);
  std::optional<V3> n;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (chain.joints[i].type == JointType::revolute) {
      const V3 a = (f[i].R * chain.joints[i].axis).normalized();
      if (!n) n = a;
      else if (a.cross(*n).norm() > kParallelTol) return std::nullopt;
    }
  if (!n) return std::nullopt;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (chain.joints[i].type == JointType::prismatic && std::abs((f[i].R * chain.joints[i].axis).dot(*n)) > kParallelTol)
      return std::nullopt;
  ChainPlane plane;
  int k1 = -1, k2 = -1;
  const V3 e1 = first_base_axis({*n}, -1, &k1);
  const V3 e2 = first_base_axis({*n, e1}, k1, &k2);
  const V3 normal = e1.cross(e2);
  plane.frame.R.col(0) = e1;
  plane.frame.R.col(1) = e2;
  plane.frame.R.col(2) = normal;
  const Frame tip = (f.empty() ? Frame{} : f.back()) * chain.tip;
  plane.frame.p = normal.dot(tip.p) * normal;
  return plane;
}

Chain in_plane_frame(const Chain& chain, const ChainPlane& plane) {
  Chain c = chain;
  if (plane.is_base_xy() && in_base_xy(chain)) {
    c.gravity.z() = 0.0;
    c.prepare();
    return c;
  }
  const M3 Rt = plane.frame.R.transpose();
  const std::vector<Frame> f = frames_at_zero(chain);
  V3 previous = V3::Zero();  // the previous joint's origin, plane frame, in the plane
  for (std::size_t i = 0; i < f.size(); ++i) {
    const ChainJoint& j = chain.joints[i];
    ChainJoint& out = c.joints[i];
    const M3 C = Rt * f[i].R;  // joint i's axes -> the plane frame's axes
    V3 at = Rt * (f[i].p - plane.frame.p);
    at.z() = 0.0;
    out.origin = Frame{};
    out.origin.p = at - previous;
    previous = at;
    const V3 a = C * j.axis;
    if (j.type == JointType::revolute) out.axis = V3(0.0, 0.0, a.z() > 0.0 ? 1.0 : -1.0);
    else out.axis = V3(a.x(), a.y(), 0.0).normalized();
    out.com = C * j.com;
    out.inertia = C * j.inertia * C.transpose();
    out.inertia = (0.5 * (out.inertia + out.inertia.transpose())).eval();
  }
  const Frame last = f.empty() ? Frame{} : f.back();
  const Frame tip = last * chain.tip;
  V3 at = Rt * (tip.p - plane.frame.p);
  at.z() = 0.0;
  const M3 Rtip = Rt * tip.R;
  const double angle = std::hypot(Rtip(0, 0), Rtip(1, 0)) >= 0.5 ? std::atan2(Rtip(1, 0), Rtip(0, 0))
                                                                  : std::atan2(Rtip(1, 1), Rtip(0, 1)) - M_PI / 2;
  c.tip = Frame{};
  c.tip.p = at - previous;
  c.tip.R << std::cos(angle), -std::sin(angle), 0.0, std::sin(angle), std::cos(angle), 0.0, 0.0, 0.0, 1.0;
  c.gravity = Rt * chain.gravity;
  c.gravity.z() = 0.0;
  c.prepare();
  return c;
}

}  // namespace ks
