// The study's robot in its plane: a planar chain (in whatever plane of its base frame it moves) is
// simulated as the same chain in its plane's frame (model/chain_plane.hpp), and gravity is checked
// against that plane.
#include <cmath>

#include "study/parser.hpp"

namespace ks::study_parse {

namespace {

std::string vec(const Eigen::Vector3d& v) {
  // components within 1e-15 of 0 shown as 0 (the plane axes of a rotated URDF frame carry roundoff)
  auto c = [](double x) { return fmt(std::abs(x) < 1e-15 ? 0.0 : x); };
  return "(" + c(v.x()) + ", " + c(v.y()) + ", " + c(v.z()) + ")";
}

}  // namespace

void Parser::place_robot_in_plane(Study& s) {
  if (!s.chain) {  // the seed's closed-form 3R: the base xy plane
    s.plane = ChainPlane{};
    return;
  }
  s.base_chain = s.chain;
  s.gravity_defaulted = robot_without_gravity_ != nullptr;
  s.plane = motion_plane(*s.chain);
  if (s.plane) s.chain = std::make_shared<const Chain>(in_plane_frame(*s.chain, *s.plane));
}

void Parser::check_gravity_given(Study& s) {
  if (!robot_without_gravity_ || !s.plane) return;
  const Eigen::Vector3d n = s.plane->normal();
  if (std::abs(n.z()) <= kParallelTol) return;  // a vertical plane: base -z lies in it
  error(*robot_without_gravity_,
        "a " + robot_without_gravity_kind_ + " robot without gravity whose chain moves in a plane that is not vertical (normal " + vec(n) +
            " in the base frame): the default, base -z (" + (robot_without_gravity_kind_ == "URDF" ? "URDF's " : "") + "z up), is " +
            (std::abs(std::abs(n.z()) - 1.0) <= kParallelTol ? "normal to the plane" : "partly normal to the plane") +
            "; expected gravity = [gx, gy, gz] in [robot] (m/s^2, base frame), e.g. [0, 0, -9.81] for a horizontal "
            "arm (no gravity torques) or [0, -9.81, 0] for gravity along base -y (the seed arm's convention)");
}

std::optional<Eigen::Vector2d> Parser::vertex_in_plane(const toml::node& at, const Eigen::Vector3d& x,
                                                       const ChainPlane& plane) {
  double off = 0.0;
  const Eigen::Vector2d u = plane.to_plane(x, &off);
  if (std::abs(off) <= kVertexOffPlane) return u;
  error(at, "the vertex " + vec(x) + " m (base frame) is " + fmt(std::abs(off)) +
                " m off the plane the robot's tip moves in (origin " + vec(plane.origin()) + " m, normal " +
                vec(plane.normal()) + "); expected a point on that plane (within " + fmt(kVertexOffPlane) +
                " m), or [x, y] in plane coordinates (along " + vec(plane.e1()) + " and " + vec(plane.e2()) + ")");
  return std::nullopt;
}

}  // namespace ks::study_parse
