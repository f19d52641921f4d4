// ResultsReader's histories (see store.hpp, FORMAT.md: "/histories"): format 3's shared datasets
// with their per-run index, and format 2's group per run.
#include <algorithm>

#include "store/h5util.hpp"
#include "store/reader_impl.hpp"
#include "store/store.hpp"

namespace ks::store {
using namespace detail;

namespace {

/// One run's entry in a format 3 file: its first row, rows, and its arrays' datasets (none when the
/// run has no history).
struct IndexEntry {
  hsize_t start = 0, rows = 0, chunk_rows = 0;
  std::vector<HistoryDataset*> datasets;
};

/// The cache of `file`'s /histories (made at the first call after an open).
HistoryIndexCache& cache_of(std::unique_ptr<HistoryIndexCache>& hist, hid_t file, const std::string& path) {
  if (hist) return *hist;
  auto c = std::make_unique<HistoryIndexCache>();
  if (link_exists(file, "histories/start")) {
    c->present = true;
    c->group = Hid(check(H5Gopen2(file, "histories", H5P_DEFAULT), path, "open /histories"));
    c->start = Hid(check(H5Dopen2(c->group, "start", H5P_DEFAULT), path, "open /histories/start"));
    c->rows = Hid(check(H5Dopen2(c->group, "rows", H5P_DEFAULT), path, "open /histories/rows"));
    c->layout = Hid(check(H5Dopen2(c->group, "layout", H5P_DEFAULT), path, "open /histories/layout"));
    for (const auto& l : read_str_list_attr(c->group, "layouts")) c->layouts.push_back(split_layout(l));
    const std::int64_t C = read_i64_attr(c->group, "chunk_rows", 0);
    if (C <= 0) throw StoreError(path, "/histories has no valid attribute chunk_rows (" + std::to_string(C) + ")");
    c->chunk_rows = static_cast<hsize_t>(C);
  }
  hist = std::move(c);
  return *hist;
}

/// Values `first` .. `first + count` of index dataset `d` into `out`.
void read_index_block(const Hid& d, const char* name, std::int64_t first, std::int64_t count,
                      std::vector<std::int64_t>& out, const std::string& path) {
  out.resize(static_cast<std::size_t>(count));
  const hsize_t at = static_cast<hsize_t>(first), n = static_cast<hsize_t>(count);
  Hid fs(H5Dget_space(d));
  Hid ms(H5Screate_simple(1, &n, nullptr));
  if (H5Sselect_hyperslab(fs, H5S_SELECT_SET, &at, nullptr, &n, nullptr) < 0 ||
      H5Dread(d, H5T_NATIVE_INT64, ms, fs, H5P_DEFAULT, out.data()) < 0)
    throw StoreError(path, std::string("cannot read /histories/") + name + ": " + h5_error_text());
}

/// The run's index entry (reading the index a block of runs at a time) and its datasets (opened once
/// per open of the file).
IndexEntry index_entry(HistoryIndexCache& c, std::int64_t id, std::int64_t n_runs, const std::string& path) {
  IndexEntry e;
  if (!c.present) return e;
  if (c.block_first < 0 || id < c.block_first || id >= c.block_first + static_cast<std::int64_t>(c.block_layout.size())) {
    const std::int64_t first = id / HistoryIndexCache::kBlock * HistoryIndexCache::kBlock;
    const std::int64_t count = std::min(HistoryIndexCache::kBlock, n_runs - first);
    c.block_first = -1;
    read_index_block(c.start, "start", first, count, c.block_start, path);
    read_index_block(c.rows, "rows", first, count, c.block_rows, path);
    read_index_block(c.layout, "layout", first, count, c.block_layout, path);
    c.block_first = first;
  }
  const std::size_t k = static_cast<std::size_t>(id - c.block_first);
  const std::int64_t layout = c.block_layout[k], start = c.block_start[k], rows = c.block_rows[k];
  if (layout < 0) return e;
  if (start < 0 || rows < 0 || static_cast<std::size_t>(layout) >= c.layouts.size())
    throw StoreError(path, "/histories index of run " + std::to_string(id) + " is inconsistent (start " +
                               std::to_string(start) + ", rows " + std::to_string(rows) + ", layout " +
                               std::to_string(layout) + ")");
  e.start = static_cast<hsize_t>(start);
  e.rows = static_cast<hsize_t>(rows);
  e.chunk_rows = c.chunk_rows;
  for (const auto& name : c.layouts[static_cast<std::size_t>(layout)]) {
    auto it = std::find_if(c.datasets.begin(), c.datasets.end(), [&](const HistoryDataset& d) { return d.name == name; });
    if (it == c.datasets.end()) {
      c.datasets.push_back(open_history_dataset(c.group, name, path));
      it = c.datasets.end() - 1;
    }
    e.datasets.push_back(&*it);
  }
  return e;
}

/// Throws StoreError naming /histories/<dataset> unless the run's rows [start, start + rows) lie
/// inside dataset `d` (a damaged index would read other runs' rows or past the end).
void check_rows(const HistoryDataset& d, const IndexEntry& e, std::int64_t run_id, const std::string& path) {
  if (d.cols == 0) return;  // an array of no columns: a fixed (0 x 0) dataset
  Hid s(H5Dget_space(d.dset));
  hsize_t dims[2] = {0, 0};
  if (H5Sget_simple_extent_dims(s, dims, nullptr) < 1 || e.start > dims[0] || e.rows > dims[0] - e.start)
    throw StoreError(path, "/histories/" + d.name + ": run " + std::to_string(run_id) + "'s rows [" +
                               std::to_string(e.start) + ", " + std::to_string(e.start + e.rows) + ") lie outside its " +
                               std::to_string(dims[0]) + " rows (/histories/start, rows)");
}

RunHistory read_v2(hid_t file, std::int64_t run_id, std::int64_t n_runs, const std::string& path) {
  RunHistory h;
  const std::string g = "histories/" + history_group_name(run_id, n_runs);
  if (!link_exists(file, g)) return h;
  Hid grp(check(H5Gopen2(file, g.c_str(), H5P_DEFAULT), path, "open /" + g));
  for (auto& name : read_str_list_attr(grp, "arrays")) {
    Hid d(check(H5Dopen2(grp, name.c_str(), H5P_DEFAULT), path, "open /" + g + "/" + name));
    Hid s(H5Dget_space(d));
    hsize_t dims[2] = {0, 1};
    int rank = H5Sget_simple_extent_dims(s, dims, nullptr);
    HistoryArray a;
    a.name = name;
    a.unit = read_str_attr(d, "unit");
    a.rows = rank >= 1 ? dims[0] : 1;
    a.cols = rank >= 2 ? dims[1] : 1;
    a.data.resize(a.rows * a.cols);
    if (!a.data.empty())
      check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.data.data()), path, "read /" + g + "/" + name);
    h.arrays.push_back(std::move(a));
  }
  return h;
}
}  // namespace

