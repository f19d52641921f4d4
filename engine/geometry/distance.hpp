#pragma once
// Closest points and distances between the shapes a motion planner with obstacles needs: a robot
// link as a capsule (a segment swept by a ball), obstacles as spheres, oriented boxes and capsules.
// Every length is in metres, in one common (e.g. the base) frame. Free functions on small value
// types; no allocation.
//
// Conventions of every result (ClosestPoints):
//  - distance: between the surfaces, the core distance (segment to segment, point or box) minus the
//    radii. Negative: the shapes overlap by -distance; for sphere and capsule pairs that is the
//    penetration depth (the shortest translation that separates them: the set of differences of two
//    segments is flat, so it has no inside, and every core point pair within r1 + r2 separates along
//    the normal by r1 + r2 - core). For a capsule and a box it is the depth only while the core
//    segment stays outside the box: once the segment touches or enters the box, the core distance
//    is 0 and distance is -radius (the true depth is larger).
//  - point_a, point_b: witness points on the first and the second shape's surface (the core
//    witnesses moved by their radii along the normal; when the shapes overlap these are the deepest
//    points, point_b then lying on the first shape's side of point_a).
//  - normal: unit, from the first shape toward the second, (core_b - core_a) / core. When the cores
//    touch (core == 0) it is not defined by the points; a separating direction is chosen instead,
//    as each function states.
//  - s, t: the parameters in [0, 1] of the witnesses on the first and the second segment
//    (x = a + s (b - a)); t = 0 when the second shape has no segment.
#include <Eigen/Core>

namespace ks::geometry {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// A ball of radius `radius` [m] about `centre` [m].
struct Sphere {
  Vec3 centre = Vec3::Zero();
  double radius = 0.0;
};

/// The points within `radius` [m] of the segment a-b [m] (a sphere when a == b).
struct Capsule {
  Vec3 a = Vec3::Zero();
  Vec3 b = Vec3::Zero();
  double radius = 0.0;
};

/// An oriented box: the points centre + rotation * x with |x_i| <= half[i]. rotation's columns are
/// the box axes in the common frame (orthonormal); half-extents >= 0 [m].
struct Box {
  Vec3 centre = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
  Vec3 half = Vec3::Zero();
};

/// Closest points of two shapes (conventions above).
struct ClosestPoints {
  double distance = 0.0;  ///< between the surfaces [m]; < 0: overlap
  double core = 0.0;      ///< between the cores (segments, centre points, box) [m], >= 0
  Vec3 point_a = Vec3::Zero();  ///< witness on the first shape's surface [m]
  Vec3 point_b = Vec3::Zero();  ///< witness on the second shape's surface [m]
  Vec3 normal = Vec3::UnitX();  ///< unit, from the first shape toward the second
  double s = 0.0;         ///< the first segment's witness parameter, in [0, 1]
  double t = 0.0;         ///< the second segment's witness parameter, in [0, 1] (0: no segment)
};

/// Segment a-b and point p [m]: the clamped projection s = clamp((p - a).(b - a) / |b - a|^2, 0, 1)
/// (s = 0 for a zero-length segment). point_a = a + s (b - a), point_b = p, distance = core =
/// |p - point_a|. Core 0 (p on the segment): the normal is any unit vector perpendicular to b - a
/// (unit x for a zero-length segment along no axis).
ClosestPoints segment_point(const Vec3& a, const Vec3& b, const Vec3& p);

/// Segments a0-b0 and a1-b1 [m]: the pair (s, t) minimising |x0(s) - x1(t)| over [0, 1]^2.
/// Method: the lines' common perpendicular, from cross products (s = ((a1 - a0) x d1).(d0 x d1) /
/// |d0 x d1|^2, t the projection of x0(s) on the second line), when the lines are not parallel and
/// it falls inside the square; else
/// the minimum lies on the square's boundary and is the least of the four endpoint-to-segment
/// clamped projections (exact for parallel segments, zero-length ones and every boundary case).
/// Core 0 (the segments cross): the normal is d0 x d1 normalised, else a unit vector
/// perpendicular to the segments.
ClosestPoints segment_segment(const Vec3& a0, const Vec3& b0, const Vec3& a1, const Vec3& b1);

/// Segment a-b and box [m]: the exact minimum over s of the point-box distance (the length of
/// x(s) - clamp(x(s)) in the box frame). Method: that squared distance is convex and piecewise
/// quadratic in s, with its pieces cut where the segment crosses a face plane (at most 6 cuts);
/// on each piece the clamped coordinates are fixed, so its minimiser is a closed-form quotient,
/// clamped to the piece; the least over the pieces is the minimum. point_a on the segment, point_b
/// on the box. Core 0 (the segment touches or enters the box): the normal points from point_a
/// across the box face nearest to it (minus that face's outward normal).
ClosestPoints segment_box(const Vec3& a, const Vec3& b, const Box& box);

/// Capsule and sphere: segment_point(capsule.a, capsule.b, sphere.centre), less both radii.
ClosestPoints capsule_sphere(const Capsule& capsule, const Sphere& sphere);

/// Capsule and capsule: segment_segment of their segments, less both radii.
ClosestPoints capsule_capsule(const Capsule& c0, const Capsule& c1);

/// Capsule and box: segment_box(capsule.a, capsule.b, box), less the capsule's radius (see the
/// conventions above for an overlap).
ClosestPoints capsule_box(const Capsule& capsule, const Box& box);

/// The derivative of a distance with respect to the endpoints a, b of the first shape's segment
/// (a capsule's or a segment's), the second shape fixed [m/m].
struct EndpointGradient {
  Vec3 d_a = Vec3::Zero();  ///< d distance / d a
  Vec3 d_b = Vec3::Zero();  ///< d distance / d b
};

/// d distance / d(a, b) of the first segment: the core distance is min over s of
/// dist(x(s), second shape), x(s) = (1 - s) a + s b, so by the envelope theorem its derivative is
/// the inner function's at the witness s (dist's gradient at x(s) being -normal):
///   d_a = -(1 - s) normal,   d_b = -s normal.
/// The witness's own variation contributes nothing: at an interior minimum d/ds vanishes; at an
/// end (s = 0 or 1, the distance growing into the segment) s stays there under small moves; where
/// the minimiser passes from the interior to an end both one-sided derivatives equal this one. The
/// radii are constants. Exact wherever core > 0 and the witness is unique. Where it is not, the
/// distance has only one-sided derivatives and this is the one of the returned witness: a
/// zero-length segment (s = 0: the derivative of the moves in which a stays the nearer end;
/// exact for translations, d_a + d_b = -normal) or parallel segments with overlapping projections
/// (a range of witnesses). At core == 0 (cores touching or crossing, a segment in a box) there is
/// no derivative: the formula then moves along the chosen normal, a separating direction.
EndpointGradient first_segment_gradient(const ClosestPoints& c);

/// d distance / d(a1, b1) of the second segment (capsule_capsule, segment_segment): by the same
/// argument, d_a = (1 - t) normal, d_b = t normal.
EndpointGradient second_segment_gradient(const ClosestPoints& c);

}  // namespace ks::geometry
