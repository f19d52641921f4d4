// geometry/distance.hpp against an independent computation: every distance is also found by
// minimising over the first segment's parameter s a distance that is exact for a point (a point's
// distance to a point, to a segment by its clamped projection, to a box by clamping in the box
// frame), on a grid of s refined by golden-section search to a bracket of 1e-15; random cases of
// fixed seeds, and the parallel, crossing, zero-length, touching and overlapping cases by hand.
// The endpoint gradients against central differences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>

#include "geometry/distance.hpp"

using namespace ks::geometry;

namespace {

constexpr double kTol = 1e-9;  // [m], agreement with the reference minimisation
constexpr int kCases = 1500;   // random cases per pair type (of each generator)

/// The largest difference from the reference over a test's random cases, printed at its end.
struct Agreement {
  const char* what;
  int cases = 0;
  double worst = 0.0;
  void add(double mine, double reference) {
    ++cases;
    worst = std::max(worst, std::abs(mine - reference));
  }
  ~Agreement() { std::printf("%s: %d random cases, largest difference from the reference %.3g m\n", what, cases, worst); }
};

/// min over s in [0, 1] of a convex f: the best of a 400-point grid, then golden-section search in
/// the grid cell pair around it down to a bracket of 1e-15; the ends 0 and 1 are candidates too.
double minimise01(const std::function<double(double)>& f) {
  constexpr int N = 400;
  int kb = 0;
  double fb = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= N; ++k)
    if (const double v = f(double(k) / N); v < fb) fb = v, kb = k;
  double lo = std::max(0.0, double(kb - 1) / N), hi = std::min(1.0, double(kb + 1) / N);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    if (f1 <= f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  return std::min({fb, f1, f2, f(lo), f(hi), f(0.0), f(1.0)});
}

Vec3 lerp(const Vec3& a, const Vec3& b, double s) { return (1.0 - s) * a + s * b; }

/// A point's distance to the segment a-b: its clamped projection.
double ref_point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double dd = d.dot(d);
  const double t = dd > 0.0 ? std::clamp((p - a).dot(d) / dd, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

/// A point's distance to a box: clamping in the box frame.
double ref_point_box(const Vec3& p, const Box& box) {
  const Vec3 x = box.rotation.transpose() * (p - box.centre);
  Vec3 c;
  for (int i = 0; i < 3; ++i) c[i] = std::clamp(x[i], -box.half[i], box.half[i]);
  return (x - c).norm();
}

double ref_segment_point(const Vec3& a, const Vec3& b, const Vec3& p) {
  return minimise01([&](double s) { return (lerp(a, b, s) - p).norm(); });
}
double ref_segment_segment(const Vec3& a0, const Vec3& b0, const Vec3& a1, const Vec3& b1) {
  return minimise01([&](double s) { return ref_point_segment(lerp(a0, b0, s), a1, b1); });
}
double ref_segment_box(const Vec3& a, const Vec3& b, const Box& box) {
  return minimise01([&](double s) { return ref_point_box(lerp(a, b, s), box); });
}

struct Random {
  std::mt19937_64 rng;
  explicit Random(unsigned seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  Vec3 point(double r = 1.0) { return {uniform(-r, r), uniform(-r, r), uniform(-r, r)}; }
  Mat3 rotation() {
    std::normal_distribution<double> n;
    return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
  }
  Box box() { return {point(), rotation(), Vec3(uniform(0.0, 0.6), uniform(0.05, 0.6), uniform(0.05, 0.6))}; }
};

/// The invariants of a result whose core witnesses are xa (first) and xb: the core is their
/// distance, the normal unit and along xb - xa, the surface witnesses the cores moved by the radii.
void expect_consistent(const ClosestPoints& c, const Vec3& xa, const Vec3& xb, double ra, double rb) {
  EXPECT_NEAR((xb - xa).norm(), c.core, 1e-12);
  EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
  if (c.core > 1e-9) {
    EXPECT_NEAR(c.normal.dot(xb - xa), c.core, 1e-12);
  }
  EXPECT_NEAR(c.distance, c.core - ra - rb, 1e-15);
  EXPECT_LT((c.point_a - (xa + ra * c.normal)).norm(), 1e-12);
  EXPECT_LT((c.point_b - (xb - rb * c.normal)).norm(), 1e-12);
  EXPECT_TRUE(c.s >= 0.0 && c.s <= 1.0 && c.t >= 0.0 && c.t <= 1.0);
}

/// Segment pairs of several kinds: generic, nearly and exactly parallel, crossing, zero-length,
/// nearly parallel passing close.
void segment_pair(Random& r, int kind, Vec3& a0, Vec3& b0, Vec3& a1, Vec3& b1) {
  a0 = r.point(), b0 = r.point(), a1 = r.point(), b1 = r.point();
  if (kind == 1) {  // parallel (or antiparallel) up to an angle of 1e-12 .. 1e-3 rad, or exactly
    const double angle = r.uniform(0.0, 1.0) < 0.2 ? 0.0 : std::pow(10.0, r.uniform(-12.0, -3.0));
    const Vec3 d = (b0 - a0) * (r.uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * r.uniform(0.3, 1.5);
    b1 = a1 + Eigen::AngleAxisd(angle, r.point().normalized()) * d;
  } else if (kind == 2) {  // crossing: both through the point x
    const Vec3 x = r.point(0.5);
    b0 = x + (x - a0) * r.uniform(0.1, 2.0);
    b1 = x + (x - a1) * r.uniform(0.1, 2.0);
  } else if (kind == 4) {  // nearly parallel (1e-12 .. 1e-3 rad) and passing within 1e-6 .. 1e-1 of
                           // each other inside both: the common perpendicular is the witness pair
    const Vec3 x = r.point(0.5), d = r.point().normalized(), off = d.cross(r.point()).normalized();
    const double angle = std::pow(10.0, r.uniform(-12.0, -3.0)), gap = std::pow(10.0, r.uniform(-6.0, -1.0));
    const Vec3 d1 = Eigen::AngleAxisd(angle, off) * d;  // both perpendicular to off: x, x + gap off the witnesses
    a0 = x - r.uniform(0.1, 1.0) * d, b0 = x + r.uniform(0.1, 1.0) * d;
    a1 = x + gap * off - r.uniform(0.1, 1.0) * d1, b1 = x + gap * off + r.uniform(0.1, 1.0) * d1;
  } else if (kind == 3) {  // zero-length first, second or both
    const double u = r.uniform(0.0, 1.0);
    if (u < 0.4) b0 = a0;
    else if (u < 0.8) b1 = a1;
    else b0 = a0, b1 = a1;
  }
}

TEST(SegmentPoint, RandomAgainstMinimisation) {
  Random r(101);
  Agreement agree{"segment-point"};
  for (int i = 0; i < kCases; ++i) {
    const Vec3 a = r.point(), b = i % 10 == 0 ? a : r.point(), p = r.point(1.5);
    const ClosestPoints c = segment_point(a, b, p);
    ASSERT_NEAR(c.distance, ref_segment_point(a, b, p), kTol) << "case " << i;
    agree.add(c.distance, ref_segment_point(a, b, p));
    expect_consistent(c, lerp(a, b, c.s), p, 0.0, 0.0);
  }
}

TEST(SegmentSegment, RandomAgainstMinimisation) {
  Agreement agree{"segment-segment"};
  for (int kind = 0; kind < 5; ++kind) {
    Random r(200 + kind);
    for (int i = 0; i < kCases; ++i) {
      Vec3 a0, b0, a1, b1;
      segment_pair(r, kind, a0, b0, a1, b1);
      const ClosestPoints c = segment_segment(a0, b0, a1, b1);
      ASSERT_NEAR(c.distance, ref_segment_segment(a0, b0, a1, b1), kTol) << "kind " << kind << " case " << i;
      agree.add(c.distance, ref_segment_segment(a0, b0, a1, b1));
      expect_consistent(c, lerp(a0, b0, c.s), lerp(a1, b1, c.t), 0.0, 0.0);
      // swapping the segments gives the same distance, the witnesses swapped
      const ClosestPoints w = segment_segment(a1, b1, a0, b0);
      EXPECT_NEAR(w.distance, c.distance, kTol);
    }
  }
}

TEST(SegmentBox, RandomAgainstMinimisation) {
  Random r(300);
  Agreement agree{"segment-box"};
  int inside = 0;
  for (int i = 0; i < 2 * kCases; ++i) {
    const Box box = r.box();
    const Vec3 a = r.point(1.5), b = i % 10 == 0 ? a : r.point(1.5);
    const ClosestPoints c = segment_box(a, b, box);
    ASSERT_NEAR(c.distance, ref_segment_box(a, b, box), kTol) << "case " << i;
    agree.add(c.distance, ref_segment_box(a, b, box));
    expect_consistent(c, lerp(a, b, c.s), c.point_b, 0.0, 0.0);
    EXPECT_LT(ref_point_box(c.point_b, box), 1e-12);  // the witness lies on the box
    inside += c.core == 0.0;
  }
  EXPECT_GT(inside, 100);  // segments into the box are among the cases
}

TEST(Capsules, RandomAgainstMinimisation) {
  Random r(400);
  Agreement agree_cc{"capsule-capsule"}, agree_cs{"capsule-sphere"}, agree_cb{"capsule-box"};
  for (int i = 0; i < kCases; ++i) {
    Vec3 a0, b0, a1, b1;
    segment_pair(r, i % 5, a0, b0, a1, b1);
    const double r0 = r.uniform(0.0, 0.5), r1 = r.uniform(0.0, 0.5);
    const Capsule c0{a0, b0, r0}, c1{a1, b1, r1};
    const ClosestPoints cc = capsule_capsule(c0, c1);
    ASSERT_NEAR(cc.distance, ref_segment_segment(a0, b0, a1, b1) - r0 - r1, kTol) << "case " << i;
    agree_cc.add(cc.distance, ref_segment_segment(a0, b0, a1, b1) - r0 - r1);
    expect_consistent(cc, lerp(a0, b0, cc.s), lerp(a1, b1, cc.t), r0, r1);

    const ClosestPoints cs = capsule_sphere(c0, {a1, r1});
    ASSERT_NEAR(cs.distance, ref_segment_point(a0, b0, a1) - r0 - r1, kTol) << "case " << i;
    agree_cs.add(cs.distance, ref_segment_point(a0, b0, a1) - r0 - r1);
    expect_consistent(cs, lerp(a0, b0, cs.s), a1, r0, r1);

    const Box box = r.box();
    const ClosestPoints cb = capsule_box(c0, box);
    ASSERT_NEAR(cb.distance, ref_segment_box(a0, b0, box) - r0, kTol) << "case " << i;
    agree_cb.add(cb.distance, ref_segment_box(a0, b0, box) - r0);
    expect_consistent(cb, lerp(a0, b0, cb.s), cb.point_b, r0, 0.0);
  }
}

TEST(SegmentSegment, ParallelCases) {
  const Vec3 o(0, 0, 0), x(1, 0, 0);
  // overlapping projections, 1 apart: every overlap pair is a witness pair
  ClosestPoints c = segment_segment(o, x, Vec3(0.5, 1, 0), Vec3(2, 1, 0));
  EXPECT_NEAR(c.distance, 1.0, 1e-15);
  EXPECT_GE(c.s, 0.5 - 1e-15);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-15);
  // disjoint projections: end to end
  c = segment_segment(o, x, Vec3(3, 1, 0), Vec3(2, 1, 0));  // antiparallel
  EXPECT_NEAR(c.distance, std::sqrt(2.0), 1e-15);
  EXPECT_EQ(c.s, 1.0);
  EXPECT_EQ(c.t, 1.0);
  // collinear overlapping: 0, the normal perpendicular to the line
  c = segment_segment(o, x, Vec3(0.5, 0, 0), Vec3(3, 0, 0));
  EXPECT_EQ(c.distance, 0.0);
  EXPECT_NEAR(c.normal.dot(x), 0.0, 1e-15);
  EXPECT_NEAR(c.normal.norm(), 1.0, 1e-15);
  // collinear with a gap of 0.25
  EXPECT_NEAR(segment_segment(o, x, Vec3(1.25, 0, 0), Vec3(3, 0, 0)).distance, 0.25, 1e-15);
  // nearly parallel (1e-9 rad), 0.1 apart at the second's start, which is the witness
  const Vec3 e = Vec3(1, 1e-9, 0);
  c = segment_segment(o, x, Vec3(0.2, 0.1, 0), Vec3(0.2, 0.1, 0) + e);
  EXPECT_NEAR(c.distance, 0.1, 1e-15);
  EXPECT_NEAR(c.s, 0.2, 1e-15);
  EXPECT_EQ(c.t, 0.0);
}

TEST(SegmentSegment, CrossingTouchingOverlapping) {
  // crossing at the origin: 0, the normal along d0 x d1
  const ClosestPoints c = segment_segment(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 2, 0));
  EXPECT_EQ(c.distance, 0.0);
  EXPECT_NEAR(c.normal.z(), 1.0, 1e-15);
  EXPECT_NEAR(c.s, 0.5, 1e-15);
  EXPECT_NEAR(c.t, 1.0 / 3.0, 1e-15);
  // capsules about them: overlap by the radii; moved apart along the normal by that much, touching
  const Capsule c0{Vec3(-1, 0, 0), Vec3(1, 0, 0), 0.2};
  Capsule c1{Vec3(0, -1, 0), Vec3(0, 2, 0), 0.3};
  EXPECT_NEAR(capsule_capsule(c0, c1).distance, -0.5, 1e-15);
  c1.a.z() += 0.5, c1.b.z() += 0.5;
  const ClosestPoints touch = capsule_capsule(c0, c1);
  EXPECT_NEAR(touch.distance, 0.0, 1e-15);
  EXPECT_LT((touch.point_a - touch.point_b).norm(), 1e-15);  // the contact point
  EXPECT_LT((touch.point_a - Vec3(0, 0, 0.2)).norm(), 1e-15);
  // penetrating by 0.1: the depth, the deepest points 0.1 apart along the normal
  c1.a.z() -= 0.1, c1.b.z() -= 0.1;
  const ClosestPoints deep = capsule_capsule(c0, c1);
  EXPECT_NEAR(deep.distance, -0.1, 1e-15);
  EXPECT_NEAR((deep.point_a - deep.point_b).dot(deep.normal), 0.1, 1e-15);
}

TEST(SegmentSegment, ZeroLength) {
  const Vec3 p(0.3, 0.4, 0), o(0, 0, 0), x(1, 0, 0);
  ClosestPoints c = segment_segment(p, p, o, x);
  EXPECT_NEAR(c.distance, 0.4, 1e-15);
  EXPECT_EQ(c.s, 0.0);
  EXPECT_NEAR(c.t, 0.3, 1e-15);
  c = segment_segment(o, x, p, p);
  EXPECT_NEAR(c.distance, 0.4, 1e-15);
  EXPECT_NEAR(c.s, 0.3, 1e-15);
  EXPECT_NEAR(segment_segment(p, p, o, o).distance, 0.5, 1e-15);
  c = segment_segment(p, p, p, p);  // one point twice: 0, some unit normal
  EXPECT_EQ(c.distance, 0.0);
  EXPECT_NEAR(c.normal.norm(), 1.0, 1e-15);
  // a zero-length capsule is a sphere
  EXPECT_NEAR(capsule_capsule({p, p, 0.1}, {o, x, 0.05}).distance, 0.25, 1e-15);
  EXPECT_NEAR(capsule_sphere({p, p, 0.1}, {o, 0.05}).distance, 0.35, 1e-15);
}

TEST(CapsuleSphere, TouchingAndPenetrating) {
  const Capsule c{Vec3(0, 0, 0), Vec3(2, 0, 0), 0.25};
  ClosestPoints d = capsule_sphere(c, {Vec3(1, 0.75, 0), 0.5});
  EXPECT_NEAR(d.distance, 0.0, 1e-15);
  EXPECT_LT((d.point_a - Vec3(1, 0.25, 0)).norm(), 1e-15);
  d = capsule_sphere(c, {Vec3(3, 0, 0), 0.9});  // beyond the end b: the cap
  EXPECT_NEAR(d.distance, -0.15, 1e-15);
  EXPECT_EQ(d.s, 1.0);
  d = capsule_sphere(c, {Vec3(1, 0, 0), 0.1});  // centre on the segment: depth of both radii
  EXPECT_NEAR(d.distance, -0.35, 1e-15);
  EXPECT_NEAR(d.normal.dot(Vec3::UnitX()), 0.0, 1e-15);
}

TEST(SegmentBox, FacesEdgesInsideAndRotated) {
  const Box unit{Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 1)};
  struct Case {
    Vec3 a, b;
    double distance;
  } cases[] = {
      {Vec3(2, -5, 0), Vec3(2, 5, 0), 1.0},                    // parallel to a face
      {Vec3(2, 2, -5), Vec3(2, 2, 5), std::sqrt(2.0)},         // parallel to an edge
      {Vec3(3, 3, 3), Vec3(2, 2, 2), std::sqrt(3.0)},          // towards a corner
      {Vec3(1, -3, 0.5), Vec3(1, 3, 0.5), 0.0},                // lying on a face
      {Vec3(-3, 0.2, 0.1), Vec3(3, 0.3, -0.2), 0.0},           // through the box
      {Vec3(0.1, 0.2, 0.3), Vec3(0.1, 0.2, 0.3), 0.0},         // a point inside
      {Vec3(0.5, 0.5, 2.5), Vec3(0.5, 0.5, 2.5), 1.5},         // a point above a face
      {Vec3(3, 0, 0), Vec3(0, 3, 0), std::sqrt(0.5)},          // across an edge, touching nothing
  };
  Random r(500);
  for (const Case& k : cases) {
    const ClosestPoints c = segment_box(k.a, k.b, unit);
    EXPECT_NEAR(c.distance, k.distance, 1e-15) << k.a.transpose() << " - " << k.b.transpose();
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-15);
    // the same after moving box and segment by one rigid motion
    const Mat3 R = r.rotation();
    const Vec3 t = r.point(3.0);
    const ClosestPoints m = segment_box(R * k.a + t, R * k.b + t, {t, R, unit.half});
    EXPECT_NEAR(m.distance, k.distance, 1e-14);
    if (k.distance > 0.0) {
      EXPECT_LT((m.normal - R * c.normal).norm(), 1e-12);
    }
    // a capsule about it: the core less the radius (-radius once the segment reaches the box)
    EXPECT_NEAR(capsule_box({k.a, k.b, 0.2}, unit).distance, k.distance - 0.2, 1e-15);
  }
  // inside: the normal crosses the nearest face inward (from the segment into the box)
  const ClosestPoints in = segment_box(Vec3(0.9, 0, 0), Vec3(0.9, 0, 0), unit);
  EXPECT_LT((in.normal - Vec3(-1, 0, 0)).norm(), 1e-15);
  // a flat box (zero half-extent): a rectangle
  EXPECT_NEAR(segment_box(Vec3(0, 0, 1), Vec3(0, 0, 2), {Vec3::Zero(), Mat3::Identity(), Vec3(1, 1, 0)}).distance,
              1.0, 1e-15);
}

