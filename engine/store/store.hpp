#pragma once
// The HDF5 results store: the only code in kinesweep that knows HDF5. File layout: FORMAT.md.
//
// Threading: encode_history() is thread-safe and HDF5-free (zlib only): call it in worker threads.
// A ResultsWriter must be used by one thread (the writer thread) only; history_chunk_rows() is the
// exception (worker threads read it to encode).
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "store/record.hpp"
#include "store/derived_tables.hpp"

namespace ks::store {

/// Every store failure: unwritable directory, disk full, existing file, sha mismatch, bad input...
class StoreError : public std::runtime_error {
 public:
  StoreError(std::string path, std::string cause)
      : std::runtime_error(message(path, cause)), path_(std::move(path)), cause_(std::move(cause)) {}
  const std::string& path() const { return path_; }
  const std::string& cause() const { return cause_; }

 private:
  static std::string message(const std::string& path, const std::string& cause) {
    std::string m("results store: ");
    if (!path.empty()) m.append(path).append(": ");
    return m.append(cause);
  }
  std::string path_, cause_;
};

/// Whether HDF5 prints its own (multi-line) error stack to stderr when a call fails (its default:
/// yes). The store's errors say the cause in one line either way.
void print_hdf5_error_stack(bool print);

inline constexpr const char* kFormatName = "kinesweep-results";
/// The format this kinesweep writes (5: netCDF-readable: the enums committed as named types with a
/// member for the missing code, sampled landscape dimensions as `sample` with a coordinate per
/// parameter, integer status grids; 4: text columns with few distinct values as HDF5 enums; 3:
/// histories as ragged arrays sharing one row space; 2: one group per run's history; all four:
/// /runs columns carry `role` and `kinds` attributes).
inline constexpr std::int64_t kFormatVersion = 5;
/// The CF conventions version a results file declares (root attribute `Conventions`).
inline constexpr const char* kConventions = "CF-1.10";
/// Rows per chunk of the fixed-size /runs columns (format 4; FORMAT.md, /runs): the unit in which
/// they are compressed, and in which a distributed sweep hands out work (so its shards merge by chunk).
inline constexpr std::uint64_t kRunsChunkRows = 16384;
/// The oldest format ResultsReader still opens (1: no role/kinds; see ResultsReader's V1ColumnRoles).
inline constexpr std::int64_t kOldestReadableFormatVersion = 1;
/// The oldest format ResultsWriter::open_for_resume continues (a format 3 file differs from 4 only in
/// how /runs stores text: its columns, read back without labels, keep their strings).
inline constexpr std::int64_t kOldestResumableFormatVersion = 3;

/// Root metadata of a results file.
/// A run kind's meaning as the engine declares it (schema/params.hpp, schema/history_arrays.hpp),
/// written as string-list attributes of the group /kinds/<name> (FORMAT.md).
struct KindMeta {
  std::string name;  ///< "trajectory" | "ik"
  std::vector<std::pair<std::string, std::vector<std::string>>> lists;  ///< attribute -> values
};

/// A block whose runs are the points of a Saltelli design (FORMAT.md, /designs/<block>): what a
/// sensitivity analysis needs to find the design's matrices A, B and AB_m among the block's runs.
struct DesignMeta {
  std::string block;                 ///< the block's name
  std::string kind;                  ///< its run kind ("trajectory" | "ik")
  std::string design;                ///< "saltelli"
  std::vector<std::string> factors;  ///< the design's axes, in its column order (AB_m takes factor m from B)
  std::int64_t base_samples = 0;     ///< N: the design's dimension has N (factors + 2) points, A, B, AB_0, ...
  std::int64_t first_run = 0;        ///< the block's first run id
  std::vector<std::string> dims;     ///< the block's dimensions in run order (the last fastest): axis names joined by "+"
  std::vector<std::int64_t> sizes;   ///< their lengths
  std::int64_t dim = 0;              ///< the index of the design's dimension in dims
};

struct StoreMeta {
  std::string study_name;
  std::string study_path;    ///< attribute "path" of /study
  std::string study_text;    ///< the study file's text verbatim (/study/text)
  std::string study_sha256;  ///< hex (of the study text, and of the robot's URDF text when there is one)
  std::string robot_path;    ///< the URDF or DH robot file the study names (attribute "path" of /study/robot; "" when none)
  std::string robot_text;    ///< its text verbatim (/study/robot; written only when non-empty)
  std::string engine_version = KINESWEEP_VERSION;
  std::string created;       ///< ISO 8601 UTC; filled at creation when empty
  std::string command_line;  ///< the command that created the file (root attribute "command_line"; "" when none)
  std::string host;          ///< the machine it ran on (root attribute "host"); filled at creation when empty
  /// The history policy the runs are written with (root attribute "histories": full, every=N or
  /// none; written when not empty; "" in files from before it was recorded).
  std::string histories;
  /// The study's run kinds (/kinds; empty in files from before they were written).
  std::vector<KindMeta> kinds;
  /// The blocks run as a Saltelli design (/designs; empty when none).
  std::vector<DesignMeta> designs;
  std::string format = kFormatName;
  std::int64_t format_version = kFormatVersion;
};

/// Throws StoreError unless a results file with these root attributes can be resumed by this
/// kinesweep (format kinesweep-results, version kOldestResumableFormatVersion .. kFormatVersion); the
/// message names the version.
void require_resumable(const std::string& path, const StoreMeta& meta);

struct StoreOptions {
  bool overwrite = false;            ///< replace an existing file at the path
  /// Automatic flush after this many written runs (0: never). A commit journals every changed page,
  /// so committing by time (below) keeps its cost small whatever the runs cost; a kill -9 loses at
  /// most the runs of the last flush_every_seconds.
  std::size_t flush_every_runs = 65536;
  double flush_every_seconds = 1.0;  ///< ... or when this much time passed since the last flush (0: never)
  bool durable = false;              ///< fsync around commits (power-loss safety; kill -9 safety needs none)
};

namespace detail {
/// Blocks of `n` bytes for ByteBuffer (byte_buffer.cpp): blocks of 16 KiB and more come from a
/// cache shared by all threads, in power-of-two sizes, keeping up to 64 MiB of freed blocks.
void* byte_buffer_allocate(std::size_t n);
void byte_buffer_deallocate(void* p, std::size_t n) noexcept;
}  // namespace detail

/// The allocator of ByteBuffer: resize leaves new bytes uninitialised (buffers an encoder or a read
/// fills completely), and the blocks are recycled (a sweep's history chunks are made by the workers
/// and freed by the writer thread, run after run; from malloc, their pages went back to the kernel
/// and were faulted in, zeroed, again for every run).
struct ByteAllocator {
  using value_type = unsigned char;
  using is_always_equal = std::true_type;
  template <class U>
  struct rebind {
    static_assert(std::is_same_v<U, unsigned char>, "ByteAllocator allocates bytes only");
    using other = ByteAllocator;
  };
  unsigned char* allocate(std::size_t n) { return static_cast<unsigned char*>(detail::byte_buffer_allocate(n)); }
  void deallocate(unsigned char* p, std::size_t n) noexcept { detail::byte_buffer_deallocate(p, n); }
  void construct(unsigned char* p) noexcept { ::new (static_cast<void*>(p)) unsigned char; }
  void construct(unsigned char* p, unsigned char v) noexcept { *p = v; }
  friend bool operator==(const ByteAllocator&, const ByteAllocator&) noexcept { return true; }
};
using ByteBuffer = std::vector<unsigned char, ByteAllocator>;

/// One HDF5 chunk of a history dataset, as its filter pipeline stores it: shuffle then deflate
/// (filter_mask 0), or the raw little-endian rows (filter_mask kRawChunk: both filters skipped).
struct EncodedChunk {
  ByteBuffer bytes;
  std::uint32_t filter_mask = 0;
};
inline constexpr std::uint32_t kRawChunk = 0x3;
/// One history array cut into chunks of chunk_rows rows (the last one padded with NaN rows), each
/// encoded for the history datasets' filter pipeline (FORMAT.md: /histories).
struct EncodedArray {
  std::string name, unit;
  std::size_t rows = 0, cols = 1;
  std::size_t chunk_rows = 0;  ///< rows per chunk (0 when rows is 0)
  int level = 0;               ///< deflate level the chunks were encoded with (0: raw)
  std::vector<EncodedChunk> chunks;  ///< ceil(rows / chunk_rows) chunks
};
struct EncodedHistory {
  std::vector<EncodedArray> arrays;
};
/// Compress a run's history in the calling thread, in chunks of `chunk_rows` rows (0: one chunk
/// holding every row): HDF5's shuffle then deflate (zlib format, by libdeflate, `level` 1..9), or
/// raw chunks for level 0. Every array of a run must have the same number of rows (the run's
/// samples or iterations). Thread-safe, no HDF5. Throws StoreError when an array's data size is not
/// rows*cols or the arrays' row counts differ.
EncodedHistory encode_history(const RunHistory& history, int level = 1, std::size_t chunk_rows = 0);
/// The arrays back from their chunks (bit-identical to what was encoded). Throws StoreError on a
/// chunk that does not decode to chunk_rows * cols values.
RunHistory decode_history(const EncodedHistory& history);
/// Total bytes of the encoded chunks.
std::size_t encoded_bytes(const EncodedHistory& history);

/// One axis of a block's grid, or one gridded metric (row-major over the axes, NaN = no value).
/// A sampled dimension (zip, LHS, random, Saltelli, or values not in order) is the axis `sample`
/// (values 0..n-1) whose `coordinates` are its parameters, each with its n values.
struct LandscapeAxis {
  std::string name, unit;
  std::vector<double> values;
  std::vector<LandscapeAxis> coordinates = {};  ///< the parameters along a sampled dimension
};
struct LandscapeMetric {
  std::string name, unit, description;
  std::vector<double> grid;
  std::string display_name = {};  ///< as ColumnSpec::display_name (attribute `display_name` when set)
  /// Non-empty: the grid holds codes 0..n-1 of these names (stored as int8/int16 with flag_values and
  /// flag_meanings, -1 where there is none; read back as NaN there).
  std::vector<std::string> flags = {};
};
struct LandscapeSpec {
  std::string block;
  std::vector<LandscapeAxis> axes;
  std::vector<LandscapeMetric> metrics;
  /// Every cell is written before the file's next commit (a sweep whose runs were all done before
  /// it began: a merge, a resumed complete file). In a new part of the file its metrics are then
  /// allocated at creation and not filled with NaN first (a first write of part of a contiguous
  /// dataset fills all of it); a commit with cells still unwritten fails.
  bool dense = false;
};

/// One stage of an optimisation (/optimizations/<name>/stages, FORMAT.md).
struct OptimizationStage {
  std::string name;         ///< "sweep", "global", "local"
  std::string algorithm;    ///< NLopt name ("" for sweep)
  std::string result;       ///< NLopt's result code name
  double wall_time_s = 0.0;
  std::int64_t evaluations = 0;
  double best_objective = 0.0;
  std::vector<double> best_x;  ///< one value per variable
  std::string best_status;
};

/// An optimisation block's results: every evaluation, the stages, the best point and its run's
/// history (/optimizations/<name>/, FORMAT.md). Plain data: filled by the runner, read by info/query.
struct OptimizationRecord {
  std::string name;       ///< group name (the block's; the preset's for a seed row)
  std::string kind;       ///< "trajectory" | "ik"
  std::string preset;     ///< seed 000 row, "" when none
  std::string objective;  ///< e.g. "E", "E + 0.01*tau_inf"
  std::string settings;   ///< the pipeline's options, human-readable (one "key = value" per line)
  std::vector<std::string> variables, units;  ///< d variables, their stored units
  std::vector<double> lower, upper;           ///< bounds (stored units)
  // Every evaluation, in order (n rows).
  std::vector<double> x;                 ///< n x d, row-major
  std::vector<double> value;             ///< objective (penalised when the run failed)
  std::vector<double> constraint;        ///< reach margin c(x) <= 0 feasible (NaN when none)
  std::vector<std::string> stage;        ///< "sweep", "global", "local"
  std::vector<std::string> status;       ///< the run's status
  std::vector<std::int64_t> start;       ///< local: index of its start; sweep: the cell's run id; global: -1
  std::vector<OptimizationStage> stages;
  std::vector<double> local_from, local_to;  ///< per local start: m x d, row-major
  std::vector<double> local_value;           ///< per local start: the best value it reached
  double best_objective = 0.0;
  std::vector<double> best_x;
  std::string best_status, best_stage;
  std::vector<std::pair<std::string, double>> best_metrics;  ///< the best point's run metrics (first run of the set)
  std::vector<std::pair<std::string, double>> reference;     ///< e.g. thesis_E, thesis_alpha1A [rad] for presets
  RunHistory history;                                        ///< the best point's run (first run of the set)
  double wall_time_s = 0.0;
  std::int64_t seed = 0;
  std::size_t dims() const { return variables.size(); }
  std::size_t size() const { return value.size(); }
};

class ResultsReader;

class ResultsWriter {
 public:
  struct Impl;
  /// Create a new results file of `n_runs` rows (all missing, none done). The file is built under a
  /// temporary name in the same directory and renamed into place; an existing file is replaced only
  /// with options.overwrite. Throws StoreError.
  static std::unique_ptr<ResultsWriter> create(const std::string& path, const StoreMeta& meta,
                                               const std::vector<ColumnSpec>& columns, std::int64_t n_runs,
                                               const StoreOptions& options = {});

