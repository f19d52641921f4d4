#pragma once
// The parameter and metric tables: the only place a run parameter or metric is declared. Each entry
// names it (the study-file key and /runs column), gives its type, its unit in the study file and as
// stored, its domain, its default (read from the typed run struct, never written here), the rule
// under which it has an effect, a one-line description, and accessors to the typed run.
//
// Everything that lists parameters or metrics reads these tables: the study parser (keys,
// validation, did-you-mean, block defaults), the /runs column specs and their attributes,
// `kinesweep schema` / `info` / `query`, and engine/store/FORMAT.md (checked by a test).
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/domain.hpp"
#include "schema/run_spec.hpp"

namespace ks {

/// How a study file writes a value: as stored, or in degrees (stored in radians).
enum class FileUnit { none, deg };

/// What the tables need to know of the study's robot: its joints and whether it is a chain.
struct RobotShape {
  int joints = 3;                  ///< n: the q0_i and per-joint metric columns
  std::vector<bool> prismatic;     ///< per joint (empty: all revolute): q0_i in m instead of deg
  bool chain = false;              ///< a generic chain (n-link planar, URDF); false: the seed's closed-form 3R
  bool planar = true;              ///< the tip moves in the xy plane (orientation: one angle alpha)
  bool pose_task = false;          ///< the path prescribes the tip's orientation too ([task] orientation)
  bool limited = false;            ///< a joint has a finite position limit (URDF <limit>, n-link `limits`)
  bool is_prismatic(int j) const { return j < static_cast<int>(prismatic.size()) && prismatic[j]; }
  /// vertex_alpha (the seed's non-redundant baseline) is defined: a planar 3-joint arm, position path.
  bool vertex_alpha() const { return planar && joints == 3 && !pose_task; }
  /// global_spline is defined (a position path: the seed's arm, planar or spatial chains).
  bool path_global() const { return !pose_task; }
  /// The shape of a chain robot (pose_task false: the task is not the chain's).
  static RobotShape of(const Chain& chain) {
    RobotShape r;
    r.chain = true;
    r.joints = chain.dof();
    r.planar = chain.planar();
    for (const ChainJoint& j : chain.joints) {
      r.prismatic.push_back(j.type == JointType::prismatic);
      r.limited = r.limited || j.limited();
    }
    return r;
  }
};

/// What a block's tables depend on: its path and the study-wide defaults of [task] and [robot].
struct KindContext {
  std::size_t path_vertices = 5;                       ///< vertices of the path (the square: 5)
  Integrator integrator = TrajectoryOptions{}.integrator;  ///< [task] integrator
  double dt = TrajectoryOptions{}.dt;                  ///< [task] dt [s]
  InertiaForm inertia = TrajectoryRun{}.inertia;       ///< [robot] inertia
  bool scara = true;                                   ///< ik: the block's problem family (units, defaults)
  RobotShape robot;                                    ///< [robot]
  Eigen::Vector3d first_vertex{1.5, 1.5, 0.0};         ///< the path's first vertex [m] (chain IK's default target)
  bool path_global = false;  ///< the block runs global_spline: its parameters and metrics are columns
  /// The block places its task (it names a task placement parameter: fixed, an axis or an [[optimize]]
  /// variable): those parameters and the metric ik_error are columns, and its runs measure ik_error.
  bool placement = false;
};

/// When a parameter has an effect: always (no controller), or only while another text parameter
/// (the controller, e.g. method) takes one of `when`. Sweeping it otherwise would only repeat runs.
struct EffectRule {
  std::string controller;
  std::vector<std::string> when;
  bool always() const { return controller.empty(); }
  bool applies(std::string_view controller_value) const;
  /// "always", or "only when method is lm or lm_adaptive"
  std::string str() const;
};

/// A run parameter of one kind.
struct ParamDef {
  std::string name;
  CellType type = CellType::f64;
  FileUnit file_unit = FileUnit::none;
  std::string unit;                  ///< stored unit ("rad", "s", "mm", "" ...)
  std::vector<std::string> choices;  ///< text parameters: the names allowed
  Domain domain;                     ///< numeric parameters: the rule (from the options struct)
  std::string description;
  EffectRule effect;
  bool leading = false;              ///< applied before the others: its value sets their defaults (preset)
  std::function<Cell(const RunSpec&)> get;
  std::function<void(RunSpec&, const Cell&)> set;

