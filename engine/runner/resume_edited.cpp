// Resume of an edited study into a new file (see resume_edited.hpp).
#include "runner/resume_edited.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "runner/placed_task.hpp"
#include "runner/run_identity.hpp"
#include "runner/study_meta.hpp"

namespace ks {

namespace {

constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

[[noreturn]] void refuse(const std::string& out, const std::string& why) {
  throw store::StoreError(out, why + "; refusing to resume: rerun with --overwrite");
}

/// The study stored in a results file, parsed again with the URDF text stored with it.
Study stored_study(const store::ResultsReader& file, const std::string& out) {
  const store::StoreMeta& meta = file.meta();
  StudyOptions so;
  so.max_runs = std::max<std::uint64_t>(so.max_runs, static_cast<std::uint64_t>(file.n_runs()));
  so.robot_text = meta.robot_text;
  try {
    return parse_study(meta.study_text, meta.study_path.empty() ? "<stored study>" : meta.study_path, so);
  } catch (const StudyError& e) {
    refuse(out, "the study stored in the file cannot be read by this kinesweep (" +
                    (e.diagnostics().empty() ? std::string(e.what()) : e.diagnostics().front().headline()) + ")");
  }
}

/// Per block of `study`: the file column of each of its parameters (by name and type).
std::vector<std::vector<std::size_t>> parameter_columns(const Study& study, const std::vector<ColumnSpec>& file,
                                                        const std::string& out) {
  std::vector<std::vector<std::size_t>> cols;
  for (const Block& b : study.blocks) {
    std::vector<std::size_t> c;
    for (const ColumnSpec& p : b.columns()) {
      std::size_t at = npos;
      for (std::size_t i = 0; i < file.size(); ++i)
        if (file[i].name == p.name && file[i].type == p.type) at = i;
      if (at == npos)
        refuse(out, "its /runs has no column '" + p.name + "' of the right type for block '" + b.name() +
                        "' of its study (written by another kinesweep)");
      c.push_back(at);
    }
    cols.push_back(std::move(c));
  }
  return cols;
}

using Entry = std::pair<Digest, std::int64_t>;  // identity, run id in the old file

/// The identities of the done runs of the old file, sorted (the first run id of equal identities).
std::vector<Entry> done_identities(const store::ResultsReader& file, const Study& before,
                                   const std::vector<ContextField>& context, const std::string& out,
                                   std::uint64_t& done) {
  const auto cols = parameter_columns(before, file.columns(), out);
  std::vector<BlockIdentity> ids;
  for (const Block& b : before.blocks) ids.emplace_back(context, b);
  constexpr std::int64_t kPiece = 8192;  // rows read at a time: memory bounded whatever the run count
  std::vector<Entry> entries;
  for (std::int64_t first = 0; first < file.n_runs(); first += kPiece) {
    const std::vector<std::uint8_t> mask = file.done_mask(first, kPiece);
    if (std::none_of(mask.begin(), mask.end(), [](auto d) { return d != 0; })) continue;
    const std::vector<Record> rows = file.read_rows(first, kPiece);
    for (std::size_t i = 0; i < mask.size() && i < rows.size(); ++i) {
      if (!mask[i]) continue;
      const std::int64_t id = first + static_cast<std::int64_t>(i);
      const RunRef ref = before.locate(static_cast<std::uint64_t>(id));
      entries.emplace_back(ids[ref.block].row(rows[i], cols[ref.block]), id);
    }
  }
  done = entries.size();
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.first < b.first; });
  return entries;
}

/// Copies the old file's runs `pairs` (new run id, old run id; ascending new ids) into `writer`:
/// each row with the edited study's run id and block (the other cells by column name), and its
/// history. Rows are read in pieces.
/// `identity_ik_error`: the ik_error of the study's task as written (a block that places its task
/// measures it), for the rows of such blocks copied from a file without that column; NaN: none.
void copy_runs(const store::ResultsReader& file, const Study& study, const StudySchema& schema,
               const std::vector<std::pair<std::uint64_t, std::int64_t>>& pairs, int compression,
               double identity_ik_error, store::ResultsWriter& writer) {
  std::vector<std::size_t> from(schema.columns.size(), npos);  // new column -> old column
  for (std::size_t c = 0; c < schema.columns.size(); ++c)
    for (std::size_t o = 0; o < file.columns().size(); ++o)
      if (file.columns()[o].name == schema.columns[c].name && file.columns()[o].type == schema.columns[c].type)
        from[c] = o;
  constexpr std::size_t kPiece = 4096;
  for (std::size_t first = 0; first < pairs.size(); first += kPiece) {
    const std::size_t n = std::min(kPiece, pairs.size() - first);
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < n; ++i) ids.push_back(pairs[first + i].second);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    const std::vector<Record> rows = file.read_rows(ids);
    for (std::size_t i = 0; i < n; ++i) {
      const auto [id, old] = pairs[first + i];
      const Record& row = rows[static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), old) - ids.begin())];
      Record rec = schema.blank;
      for (std::size_t c = 0; c < rec.cells.size(); ++c)
        if (from[c] != npos) rec.cells[c] = row.cells[from[c]];
      // a parameter column the old file lacks (a placement axis added at its identity value): the
      // edited study's value, which the identity left out
      const RunRef ref = study.locate(id);
      const auto& pc = schema.param_column[ref.block];
      if (std::any_of(pc.begin(), pc.end(), [&](std::size_t c) { return from[c] == npos; })) {
        const std::vector<Cell> cells = study.blocks[ref.block].params(ref.local);
        for (std::size_t i = 0; i < pc.size(); ++i)
          if (from[pc[i]] == npos) rec.cells[pc[i]] = cells[i];
      }
      if (study.blocks[ref.block].context().placement && !std::isnan(identity_ik_error)) {
        const auto& bm = study.blocks[ref.block].metrics();
        for (std::size_t j = 0; j < bm.size(); ++j)
          if (bm[j].name == "ik_error" && from[schema.metric_column[ref.block][j]] == npos)
            rec.cells[schema.metric_column[ref.block][j]] = identity_ik_error;
      }
      rec.cells[schema.run_id] = static_cast<std::int64_t>(id);
      rec.cells[schema.block] = study.blocks[study.locate(id).block].name();
      // the stored chunks, copied as they are (a format 2 file's histories are encoded at `compression`)
      writer.write_run(static_cast<std::int64_t>(id), rec, file.read_history_chunks(old, compression));
    }
  }
  writer.flush();
}

}  // namespace

