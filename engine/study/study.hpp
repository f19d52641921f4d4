#pragma once
// Study files (studies/*.toml, syntax in studies/README.md): parse + validate into a Study.
// Every problem found is reported as FILE:LINE:COL: error: <what>; expected <what> (+ suggestion).
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "methods/base/trajectory.hpp"
#include "model/arm.hpp"
#include "geometry/link_capsules.hpp"
#include "model/chain.hpp"
#include "model/chain_plane.hpp"
#include "optimize/optimize.hpp"
#include "space/space.hpp"
#include "task/task_path.hpp"

namespace ks {

/// One problem in a study file. Lines and columns are 1-based; columns count Unicode code points (as
/// toml++ does), not bytes: a multi-byte UTF-8 character such as 'é' is one column, and so is a tab.
struct StudyDiagnostic {
  /// A secondary note: another place that explains the error (e.g. where a duplicate name was first
  /// defined), or a remark without a place (line 0).
  struct Note {
    int line = 0, column = 0;                ///< 0: the note has no place
    std::string message;
    std::optional<std::string> source_line;  ///< the text of `line`, when known
    int length = 1;                          ///< code points underlined from `column`
    std::string file;                        ///< the file of `line` when not the diagnostic's (a robot file's error noted in the study)
  };

  std::string file;
  int line = 0, column = 0;
  std::string message;  ///< "<what was wrong>; expected <what was expected>[; did you mean 'x'?]"
  /// The text of `line` without its line break; nullopt when there is no source (unreadable file).
  std::optional<std::string> source_line;
  int length = 1;           ///< code points underlined from `column` (the key or token; at least 1)
  std::vector<Note> notes;  ///< in the order they explain the error