  struct Resumed;
  /// Reopen an existing file to fill its missing runs (recovering it first after a crash, when its
  /// journal matches the file as it is; otherwise refusing with the file untouched). Refuses
  /// with StoreError when the file's study_sha256 differs from `expected_sha256`, or when its
  /// format_version is not kOldestResumableFormatVersion .. kFormatVersion (checked read-only: a
  /// refused file is left untouched).
  static Resumed open_for_resume(const std::string& path, const std::string& expected_sha256,
                                 const StoreOptions& options = {});

  ~ResultsWriter();  ///< closes (commits) the file; errors are swallowed: call close() to see them
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  /// Store run `run_id` (0 <= run_id < n_runs, any order, rewriting allowed). The row becomes
  /// visible (done) at the next flush, automatic or explicit; its history is stored at once.
  void write_run(std::int64_t run_id, const Record& record, const EncodedHistory& history = {});
  void write_run(std::int64_t run_id, const Record& record, const RunHistory& history, int level = 1);
  /// Copy the runs that `owner` assigns to a source (owner[id]: an index into `sources`, or -1) and
  /// this file does not hold yet: their histories (chunks as stored; re-encoded at `level` only from
  /// a format 2 source) and /runs rows, counted done (visible at the next flush, which holds both).
  /// Every source is a results file of this file's columns and run count. A chunk of /runs whose
  /// rows all come from one source, and of which this file holds none, is copied as stored (no
  /// decoding); the other chunks are assembled per column from the sources' rows and encoded once
  /// complete (writer_merge.cpp). Landscapes are not copied. Returns false, having copied nothing,
  /// when a layout does not allow it (a format 3 file or source, a variable-length column, other
  /// columns or chunk sizes); the caller then copies rows with write_run.
  bool copy_runs(const std::vector<const ResultsReader*>& sources, const std::vector<std::int32_t>& owner,
                 int level = 1);
  /// Rows per chunk of the file's history datasets: what encode_history should be given for
  /// write_run to store the chunks as they are (others are re-cut). 0 until the first history sets
  /// it (from that run's rows). Thread-safe: worker threads read it while the writer thread writes.
  std::size_t history_chunk_rows() const;
  /// Commit everything written so far (atomic: after a crash the file holds exactly the runs done
  /// at the last completed flush).
  void flush();
  /// Create /landscapes/<spec.block>/ (replacing an existing one) with the axes of `spec` and its
  /// metrics' names, units and descriptions (their grids are not read): every cell NaN until
  /// write_landscape_cell sets it. Returns the landscape's handle. The group is written at once
  /// (committed at the next flush), so a file of an interrupted sweep has its partial landscapes.
  /// Exception: a group that was in the file when this writer opened it, with the same axes and
  /// metrics (a resumed sweep), is kept with its cells (FORMAT.md, /landscapes).
  std::size_t begin_landscape(const LandscapeSpec& spec);
  /// Set one cell (row-major index into the axes' grid) of a begun landscape to `values` (one per
  /// metric, in the spec's order). Written with the rows and committed with them; a cell set twice
  /// keeps its last values. Memory: only cells not yet written are held.
  void write_landscape_cell(std::size_t landscape, std::uint64_t cell, const double* values);
  /// Set the `count` consecutive cells (row-major) from `first` of a begun landscape at once:
  /// values[m] points to metric m's count values (the spec's order). Cells set before are written
  /// first, so the last value set for a cell is kept. Committed with the rows.
  void write_landscape_range(std::size_t landscape, std::uint64_t first, std::uint64_t count,
                             const std::vector<const double*>& values);
  /// Set the cells of a begun landscape from the same landscape (the same block's group, metric names
  /// and shape) of other results files of the same study (the shards of a distributed sweep): cell
  /// c from sources[owner[c]] (owner: one entry per cell; -1 leaves the cell as it is), read and
  /// written by ranges of cells of one owner. Returns false, having written nothing, when a source
  /// named by `owner` lacks that landscape; the caller then computes the cells from the rows.
  bool copy_landscape(std::size_t landscape, const std::vector<const ResultsReader*>& sources, const std::int32_t* owner);
  /// Write /landscapes/<block>/ with every cell of `spec` (replacing an existing one) and flush.
  void write_landscape(const LandscapeSpec& spec);
  /// Write /optimizations/<record.name>/ (replacing an existing one) and flush (optimizations.cpp).
  void write_optimization(const OptimizationRecord& record);
  /// Write /verification (replacing an existing one) and flush (verification.cpp).
  void write_verification(const VerificationTable& table);
  /// Write /sensitivity (replacing an existing one) and flush (sensitivity.cpp).
  void write_sensitivity(const SensitivityTable& table);
  /// Flush and close; further calls throw.
  void close();