/// Central differences of f (3 coordinates of one endpoint) against an analytic gradient; returns
/// false (not compared) when f has a kink within the step (one-sided differences disagree).
bool check_gradient(const std::function<double(const Vec3&)>& f, const Vec3& x, const Vec3& analytic) {
  constexpr double h = 1e-6;
  const double f0 = f(x);
  for (int i = 0; i < 3; ++i) {
    Vec3 xp = x, xm = x;
    xp[i] += h, xm[i] -= h;
    const double fp = f(xp), fm = f(xm);
    if (std::abs((fp - f0) - (f0 - fm)) / h > 1e-4) return false;
    EXPECT_NEAR((fp - fm) / (2 * h), analytic[i], 1e-6 * std::max(1.0, std::abs(analytic[i])));
  }
  return true;
}

TEST(EndpointGradient, AgainstCentralDifferences) {
  Random r(600);
  int checked = 0, tried = 0;
  for (int i = 0; i < kCases; ++i) {
    Vec3 a0, b0, a1, b1;
    segment_pair(r, i % 4 == 3 ? 3 : 0, a0, b0, a1, b1);  // generic and zero-length
    const Capsule c1{a1, b1, 0.1};
    const Box box = r.box();
    const double rad = 0.05;
    using Fn = std::function<double(const Vec3&, const Vec3&)>;
    const Fn fns[] = {
        [&](const Vec3& a, const Vec3& b) { return capsule_capsule({a, b, rad}, c1).distance; },
        [&](const Vec3& a, const Vec3& b) { return capsule_sphere({a, b, rad}, {a1, 0.2}).distance; },
        [&](const Vec3& a, const Vec3& b) { return capsule_box({a, b, rad}, box).distance; },
    };
    const ClosestPoints cs[] = {capsule_capsule({a0, b0, rad}, c1), capsule_sphere({a0, b0, rad}, {a1, 0.2}),
                                capsule_box({a0, b0, rad}, box)};
    for (int k = 0; k < 3; ++k) {
      if (cs[k].core < 1e-3) continue;  // no derivative at touching cores
      if (a0 == b0) continue;           // one-sided there (first_segment_gradient): see ZeroLength below
      ++tried;
      const EndpointGradient g = first_segment_gradient(cs[k]);
      const bool ok_a = check_gradient([&](const Vec3& a) { return fns[k](a, b0); }, a0, g.d_a);
      const bool ok_b = check_gradient([&](const Vec3& b) { return fns[k](a0, b); }, b0, g.d_b);
      checked += ok_a && ok_b;
    }
    if (cs[0].core >= 1e-3 && a1 != b1) {  // the second capsule's endpoints
      const EndpointGradient g = second_segment_gradient(cs[0]);
      check_gradient([&](const Vec3& a) { return capsule_capsule({a0, b0, rad}, {a, b1, 0.1}).distance; }, a1, g.d_a);
      check_gradient([&](const Vec3& b) { return capsule_capsule({a0, b0, rad}, {a1, b, 0.1}).distance; }, b1, g.d_b);
    }
  }
  EXPECT_GT(checked, 0.95 * tried) << checked << " of " << tried;
  std::printf("endpoint gradients compared: %d of %d cases (the rest at a kink within the step)\n", checked, tried);
}

TEST(EndpointGradient, ZeroLengthIsOneSided) {
  // a zero-length capsule at p: moving a and b together (a translation) is exact: d_a + d_b = -normal
  const Vec3 p(0.3, 0.4, 0);
  const ClosestPoints c = capsule_sphere({p, p, 0.1}, {Vec3::Zero(), 0.2});
  const EndpointGradient g = first_segment_gradient(c);
  EXPECT_LT((g.d_a + g.d_b + c.normal).norm(), 1e-15);
  const double h = 1e-6;
  const Vec3 e = Vec3(1, 2, -1).normalized();
  const double fd = (capsule_sphere({p + h * e, p + h * e, 0.1}, {Vec3::Zero(), 0.2}).distance -
                     capsule_sphere({p - h * e, p - h * e, 0.1}, {Vec3::Zero(), 0.2}).distance) / (2 * h);
  EXPECT_NEAR(fd, (g.d_a + g.d_b).dot(e), 1e-9);
}

}  // namespace