  /// FILE:LINE:COL: error: message
  std::string headline() const;
  /// The headline; with a source line, the line in a numbered gutter and a caret (^^^) under the
  /// column, as rustc shows errors; then the notes ("note: FILE:LINE:COL: ..." with their own line,
  /// or "= note: ..."). Tabs are expanded; a long line is clipped around the column.
  std::string str() const;
};

/// A malformed study file. what(): every diagnostic's str(), in file order (a blank line between
/// diagnostics that take more than one line).
class StudyError : public std::runtime_error {
 public:
  explicit StudyError(std::vector<StudyDiagnostic> diagnostics);
  const std::vector<StudyDiagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<StudyDiagnostic> diagnostics_;
};

/// How much of each run's history to keep.
struct HistoryPolicy {
  enum class Mode { full, every, none };
  Mode mode = Mode::full;
  int stride = 1;  ///< every=N: N (full: 1; none: 0)
  std::string str() const;  ///< "full", "every=10", "none"
  /// "full", "none", "every=N" (N >= 1) -> policy; false (p unchanged) when malformed.
  static bool parse(const std::string& s, HistoryPolicy& p);
};

/// The task's path: vertices and segment durations joined by rest-to-rest quintics ([task] vertices,
/// durations), or timed waypoints joined by a cubic spline ([task] waypoints, spline): then `vertices`
/// are the waypoints and `durations` the differences of their times.
struct StudyTask {
  std::vector<Eigen::Vector2d> vertices;  ///< x, y [m]
  std::vector<double> z;                  ///< vertex heights [m] (spatial robots; empty: planar, z = 0)
  std::vector<double> durations;          ///< [s], vertices.size() - 1 values
  PathShape shape = PathShape::quintic;   ///< how the path joins the vertices
  double dt = 1e-3;                       ///< [s]
  Integrator integrator = Integrator::semi_implicit_euler;
  /// The tip orientation along the path: planar robots, one angle per vertex [rad] (a quintic between
  /// them); empty with hold_orientation false: a position task.
  std::vector<double> orientation;
  bool hold_orientation = false;          ///< spatial robots: the start's tip orientation held along the path
  Path2 path() const { return Path2(vertices, durations, shape); }
  /// The spans [s] the sampling rule (samples_path: at least kMinSamplesPerSegment samples on each)
  /// applies to: every segment of a quintic path (each a motion from rest to rest); the whole path of a
  /// spline (one motion through its waypoints, whatever their spacing).
  std::vector<double> sampled_spans() const {
    if (shape == PathShape::quintic) return durations;
    double total = 0.0;
    for (double d : durations) total += d;
    return {total};
  }
  Eigen::Vector3d vertex(std::size_t i) const {
    return {vertices[i].x(), vertices[i].y(), i < z.size() ? z[i] : 0.0};
  }
  bool pose() const { return !orientation.empty() || hold_orientation; }
};

/// An optimisation block ([[optimize]] in a study file; syntax in studies/README.md).
/// One evaluation = the runs of `base` (its fixed parameters, and its axes as an evaluation set, e.g.
/// the IK start set) with the variables' columns replaced by x; the objective is the weighted sum of
/// metrics averaged over those runs (failure_rate: the fraction of runs not converged).
struct OptimizeVariable {
  std::string name;  ///< a f64 run parameter of the block's kind
  std::string unit;  ///< stored unit ("rad", "", ...)
  double lower = 0.0, upper = 0.0;  ///< stored units
  double start = std::numeric_limits<double>::quiet_NaN();  ///< NaN: the block's value of the parameter
};
/// One term of an [[optimize]] objective: weight * metric, or weight / metric (`reciprocal`: a
/// criterion to maximise as seed 002 Eq. 7.6 writes it, f1^0 / f1); with a reference, the term is
/// divided by its value at the reference (so it is 1 there).
struct ObjectiveTerm {
  std::string metric;
  double weight = 1.0;
  bool reciprocal = false;
};
/// Where a normalised objective takes its references f^0 (seed 002 Eqs. 7.1 and 7.6: the criteria
/// at the initial design). None: the objective is the plain weighted sum.
struct ObjectiveReference {
  bool start = false;                                  ///< the variables' start point
  std::vector<std::pair<std::string, double>> design;  ///< variable -> value [stored units]; the others at their start
  bool active() const { return start || !design.empty(); }
};
struct OptimizeBlock {
  std::string name;    ///< the HDF5 group /optimizations/<name> (default: the preset's name)
  std::string preset;  ///< seed 000 Table 4 row, "" when none
  std::vector<Block> base;  ///< exactly one: the runs one evaluation executes (vector: Block has no default)
  std::vector<OptimizeVariable> variables;                  ///< file order
  std::vector<ObjectiveTerm> objective;                     ///< a weighted sum of terms
  ObjectiveReference reference;                             ///< normalise each term by its value there
  /// trade_off: this block is one weight k of a two-term objective swept as k f_a + (1 - k) f_b
  /// (named <name>_k<k>); NaN when the file wrote the weights.
  double trade_off_k = std::numeric_limits<double>::quiet_NaN();
  std::string objective_text;                               ///< e.g. "E", "E + 0.01*tau_inf", "0.9*min_manipulability_0/min_manipulability + ..."
  std::optional<opt::StageOptions> global, local;
  int local_starts = 1;     ///< best distinct global points polished by the local stage
  double distinct = 1e-2;   ///< range-normalised distance that makes two points distinct
  std::string polish_block; ///< sweep then polish: the [[block]] whose best cells start the local stage
  int polish_best = 0;      ///< ... how many of its best cells
  std::uint64_t seed = 42;  ///< nlopt::srand before the global stage
  opt::ConstraintMode constraint = opt::ConstraintMode::automatic;
  double penalty = 1.0e7;   ///< deterministic penalty scale of failed runs (larger than any feasible objective)
  int line = 0;             ///< of the [[optimize]] table
  const Block& block() const { return base.front(); }
};

/// The study's [world]: fixed obstacles in the robot's base frame and the radii of the links'
/// capsules (geometry/link_capsules.hpp), which motion runs keep clear of the obstacles.
struct World {
  std::vector<geometry::Obstacle> obstacles;  ///< spheres, oriented boxes, capsules [m] (at t = 0)
  std::vector<Vec3> velocities;               ///< one per obstacle [m/s] when any moves, else empty
  std::vector<double> link_radius;            ///< one per joint's link [m] (empty without obstacles)
  bool has_obstacles() const { return !obstacles.empty(); }
};

struct Study {
  std::string file;         ///< the path or name it was parsed from
  std::string name;
  std::string description;
  std::string output;       ///< default "results/<name>.h5"
  HistoryPolicy histories;
  PlanarArm3 robot;         ///< the seed's closed-form 3R, with the study's inertia form (the blocks' default)
  double robot_b = 0.1;     ///< link thickness [m] the inertias came from
  /// The robot as a chain (an n-link planar arm or a URDF robot); null when it is the seed's
  /// closed-form 3R (`robot`). Shared, immutable: runs read it concurrently.
  std::shared_ptr<const Chain> chain;
  /// The robot as a chain for the position / pose IK problems: `chain`, or the seed's 3R as a chain
  /// (physical inertia) when that is null. Set by the parser.
  std::shared_ptr<const Chain> arm_chain;
  /// The chain robot as its description gives it, in its base frame (a URDF file's base link);
  /// null for the seed's closed-form 3R. `chain` is this chain in its plane's frame when it is planar
  /// (model/chain_plane.hpp: the same chain, bit for bit, when that plane is the base xy plane).
  std::shared_ptr<const Chain> base_chain;
  /// The plane a planar robot moves in, in its base frame: the base xy plane for the seed's 3R and
  /// the n-link arms; nullopt for a spatial robot. A planar robot's vertices, IK targets, tip
  /// angles and histories' x are in this plane's coordinates.
  std::optional<ChainPlane> plane;
  bool gravity_defaulted = false;  ///< a URDF robot given no gravity: base -z taken (URDF's z up)
  std::string robot_format;  ///< "urdf", "dh" (a DH table) or "" (the seed's 3R, an n-link planar arm)
  std::string robot_file;   ///< the URDF or DH robot file as the study names it ("" when none)
  std::string robot_text;   ///< its text, verbatim (kept with the results)
  StudyTask task;
  World world;              ///< [world] (motion runs); empty when the study has none
  std::string text;         ///< the study file's text, verbatim
  std::string sha256;       ///< lower-case hex SHA-256 of text
  std::vector<Block> blocks;  ///< file order; global run ids concatenate them
  std::vector<OptimizeBlock> optimizations;  ///< [[optimize]] tables, file order (run after the blocks)

