#include "runner/execute.hpp"

#include <cmath>
#include <optional>
#include <vector>

#include "ik/solve.hpp"
#include "methods/trajectory.hpp"

namespace ks {

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();

ColumnSpec f64(std::string n, std::string unit, std::string d) { return {std::move(n), CellType::f64, std::move(unit), std::move(d)}; }
ColumnSpec i64(std::string n, std::string unit, std::string d) { return {std::move(n), CellType::i64, std::move(unit), std::move(d)}; }

double num(std::span<const Cell> p, const Block& b, std::string_view name) {
  const Cell& c = p[b.column_index(name)];
  if (const double* d = std::get_if<double>(&c)) return *d;
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return static_cast<double>(*i);
  return kNaN;
}
const std::string& str(std::span<const Cell> p, const Block& b, std::string_view name) {
  return std::get<std::string>(p[b.column_index(name)]);
}

/// A row-major rows x cols history array from the first `rows` columns of a cols x N matrix
/// (column-major storage: the same bytes).
template <class M>
HistoryArray array_of(std::string name, std::string unit, const M& m, Eigen::Index rows) {
  HistoryArray a{std::move(name), std::move(unit), static_cast<std::size_t>(rows), static_cast<std::size_t>(m.rows()), {}};
  a.data.assign(m.data(), m.data() + rows * m.rows());
  return a;
}
}  // namespace

const std::vector<ColumnSpec>& trajectory_metric_columns() {
  static const std::vector<ColumnSpec> c{
      f64("E", "Nm", "mean over samples of sqrt(tau^T tau) (seed Eq. 60)"),
      f64("E_M", "Nm/sqrt(kg m^2)", "mean over samples of sqrt(tau^T M^-1 tau)"),
      f64("tau_inf", "Nm", "max over samples and joints of |tau_i|"),
      f64("tau1_inf", "Nm", "max over samples of |tau_1|"),
      f64("tau2_inf", "Nm", "max over samples of |tau_2|"),
      f64("tau3_inf", "Nm", "max over samples of |tau_3|"),
      f64("min_manipulability", "m^2", "min over samples of sqrt(det(J J^T))"),
      f64("torque_sq_integral", "N^2 m^2 s", "trapezoidal integral of sum tau_i^2 (seed 002 f5)"),
      f64("power_sq_integral", "W^2 s", "trapezoidal integral of sum (tau_i qd_i)^2 (seed 002 f6)"),
      f64("max_tracking_error", "m", "max over samples of |tip - path| (open-loop drift)"),
      f64("final_alpha", "rad", "end-effector orientation at the last sample"),
      i64("samples", "", "samples computed (2001 for the seed's square)"),
      f64("stop_time", "s", "time of the last sample computed"),
  };
  return c;
}

const std::vector<ColumnSpec>& ik_metric_columns() {
  static const std::vector<ColumnSpec> c{
      i64("iterations", "", "updates made (the seed's count)"),
      f64("error", "problem units", "||F|| at the final iterate (mm for scara, m/rad for planar3r)"),
      i64("solution", "", "index of the known exact solution reached (mod 2 pi), -1 if none"),
      i64("rejected", "", "lm_adaptive: rejected trial steps"),
      f64("min_rcond", "", "smallest reciprocal condition number met"),
      f64("q_final_1", "rad", "final iterate, joint 1"),
      f64("q_final_2", "rad", "final iterate, joint 2"),
      f64("q_final_3", "rad or mm", "final iterate, joint 3 (scara: d in mm)"),
  };
  return c;
}

const std::vector<ColumnSpec>& metric_columns(BlockKind kind) {
  return kind == BlockKind::trajectory ? trajectory_metric_columns() : ik_metric_columns();
}

struct RunWorkspace::Impl {
  const Study* study = nullptr;
  std::vector<SampledPath> paths;  // the study's path sampled at the last few dt asked for
  TrajectoryHistory history;
  ik::Summary<3, 3> s33;
  ik::Summary<3, 2> s32;
  const SampledPath& path_of(const Study& s, double dt) {
    if (study != &s) {
      paths.clear();
      study = &s;
    }
    for (const SampledPath& p : paths)  // a dt axis alternates between a few values: keep them all
      if (p.dt() == dt) return p;
    if (paths.size() == 8) paths.erase(paths.begin());
    return paths.emplace_back(s.task.path(), dt);
  }
};
RunWorkspace::RunWorkspace() : impl_(std::make_unique<Impl>()) {}
RunWorkspace::~RunWorkspace() = default;

