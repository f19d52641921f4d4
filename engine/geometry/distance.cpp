// Closest points of segments, points, boxes; capsules and spheres as those less their radii.
#include "geometry/distance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace ks::geometry {

namespace {

/// A unit vector perpendicular to v (unit x when v is zero): v crossed with the axis it is least
/// aligned with.
Vec3 any_perpendicular(const Vec3& v) {
  if (v.squaredNorm() == 0.0) return Vec3::UnitX();
  const Vec3 m = v.cwiseAbs();
  const Vec3 axis = m.x() <= m.y() && m.x() <= m.z() ? Vec3::UnitX() : (m.y() <= m.z() ? Vec3::UnitY() : Vec3::UnitZ());
  return v.cross(axis).normalized();
}

/// The point a + s (b - a), exactly b at s = 1.
Vec3 on_segment(const Vec3& a, const Vec3& b, double s) { return s >= 1.0 ? b : Vec3(a + s * (b - a)); }

/// The clamped projection parameter of p on a-b (0 for a zero-length segment).
double project(const Vec3& a, const Vec3& d, const Vec3& p) {
  const double dd = d.squaredNorm();
  if (!(dd > 0.0)) return 0.0;
  return std::clamp((p - a).dot(d) / dd, 0.0, 1.0);
}

/// Fills c from the core witnesses xa (first shape) and xb (second): core, normal (fallback when
/// they coincide), and the surface values for radii ra, rb.
void finish(ClosestPoints& c, const Vec3& xa, const Vec3& xb, double ra, double rb, const Vec3& fallback) {
  const Vec3 r = xb - xa;
  c.core = r.norm();
  c.normal = c.core > 0.0 ? Vec3(r / c.core) : fallback;
  c.distance = c.core - ra - rb;
  c.point_a = xa + ra * c.normal;
  c.point_b = xb - rb * c.normal;
}

/// Squared distance of the box-frame point x from the box [-h, h].
double box_gap2(const Vec3& x, const Vec3& h) { return (x - x.cwiseMax(-h).cwiseMin(h)).squaredNorm(); }

}  // namespace

ClosestPoints segment_point(const Vec3& a, const Vec3& b, const Vec3& p) {
  ClosestPoints c;
  c.s = project(a, b - a, p);
  finish(c, on_segment(a, b, c.s), p, 0.0, 0.0, any_perpendicular(b - a));
  return c;
}

ClosestPoints segment_segment(const Vec3& a0, const Vec3& b0, const Vec3& a1, const Vec3& b1) {
  const Vec3 d0 = b0 - a0, d1 = b1 - a1, r = a1 - a0;
  const Vec3 n = d0.cross(d1);
  const double nn = n.squaredNorm(), scale = d0.squaredNorm() * d1.squaredNorm();
  const Vec3 fallback = nn > 0.0 ? Vec3(n / std::sqrt(nn)) : any_perpendicular(d0.squaredNorm() > 0.0 ? d0 : d1);

  // The common perpendicular of the lines, when it joins points of both segments: the minimum.
  // t is x0(s)'s projection on the second line rather than its own quotient: for nearly parallel
  // lines both quotients carry relative errors of order eps / sin(angle), harmless along the
  // valley of equal distances but not across it; the projection puts the pair on the valley floor.
  double best = std::numeric_limits<double>::infinity(), bs = 0.0, bt = 0.0;
  if (nn > 0.0) {
    const double s = r.cross(d1).dot(n) / nn;
    const double t = s >= 0.0 && s <= 1.0 ? (on_segment(a0, b0, s) - a1).dot(d1) / d1.squaredNorm() : -1.0;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) {
      best = (on_segment(a1, b1, t) - on_segment(a0, b0, s)).squaredNorm();
      bs = s, bt = t;
      // well conditioned (sin^2 of the angle > 1e-8): no boundary point can be nearer
      if (nn > 1e-8 * scale) {
        ClosestPoints c;
        c.s = s, c.t = t;
        finish(c, on_segment(a0, b0, s), on_segment(a1, b1, t), 0.0, 0.0, fallback);
        return c;
      }
    }
  }
  // Otherwise the minimum lies on the boundary of [0, 1]^2 (or nearly parallel lines leave its
  // interior point in doubt): each edge fixes one parameter at 0 or 1, its minimum is a clamped
  // projection of that endpoint on the other segment.
  const auto consider = [&](double s, double t) {
    const double g = (on_segment(a1, b1, t) - on_segment(a0, b0, s)).squaredNorm();
    if (g < best) best = g, bs = s, bt = t;
  };
  consider(0.0, project(a1, d1, a0));
  consider(1.0, project(a1, d1, b0));
  consider(project(a0, d0, a1), 0.0);
  consider(project(a0, d0, b1), 1.0);
  ClosestPoints c;
  c.s = bs, c.t = bt;
  finish(c, on_segment(a0, b0, bs), on_segment(a1, b1, bt), 0.0, 0.0, fallback);
  return c;
}

