#include "runner/execute.hpp"

#include <cmath>
#include <optional>
#include <vector>

#include "ik/solve.hpp"
#include "methods/trajectory.hpp"

namespace ks {

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();


/// A row-major rows x cols history array from the first `rows` columns of a cols x N matrix
/// (column-major storage: the same bytes).
template <class M>
HistoryArray array_of(std::string name, std::string unit, const M& m, Eigen::Index rows) {
  HistoryArray a{std::move(name), std::move(unit), static_cast<std::size_t>(rows), static_cast<std::size_t>(m.rows()), {}};
  a.data.assign(m.data(), m.data() + rows * m.rows());
  return a;
}
}  // namespace

struct RunWorkspace::Impl {
  const StudyTask* task = nullptr;
  std::vector<SampledPath> paths;  // the study's path sampled at the last few dt asked for
  TrajectoryHistory history;
  ik::Summary<3, 3> s33;
  ik::Summary<3, 2> s32;
  const SampledPath& path_of(const StudyTask& t, double dt) {
    if (task != &t) {
      paths.clear();
      task = &t;
    }
    for (const SampledPath& p : paths)  // a dt axis alternates between a few values: keep them all
      if (p.dt() == dt) return p;
    if (paths.size() == 8) paths.erase(paths.begin());
    return paths.emplace_back(t.path(), dt);
  }
};
RunWorkspace::RunWorkspace() : impl_(std::make_unique<Impl>()) {}
RunWorkspace::~RunWorkspace() = default;

namespace {

RunOutcome run_trajectory(const Scenario& sc, const TrajectoryRun& run, int stride, RunWorkspace::Impl& ws) {
  PlanarArm3 arm = *sc.robot;
  arm.inertia_form = run.inertia;
  const SampledPath& path = ws.path_of(*sc.task, run.options.dt);
  TrajectoryHistory* h = nullptr;
  if (stride > 0) {
    ws.history.stride = stride;
    h = &ws.history;
  }
  RunOutcome out;
  out.result = simulate(arm, path, run.options, h);
  if (h && h->size > 0) {
    const Eigen::Index n = h->size;
    auto& a = out.history.arrays;
    a.push_back({"t", "s", static_cast<std::size_t>(n), 1, std::vector<double>(h->t.data(), h->t.data() + n)});
    a.push_back(array_of("q", "rad", h->q, n));
    a.push_back(array_of("qd", "rad/s", h->qd, n));
    a.push_back(array_of("qdd", "rad/s^2", h->qdd, n));
    a.push_back(array_of("tau", "Nm", h->tau, n));
    a.push_back(array_of("x", "m", h->x, n));
    a.push_back({"alpha", "rad", static_cast<std::size_t>(n), 1, std::vector<double>(h->alpha.data(), h->alpha.data() + n)});
  }
  return out;
}

template <class P, int M>
RunOutcome solve_ik(const P& problem, const Vec3& q0, const ik::Options& o, int stride, ik::Summary<3, M>& s,
                    const char* q3_unit) {
  ik::solve(problem, q0, o, s);
  RunOutcome out;
  out.result = IkResult{s.status, s.iterations, s.rejected, s.solution, s.error, s.min_rcond, s.q};
  if (stride > 0 && s.history.size() > 0) {
    const std::size_t n = s.history.size();
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < n; k += stride) rows.push_back(k);
    if (rows.back() != n - 1) rows.push_back(n - 1);
    HistoryArray k{"k", "", rows.size(), 1, {}}, q{"q", std::string("rad, rad, ") + q3_unit, rows.size(), 3, {}},
        F{"F", "problem units", rows.size(), M, {}}, e{"norm_F", "problem units", rows.size(), 1, {}},
        st{"step", "problem units", rows.size(), 1, {}}, l{"lambda", "", rows.size(), 1, {}};
    for (std::size_t r : rows) {
      k.data.push_back(static_cast<double>(r));
      for (int j = 0; j < 3; ++j) q.data.push_back(s.history.q[r][j]);
      for (int j = 0; j < M; ++j) F.data.push_back(s.history.F[r][j]);
      e.data.push_back(s.history.error[r]);
      st.data.push_back(s.history.step[r]);
      l.data.push_back(s.history.lambda[r]);
    }
    out.history.arrays = {std::move(k), std::move(q), std::move(F), std::move(e), std::move(st), std::move(l)};
  }
  return out;
}

RunOutcome run_ik(const Scenario& sc, const IkRun& run, int stride, RunWorkspace::Impl& ws) {
  ik::Options o = run.options;
  o.keep_history = stride > 0;
  switch (run.problem) {
    case IkProblem::scara: {
      ik::ScaraPosition s;
      s.target = run.target;
      s.z_mode = run.z_mode == ZMode::physical ? ik::ScaraZ::physical : ik::ScaraZ::thesis;
      return solve_ik(s, run.q0, o, stride, ws.s33, "mm");
    }
    case IkProblem::planar3r_pose: {
      ik::PlanarPose s;
      s.arm = *sc.robot;
      s.target = run.target.head<2>();
      s.alpha = run.target_alpha;
      return solve_ik(s, run.q0, o, stride, ws.s33, "rad");
    }
    case IkProblem::planar3r_position: break;
  }
  ik::PlanarPosition s;
  s.arm = *sc.robot;
  s.target = run.target.head<2>();
  return solve_ik(s, run.q0, o, stride, ws.s32, "rad");
}

}  // namespace

RunOutcome execute(const Scenario& scenario, const RunSpec& run, int history_stride, RunWorkspace& workspace) {
  if (const auto* t = std::get_if<TrajectoryRun>(&run))
    return run_trajectory(scenario, *t, history_stride, workspace.impl());
  return run_ik(scenario, std::get<IkRun>(run), history_stride, workspace.impl());
}

}  // namespace ks