bool ResultsReader::has_history(std::int64_t run_id) const {
  QuietHdf5 quiet;
  Impl& r = *impl_;
  if (r.meta.format_version <= 2) return link_exists(r.file, "histories/" + history_group_name(run_id, r.n_runs));
  if (run_id < 0 || run_id >= r.n_runs) return false;
  return !index_entry(cache_of(r.hist, r.file, r.path), run_id, r.n_runs, r.path).datasets.empty();
}

bool ResultsReader::has_histories() const {
  QuietHdf5 quiet;
  Impl& r = *impl_;
  if (r.meta.format_version <= 2) {  // one group per run's history
    H5G_info_t info;
    return link_exists(r.file, "histories") && H5Gget_info_by_name(r.file, "histories", &info, H5P_DEFAULT) >= 0 &&
           info.nlinks > 0;
  }
  return link_exists(r.file, "histories/start");  // the index, created with the first history
}

RunHistory ResultsReader::read_history(std::int64_t run_id) const {
  QuietHdf5 quiet;
  Impl& r = *impl_;
  if (r.meta.format_version <= 2) return read_v2(r.file, run_id, r.n_runs, r.path);
  RunHistory h;
  if (run_id < 0 || run_id >= r.n_runs) return h;
  const IndexEntry e = index_entry(cache_of(r.hist, r.file, r.path), run_id, r.n_runs, r.path);
  for (const HistoryDataset* d : e.datasets) {
    check_rows(*d, e, run_id, r.path);
    HistoryArray a{d->array, d->unit, e.rows, d->cols, std::vector<double>(e.rows * d->cols)};
    if (!a.data.empty()) {
      Hid fs(H5Dget_space(d->dset));
      const hsize_t first[2] = {e.start, 0}, count[2] = {e.rows, d->cols};
      Hid ms(H5Screate_simple(2, count, nullptr));
      if (H5Sselect_hyperslab(fs, H5S_SELECT_SET, first, nullptr, count, nullptr) < 0 ||
          H5Dread(d->dset, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, a.data.data()) < 0)
        throw StoreError(r.path, "cannot read /histories/" + d->name + " of run " + std::to_string(run_id) + ": " +
                                     h5_error_text());
    }
    h.arrays.push_back(std::move(a));
  }
  return h;
}

EncodedHistory ResultsReader::read_history_chunks(std::int64_t run_id, int level) const {
  QuietHdf5 quiet;
  Impl& r = *impl_;
  if (r.meta.format_version <= 2) {
    const RunHistory h = read_v2(r.file, run_id, r.n_runs, r.path);
    return h.arrays.empty() ? EncodedHistory{} : encode_history(h, level);
  }
  EncodedHistory out;
  if (run_id < 0 || run_id >= r.n_runs) return out;
  const IndexEntry e = index_entry(cache_of(r.hist, r.file, r.path), run_id, r.n_runs, r.path);
  for (const HistoryDataset* d : e.datasets) {
    check_rows(*d, e, run_id, r.path);
    EncodedArray a;
    a.name = d->array; a.unit = d->unit; a.rows = e.rows; a.cols = d->cols;
    a.chunk_rows = e.rows == 0 ? 0 : e.chunk_rows;
    a.level = level;
    if (d->cols > 0)
      for (hsize_t row = 0; row < e.rows; row += e.chunk_rows) {
        hsize_t offset[2] = {e.start + row, 0}, size = 0;
        EncodedChunk c;
        if (H5Dget_chunk_storage_size(d->dset, offset, &size) < 0 || size == 0)
          throw StoreError(r.path, "run " + std::to_string(run_id) + ": /histories/" + d->name +
                                       " has no chunk at row " + std::to_string(offset[0]));
        c.bytes.resize(size);
        if (H5Dread_chunk(d->dset, H5P_DEFAULT, offset, &c.filter_mask, c.bytes.data()) < 0)
          throw StoreError(r.path, "cannot read a chunk of /histories/" + d->name + ": " + h5_error_text());
        a.chunks.push_back(std::move(c));
      }
    out.arrays.push_back(std::move(a));
  }
  return out;
}

}  // namespace ks::store