ClosestPoints segment_box(const Vec3& a, const Vec3& b, const Box& box) {
  const Mat3& R = box.rotation;
  const Vec3& h = box.half;
  const Vec3 p = R.transpose() * (a - box.centre), d = R.transpose() * (b - a);  // box frame

  // The pieces: [0, 1] cut where a coordinate crosses -h_i or h_i.
  double cut[8];
  int m = 0;
  cut[m++] = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) continue;
    for (const double face : {-h[i], h[i]}) {
      const double s = (face - p[i]) / d[i];
      if (s > 0.0 && s < 1.0) cut[m++] = s;
    }
  }
  cut[m++] = 1.0;
  for (int k = 1; k < m; ++k)  // insertion sort of the at most 8 cuts
    for (int j = k; j > 0 && cut[j] < cut[j - 1]; --j) std::swap(cut[j], cut[j - 1]);

  // On each piece the coordinates outside [-h_i, h_i] stay on one side: the squared distance is
  // sum over them of (p_i - c_i + s d_i)^2 (c_i the face), least at s = -sum (p_i - c_i) d_i / sum d_i^2.
  double best = std::numeric_limits<double>::infinity(), bs = 0.0;
  for (int k = 0; k + 1 < m; ++k) {
    const double lo = cut[k], hi = cut[k + 1], mid = 0.5 * (lo + hi);
    double num = 0.0, den = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double x = p[i] + mid * d[i];
      if (x > h[i] || x < -h[i]) {
        num += (p[i] - (x > h[i] ? h[i] : -h[i])) * d[i];
        den += d[i] * d[i];
      }
    }
    const double s = den > 0.0 ? std::clamp(-num / den, lo, hi) : lo;
    const double g = box_gap2(s >= 1.0 ? Vec3(p + d) : Vec3(p + s * d), h);
    if (g < best) best = g, bs = s;
  }

  const Vec3 x = bs >= 1.0 ? Vec3(p + d) : Vec3(p + bs * d);
  const Vec3 y = x.cwiseMax(-h).cwiseMin(h);
  ClosestPoints c;
  c.s = bs;
  c.point_a = on_segment(a, b, bs);
  c.point_b = box.centre + R * y;
  const Vec3 e = y - x;
  c.core = e.norm();
  if (c.core > 0.0) {
    c.normal = R * (e / c.core);
  } else {  // inside or on the box: across the face of least depth, inward
    int i = 0;
    for (int j = 1; j < 3; ++j)
      if (h[j] - std::abs(x[j]) < h[i] - std::abs(x[i])) i = j;
    c.normal = R.col(i) * (x[i] < 0.0 ? 1.0 : -1.0);
  }
  c.distance = c.core;
  return c;
}

ClosestPoints capsule_sphere(const Capsule& capsule, const Sphere& sphere) {
  const ClosestPoints core = segment_point(capsule.a, capsule.b, sphere.centre);
  ClosestPoints c = core;
  finish(c, core.point_a, core.point_b, capsule.radius, sphere.radius, core.normal);
  return c;
}

ClosestPoints capsule_capsule(const Capsule& c0, const Capsule& c1) {
  const ClosestPoints core = segment_segment(c0.a, c0.b, c1.a, c1.b);
  ClosestPoints c = core;
  finish(c, core.point_a, core.point_b, c0.radius, c1.radius, core.normal);
  return c;
}

ClosestPoints capsule_box(const Capsule& capsule, const Box& box) {
  ClosestPoints c = segment_box(capsule.a, capsule.b, box);
  // the core witnesses as segment_box found them; its normal (a fallback when they coincide)
  c.distance = c.core - capsule.radius;
  c.point_a += capsule.radius * c.normal;
  return c;
}

EndpointGradient first_segment_gradient(const ClosestPoints& c) {
  return {-(1.0 - c.s) * c.normal, -c.s * c.normal};
}

EndpointGradient second_segment_gradient(const ClosestPoints& c) {
  return {(1.0 - c.t) * c.normal, c.t * c.normal};
}

}  // namespace ks::geometry
