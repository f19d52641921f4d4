// [task] waypoints and spline: the task's path as timed waypoints joined by a cubic spline (seed 002
// Eq. 2.20) instead of vertices and durations joined by rest-to-rest quintics.
#include <cmath>

#include "study/parser.hpp"

namespace ks::study_parse {

/// Reads t's waypoints = [[t, x, y(, z)], ...] (t [s], position [m]) and spline = "natural" | "clamped"
/// (default "clamped": at rest at both ends) into s.task: the waypoints' positions as its vertices, the
/// differences of their times as its durations [s] (the path's time 0 is the first waypoint's t), the
/// spline as its shape. Reports every problem where it is; returns false when the waypoints are unusable.
bool Parser::parse_task_waypoints(const toml::table& t, Study& s) {
  s.task.shape = PathShape::clamped_spline;
  if (t.get("spline")) {
    if (auto v = get_string(t, "spline", "spline")) {
      if (*v == "natural") s.task.shape = PathShape::natural_spline;
      else if (*v != "clamped")
        error(*t.get("spline"), "unknown spline '" + *v + "'; expected \"clamped\" (zero velocity at both ends: "
                                "at rest) or \"natural\" (zero acceleration at both ends)" +
                                    suggest(*v, {"clamped", "natural"}));
    }
  }
  const toml::node& wn = *t.get("waypoints");
  const bool spatial = s.chain && !s.chain->planar();
  const std::size_t dims = spatial ? 3 : 2;
  const std::string point = spatial ? "[t, x, y, z] (t in s, x, y, z in m)"
                                    : "[t, x, y] (t in s, x, y in m, plane coordinates) or [t, x, y, z] (base frame, "
                                      "on the plane)";
  const auto* a = wn.as_array();
  if (!a || a->size() < 2) {
    error(wn, "waypoints is " + (a ? "an array of " + std::to_string(a->size()) : type_name(wn)) +
                  "; expected an array of at least 2 waypoints " + point);
    return false;
  }
  std::vector<Eigen::Vector2d> v;
  std::vector<double> z, times;
  bool ok = true;
  for (const auto& e : *a) {
    const auto* p = e.as_array();
    const bool base_point = !spatial && s.plane && p && p->size() == 4;  // a planar robot's waypoint, base frame
    if (!p || (p->size() != dims + 1 && !base_point)) {
      error(e, "a waypoint is " + (p ? "an array of " + std::to_string(p->size()) : type_name(e)) + "; expected " +
                   point + (spatial ? " (the robot is spatial)" : ""));
      ok = false;
      continue;
    }
    const auto tt = get_number(*p->get(0), "waypoint t");
    const auto x = get_number(*p->get(1), "waypoint x");
    const auto y = get_number(*p->get(2), "waypoint y");
    const std::optional<double> zz =
        spatial || base_point ? get_number(*p->get(3), "waypoint z") : std::optional<double>(0.0);
    if (!tt || !x || !y || !zz) {
      ok = false;
      continue;
    }
    if (!times.empty() && !(*tt > times.back())) {
      error(*p->get(0), "waypoint time t = " + fmt(*tt) + " s is not after the previous waypoint's, " +
                            fmt(times.back()) + " s; expected times strictly increasing");
      ok = false;
    } else if (!times.empty() && !std::isfinite(*tt - times.back())) {
      error(*p->get(0), "waypoint time t = " + fmt(*tt) + " s is " + fmt(*tt - times.back()) +
                            " s after the previous waypoint's; expected a finite time step");
      ok = false;
    }
    times.push_back(*tt);
    if (base_point) {
      if (const auto u = vertex_in_plane(e, {*x, *y, *zz}, *s.plane)) v.push_back(*u), z.push_back(0.0);
      else ok = false;
    } else {
      v.emplace_back(*x, *y), z.push_back(*zz);
    }
  }
  s.task.vertices = v;
  if (spatial) s.task.z = z;
  s.task.durations.clear();
  if (!ok) return false;
  for (std::size_t i = 1; i < times.size(); ++i) s.task.durations.push_back(times[i] - times[i - 1]);
  return true;
}

}  // namespace ks::study_parse