  const std::string& path() const;
  const std::vector<ColumnSpec>& columns() const;
  /// The history policy recorded in the file (root attribute "histories"; "" when it has none).
  std::string recorded_histories() const;
  std::int64_t n_runs() const;
  bool is_done(std::int64_t run_id) const;  ///< committed or pending
  /// Rows `first` .. `first + count` (clamped to n_runs) as they are in the file, pending rows
  /// included (written to their datasets first, without a commit): what a resumed sweep already holds.
  std::vector<Record> read_rows(std::int64_t first, std::int64_t count);
  /// Rows `first` .. `first + count` (clamped) of one numeric column (an i64 column's values
  /// converted), pending rows included, without building Records: what a resumed sweep or a merge
  /// counts and grids its done runs by.
  std::vector<double> read_numbers(const std::string& column, std::int64_t first, std::int64_t count);
  /// The same of a labelled text column: each row's code, an index into the column's labels (a code
  /// past them: the missing value ""). Throws StoreError for a column without labels.
  std::vector<std::uint16_t> read_codes(const std::string& column, std::int64_t first, std::int64_t count);
  std::size_t pending() const;              ///< runs written since the last flush

 private:
  explicit ResultsWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct ResultsWriter::Resumed {
  std::unique_ptr<ResultsWriter> writer;  ///< the runs already done: writer->is_done(id)
};

// ------------------------------------------------------------------------------------------------
/// Read access (kinesweep info/query, tests). Works on a file that is being written: it sees the
/// last committed state at open time (re-open to see newer runs; read the done mask before the
/// columns). A reader never modifies the file or its journal: after a crash it reads the last
/// committed state as the writer left it (a commit the writer had not finished applying is read
/// from the journal), and refuses, saying why, a journal that does not match the file (FORMAT.md).
class ResultsReader {
 public:
  /// Fills `role` and `kinds` of the /runs columns of a format_version 1 file, which stores neither.
  /// The store knows no column tables, so the caller brings them (kinesweep info/query pass
  /// cli::v1_column_roles). Called with the columns in file order, after every (re)open of a v1 file.
  using V1ColumnRoles = std::function<void(std::vector<ColumnSpec>&)>;

