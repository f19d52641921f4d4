#pragma once
// Internal to engine/study (not included from outside it): the study parser. One Parser reads one
// study text; its parts live in the files named for their jobs:
//   study_tables.cpp     [study], [task]
//   task_waypoints.cpp   [task] waypoints and spline: the spline form of the task's path
//   robot_table.cpp      [robot]: the seed 3R, an n-link planar arm or a URDF robot
//   robot_dh.cpp         [robot] dh: a standard DH table (in the study or a robot file)
//   axes.cpp             parameter values and the [block.axes] forms (values, range, linspace, random, lhs)
//   world_table.cpp      [world]: obstacles and link radii (motion runs)
//   blocks.cpp           [[block]] tables: name, kind, keys, IK problem family, fixed parameters
//   block_axes.cpp       a block's axes: lhs settings, [block.axes], lhs and zip groups, axes a run would ignore
//   optimize_tables.cpp  [[optimize]] tables and their stages
//   toml_prescan.cpp     the inputs toml++ 3.3 mishandles, found before it parses
//   parse.cpp            Parser::run, parse_study, load_study
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "study/toml_access.hpp"

namespace ks::study_parse {

/// At most this many samples per trajectory run (the seed takes 2001): each thread keeps the sampled
/// path, and a full history holds 16 doubles per sample.
constexpr double kMaxSamples = 1e7;

/// True for the task placement parameters' names (task_rotation, task_dx, task_dy, task_dz,
/// task_time_scale: schema/trajectory_table.cpp).
bool is_placement_param(std::string_view name);
/// The placement parameters a trajectory block of `robot` may name (task_dz: spatial robots only), for
/// did-you-mean suggestions in blocks that name none yet.
std::vector<std::string> placement_names(const RobotShape& robot);
/// Why `name` cannot be a parameter of a trajectory block of `robot` though it is a placement
/// parameter ("" when nothing refuses it): task_dz for a planar robot, whose task stays in its plane.
std::string placement_refusal(std::string_view name, const RobotShape& robot);

/// A place in a study's text where toml++ 3.3 would reach undefined behaviour (see toml_prescan.cpp).
struct TomlHazard {
  int line = 1, column = 1;
  std::string message;  ///< "<what>; expected <what>"
};
/// The first such place in `text`, if any.
std::optional<TomlHazard> toml_hazard(std::string_view text);

/// One axis of [block.axes] as parsed. A value list holds its values; a generated axis (range,
/// linspace, random) holds its count and how to generate them, and an LHS axis its range: their
/// values are made only once the block's run count, computed from the counts, is within bounds.
struct AxisDraft {
  Axis axis;
  Pos pos;                                   // the axis key
  bool lhs = false;
  std::pair<double, double> lhs_range{0, 0};  // LHS axes: [from, to) in file units
  std::uint64_t count = 0;                   // the axis's values (LHS axes: 0, the block's lhs count applies)
  /// Generated axes: their values in file units, and where the axis is written (for their errors).
  std::function<std::vector<double>()> generate;
  const toml::node* node = nullptr;
};

/// One [[block]] table (or the block part of an [[optimize]] table) while Parser::parse_block reads
/// it: each step reads its part of the table into the draft and reports what is wrong there.
struct BlockDraft {
  BlockDraft(const toml::table& t, bool opt, std::string lbl)
      : table(t), optimize(opt), pos(pos_of(t.source())), label(std::move(lbl)) {}

  const toml::table& table;
  bool optimize = false;
  Pos pos;            // the table
  std::string label;  // "[[block]] #N" or "[[optimize]] #N"
  BlockSpec spec;
  // The kind and its words for messages ("ik", "an ik"; the other kind's "trajectory", "a trajectory").
  BlockKind kind{};
  std::string kname, other_kname, a_kind, a_other;
  std::size_t nverts = 0;                // the task's path vertices
  std::vector<ParamDef> infos;          // the kind's parameters (SCARA units until the IK family is known)
  std::vector<ParamDef> other;          // the other kind's parameters
  std::vector<std::string> param_names;  // the kind's parameter names
  const toml::table* axes_t = nullptr;   // [block.axes], when it is a table
  std::set<std::string> axis_names;
  std::map<std::string, Pos> axis_keys;  // where each axis is written
  bool scara = true;                     // the IK problem family
  const toml::node* lhs_node = nullptr;  // the sampled design's settings: lhs or saltelli = { count, seed }
  std::string design = "lhs";            // which: "lhs" or "saltelli" (the key of lhs_node)
  std::optional<std::uint64_t> lhs_count, lhs_seed;
  std::vector<AxisDraft> drafts;         // the axes read so far
  std::vector<std::string> lhs_group;    // the LHS axes, once drawn
  KindContext ctx;