  std::uint64_t run_count() const { return total_runs(blocks); }
  /// What the parameter tables need to know of the robot and task.
  RobotShape robot_shape() const;
  /// A new chain of the study's robot: a copy of `chain`, or the seed's 3R (`robot`, physical inertia).
  std::shared_ptr<const Chain> robot_chain() const;
  RunRef locate(std::uint64_t global) const { return locate_run(blocks, global); }
  std::uint64_t first_run(std::size_t block) const { return ks::first_run(blocks, block); }
  /// Index of the block named `name`, or Block::npos.
  std::size_t block_index(std::string_view name) const;
};

struct StudyOptions {
  /// Total runs allowed (kinesweep run --max-runs); a [study] max_runs key may only lower it.
  std::uint64_t max_runs = 50'000'000;
  /// The text of the URDF file the study names, used instead of reading that file (a study stored
  /// in a results file is parsed again with the robot stored with it). Unset: the file is read.
  std::optional<std::string> robot_text;
};

/// Parse a study from text. `file` names it in diagnostics. Throws StudyError.
Study parse_study(std::string_view text, std::string_view file = "<string>", const StudyOptions& options = {});
/// Read and parse a study file. Throws StudyError (also when the file cannot be read).
Study load_study(const std::filesystem::path& file, const StudyOptions& options = {});


}  // namespace ks
