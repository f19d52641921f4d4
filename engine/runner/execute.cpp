#include "runner/execute.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ik/chain_ik.hpp"
#include "ik/solve.hpp"
#include "methods/chain/trajectory.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/closed_form/lanes.hpp"
#include "runner/execute_motion.hpp"
#include "runner/placed_task.hpp"
#include "schema/history_arrays.hpp"

namespace ks {

namespace {

/// The history arrays `defs` declares, from a run's buffers (TrajectoryHistory or ChainHistory:
/// column-major cols x N matrices, so their first `size` columns are the row-major array's bytes),
/// in the declared order t, q, qd, qdd, tau, x, alpha.
template <class H>
std::vector<HistoryArray> trajectory_arrays(const std::vector<HistoryArrayDef>& defs, const H& h) {
  const double* src[] = {h.t.data(), h.q.data(), h.qd.data(), h.qdd.data(), h.tau.data(), h.x.data(), h.alpha.data()};
  const Eigen::Index rows[] = {1, h.q.rows(), h.qd.rows(), h.qdd.rows(), h.tau.rows(), h.x.rows(), 1};
  std::vector<HistoryArray> out;
  out.reserve(defs.size());
  const auto n = static_cast<std::size_t>(h.size);
  for (std::size_t i = 0; i < defs.size(); ++i) {
    assert(static_cast<std::size_t>(rows[i]) == defs[i].columns);
    out.push_back({defs[i].name, defs[i].unit, n, defs[i].columns,
                   std::vector<double>(src[i], src[i] + n * static_cast<std::size_t>(rows[i]))});
  }
  return out;
}


/// The history arrays of an IK run, `defs` declaring k, q, F, norm_F, step, lambda: every
/// stride-th iterate of `h` and the last.
template <class Hist>
std::vector<HistoryArray> ik_arrays(const std::vector<HistoryArrayDef>& defs, const Hist& h, int stride) {
  const std::size_t n = h.size();
  std::vector<std::size_t> rows;
  for (std::size_t k = 0; k < n; k += static_cast<std::size_t>(stride)) rows.push_back(k);
  if (rows.back() != n - 1) rows.push_back(n - 1);
  std::vector<HistoryArray> a;
  for (const HistoryArrayDef& d : defs) a.push_back({d.name, d.unit, rows.size(), d.columns, {}});
  for (auto& x : a) x.data.reserve(rows.size() * x.cols);
  for (std::size_t r : rows) {
    a[0].data.push_back(static_cast<double>(r));
    for (std::size_t j = 0; j < a[1].cols; ++j) a[1].data.push_back(h.q[r][j]);
    for (std::size_t j = 0; j < a[2].cols; ++j) a[2].data.push_back(h.F[r][j]);
    a[3].data.push_back(h.error[r]);
    a[4].data.push_back(h.step[r]);
    a[5].data.push_back(h.lambda[r]);
  }
  return a;
}
}  // namespace

struct RunWorkspace::Impl {
  const StudyTask* task = nullptr;
  /// The study's task at a placement (the identity: the task as written) and its IK error (NaN until
  /// measured); the last few placements asked for.
  struct Placed {
    TaskPlacement placement;
    StudyTask task;
    double ik_error = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<Placed> placed;
  std::vector<std::pair<TaskPlacement, SampledPath>> paths;  // a placed task sampled at the last few dt asked for
  std::vector<std::pair<TaskPlacement, ChainTask>> chain_tasks;  // the same for chains
  TrajectoryHistory history;
  std::array<TrajectoryHistory, 8> lane_histories;  // one per lane of a batch
  ChainHistory chain_history;
  ik::Summary<3, 3> s33;
  ik::Summary<3, 2> s32;
  ik::ChainIkWorkspace chain_ik;
  ik::ChainIkResult chain_result;
  /// Forget every cached task when the study's task is another one.
  void use(const StudyTask& t) {
    if (task == &t) return;
    placed.clear();
    paths.clear();
    chain_tasks.clear();
    task = &t;
  }
  /// The study's task `t` at placement `p` (`planar`: the robot's task is in its plane).
  Placed& placed_of(const StudyTask& t, const TaskPlacement& p, bool planar) {
    use(t);
    for (Placed& x : placed)
      if (x.placement.same_transform(p)) return x;
    if (placed.size() == 8) placed.erase(placed.begin());
    return placed.emplace_back(Placed{p, p.identity() ? t : place_task(t, p, planar)});
  }
  const ChainTask& chain_task_of(const StudyTask& t, const TaskPlacement& p, bool planar, TaskSpace space, double dt) {
    use(t);
    for (const auto& [q, c] : chain_tasks)
      if (c.path.dt() == dt && c.space == space && q.same_transform(p)) return c;
    if (chain_tasks.size() == 8) chain_tasks.erase(chain_tasks.begin());
    const StudyTask& pt = placed_of(t, p, planar).task;
    std::vector<Eigen::Vector3d> v;
    for (std::size_t i = 0; i < pt.vertices.size(); ++i) v.push_back(pt.vertex(i));
    return chain_tasks.emplace_back(p, ChainTask(space, Path3(std::move(v), pt.durations, pt.shape), dt)).second;
  }
  const SampledPath& path_of(const StudyTask& t, const TaskPlacement& p, double dt) {
    use(t);
    for (const auto& [q, path] : paths)  // a dt axis alternates between a few values: keep them all
      if (path.dt() == dt && q.same_transform(p)) return path;
    if (paths.size() == 8) paths.erase(paths.begin());
    return paths.emplace_back(p, SampledPath(placed_of(t, p, true).task.path(), dt)).second;
  }
};
RunWorkspace::RunWorkspace() : impl_(std::make_unique<Impl>()) {}
RunWorkspace::~RunWorkspace() = default;

namespace {

/// The task space of a chain's path: planar or spatial, with or without the orientation.
TaskSpace task_space(const Chain& chain, const StudyTask& task) {
  if (chain.planar()) return task.orientation.empty() ? TaskSpace::planar_position : TaskSpace::planar_pose;
  return task.hold_orientation ? TaskSpace::spatial_pose : TaskSpace::spatial_position;
}

/// The initial guess of a chain's start: the run's q0, or (NaN entries) the automatic guess: for
/// planar chains planar_start_guess, for spatial ones mid-range of each limited joint, else 0.3 rad.
VecN start_guess(const Chain& chain, const VecN& q0) {
  if (q0.size() == chain.dof() && q0.allFinite()) return q0;
  VecN g = chain.planar() ? planar_start_guess(chain.dof()) : VecN::Constant(chain.dof(), 0.3);
  for (int j = 0; j < chain.dof(); ++j) {
    const ChainJoint& c = chain.joints[j];
    if (!chain.planar() && c.limited() && std::isfinite(c.lower) && std::isfinite(c.upper))
      g[j] = c.type == JointType::prismatic ? 0.5 * (c.lower + c.upper) : std::clamp(0.3, c.lower, c.upper);
    if (j < q0.size() && std::isfinite(q0[j])) g[j] = q0[j];
  }
  return g;
}

/// The most samples a trajectory run takes (its path's duration / dt; a time scale lengthens the
/// path): more are not simulated (undersampled: the run would hold more samples than a sweep keeps).
constexpr double kMaxRunSamples = 1e7;

RunOutcome run_chain_trajectory(const Scenario& sc, const TrajectoryRun& run, const StudyTask& placed, int stride,
                                RunWorkspace::Impl& ws) {
  const Chain& chain = *sc.chain;
  TaskSpace space = task_space(chain, placed);
  // vertex_alpha: the seed's baseline prescribes the tip angle at the vertices (alpha1A and the run's
  // vertex_alpha_i): a planar pose task of a 3-joint arm
  const bool vertex_alpha = run.options.method == TrajectoryMethod::vertex_alpha && space == TaskSpace::planar_position;
  if (vertex_alpha) space = TaskSpace::planar_pose;
  const ChainTask& task = ws.chain_task_of(*sc.task, run.placement, chain.planar(), space, run.options.dt);
  TrajectoryOptions o = run.options;
  if (space == TaskSpace::planar_pose && !vertex_alpha) {  // the path's orientation: alpha1A and the later vertices
    o.alpha1A = placed.orientation.front();
    o.vertex_alpha.assign(placed.orientation.begin() + 1, placed.orientation.end());
  }
  ChainHistory* h = nullptr;
  if (stride > 0) {
    ws.chain_history.stride = stride;
    h = &ws.chain_history;
  }
  RunOutcome out;
  out.result = simulate(chain, task, start_guess(chain, run.q0), o, h);
  if (h && h->size > 0) out.history.arrays = trajectory_arrays(trajectory_history_arrays(RobotShape::of(chain)), *h);
  return out;
}

/// A closed-form 3R run's outcome: its metrics and (when `h` holds samples) its history arrays.
RunOutcome trajectory_outcome(const TrajectoryMetrics& metrics, const TrajectoryHistory* h) {
  RunOutcome out;
  out.result = metrics;
  if (h && h->size > 0) out.history.arrays = trajectory_arrays(trajectory_history_arrays(RobotShape{}), *h);
  return out;
}


RunOutcome run_trajectory(const Scenario& sc, const TrajectoryRun& run, int stride, RunWorkspace::Impl& ws) {
  const int joints = sc.chain ? sc.chain->dof() : 3;
  const bool planar = !sc.chain || sc.chain->planar();
  RunWorkspace::Impl::Placed& placed = ws.placed_of(*sc.task, run.placement, planar);
  const StudyTask& task = placed.task;
  double ik_error = std::numeric_limits<double>::quiet_NaN();
  if (run.placement.measured) {  // seed 002's IK error of the placed task, once per placement
    if (std::isnan(placed.ik_error)) placed.ik_error = task_ik_error(task, *sc.robot, sc.chain);
    ik_error = placed.ik_error;
  }
  const auto ended = [&](RunStatus status) {
    RunOutcome out;
    TrajectoryMetrics m = not_simulated(status, joints);
    m.ik_error = ik_error;
    out.result = m;
    return out;
  };
  if (ik_error > 0.0) return ended(RunStatus::out_of_reach);
  double duration = 0.0;
  for (double d : task.durations) duration += d;
  if (!samples_path(task.sampled_spans(), run.options.dt) || !(duration / run.options.dt < kMaxRunSamples))
    return ended(RunStatus::undersampled);  // a swept dt (or time scale) the path cannot be sampled at
  RunOutcome out;
  if (sc.chain) {
    out = run_chain_trajectory(sc, run, task, stride, ws);
  } else {
    PlanarArm3 arm = *sc.robot;
    arm.inertia_form = run.inertia;
    const SampledPath& path = ws.path_of(*sc.task, run.placement, run.options.dt);
    TrajectoryHistory* h = nullptr;
    if (stride > 0) {
      ws.history.stride = stride;
      h = &ws.history;
    }
    out = trajectory_outcome(simulate(arm, path, run.options, h), h);
  }
  std::get<TrajectoryMetrics>(out.result).ik_error = ik_error;
  return out;
}

/// The restarts' generator seed of an IK run: its restart_seed mixed (splitmix64 steps) with the bits
/// of its problem, start and target, so a run stays a pure function of its parameters (the same
/// whatever the thread count, rank or run id) while different starts and targets draw independent
/// restarts. The method is left out: methods compared on one start and target restart from the same
/// configurations.
std::uint64_t restart_seed_of(const IkRun& run) {
  std::uint64_t h = 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(run.restart_seed);
  auto mix = [&h](std::uint64_t v) {
    h += v + 0x9E3779B97F4A7C15ull;
    std::uint64_t z = h;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    h = z ^ (z >> 31);
  };
  auto bits = [](double x) {
    std::uint64_t u;
    std::memcpy(&u, &x, sizeof u);
    return u;
  };
  mix(static_cast<std::uint64_t>(run.problem));
  for (Eigen::Index j = 0; j < run.q0.size(); ++j) mix(bits(run.q0[j]));
  for (int j = 0; j < 3; ++j) mix(bits(run.target[j]));
  mix(bits(run.target_alpha));
  for (int j = 0; j < 3; ++j) mix(bits(run.target_rpy[j]));
  return h;
}

template <class P, int M>
RunOutcome solve_ik(const P& problem, IkProblem problem_id, const VecN& q0, const ik::Options& o, int stride,
                    ik::Summary<3, M>& s) {
  ik::solve(problem, Vec3(q0.head<3>()), o, s);
  RunOutcome out;
  out.result = IkResult{s.status, s.iterations, s.rejected, s.solution, s.error, s.min_rcond, s.q, s.restarts_used};
  if (stride > 0 && s.history.size() > 0) out.history.arrays = ik_arrays(ik_history_arrays(problem_id, RobotShape{}), s.history, stride);
  return out;
}

/// Rotation R = Rz(yaw) Ry(pitch) Rx(roll) [rad].
Eigen::Matrix3d rotation_rpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

RunOutcome run_chain_ik(const Scenario& sc, const IkRun& run, const ik::Options& o, int stride,
                        RunWorkspace::Impl& ws) {
  const Chain& chain = *sc.ik_chain;
  ik::ChainIkTask task;
  const bool pose = run.problem == IkProblem::pose;
  task.kind = chain.planar() ? (pose ? ik::ChainIkTask::Kind::planar_pose : ik::ChainIkTask::Kind::planar_position)
                             : (pose ? ik::ChainIkTask::Kind::spatial_pose : ik::ChainIkTask::Kind::spatial_position);
  task.position = chain.planar() ? Eigen::Vector3d(run.target[0], run.target[1], 0.0) : Eigen::Vector3d(run.target);
  task.alpha = run.target_alpha;
  task.rotation = rotation_rpy(run.target_rpy);
  ik::ChainIkResult& r = ws.chain_result;
  ik::solve_chain(chain, task, run.q0, o, r, ws.chain_ik);
  RunOutcome out;
  out.result = IkResult{r.status, r.iterations, r.rejected, -1, r.error, r.min_rcond, r.q, r.restarts_used};
  if (stride > 0 && r.history.size() > 0) out.history.arrays = ik_arrays(ik_history_arrays(run.problem, RobotShape::of(chain)), r.history, stride);
  return out;
}

RunOutcome run_ik(const Scenario& sc, const IkRun& run, int stride, RunWorkspace::Impl& ws) {
  ik::Options o = run.options;
  if (std::string why; !o.IsValid(&why)) throw std::invalid_argument("ik run: " + why);
  o.keep_history = stride > 0;
  if (o.restarts > 0) o.restart_seed = restart_seed_of(run);
  switch (run.problem) {
    case IkProblem::position:
    case IkProblem::pose:
      return run_chain_ik(sc, run, o, stride, ws);
    case IkProblem::scara: {
      ik::ScaraPosition s;
      s.target = run.target;
      s.z_mode = run.z_mode == ZMode::physical ? ik::ScaraZ::physical : ik::ScaraZ::thesis;
      return solve_ik(s, run.problem, run.q0, o, stride, ws.s33);
    }
    case IkProblem::planar3r_pose: {
      ik::PlanarPose s;
      s.arm = *sc.robot;
      s.target = run.target.head<2>();
      s.alpha = run.target_alpha;
      return solve_ik(s, run.problem, run.q0, o, stride, ws.s33);
    }
    case IkProblem::planar3r_position: break;
  }
  ik::PlanarPosition s;
  s.arm = *sc.robot;
  s.target = run.target.head<2>();
  return solve_ik(s, IkProblem::planar3r_position, run.q0, o, stride, ws.s32);
}

}  // namespace

// (a placed task's runs run one at a time)
const TrajectoryRun* lane_run(const Scenario& sc, const RunSpec& run) {
  const auto* t = std::get_if<TrajectoryRun>(&run);
  return t && !sc.chain && t->options.method != TrajectoryMethod::global_spline && t->placement.identity() &&
                 !t->placement.measured && samples_path(sc.task->sampled_spans(), t->options.dt)
             ? t
             : nullptr;
}

RunOutcome execute(const Scenario& scenario, const RunSpec& run, int history_stride, RunWorkspace& workspace) {
  if (const auto* t = std::get_if<TrajectoryRun>(&run))
    return run_trajectory(scenario, *t, history_stride, workspace.impl());
  if (const auto* m = std::get_if<MotionRun>(&run)) return run_motion(scenario, *m, history_stride);
  return run_ik(scenario, std::get<IkRun>(run), history_stride, workspace.impl());
}

void execute_batch(const Scenario& scenario, const RunSpec* runs, std::size_t n, int history_stride, int lanes,
                   RunWorkspace& workspace, RunOutcome* out, double* wall_s) {
  using Clock = std::chrono::steady_clock;
  RunWorkspace::Impl& ws = workspace.impl();
  lanes = std::clamp(lanes, 1, std::min(8, max_lanes()));
  std::vector<char> taken(n, 0);
  std::array<std::size_t, 8> group{};
  std::array<TrajectoryOptions, 8> options;
  std::array<TrajectoryMetrics, 8> results;
  std::array<TrajectoryHistory*, 8> histories{};
  for (std::size_t i = 0; i < n; ++i) {
    if (taken[i]) continue;
    const TrajectoryRun* first = lanes > 1 ? lane_run(scenario, runs[i]) : nullptr;
    const auto t0 = Clock::now();
    if (!first) {  // one run alone
      out[i] = execute(scenario, runs[i], history_stride, workspace);
      wall_s[i] = std::chrono::duration<double>(Clock::now() - t0).count();
      continue;
    }
    // The later runs of the batch that can share lanes with run i, in run order.
    int count = 0;
    for (std::size_t j = i; j < n && count < lanes; ++j) {
      const TrajectoryRun* r = taken[j] ? nullptr : lane_run(scenario, runs[j]);
      if (!r || r->inertia != first->inertia || !lane_compatible(first->options, r->options)) continue;
      taken[j] = 1;
      group[count] = j;
      options[count] = r->options;
      if (history_stride > 0) {
        ws.lane_histories[count].stride = history_stride;
        histories[count] = &ws.lane_histories[count];
      } else {
        histories[count] = nullptr;
      }
      ++count;
    }
    PlanarArm3 arm = *scenario.robot;
    arm.inertia_form = first->inertia;
    const SampledPath& path = ws.path_of(*scenario.task, first->placement, first->options.dt);
    simulate_lanes(count == 1 ? 1 : lanes, arm, path, options.data(), count, results.data(), histories.data());
    const double each = std::chrono::duration<double>(Clock::now() - t0).count() / count;
    for (int k = 0; k < count; ++k) {
      out[group[k]] = trajectory_outcome(results[k], histories[k]);
      wall_s[group[k]] = each;
    }
  }
}

}  // namespace ks