  /// Opens a results file of format kOldestReadableFormatVersion .. kFormatVersion. Without
  /// `v1_roles`, the columns of a version 1 file keep the ColumnSpec defaults (bookkeeping, kinds "").
  explicit ResultsReader(const std::string& path, V1ColumnRoles v1_roles = {});
  ~ResultsReader();
  /// Close and reopen, to see the runs committed since the open.
  ///
  /// Reading while a writer runs: the reader opens between two commits, but the writer keeps
  /// committing, and HDF5 reads metadata lazily, so a long-lived reader may mix two committed
  /// states: a read may then throw StoreError (HDF5's checksums catch most mixtures) or miss the
  /// newest runs' histories. Everything read is trustworthy when unchanged_since_open() is still
  /// true after the reads; otherwise refresh() and read again.
  void refresh();
  /// True when no commit happened since the open (so all reads so far saw one committed state).
  bool unchanged_since_open() const;
  ResultsReader(const ResultsReader&) = delete;
  ResultsReader& operator=(const ResultsReader&) = delete;

  const StoreMeta& meta() const;
  const std::vector<ColumnSpec>& columns() const;  ///< schema order, with role and kinds
  std::int64_t n_runs() const;
  /// Reads of /runs take all rows, or `count` rows from `first` (clamped to n_runs), so a caller
  /// can stream a large file in pieces of bounded memory.
  static constexpr std::int64_t kAll = std::numeric_limits<std::int64_t>::max();
  std::vector<std::uint8_t> done_mask(std::int64_t first = 0, std::int64_t count = kAll) const;
  std::vector<Cell> read_column(const std::string& name) const;
  std::vector<double> read_f64(const std::string& name, std::int64_t first = 0, std::int64_t count = kAll) const;
  std::vector<std::int64_t> read_i64(const std::string& name, std::int64_t first = 0, std::int64_t count = kAll) const;
  std::vector<std::string> read_str(const std::string& name, std::int64_t first = 0, std::int64_t count = kAll) const;
  /// Rows `first` .. `first + count` (clamped), every column in schema order.
  std::vector<Record> read_rows(std::int64_t first, std::int64_t count) const;
  /// The rows of `ids` (ascending run ids), every column in schema order (one read per column).
  std::vector<Record> read_rows(const std::vector<std::int64_t>& ids) const;
  Record read_record(std::int64_t run_id) const;
  bool has_history(std::int64_t run_id) const;
  bool has_histories() const;  ///< whether any run has a history
  RunHistory read_history(std::int64_t run_id) const;  ///< empty when the run has none
  /// The run's history as the file stores it, chunks undecoded (for copying runs between files:
  /// ResultsWriter::write_run stores them without decompressing when the chunk sizes agree). Empty
  /// when the run has none. Format 3 files; older ones are read and encoded at `level`.
  EncodedHistory read_history_chunks(std::int64_t run_id, int level = 1) const;
  std::vector<std::string> landscapes() const;
  /// The blocks run as a Saltelli design (/designs; empty in files without one) (designs.cpp).
  std::vector<DesignMeta> designs() const;
  /// A block's landscape: its axes and metrics, with every metric's grid, or (`grids` false) with
  /// their names, units and descriptions only (grid vectors empty).
  LandscapeSpec read_landscape(const std::string& block, bool grids = true) const;
  /// Names of the groups under /optimizations (empty when none), and one of them (optimizations_read.cpp).
  std::vector<std::string> optimizations() const;
  OptimizationRecord read_optimization(const std::string& name) const;
  /// The /verification table (verification.cpp); no rows when the file has none.
  VerificationTable read_verification() const;
  /// The /sensitivity table (sensitivity.cpp); no rows when the file has none.
  SensitivityTable read_sensitivity() const;