  /// The kind's parameter named `n`, or nullptr.
  const ParamDef* info_of(std::string_view n) const;
  /// True for a parameter of the other kind (and vertex_alpha in an IK block).
  bool belongs_to_other(std::string_view n) const;
};

/// `names` and the placement parameters a trajectory block of the draft may name (did-you-mean candidates).
std::vector<std::string> with_placement(std::vector<std::string> names, const BlockDraft& d);

class Parser : public ParserCore {
 public:
  /// `text` must outlive the parser.
  Parser(std::string file, std::string_view text, StudyOptions options)
      : ParserCore(std::move(file), text), text_(text), options_(options) {}

  Study run();

 private:
  // study_tables.cpp
  void parse_study_table(const toml::table& root, Study& s);
  void parse_task(const toml::table& root, Study& s);
  /// The task's orientation key (after the vertices): per-vertex angles (planar) or "hold" (spatial).
  void parse_task_orientation(const toml::table& t, Study& s);
  /// task_waypoints.cpp: [task] waypoints = [[t, x, y(, z)], ...] and spline = "natural" | "clamped"
  /// (a cubic spline through timed waypoints). False when the waypoints are unusable (reported).
  bool parse_task_waypoints(const toml::table& t, Study& s);
  /// The path's vertices against the robot's reach (chains); the task's equations against its joints.
  void check_task_fits_robot(const toml::table* task, Study& s);

  // robot_table.cpp
  void parse_robot(const toml::table& root, Study& s);
  void parse_planar_robot(const toml::table& t, Study& s);
  void parse_urdf_robot(const toml::table& t, Study& s);
  /// robot_dh.cpp: a standard DH table, in the study ([[robot.dh]]) or in a robot file (dh = "FILE").
  void parse_dh_robot(const toml::table& t, Study& s);
  /// After [robot] (robot_plane.cpp): base_chain, plane, and a planar chain in its plane's frame.
  void place_robot_in_plane(Study& s);
  /// Trajectory studies: a URDF or DH robot without gravity whose plane is not vertical is refused.
  void check_gravity_given(Study& s);
  const toml::node* robot_without_gravity_ = nullptr;  ///< the urdf (dh) key of a URDF (DH) robot given no gravity
  std::string robot_without_gravity_kind_ = "URDF";    ///< which: "URDF" or "DH"
  /// The plane coordinates of vertex x (base frame [m]) of a planar robot; nullopt, reported at
  /// `at`, when x is off the plane by more than kVertexOffPlane.
  std::optional<Eigen::Vector2d> vertex_in_plane(const toml::node& at, const Eigen::Vector3d& x, const ChainPlane& plane);
  static constexpr double kVertexOffPlane = 1e-6;  ///< [m]
  /// A list of 2 .. kMaxJoints numbers (or exactly `count` when count > 0); nullopt after reporting.
  std::optional<std::vector<double>> get_joint_numbers(const toml::table& t, std::string_view key, std::size_t count,
                                                       std::string_view what, std::string_view unit);

  // world_table.cpp
  /// [world]: obstacles = [{ type, ... }] and link_radius = [one per joint], in the robot's base frame.
  void parse_world(const toml::table& root, Study& s);
  /// One obstacle inline table of [world] obstacles; nullopt after reporting.
  std::optional<geometry::Obstacle> parse_obstacle(const toml::node& n, std::size_t index);

  // blocks.cpp
  void parse_blocks(const toml::table& root, Study& s);
  /// One [[block]] table, or with optimize = true the block part of an [[optimize]] table. `names`
  /// holds the names seen so far (and where).
  std::optional<Block> parse_block(const toml::table& b, std::size_t index, const Study& s,
                                   std::map<std::string, Pos>& names, bool optimize = false);
  // parse_block's steps, in order.
  /// Reads name (else an optimisation's preset); reports an empty, duplicate or missing name.
  void read_block_name(BlockDraft& d, std::map<std::string, Pos>& names);
  /// Reads kind and sets up its parameters; reports an unknown or missing kind (false: read no further).
  bool read_block_kind(BlockDraft& d);
  /// Reads the table's keys; reports those neither block keys nor the kind's parameters.
  void check_block_keys(const BlockDraft& d);
  /// Reads where the axes are written; reports an axes that is not a table.
  void find_axes_table(BlockDraft& d);
  /// Reads an IK block's problems for its units; reports SCARA and planar 3R problems mixed.
  void read_ik_family(BlockDraft& d);
  /// Reads the fixed parameters (and vertex_alpha = [...]); reports bad values and parameters also axes.
  void read_fixed_params(BlockDraft& d);
  /// A trajectory block whose dt is not swept: its dt (fixed, else the task's, else the default)
  /// against the path; reports a dt that samples a segment too coarsely or the path too finely.
  void check_block_dt(const BlockDraft& d, const Study& s);

