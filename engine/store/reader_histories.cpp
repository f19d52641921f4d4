// ResultsReader's histories (see store.hpp, FORMAT.md: "/histories"): format 3's shared datasets
// with their per-run index, and format 2's group per run.
#include <algorithm>

#include "store/h5util.hpp"
#include "store/store.hpp"

namespace ks::store {
using namespace detail;

namespace {

/// One run's entry in a format 3 file: its first row, rows, and its arrays' dataset names
/// (no datasets when the run has no history).
struct IndexEntry {
  hsize_t start = 0, rows = 0, chunk_rows = 0;
  std::vector<std::string> datasets;
};

std::int64_t read_index(hid_t histories, const char* name, std::int64_t id, const std::string& path) {
  Hid d(check(H5Dopen2(histories, name, H5P_DEFAULT), path, std::string("open /histories/") + name));
  Hid fs(H5Dget_space(d));
  const hsize_t at = static_cast<hsize_t>(id), one = 1;
  std::int64_t v = -1;
  Hid ms(H5Screate_simple(1, &one, nullptr));
  if (H5Sselect_hyperslab(fs, H5S_SELECT_SET, &at, nullptr, &one, nullptr) < 0 ||
      H5Dread(d, H5T_NATIVE_INT64, ms, fs, H5P_DEFAULT, &v) < 0)
    throw StoreError(path, std::string("cannot read /histories/") + name + ": " + h5_error_text());
  return v;
}

IndexEntry index_entry(hid_t file, std::int64_t id, const std::string& path) {
  IndexEntry e;
  if (!link_exists(file, "histories/start")) return e;
  Hid h(check(H5Gopen2(file, "histories", H5P_DEFAULT), path, "open /histories"));
  const std::int64_t layout = read_index(h, "layout", id, path);
  if (layout < 0) return e;
  const std::int64_t start = read_index(h, "start", id, path), rows = read_index(h, "rows", id, path);
  const std::vector<std::string> layouts = read_str_list_attr(h, "layouts");
  const std::int64_t C = read_i64_attr(h, "chunk_rows", 0);
  if (start < 0 || rows < 0 || C <= 0 || static_cast<std::size_t>(layout) >= layouts.size())
    throw StoreError(path, "/histories index of run " + std::to_string(id) + " is inconsistent (start " +
                               std::to_string(start) + ", rows " + std::to_string(rows) + ", layout " +
                               std::to_string(layout) + ", chunk_rows " + std::to_string(C) + ")");
  e.start = static_cast<hsize_t>(start);
  e.rows = static_cast<hsize_t>(rows);
  e.chunk_rows = static_cast<hsize_t>(C);
  const std::string& l = layouts[static_cast<std::size_t>(layout)];
  for (std::size_t at = 0; at < l.size();) {
    const std::size_t comma = std::min(l.find(',', at), l.size());
    e.datasets.push_back(l.substr(at, comma - at));
    at = comma + 1;
  }
  return e;
}

/// A format 3 dataset of the run: its array name, unit and columns.
struct Opened {
  Hid d;
  std::string array, unit;
  hsize_t cols = 0;
};
Opened open_dataset(hid_t file, const std::string& name, const std::string& path) {
  Opened o;
  const std::string p = "histories/" + name;
  o.d = Hid(check(H5Dopen2(file, p.c_str(), H5P_DEFAULT), path, "open /" + p));
  o.array = read_str_attr(o.d, "array");
  o.unit = read_str_attr(o.d, "unit");
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(Hid(H5Dget_space(o.d)), dims, nullptr);
  o.cols = dims[1];
  return o;
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
  const hid_t file = static_cast<hid_t>(raw_file_id());
  if (meta().format_version <= 2) return link_exists(file, "histories/" + history_group_name(run_id, n_runs()));
  if (run_id < 0 || run_id >= n_runs()) return false;
  return !index_entry(file, run_id, raw_path()).datasets.empty();
}

RunHistory ResultsReader::read_history(std::int64_t run_id) const {
  QuietHdf5 quiet;
  const hid_t file = static_cast<hid_t>(raw_file_id());
  const std::string& path = raw_path();
  if (meta().format_version <= 2) return read_v2(file, run_id, n_runs(), path);
  RunHistory h;
  if (run_id < 0 || run_id >= n_runs()) return h;
  const IndexEntry e = index_entry(file, run_id, path);
  for (const auto& name : e.datasets) {
    Opened o = open_dataset(file, name, path);
    HistoryArray a{o.array, o.unit, e.rows, o.cols, std::vector<double>(e.rows * o.cols)};
    if (!a.data.empty()) {
      Hid fs(H5Dget_space(o.d));
      const hsize_t first[2] = {e.start, 0}, count[2] = {e.rows, o.cols};
      Hid ms(H5Screate_simple(2, count, nullptr));
      if (H5Sselect_hyperslab(fs, H5S_SELECT_SET, first, nullptr, count, nullptr) < 0 ||
          H5Dread(o.d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, a.data.data()) < 0)
        throw StoreError(path, "cannot read /histories/" + name + " of run " + std::to_string(run_id) + ": " +
                                   h5_error_text());
    }
    h.arrays.push_back(std::move(a));
  }
  return h;
}

EncodedHistory ResultsReader::read_history_chunks(std::int64_t run_id, int level) const {
  QuietHdf5 quiet;
  const hid_t file = static_cast<hid_t>(raw_file_id());
  const std::string& path = raw_path();
  if (meta().format_version <= 2) {
    const RunHistory h = read_v2(file, run_id, n_runs(), path);
    return h.arrays.empty() ? EncodedHistory{} : encode_history(h, level);
  }
  EncodedHistory out;
  if (run_id < 0 || run_id >= n_runs()) return out;
  const IndexEntry e = index_entry(file, run_id, path);
  for (const auto& name : e.datasets) {
    Opened o = open_dataset(file, name, path);
    EncodedArray a;
    a.name = o.array; a.unit = o.unit; a.rows = e.rows; a.cols = o.cols;
    a.chunk_rows = e.rows == 0 ? 0 : e.chunk_rows;
    a.level = level;
    if (o.cols > 0)
      for (hsize_t r = 0; r < e.rows; r += e.chunk_rows) {
        hsize_t offset[2] = {e.start + r, 0}, size = 0;
        EncodedChunk c;
        if (H5Dget_chunk_storage_size(o.d, offset, &size) < 0 || size == 0)
          throw StoreError(path, "run " + std::to_string(run_id) + ": /histories/" + name + " has no chunk at row " +
                                     std::to_string(offset[0]));
        c.bytes.resize(size);
        if (H5Dread_chunk(o.d, H5P_DEFAULT, offset, &c.filter_mask, c.bytes.data()) < 0)
          throw StoreError(path, "cannot read a chunk of /histories/" + name + ": " + h5_error_text());
        a.chunks.push_back(std::move(c));
      }
    out.arrays.push_back(std::move(a));
  }
  return out;
}

}  // namespace ks::store