 private:
  friend class ResultsWriter;                ///< copy_runs reads a source's chunks as stored
  std::int64_t raw_file_id() const;          ///< the open HDF5 file id (reader.cpp)
  /// True when the file's bytes on disk are its committed state (no commit waits in its journal),
  /// so that its raw data may be copied by file offset.
  bool bytes_are_committed_state() const;
  const std::string& raw_path() const;       ///< the file's path (reader.cpp)
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ------------------------------------------------------------------------------------------------
// A results file built beside the one it replaces (resume of an edited study, FORMAT.md "Creation,
// overwrite, resume").

/// A path beside `path` to build its replacement under: `.<name>.tmp-<pid>-staged-<n>.h5`, a name the
/// store deletes (with its journal) as an orphan once process <pid> is gone. Deletes such orphans of
/// killed processes first.
std::string staging_path(const std::string& path);
/// Replace the results file `path` by the closed results file `from` (an atomic rename), holding
/// `path`'s writer lock meanwhile (a live writer of `path` refuses it: StoreError, both files kept)
/// and deleting the journal a crashed writer of `path` left. Throws StoreError.
void replace_results_file(const std::string& from, const std::string& path, const StoreOptions& options = {});
/// Delete a closed results file and its journal (a staged file given up). Errors are ignored.
void remove_results_file(const std::string& path);

/// The git commit of the program that writes results files, recorded in every new file's root
/// attribute `engine_commit` (the kinesweep executable sets it once at startup, from its build;
/// not set: the attribute is not written).
void set_engine_commit(std::string commit);

/// Name of run `run_id`'s group under /histories in format 2 files ("000123"; wider when n_runs needs it).
std::string history_group_name(std::int64_t run_id, std::int64_t n_runs);

}  // namespace ks::store