namespace {

RunOutcome run_trajectory(const Study& study, const Block& b, std::span<const Cell> p, int stride,
                          RunWorkspace::Impl& ws) {
  TrajectoryOptions o;
  PlanarArm3 arm = study.robot;
  parse(str(p, b, "method"), o.method);
  parse(str(p, b, "integrator"), o.integrator);
  parse(str(p, b, "inertia"), arm.inertia_form);
  o.k = num(p, b, "k");
  o.alpha1A = num(p, b, "alpha1A");
  o.null_damping = num(p, b, "K_N");
  o.dt = num(p, b, "dt");
  o.torque_bound = num(p, b, "torque_bound");
  const SampledPath& path = ws.path_of(study, o.dt);
  if (o.method == TrajectoryMethod::vertex_alpha)
    for (std::size_t v = 2; v <= path.path().vertices().size(); ++v) o.vertex_alpha.push_back(num(p, b, "vertex_alpha_" + std::to_string(v)));
  TrajectoryHistory* h = nullptr;
  if (stride > 0) {
    ws.history.stride = stride;
    h = &ws.history;
  }
  const TrajectoryMetrics m = simulate(arm, path, o, h);
  RunOutcome out;
  out.status = std::string(to_string(m.status));
  out.metrics = {m.E, m.E_M, m.tau_inf.maxCoeff(), m.tau_inf[0], m.tau_inf[1], m.tau_inf[2], m.min_manipulability,
                 m.torque_sq_integral, m.power_sq_integral, m.max_tracking_error, m.final_alpha,
                 static_cast<std::int64_t>(m.samples), m.stop_time};
  if (m.samples == 0) out.metrics.back() = kNaN;
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
  out.status = std::string(ik::to_string(s.status));
  out.metrics = {static_cast<std::int64_t>(s.iterations), s.error, static_cast<std::int64_t>(s.solution),
                 static_cast<std::int64_t>(s.rejected), s.min_rcond, s.q[0], s.q[1], s.q[2]};
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

RunOutcome run_ik(const Study& study, const Block& b, std::span<const Cell> p, int stride, RunWorkspace::Impl& ws) {
  ik::Options o;
  ik::parse(str(p, b, "method"), o.method);
  o.lambda = num(p, b, "lambda");
  o.tolerance = num(p, b, "tol");
  o.max_iter = static_cast<int>(num(p, b, "max_iter"));
  o.keep_history = stride > 0;
  const Vec3 q0(num(p, b, "q0_1"), num(p, b, "q0_2"), num(p, b, "q0_3"));
  const std::string& problem = str(p, b, "problem");
  if (problem == "scara") {
    ik::ScaraPosition s;
    s.target = {num(p, b, "target_x"), num(p, b, "target_y"), num(p, b, "target_z")};
    s.z_mode = str(p, b, "z_mode") == "physical" ? ik::ScaraZ::physical : ik::ScaraZ::thesis;
    return solve_ik(s, q0, o, stride, ws.s33, "mm");
  }
  if (problem == "planar3r_pose") {
    ik::PlanarPose s;
    s.arm = study.robot;
    s.target = {num(p, b, "target_x"), num(p, b, "target_y")};
    s.alpha = num(p, b, "target_alpha");
    return solve_ik(s, q0, o, stride, ws.s33, "rad");
  }
  ik::PlanarPosition s;
  s.arm = study.robot;
  s.target = {num(p, b, "target_x"), num(p, b, "target_y")};
  return solve_ik(s, q0, o, stride, ws.s32, "rad");
}

}  // namespace

RunOutcome execute_run(const Study& study, std::size_t block, std::span<const Cell> params, int history_stride,
                       RunWorkspace& workspace) {
  const Block& b = study.blocks[block];
  return b.kind() == BlockKind::trajectory ? run_trajectory(study, b, params, history_stride, workspace.impl())
                                           : run_ik(study, b, params, history_stride, workspace.impl());
}

}  // namespace ks
