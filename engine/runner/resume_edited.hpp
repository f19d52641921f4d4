#pragma once
// `kinesweep run --resume` of a results file whose study text differs from the study given (the
// study was edited: comments, block order, axis values, blocks added or removed, the robot, task or
// settings). When some kind of the edited study's runs reads no changed part of the run context
// (robot, task, settings: runner/run_identity.hpp; e.g. IK runs when only the task changed), a new
// file for the edited study is built beside the old one: every done run of the old file whose identity a run of
// the edited study has is copied into it (its row, with the edited study's run id and block, and its
// history, through the store's public reads and writes), the sweep computes the rest, and the new
// file replaces the old one once complete. The old file is never written: if the process ends
// early (a signal, an error, a kill), it stays as it was and the new file is deleted.
#include <memory>
#include <string>

#include "runner/sweep.hpp"

namespace ks {

struct EditedResumeOptions {
  HistoryPolicy histories;    ///< the histories of the runs computed now (part of the run context)
  int compression = 1;        ///< deflate level of the copied histories (as of the computed ones)
  store::StoreOptions store;  ///< of the new file
};

/// The new file of an edited study, with the reused runs copied in.
struct EditedResume {
  std::unique_ptr<store::ResultsWriter> writer;  ///< the new file, open, at `staging`
  PreviousRuns previous;                         ///< per run id of the edited study: copied
  std::string staging;                           ///< the new file's path until it replaces the old one
  std::uint64_t reused = 0;                      ///< runs copied
  std::uint64_t old_done = 0;                    ///< done runs of the old file
  /// What changed in the run context ("" when nothing did) and which kinds' runs are computed again.
  std::string context_changes;
};

/// True when `out` is a results file of a study whose text (or URDF robot) differs from `study`'s
/// (another study_sha256); false when it is the same study or cannot be read (the in-place resume
/// then says why).
bool holds_edited_study(const std::string& out, const Study& study);

/// Build the new file of `study` beside `out` and copy the reusable runs of `out` into it. Refuses
/// with store::StoreError, `out` untouched, when the stored study's run context differs from
/// `study`'s in a part that every kind of `study`'s runs reads (the message says what changed: "the robot changed: [robot] l: ... -> ...; refusing to
/// resume: rerun with --overwrite"), or when the stored study cannot be read again.
EditedResume begin_edited_resume(const Study& study, const StudySchema& schema, const std::string& out,
                                 const EditedResumeOptions& options);

}  // namespace ks
