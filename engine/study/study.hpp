#pragma once
// Study files (studies/*.toml, syntax in studies/README.md): parse + validate into a Study.
// Every problem found is reported as FILE:LINE:COL: error: <what>; expected <what> (+ suggestion).
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "methods/trajectory.hpp"
#include "model/arm.hpp"
#include "space/space.hpp"
#include "task/quintic_path.hpp"

namespace ks {

/// One problem in a study file.
struct StudyDiagnostic {
  std::string file;
  int line = 0, column = 0;  ///< 1-based
  std::string message;       ///< "<what was wrong>; expected <what was expected>[; did you mean 'x'?]"
  /// FILE:LINE:COL: error: message
  std::string str() const;
};

/// A malformed study file. what(): every diagnostic's str(), one per line, in file order.
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
};

struct StudyTask {
  std::vector<Eigen::Vector2d> vertices;  ///< [m]
  std::vector<double> durations;          ///< [s], vertices.size() - 1 values
  double dt = 1e-3;                       ///< [s]
  Integrator integrator = Integrator::semi_implicit_euler;
  Path2 path() const { return Path2(vertices, durations); }
};

struct Study {
  std::string file;         ///< the path or name it was parsed from
  std::string name;
  std::string description;
  std::string output;       ///< default "results/<name>.h5"
  HistoryPolicy histories;
  PlanarArm3 robot;         ///< with the study's inertia form (the blocks' default)
  double robot_b = 0.1;     ///< link thickness [m] the inertias came from
  StudyTask task;
  std::string text;         ///< the study file's text, verbatim
  std::string sha256;       ///< lower-case hex SHA-256 of text
  std::vector<Block> blocks;  ///< file order; global run ids concatenate them

  std::uint64_t run_count() const { return total_runs(blocks); }
  RunRef locate(std::uint64_t global) const { return locate_run(blocks, global); }
  std::uint64_t first_run(std::size_t block) const { return ks::first_run(blocks, block); }
  /// Index of the block named `name`, or Block::npos.
  std::size_t block_index(std::string_view name) const;
};

struct StudyOptions {
  std::uint64_t max_runs = 50'000'000;  ///< total runs allowed; a [study] max_runs key overrides it
};

/// Parse a study from text. `file` names it in diagnostics. Throws StudyError.
Study parse_study(std::string_view text, std::string_view file = "<string>", const StudyOptions& options = {});
/// Read and parse a study file. Throws StudyError (also when the file cannot be read).
Study load_study(const std::filesystem::path& file, const StudyOptions& options = {});

/// Levenshtein distance (for "did you mean" suggestions).
std::size_t edit_distance(std::string_view a, std::string_view b);

}  // namespace ks
