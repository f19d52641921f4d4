// A chain's links as capsules, their least clearance from obstacles and its joint-space gradient.
#include "geometry/link_capsules.hpp"

#include <Eigen/Geometry>
#include <limits>
#include <stdexcept>

namespace ks::geometry {

namespace {

/// Frame k's origin in the base frame: joint k's, the tip's for k = dof.
const Vec3& frame_origin(const Chain& chain, const ChainData& data, int k) {
  return k < chain.dof() ? data.joint[k].p : data.tip.p;
}

/// The velocity of the point p (moving with frame k's origin) per unit q̇_i, for a joint i <= k.
Vec3 origin_column(const Chain& chain, const ChainData& data, int i, const Vec3& p) {
  if (chain.joints[i].type == JointType::revolute) return data.axis[i].cross(p - data.joint[i].p);
  return data.axis[i];
}

}  // namespace

ClosestPoints capsule_obstacle(const Capsule& link, const Obstacle& obstacle) {
  if (const auto* s = std::get_if<Sphere>(&obstacle)) return capsule_sphere(link, *s);
  if (const auto* b = std::get_if<Box>(&obstacle)) return capsule_box(link, *b);
  return capsule_capsule(link, std::get<Capsule>(obstacle));
}

Obstacle translated(const Obstacle& obstacle, const Vec3& by) {
  if (const auto* s = std::get_if<Sphere>(&obstacle)) return Sphere{s->centre + by, s->radius};
  if (const auto* b = std::get_if<Box>(&obstacle)) {
    Box m = *b;
    m.centre += by;
    return m;
  }
  const auto& c = std::get<Capsule>(obstacle);
  return Capsule{c.a + by, c.b + by, c.radius};
}

void link_capsules(const Chain& chain, const ChainData& data, std::span<const double> radii,
                   std::array<Capsule, kMaxJoints>& links) {
  const int n = chain.dof();
  for (int k = 0; k < n; ++k) {
    links[k].a = frame_origin(chain, data, k);
    links[k].b = frame_origin(chain, data, k + 1);
    links[k].radius = radii[k];
  }
}

void frame_origin_jacobian(const Chain& chain, const ChainData& data, int k,
                           Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxJoints>& J) {
  const int n = chain.dof();
  J.setZero(3, n);
  const Vec3& p = frame_origin(chain, data, k);
  for (int i = 0; i <= k && i < n; ++i) J.col(i) = origin_column(chain, data, i, p);
}

Clearance min_clearance(const Chain& chain, const VecN& q, std::span<const double> radii,
                        std::span<const Obstacle> obstacles, ClearanceWorkspace& ws) {
  const int n = chain.dof();
  if (static_cast<int>(radii.size()) != n || q.size() != n)
    throw std::invalid_argument("min_clearance: radii and q need one entry per joint");
  forward_kinematics(chain, ws.chain, q);
  link_capsules(chain, ws.chain, radii, ws.links);

  Clearance out;
  out.distance = std::numeric_limits<double>::infinity();
  out.gradient.setZero(n);
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < static_cast<int>(obstacles.size()); ++j) {
      const ClosestPoints c = capsule_obstacle(ws.links[k], obstacles[j]);
      if (c.distance < out.distance) {
        out.distance = c.distance;
        out.link = k;
        out.obstacle = j;
        out.closest = c;
      }
    }
  }
  if (out.link < 0) return out;

  // d distance / d q_i = d_a . (d a / d q_i) + d_b . (d b / d q_i), a and b the origins of frames
  // k and k + 1; joint i moves frame m's origin when i <= m (and i < n).
  const int k = out.link;
  const EndpointGradient g = first_segment_gradient(out.closest);
  out.obstacle_gradient = -(g.d_a + g.d_b);
  const Vec3& a = ws.links[k].a;
  const Vec3& b = ws.links[k].b;
  for (int i = 0; i <= k + 1 && i < n; ++i) {
    double v = g.d_b.dot(origin_column(chain, ws.chain, i, b));
    if (i <= k) v += g.d_a.dot(origin_column(chain, ws.chain, i, a));
    out.gradient[i] = v;
  }
  return out;
}

}  // namespace ks::geometry