  /// The unit as the study file writes it ("deg" for angles).
  std::string file_unit_name() const { return file_unit == FileUnit::deg ? "deg" : unit; }
  /// A stored value from a value as the study file writes it (degrees -> radians; integers rounded).
  Cell from_file(double file_value) const;
  /// The /runs column (role parameter).
  ColumnSpec column(BlockKind kind) const;
};

/// A metric of one kind, read from a run's outcome.
struct MetricDef {
  std::string name;
  CellType type = CellType::f64;
  std::string unit;
  std::string description;
  bool gridded = false;  ///< also kept in /landscapes
  std::function<Cell(const RunOutcome&)> get;
  /// The value an [[optimize]] objective term takes for a run whose status is not the good one
  /// (empty: the metric's own value): e.g. a failed IK run counts max_iter iterations.
  std::function<double(const RunSpec&)> if_failed;
  std::string label;  ///< how plots and reports name it, e.g. "E (mean ‖τ‖)" (empty: its name)
  ColumnSpec column(BlockKind kind) const;
  /// This metric with display label `l` (the tables' way to set `label`).
  MetricDef labelled(std::string l) && {
    label = std::move(l);
    return std::move(*this);
  }
};

/// The kinds, in order; their names are the study file's `kind` values.
std::span<const BlockKind> block_kinds();
/// The parameters of a kind, in /runs column order. Trajectory: preset, method, k, alpha1A, K_N,
/// vertex_alpha_2 .. vertex_alpha_<path_vertices>, integrator, dt, torque_bound, inertia. IK:
/// problem, method, lambda, q0_1 .. q0_3, target_x, target_y, target_z, target_alpha, tol, max_iter, z_mode.
/// Motion: start_1 .. start_n, goal_1 .. goal_n, duration, vary_duration, ..., the weights w_*, normalise,
/// solve, starts, max_evaluations, clearance_margin (schema/motion_table.cpp).
std::vector<ParamDef> params(BlockKind kind, const KindContext& context = {});
/// The parameter named `name` in `table`, or nullptr.
const ParamDef* find_param(const std::vector<ParamDef>& table, std::string_view name);
/// The metrics of a kind, in /runs column order (per-joint metrics: one per joint of context.robot).
std::vector<MetricDef> metrics(BlockKind kind, const KindContext& context = {});
/// The status names of a kind, in enum order (the first is the good one: ok / converged / ok).
std::span<const std::string_view> statuses(BlockKind kind);
/// How the runs of a kind are ranked ("best"): the lowest `objective` metric among the runs whose
/// status is the kind's good one (statuses(kind).front()), ties broken by the `tie` metric (lower
/// first; none when empty), then by run id. Trajectory: E; ik: iterations, then error; motion:
/// objective. The one
/// rule of the run summary and `kinesweep info`.
struct Ranking {
  std::string_view objective;
  std::string_view tie;
};
Ranking ranking(BlockKind kind);

/// The metrics a one-line summary of a run of the kind shows (query's compact table, info's best
/// run), in order: trajectory E, E_M, tau_inf; ik iterations, error, solution; motion objective,
/// torque_sq_integral, power_sq_integral.
std::span<const std::string_view> key_metrics(BlockKind kind);

/// The parts of a study's run context (runner/run_identity.hpp: "robot", "task", "settings") that a
/// run of the kind reads besides its parameters; a change of any other part keeps the run's identity,
/// so a resume of the edited study reuses it. Trajectory: robot, task, settings. IK: robot, settings
/// (its target is a parameter, its initial guess too; it reads no path). Motion: robot, world ([world]:
/// its obstacles and link radii), settings.
std::span<const std::string_view> context_parts(BlockKind kind);

/// True when parameter `name` at value `value` leaves a run as it is without that parameter: the task
/// placement parameters at the identity (task_rotation, task_dx, task_dy, task_dz = 0; task_time_scale
/// = 1). A run's identity (runner/run_identity.hpp) leaves such cells out, so a block that gains a
/// placement axis keeps the identities of the runs it had.
bool identity_neutral(std::string_view name, const Cell& value);

/// What an [[optimize]] block of a kind may minimise (a weighted sum of these): every numeric metric
/// in `metrics` (the block's, per-joint columns for its robot), and "failure_rate" (the fraction of
/// an evaluation's runs whose status is not the good one). The default is ranking(kind).objective.
std::vector<std::string> objective_names(const std::vector<MetricDef>& metrics);
/// The objective term counting failed runs (not a metric of any kind).
inline constexpr std::string_view kFailureRate = "failure_rate";

/// The ordering key of a good run under ranking(): NaN values sort after every number.
struct RankKey {
  double objective = 0.0, tie = 0.0;
  std::uint64_t run = 0;
  friend bool operator<(const RankKey& a, const RankKey& b) {
    return a.objective < b.objective ||
           (a.objective == b.objective && (a.tie < b.tie || (a.tie == b.tie && a.run < b.run)));
  }
};
/// The key of run `run` with metric values `objective` and `tie` (0 when the kind has no tie).
RankKey rank_key(double objective, double tie, std::uint64_t run);

/// A run of the kind with every default (the typed structs' own, with the context's study defaults).
RunSpec default_run(BlockKind kind, const KindContext& context = {});
/// True when parameter `p` of `table` has an effect on run `r` (its EffectRule).
bool has_effect(const ParamDef& p, const std::vector<ParamDef>& table, const RunSpec& r);

/// The bookkeeping columns of /runs.
ColumnSpec run_id_column();
ColumnSpec block_column();
ColumnSpec status_column();
ColumnSpec wall_time_column();

}  // namespace ks