  // block_axes.cpp: parse_block's steps for the axes, in order.
  /// Reads the block's sampled design, lhs = { count, seed } or saltelli = { count, seed,
  /// second_order = false }; reports a bad or missing count or seed, or both designs.
  void read_block_lhs(BlockDraft& d);
  /// Reads [block.axes]; reports axes that are not the kind's parameters (and their bad values).
  void read_axes(BlockDraft& d);
  /// Reads zip; reports bad groups, unknown, twice-zipped or LHS axes and unequal lengths.
  void read_zip_groups(BlockDraft& d);
  /// The block's run count from its axes' counts (nothing generated yet), against the run limit:
  /// the block's own for an [[optimize]] block, the study's total for a [[block]]. False after
  /// reporting the block as too large.
  bool check_block_runs(BlockDraft& d);
  /// Generates the axes' values (and checks each against its parameter's domain); draws the LHS
  /// axes' values; reports lhs settings no axis uses.
  void generate_axes(BlockDraft& d);
  /// How the run limit in force can change, for "too many runs" messages.
  std::string limit_hint() const;
  /// Checks the block's runs against the robot: redundancy left by the task, vertex_alpha's domain.
  void check_robot_supports(const BlockDraft& d, const Study& s);
  /// Motion blocks of a study without obstacles: a positive w_clearance (fixed or an axis value) is
  /// reported at its key (its reference, the clearance, is +inf: nothing to weigh).
  void check_motion_world(const BlockDraft& d, const Study& s);
  /// Reads the axes against their controlling parameters; reports axes a run would ignore.
  void reject_ineffective_axes(const BlockDraft& d);
  /// Reads the draft into a Block unless a step reported since errors_before; reports a spec Block refuses.
  std::optional<Block> finish_block(BlockDraft& d, std::size_t errors_before);

  // optimize_tables.cpp: [[optimize]] tables, a block (parse_block with optimize = true) + the
  // optimisation keys.
  void parse_optimizations(const toml::table& root, Study& s);
  std::optional<opt::StageOptions> parse_stage(const toml::node& n, bool global, OptimizeBlock& ob);
  // optimize_objective.cpp
  /// objective, reference and trade_off of an [[optimize]] table into `ob` (its variables read first).
  void parse_objective(const toml::table& t, const Block& block, BlockKind kind, OptimizeBlock& ob);
  /// `ob` as the optimisations it stands for: itself, or one per trade_off weight k.
  std::vector<OptimizeBlock> expand_trade_off(OptimizeBlock ob) const;
  std::vector<double> trade_off_ks_;  ///< the trade_off weights of the [[optimize]] table being read

  // axes.cpp
  /// One axis of [block.axes] (its values in stored units; LHS axes get their values later).
  std::optional<AxisDraft> parse_axis(const ParamDef& info, const toml::key& key, const toml::node& node,
                                      const toml::node* lhs_node, const std::string& design = "lhs");
  /// A parameter value from a node: type + choices + unit conversion + domain. nullopt on error.
  std::optional<Cell> param_value(const ParamDef& info, const toml::node& n);
  /// Check a stored numeric value's domain (expects file units for messages). Empty when fine.
  std::string domain_problem(const ParamDef& info, double file_value);
  /// Why dt [s] cannot sample the task's path in every run ("" when it can): fewer than
  /// kMinSamplesPerSegment samples on a segment (a spline: on the whole path; StudyTask::sampled_spans).
  std::string sampling_problem(const StudyTask& task, double dt) const;
  /// Why a generated value `v` (file units) of the axis `what` cannot be the parameter's ("" when it can).
  std::string value_problem(const ParamDef& info, const std::string& what, double v);
  /// A count >= 1 and at most max_runs, and from <= to (random and linspace axes); false after reporting.
  bool count_and_interval_ok(const std::string& what, std::int64_t count, const toml::node& count_node, double from,
                             double to, const toml::node& at);

  std::string_view text_;
  StudyOptions options_;
  std::uint64_t max_runs_ = 0;
  std::uint64_t sweep_runs_ = 0;     // the runs of the [[block]] tables read so far
  bool reported_runs_ = false;       // "too many runs" said once
  double path_duration_ = 2.0;  // [s], the task's; bounds the samples a dt asks for
  std::optional<Pos> task_dt_pos_;  // [task] dt, when given
  Pos path_pos_;                    // [task] durations (or the table, or 1:1): where the default dt is reported
  bool task_dt_reported_ = false;   // the task's dt found unable to sample the path (said once)
};

}  // namespace ks::study_parse