bool holds_edited_study(const std::string& out, const Study& study) {
  try {
    const store::ResultsReader file(out);
    return lower(file.meta().study_sha256) != lower(study.sha256);
  } catch (const store::StoreError&) {
    return false;
  }
}

EditedResume begin_edited_resume(const Study& study, const StudySchema& schema, const std::string& out,
                                 const EditedResumeOptions& options) {
  const store::ResultsReader file(out);
  store::require_resumable(out, file.meta());
  const Study before = stored_study(file, out);
  // The policy the old runs were written with: the one the file records (a --histories given then),
  // else its study's.
  HistoryPolicy was_histories = before.histories;
  if (!file.meta().histories.empty() && !HistoryPolicy::parse(file.meta().histories, was_histories))
    refuse(out, "the file records an unknown history policy '" + file.meta().histories + "'");
  const auto was = run_context(before, was_histories, file.meta().engine_version);
  const auto now = run_context(study, options.histories);
  EditedResume r;
  if (const std::string what = context_changes(was, now); !what.empty()) {
    // the kinds of the edited study whose runs read a changed part of the context are computed
    // again; when that is every kind, no run could be reused
    std::string again;
    bool reusable = false;
    for (const BlockKind kind : block_kinds()) {
      const bool used = std::any_of(study.blocks.begin(), study.blocks.end(),
                                    [&](const Block& b) { return b.kind() == kind; });
      if (!used) continue;
      if (context_digest(was, kind) == context_digest(now, kind)) reusable = true;
      else again += (again.empty() ? "" : " and ") + std::string(to_string(kind));
    }
    if (!reusable) refuse(out, what);
    r.context_changes = what + " (read by the " + again + " runs, which are computed again)";
  }
  if (file.n_runs() != static_cast<std::int64_t>(before.run_count()))
    refuse(out, "the file has " + std::to_string(file.n_runs()) + " runs, its study " +
                    std::to_string(before.run_count()));

  const std::vector<Entry> old = done_identities(file, before, was, out, r.old_done);
  std::vector<std::pair<std::uint64_t, std::int64_t>> pairs;  // new run id, old run id
  std::uint64_t id = 0;
  for (const Block& b : study.blocks) {
    const BlockIdentity ids(now, b);
    for (std::uint64_t local = 0; local < b.run_count(); ++local, ++id) {
      const Entry key{ids.run(local), 0};
      const auto it = std::lower_bound(old.begin(), old.end(), key,
                                       [](const Entry& a, const Entry& b) { return a.first < b.first; });
      if (it != old.end() && it->first == key.first) pairs.emplace_back(id, it->second);
    }
  }

  // Blocks that now place their task measure ik_error; a file without that column did not. The
  // runs reused there are at the identity placement (the identity leaves it out otherwise): their
  // ik_error is the task's as written, and when that is not 0 a fresh run would end out_of_reach,
  // so they are computed again instead.
  double identity_ik_error = std::numeric_limits<double>::quiet_NaN();
  const bool file_has_ik_error = std::any_of(file.columns().begin(), file.columns().end(),
                                             [](const ColumnSpec& c) { return c.name == "ik_error"; });
  const bool placing = std::any_of(study.blocks.begin(), study.blocks.end(),
                                   [](const Block& b) { return b.context().placement; });
  if (placing && !file_has_ik_error) {
    identity_ik_error = task_ik_error(study.task, study.robot, study.chain.get());
    if (identity_ik_error > 0.0)
      std::erase_if(pairs, [&](const auto& p) { return study.blocks[study.locate(p.first).block].context().placement; });
  }

  r.staging = store::staging_path(out);
  store::StoreOptions so = options.store;
  so.overwrite = false;
  r.writer = store::ResultsWriter::create(r.staging, store_meta(study, options.histories), schema.columns,
                                          static_cast<std::int64_t>(study.run_count()), so);
  try {
    copy_runs(file, study, schema, pairs, options.compression, identity_ik_error, *r.writer);
  } catch (...) {
    r.writer.reset();
    store::remove_results_file(r.staging);
    throw;
  }
  r.previous.done.assign(study.run_count(), 0);
  for (const auto& [n, o] : pairs) r.previous.done[n] = 1;
  r.reused = pairs.size();
  return r;
}

}  // namespace ks
