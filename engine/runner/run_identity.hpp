#pragma once
// The identity of a run: what its row and history are a function of, so that a results file can be
// resumed after its study was edited (runner/resume_edited.hpp) by reusing the runs whose identity
// the edited study still has. Two runs of equal identity give the same /runs cells (all but run_id,
// block and wall_time) and the same history, bit for bit.
//
// A run's identity has two parts:
// - the study's run context (run_context): every input of execute() and of the stored history
//   that is not a run parameter, as values (not as the study file wrote them):
//     robot     the closed-form 3R's constants (l, m, lc, I, g, inertia form), and for a chain robot
//               (an n-link [robot] arm or a URDF robot) every joint's type, origin, axis, position
//               limits, velocity and effort limits (where finite), mass, centre of mass and inertia,
//               the tip frame and gravity (a URDF file's comments,
//               names and unused links are not part of it);
//     task      vertices (and heights), durations, dt and integrator (the defaults of the runs'
//               columns of the same names), orientation;
//     settings  the histories policy and the kinesweep version;
//   of these parts, a run's identity covers those its kind reads (schema/params.hpp context_parts:
//   trajectory runs robot, task and settings; IK runs robot and settings), so an edit of the task
//   keeps the identities of the study's IK runs.
// - its parameters: the run's kind and every parameter column of its block with its value as stored
//   in /runs (stored units; strings by value), by column name.
//
// Canonical bytes of a run (run_identity_bytes), hashed with SHA-256 into its 256-bit identity:
//   "kinesweep-run-identity-1\n", the 32-byte context digest of the kind, the kind ("trajectory" | "ik"), "\n",
//   then per parameter column, in byte order of the column names: the name, a NUL, a type tag and the
//   value (a cell schema/params.hpp identity_neutral calls neutral, a task placement parameter at the
//   identity, is left out: a block that gains a placement axis keeps its runs' identities):
//   'f' + the f64's 8 IEEE bytes (little-endian, NaN payloads and -0 as they are), 'i' + the
//   i64's 8 bytes (little-endian), 's' + the length (u64, little-endian) and the UTF-8 bytes.
// The context digest of a kind is SHA-256 of "key\0value\n" of the context fields of the kind's parts,
// in run_context's order.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "runner/schema.hpp"
#include "study/study.hpp"

namespace ks {

using Digest = std::array<std::uint8_t, 32>;

/// One value of a study's run context.
struct ContextField {
  std::string group;  ///< "robot", "task", "settings"
  std::string key;    ///< what it is, as a user reads it: "[robot] l", "[robot] joint 2 mass", "[task] dt"
  std::string value;  ///< exact, human-readable (numbers in shortest round-trip form, stored units)
};

/// The run context of `study` run with `histories` by kinesweep `engine_version`.
std::vector<ContextField> run_context(const Study& study, const HistoryPolicy& histories,
                                      const std::string& engine_version = KINESWEEP_VERSION);
/// The digest of the fields of `context` that runs of `kind` read (its context_parts).
Digest context_digest(const std::vector<ContextField>& context, BlockKind kind);
/// What differs from `before` to `after`, one clause per group: "the robot changed: [robot] l: [1, 1, 1]
/// -> [1, 1.2, 1]; the task changed: ..." ("" when nothing does).
std::string context_changes(const std::vector<ContextField>& before, const std::vector<ContextField>& after);

/// The canonical bytes of a run (see above): `context` is context_digest(..., kind), `names` and
/// `cells` are the block's parameter columns and the run's values of them, in any order.
std::string run_identity_bytes(const Digest& context, BlockKind kind, const std::vector<std::string>& names,
                               const std::vector<Cell>& cells);

/// The identities of one block's runs under a context.
class BlockIdentity {
 public:
  /// The runs of `block` under the run context `context` (the parts its kind reads).
  BlockIdentity(const std::vector<ContextField>& context, const Block& block);
  /// Run `local` of the block (its parameter cells as Block::params gives them: as a run stores them).
  Digest run(std::uint64_t local) const;
  /// A stored row of a run of the block: its cells at `column[i]` for the block's parameter i
  /// (columns() order), e.g. a results file's column of that name.
  Digest row(const Record& row, const std::vector<std::size_t>& column) const;

 private:
  Digest of(const std::vector<Cell>& cells) const;
  const Block& block_;
  std::string prefix_;               // the bytes before the parameters
  std::vector<std::size_t> order_;   // parameter indices in byte order of their names
};

}  // namespace ks
