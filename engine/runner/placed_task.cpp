// A task at its place and its inverse-kinematics error (see placed_task.hpp).
#include "runner/placed_task.hpp"

#include <algorithm>
#include <cmath>

#include "ik/chain_ik.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/chain/start.hpp"

namespace ks {

StudyTask place_task(const StudyTask& task, const TaskPlacement& p, bool planar) {
  StudyTask out = task;
  if (planar) {
    for (Eigen::Vector2d& v : out.vertices) v = p.place(Eigen::Vector2d(v));
    for (double& a : out.orientation) a += p.rotation;
  } else {
    out.z.assign(task.vertices.size(), 0.0);
    for (std::size_t i = 0; i < task.vertices.size(); ++i) {
      const Eigen::Vector3d v = p.place(task.vertex(i));
      out.vertices[i] = v.head<2>();
      out.z[i] = v.z();
    }
  }
  for (double& d : out.durations) d *= p.time_scale;
  return out;
}

namespace {

/// Eq. 2.24: the residual counted when it is epsilon or more [m].
double counted(double residual) { return residual >= kIkErrorEpsilon ? residual : 0.0; }

/// The distance [m] from p to the annulus radii [inner, outer] about the origin.
double annulus_distance(const Eigen::Vector2d& p, double inner, double outer) {
  const double r = p.norm();
  return std::max({0.0, r - outer, inner - r});
}

/// The position IK error of a chain at the task's vertices (task_ik_error).
double chain_ik_error(const StudyTask& task, const Chain& chain) {
  bool limited = false;
  for (const ChainJoint& j : chain.joints) limited = limited || j.limited();
  ik::Options o;
  o.method = ik::Method::lm_adaptive;
  o.tolerance = 1e-12;
  o.max_iter = 500;
  o.keep_history = false;
  o.joint_limits = limited ? ik::JointLimits::clamp : ik::JointLimits::none;
  ik::ChainIkTask t;
  t.kind = chain.planar() ? ik::ChainIkTask::Kind::planar_position : ik::ChainIkTask::Kind::spatial_position;
  ik::ChainIkWorkspace ws;
  ik::ChainIkResult r;
  // the automatic guess of a run's start (runner/execute.cpp start_guess with q0 unset), within the limits
  VecN guess = chain.planar() ? planar_start_guess(chain.dof()) : VecN::Constant(chain.dof(), 0.3);
  for (int j = 0; j < chain.dof(); ++j) {
    const ChainJoint& c = chain.joints[j];
    if (c.limited() && std::isfinite(c.lower) && std::isfinite(c.upper))
      guess[j] = c.type == JointType::prismatic ? 0.5 * (c.lower + c.upper) : std::clamp(guess[j], c.lower, c.upper);
  }
  // a second start for arms whose limits leave the first one's branch: each limited joint mid-range
  VecN middle = guess;
  for (int j = 0; j < chain.dof(); ++j) {
    const ChainJoint& c = chain.joints[j];
    if (c.limited() && std::isfinite(c.lower) && std::isfinite(c.upper)) middle[j] = 0.5 * (c.lower + c.upper);
  }
  VecN q = guess;
  double sum = 0.0;
  for (std::size_t i = 0; i < task.vertices.size(); ++i) {
    t.position = task.vertex(i);
    if (chain.planar()) t.position.z() = 0.0;
    ik::solve_chain(chain, t, q, o, r, ws);
    double best = std::isfinite(r.error) ? r.error : std::numeric_limits<double>::infinity();
    VecN best_q = r.q;
    for (const VecN* start : {&guess, &middle}) {  // again from the automatic guess, then mid-range
      if (best < kIkErrorEpsilon || (start == &middle && middle == guess)) break;
      ik::solve_chain(chain, t, *start, o, r, ws);
      if (std::isfinite(r.error) && r.error < best) {
        best = r.error;
        best_q = r.q;
      }
    }
    sum += counted(best);
    if (best_q.size() == chain.dof() && best_q.allFinite()) q = best_q;
  }
  return sum;
}

}  // namespace

double task_ik_error(const StudyTask& task, const PlanarArm3& arm, const Chain* chain) {
  if (chain) return chain_ik_error(task, *chain);
  const double outer = arm.l[0] + arm.l[1] + arm.l[2];
  const double inner = std::max(0.0, 2.0 * std::max({arm.l[0], arm.l[1], arm.l[2]}) - outer);
  double sum = 0.0;
  for (const Eigen::Vector2d& v : task.vertices) sum += counted(annulus_distance(v, inner, outer));
  return sum;
}

}  // namespace ks
