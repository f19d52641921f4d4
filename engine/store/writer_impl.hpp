#pragma once
// Internal: the state of a ResultsWriter, shared by writer.cpp, writer_histories.cpp, writer_resume.cpp
// and optimizations.cpp. Only store/*.cpp.
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "store/h5util.hpp"
#include "store/history_datasets.hpp"
#include "store/journal/vfd.hpp"
#include "store/label_columns.hpp"
#include "store/runs_chunks.hpp"
#include "store/store.hpp"

namespace ks::store {

struct ResultsWriter::Impl {
  std::string path;
  StoreOptions opt;
  std::vector<ColumnSpec> columns;
  std::int64_t n_runs = 0;
  detail::Hid file, runs, histories, landscapes, done_dset;
  std::vector<detail::Hid> col_dsets;
  std::vector<detail::LabelEncoder> encoders;  // per column (labelled text columns only)
  /// The chunked columns (format 4: every fixed-size one) and, per chunk, how many of its rows are
  /// done (committed or pending): a chunk is encoded once that reaches its row count.
  detail::RunsChunks runs_chunks;
  std::vector<int> chunk_col;             // per column: its index in runs_chunks, -1 when contiguous
  std::vector<std::uint32_t> chunk_done;  // per chunk of runs_chunks.chunk_rows() rows
  std::vector<bool> done;                   // per run, one bit: committed or pending
  std::map<std::int64_t, Record> pending;   // rows not yet in the datasets
  std::vector<hsize_t> unflagged;           // rows in the datasets, not yet committed with done = 1
  /// A landscape whose cells are streamed in (writer_landscapes.cpp): its metric datasets and the
  /// cells set since the last write_rows (values cell-major, one per metric).
  struct LandscapeStream {
    std::string block;
    std::vector<hsize_t> dims;
    std::vector<detail::Hid> metrics;
    std::vector<std::uint64_t> cells;
    std::vector<double> values;
    /// Created by this writer since its last commit: its grids lie past the committed size, where
    /// writes go straight to the file (journal_vfd.cpp), so they hold no journal memory.
    bool fresh = false;
    /// A dense stream created without the NaN fill (LandscapeSpec::dense, fresh): its cells not yet
    /// written, which must be none at the next commit.
    std::uint64_t unwritten = 0;
    void written(std::uint64_t n) { unwritten -= std::min(unwritten, n); }
  };
  std::vector<LandscapeStream> landscape_streams;
  /// The histories' shared row space (writer_histories.cpp, FORMAT.md: /histories).
  using HistoryDataset = detail::HistoryDataset;
  struct HistoryIndexEntry {
    std::int64_t start = -1, rows = 0, layout = -1;
  };
  struct Histories {
    std::atomic<std::size_t> chunk_rows{0};   ///< 0 until the first history (or the file's attribute)
    hsize_t used_rows = 0, written_used_rows = 0;
    std::vector<HistoryDataset> datasets;
    std::vector<std::string> layouts;
    detail::Hid start, rows, layout;          ///< the index datasets (absent until the first history)
    detail::Hid row_dim;                      ///< the netCDF dimension history_row (opened at the first need)
    hsize_t row_dim_extent = 0;
    std::map<std::int64_t, HistoryIndexEntry> pending;  ///< index entries not yet in the datasets
    bool layouts_dirty = false;
    void close_handles() {
      datasets.clear();
      start.reset(); rows.reset(); layout.reset(); row_dim.reset();
      row_dim_extent = 0;
    }
  } hist;
  std::set<std::string> begun_landscapes;  // blocks begin_landscape was called for by this writer
  /// This writer deleted an object (a replaced landscape or optimisation): HDF5 may place new
  /// objects in the space it freed, below the committed size, so no new landscape counts as fresh.
  bool freed_space = false;
  static constexpr std::size_t kRowBatch = 512;
  /// Bytes of rows, done flags and landscape cells written into their datasets since the last commit.
  /// Those datasets lie in the committed part of the file, so until the commit the journal holds
  /// these bytes' pages in memory: write_run commits once they reach kMaxUncommittedBytes, whatever
  /// the runs' pace (a fast sweep would otherwise hold flush_every_runs rows' pages, ~20 MB).
  std::size_t uncommitted_bytes = 0;
  static constexpr std::size_t kMaxUncommittedBytes = std::size_t{4} << 20;
  std::chrono::steady_clock::time_point last_flush = std::chrono::steady_clock::now();
  bool closed = false, broken = false;
  bool touched = false;  ///< this writer created the file or wrote into it (close() then records when)
  bool content = false;  ///< runs or optimizations were written (a file written aside is then placed)
  /// A file created over an existing one (overwrite) is written aside, under this temporary name in
  /// the same folder, with its own journal, while `path` keeps the previous file and `place_lock`
  /// holds the writer lock of path's journal; the first commit after `content` (or at close())
  /// renames it into place. Empty once placed (or for any other writer).
  std::string aside;
  int place_lock = -1;
  void place_aside();   ///< journal then file renamed over path's (writer.cpp)
  void drop_aside();    ///< the aside file and its journal removed, the lock released (a failed writer)

