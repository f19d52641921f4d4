// What the kinds share: names, effect rules, columns, defaults, outcomes (see schema/params.hpp).
#include "schema/params.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "common/name_table.hpp"
#include "schema/kind_tables.hpp"

namespace ks {

namespace {
constexpr NameTable<BlockKind, 3> kKinds{
    {{BlockKind::trajectory, "trajectory"}, {BlockKind::ik, "ik"}, {BlockKind::motion, "motion"}}};
constexpr NameTable<InertiaForm, 2> kInertia{{{InertiaForm::physical, "physical"},
                                              {InertiaForm::thesis_m11, "thesis_m11"}}};
constexpr NameTable<IkProblem, 5> kProblems{{{IkProblem::scara, "scara"},
                                             {IkProblem::planar3r_pose, "planar3r_pose"},
                                             {IkProblem::planar3r_position, "planar3r_position"},
                                             {IkProblem::position, "position"},
                                             {IkProblem::pose, "pose"}}};
constexpr NameTable<ZMode, 3> kZModes{{{ZMode::unset, ""}, {ZMode::thesis, "thesis"}, {ZMode::physical, "physical"}}};
constexpr std::array<BlockKind, 3> kKindList{BlockKind::trajectory, BlockKind::ik, BlockKind::motion};
}  // namespace

std::string_view to_string(BlockKind k) { return name_of(kKinds, k); }
bool parse(std::string_view n, BlockKind& out) { return value_of(kKinds, n, out); }
std::string_view to_string(InertiaForm f) { return name_of(kInertia, f); }
bool parse(std::string_view n, InertiaForm& out) { return value_of(kInertia, n, out); }
std::string_view to_string(IkProblem p) { return name_of(kProblems, p); }
bool parse(std::string_view n, IkProblem& out) { return value_of(kProblems, n, out); }
std::string_view to_string(ZMode z) { return name_of(kZModes, z); }
bool parse(std::string_view n, ZMode& out) { return value_of(kZModes, n, out); }

bool RunOutcome::good() const {
  if (const auto* t = std::get_if<TrajectoryMetrics>(&result)) return t->status == RunStatus::ok;
  if (const auto* m = std::get_if<MotionResult>(&result)) return m->status == MotionStatus::ok;
  return std::get<IkResult>(result).status == ik::Status::converged;
}
std::string_view RunOutcome::status() const {
  if (const auto* t = std::get_if<TrajectoryMetrics>(&result)) return to_string(t->status);
  if (const auto* m = std::get_if<MotionResult>(&result)) return to_string(m->status);
  return ik::to_string(std::get<IkResult>(result).status);
}

bool EffectRule::applies(std::string_view v) const {
  if (always()) return true;
  for (const auto& w : when)
    if (w == v) return true;
  return false;
}
std::string EffectRule::str() const {
  if (always()) return "always";
  std::string s = "only when " + controller + " is ";
  for (std::size_t i = 0; i < when.size(); ++i) s += (i ? (i + 1 == when.size() ? " or " : ", ") : "") + when[i];
  return s;
}

Cell ParamDef::from_file(double v) const {
  if (type == CellType::i64) return static_cast<std::int64_t>(std::llround(v));
  return file_unit == FileUnit::deg ? v * kDeg : v;
}
ColumnSpec ParamDef::column(BlockKind kind) const {
  ColumnSpec c{name, type, unit, description, Role::parameter, std::string(to_string(kind))};
  if (type == CellType::str) c.labels = choices;
  return c;
}
ColumnSpec MetricDef::column(BlockKind kind) const {
  return {name, type, unit, description, Role::metric, std::string(to_string(kind)), {}, label.empty() ? name : label};
}

std::span<const BlockKind> block_kinds() { return kKindList; }

std::vector<ParamDef> params(BlockKind kind, const KindContext& context) {
  if (kind == BlockKind::motion) return motion_params(context);
  return kind == BlockKind::trajectory ? trajectory_params(context) : ik_params(context);
}
const ParamDef* find_param(const std::vector<ParamDef>& table, std::string_view name) {
  for (const ParamDef& p : table)
    if (p.name == name) return &p;
  return nullptr;
}
std::vector<MetricDef> metrics(BlockKind kind, const KindContext& context) {
  if (kind == BlockKind::motion) return motion_metrics(context);
  return kind == BlockKind::trajectory ? trajectory_metrics(context) : ik_metrics(context);
}
Ranking ranking(BlockKind kind) {
  if (kind == BlockKind::trajectory) return {"E", ""};
  if (kind == BlockKind::motion) return {"objective", ""};
  return {"iterations", "error"};
}
std::span<const std::string_view> key_metrics(BlockKind kind) {
  static const std::array<std::string_view, 3> trajectory{"E", "E_M", "tau_inf"}, ik{"iterations", "error", "solution"},
      motion{"objective", "torque_sq_integral", "power_sq_integral"};
  if (kind == BlockKind::motion) return motion;
  return kind == BlockKind::trajectory ? trajectory : ik;
}
std::span<const std::string_view> context_parts(BlockKind kind) {
  static const std::array<std::string_view, 3> trajectory{"robot", "task", "settings"};
  static const std::array<std::string_view, 2> ik{"robot", "settings"};
  static const std::array<std::string_view, 3> motion{"robot", "world", "settings"};
  if (kind == BlockKind::trajectory) return trajectory;
  if (kind == BlockKind::motion) return motion;
  return ik;
}
std::vector<std::string> objective_names(const std::vector<MetricDef>& metrics) {
  std::vector<std::string> out;
  for (const MetricDef& m : metrics)
    if (m.type != CellType::str) out.push_back(m.name);
  out.emplace_back(kFailureRate);
  return out;
}
RankKey rank_key(double objective, double tie, std::uint64_t run) {
  constexpr double last = std::numeric_limits<double>::infinity();
  return {std::isnan(objective) ? last : objective, std::isnan(tie) ? last : tie, run};
}
std::span<const std::string_view> statuses(BlockKind kind) {
  using ik::Status;
  static const std::array<std::string_view, 12> trajectory{
      to_string(RunStatus::ok),           to_string(RunStatus::unreachable_start), to_string(RunStatus::singular),
      to_string(RunStatus::diverged),     to_string(RunStatus::undersampled),      to_string(RunStatus::off_path),
      to_string(RunStatus::out_of_limits), to_string(RunStatus::max_evaluations),  to_string(RunStatus::not_converged),
      to_string(RunStatus::infeasible),   to_string(RunStatus::singular_extension),
      to_string(RunStatus::out_of_reach)};
  static const std::array<std::string_view, 9> ik{
      ik::to_string(Status::converged), ik::to_string(Status::stalled),  ik::to_string(Status::singular),
      ik::to_string(Status::max_iter),  ik::to_string(Status::cycle),    ik::to_string(Status::diverged),
      ik::to_string(Status::unsupported), ik::to_string(Status::no_solution), ik::to_string(Status::out_of_limits)};
  static const std::array<std::string_view, 5> motion{
      to_string(MotionStatus::ok), to_string(MotionStatus::infeasible), to_string(MotionStatus::collision),
      to_string(MotionStatus::max_evaluations), to_string(MotionStatus::failure)};
  if (kind == BlockKind::trajectory) return trajectory;
  if (kind == BlockKind::motion) return motion;
  return ik;
}

bool identity_neutral(std::string_view name, const Cell& value) {
  const double* v = std::get_if<double>(&value);
  if (!v) return false;
  if (name == "task_rotation" || name == "task_dx" || name == "task_dy" || name == "task_dz") return *v == 0.0;
  if (name == "task_time_scale") return *v == 1.0;
  return false;
}

RunSpec default_run(BlockKind kind, const KindContext& c) {
  if (kind == BlockKind::motion) return MotionRun::defaults(c.robot.prismatic, c.robot.joints);
  if (kind == BlockKind::ik) {
    if (c.scara) return IkRun{};
    if (c.robot.chain) return IkRun::chain_defaults(c.robot.prismatic, c.robot.joints, c.first_vertex, c.robot.limited);
    return IkRun::planar_defaults();
  }
  TrajectoryRun r;
  // chains: NaN asks for the automatic initial guess of the start (see simulate_chain)
  r.q0.setConstant(c.robot.joints, std::numeric_limits<double>::quiet_NaN());
  r.options.integrator = c.integrator;
  r.options.dt = c.dt;
  r.options.vertex_alpha.assign(c.path_vertices >= 1 ? c.path_vertices - 1 : 0, 0.0);
  r.inertia = c.inertia;
  if (c.robot.chain && !c.robot.planar) r.options.global.extension = Extension::joints;  // no planar chart
  r.placement.measured = c.placement;
  return r;
}

bool has_effect(const ParamDef& p, const std::vector<ParamDef>& table, const RunSpec& r) {
  if (p.effect.always()) return true;
  const ParamDef* ctl = find_param(table, p.effect.controller);
  if (!ctl) return true;
  const Cell v = ctl->get(r);
  return p.effect.applies(std::get<std::string>(v));
}

ColumnSpec run_id_column() { return {"run_id", CellType::i64, "", "global run id (row index)", Role::bookkeeping, ""}; }
ColumnSpec block_column() {
  return {"block", CellType::str, "", "name of the study block the run belongs to", Role::bookkeeping, ""};
}
ColumnSpec status_column() {
  std::string d;
  for (BlockKind k : block_kinds()) {
    d += (d.empty() ? "" : "; ") + std::string(to_string(k)) + ":";
    const auto s = statuses(k);
    for (std::size_t i = 0; i < s.size(); ++i) d += (i ? ", " : " ") + std::string(s[i]);
  }
  ColumnSpec c{"status", CellType::str, "", d, Role::bookkeeping, ""};
  for (BlockKind k : block_kinds())
    for (std::string_view w : statuses(k))
      if (std::find(c.labels.begin(), c.labels.end(), w) == c.labels.end()) c.labels.emplace_back(w);
  return c;
}
ColumnSpec wall_time_column() {
  return {"wall_time", CellType::f64, "s",
          "wall-clock time of the run (the only column that varies between identical sweeps)", Role::bookkeeping, ""};
}

}  // namespace ks
