#include "schema/history_arrays.hpp"

#include <algorithm>
#include <cmath>

namespace ks {

namespace {

/// One unit per joint: `revolute` or `prismatic` by joint type; a single unit when all joints agree.
std::string joint_units(const RobotShape& robot, const char* revolute, const char* prismatic) {
  bool any_prismatic = false, all_prismatic = true;
  for (int j = 0; j < robot.joints; ++j) {
    any_prismatic = any_prismatic || robot.is_prismatic(j);
    all_prismatic = all_prismatic && robot.is_prismatic(j);
  }
  if (!any_prismatic) return revolute;
  if (all_prismatic) return prismatic;
  std::string u;
  for (int j = 0; j < robot.joints; ++j) u += (j ? ", " : "") + std::string(robot.is_prismatic(j) ? prismatic : revolute);
  return u;
}

/// The unit of the norm of a vector whose components have the units `units` ("rad, rad, rad"):
/// their one unit, or "problem units" when they differ or are not known.
std::string norm_of(const std::string& units) {
  std::string first;
  for (std::size_t at = 0; at <= units.size();) {
    const std::size_t end = std::min(units.find(", ", at), units.size());
    const std::string part = units.substr(at, end - at);
    if (at == 0) first = part;
    else if (part != first) return "problem units";
    at = end + 2;
  }
  return first.empty() ? "problem units" : first;
}

}  // namespace

std::vector<HistoryArrayDef> trajectory_history_arrays(const RobotShape& robot) {
  const auto n = static_cast<std::size_t>(robot.joints);
  return {
      {"t", "s", 1, "time of the sample"},
      {"q", joint_units(robot, "rad", "m"), n, "joint positions"},
      {"qd", joint_units(robot, "rad/s", "m/s"), n, "joint velocities"},
      {"qdd", joint_units(robot, "rad/s^2", "m/s^2"), n, "joint accelerations"},
      {"tau", joint_units(robot, "Nm", "N"), n, "joint torques (forces for prismatic joints)"},
      {"x", "m", robot.planar ? 2u : 3u, "tip position (planar: in the robot's plane)"},
      {"alpha", "rad", 1, "tip angle in the plane (NaN for spatial robots)"},
  };
}

std::vector<HistoryArrayDef> motion_history_arrays(const RobotShape& robot) {
  const auto n = static_cast<std::size_t>(robot.joints);
  return {
      {"t", "s", 1, "time of the sample (the samples the criteria are integrated on)"},
      {"q", joint_units(robot, "rad", "m"), n, "joint positions"},
      {"qd", joint_units(robot, "rad/s", "m/s"), n, "joint velocities"},
      {"tau", joint_units(robot, "Nm", "N"), n, "joint torques (forces for prismatic joints), RNEA"},
      {"points", "m", 3 * (n + 1),
       "base-frame positions (x, y, z) of joint 1 .. n's origins and of the tip: the link capsules' ends"},
  };
}

std::vector<HistoryArrayDef> ik_history_arrays(IkProblem problem, const RobotShape& robot) {
  // A norm's unit: its components' one unit, "problem units" when they mix units (q in rad and mm).
  std::string q_unit, f_unit = "problem units", norm_unit = "problem units", step_unit;
  std::size_t nq = 3, m = 3;
  switch (problem) {
    case IkProblem::scara:
      q_unit = "rad, rad, mm";
      f_unit = norm_unit = "mm";
      break;
    case IkProblem::planar3r_pose:
      q_unit = step_unit = "rad, rad, rad";
      break;
    case IkProblem::planar3r_position:
      q_unit = step_unit = "rad, rad, rad";
      f_unit = norm_unit = "m";
      m = 2;
      break;
    case IkProblem::position:
    case IkProblem::pose: {
      const bool pose = problem == IkProblem::pose;
      nq = static_cast<std::size_t>(robot.joints);
      m = robot.planar ? (pose ? 3 : 2) : (pose ? 6 : 3);
      std::string u;
      for (int j = 0; j < robot.joints; ++j) u += (j ? ", " : "") + std::string(robot.is_prismatic(j) ? "m" : "rad");
      q_unit = step_unit = u;
      const std::size_t lengths = robot.planar ? 2 : 3;
      f_unit.clear();
      for (std::size_t i = 0; i < m; ++i) f_unit += (i ? ", " : "") + std::string(i < lengths ? "m" : "rad");
      if (!pose) f_unit = norm_unit = "m";
      break;
    }
  }
  return {
      {"k", "", 1, "iteration of the row (every stride-th and the last)"},
      {"q", q_unit, nq, "iterate q_k"},
      {"F", f_unit, m, "residual F(q_k)"},
      {"norm_F", norm_unit, 1, "||F(q_k)||"},
      {"step", norm_of(step_unit), 1, "||q_k - q_{k-1}|| (0 at k = 0)"},
      {"lambda", "", 1, "damping of the step to q_k (lm, lm_adaptive; 0 otherwise)"},
  };
}

std::size_t values_per_row(const std::vector<HistoryArrayDef>& arrays) {
  std::size_t v = 0;
  for (const auto& a : arrays) v += a.columns;
  return v;
}

double history_rows(double duration, double dt, int stride) {
  const double samples = std::floor(duration / dt) + 1;
  return std::ceil(samples / std::max(1, stride)) + 1;
}

double history_bytes_in_memory(double rows, std::size_t values_per_row) {
  return rows * static_cast<double>(values_per_row) * 8.0 * 4.0;
}

}  // namespace ks