  /// Marks the writer broken and throws StoreError: the file keeps its last commit (the journal
  /// driver commits nothing more: abandon_journal_file; close() leaves the file as that commit left it).
  void fail(const std::string& what) {
    broken = true;
    std::string cause = what + ": " + detail::h5_error_text();
    std::string j = detail::journal_last_error();
    if (!j.empty()) cause += " (" + j + ")";
    if (file.get() >= 0) detail::abandon_journal_file(file);
    throw StoreError(path, cause);
  }
  void usable() const {
    if (closed) throw StoreError(path, "writer is closed");
    if (broken) throw StoreError(path, "writer failed earlier; the file holds the runs of the last successful flush");
  }
  void open_objects();
  void count_chunk_done();  ///< chunk_done from done (after open_objects and done are set)
  void mark_done(std::int64_t id) {
    if (done[static_cast<std::size_t>(id)]) return;
    done[static_cast<std::size_t>(id)] = true;
    if (runs_chunks.active()) ++chunk_done[static_cast<std::size_t>(static_cast<hsize_t>(id) / runs_chunks.chunk_rows())];
  }
  void write_history(std::int64_t id, const EncodedHistory& h);
  void open_histories();          ///< the history state of an existing file (resume)
  void write_history_index();     ///< pending index entries and the group's attributes (no commit)
  void trim_histories();          ///< extents down to used_rows (at close)
  void write_rows();  // pending rows and landscape cells into the datasets (no commit)
  void write_landscape_cells();  // the pending landscape cells (writer_landscapes.cpp)
  void do_flush();    // write_rows, commit, set done flags, commit
};

namespace detail {
/// Throws StoreError unless `name` is usable as an HDF5 link name ("what": column, history array, ...).
void validate_name(const std::string& path, const std::string& name, const std::string& what);
/// A file-access property list for the store's on-disk format (see FORMAT.md: 1.8 object formats,
/// superblock v2, which has no "open for write" flag, so readers can open a file being written).
void set_format(hid_t fapl);
/// A file-space selection of `dset`'s rows `ids` (sorted, unique) as a union of hyperslabs.
Hid select_rows(hid_t dset, const std::vector<hsize_t>& ids);
/// The writer of a new file `tmp` (its skeleton written) that is to replace the existing file `path`
/// (overwrite): the previous file stays until the new one holds runs (Impl::aside). Takes the writer
/// lock of path's journal at once, so that no other writer starts on the previous file meanwhile.
/// Only path, opt, file, aside and place_lock are set. Throws StoreError (writer_aside.cpp).
std::unique_ptr<ResultsWriter::Impl> open_aside(const std::string& path, const std::string& tmp,
                                                const StoreOptions& opt);
/// Opens an existing results file for writing through the journal driver (which recovers it first
/// after a crash). Only path, opt and file are set. Throws StoreError.
std::unique_ptr<ResultsWriter::Impl> open_writer_impl(const std::string& path, const StoreOptions& opt);
/// Writes a new results file's skeleton into the open `file`: root attributes, /study, the /runs
/// columns (n_runs rows, every row missing), /kinds, /designs, /histories, /landscapes
/// (writer_skeleton.cpp).
/// The commit set_engine_commit recorded ("" when none).
std::string& engine_commit();
/// The time now, ISO 8601 UTC ("2026-12-05T02:30:00Z").
std::string now_iso8601();
void build_skeleton(hid_t file, const std::string& path, const StoreMeta& meta, const std::vector<ColumnSpec>& columns,
                    std::int64_t n_runs);
}  // namespace detail

}  // namespace ks::store
