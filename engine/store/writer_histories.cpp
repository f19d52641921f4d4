// ResultsWriter's histories (see store.hpp, FORMAT.md: "/histories"): every run's arrays go into
// datasets shared by all runs, one per array, at a chunk-aligned start in one row space, with a
// per-run index. The chunks come encoded from the worker threads (history_codec.cpp): the writer
// thread creates no per-run object and compresses nothing.
#include <hdf5_hl.h>  // H5DS: dimension scales

#include <algorithm>
#include <limits>
#include <set>

#include "store/h5util.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

std::string history_group_name(std::int64_t run_id, std::int64_t n_runs) {
  std::size_t width = 6;
  std::string last = std::to_string(n_runs > 0 ? n_runs - 1 : 0);
  width = std::max(width, last.size());
  std::string s = std::to_string(run_id);
  if (s.size() < width) s = std::string(width - s.size(), '0') + s;
  return s;
}

namespace {
constexpr const char* kIndex[] = {"start", "rows", "layout"};

/// Rows per chunk for a file whose first history comes in chunks of `rows` rows (a new run: all
/// its rows, so runs like it fill their chunk exactly; a copied run: its file's chunk size) of at
/// most `cols` columns: at least 64, at most what keeps a chunk of the widest array under 4 MiB.
std::size_t choose_chunk_rows(std::size_t rows, std::size_t cols) {
  const std::size_t cap = std::max<std::size_t>(64, (std::size_t{4} << 20) / (8 * std::max<std::size_t>(cols, 1)));
  return std::clamp<std::size_t>(rows, 64, cap);
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}
}  // namespace

std::size_t ResultsWriter::history_chunk_rows() const { return impl_->hist.chunk_rows.load(std::memory_order_acquire); }

void ResultsWriter::Impl::open_histories() {
  Histories& h = hist;
  h.chunk_rows = static_cast<std::size_t>(std::max<std::int64_t>(0, read_i64_attr(histories, "chunk_rows", 0)));
  h.used_rows = h.written_used_rows = static_cast<hsize_t>(std::max<std::int64_t>(0, read_i64_attr(histories, "used_rows", 0)));
  if (!link_exists(histories, "start")) return;
  h.start = Hid(check(H5Dopen2(histories, "start", H5P_DEFAULT), path, "open /histories/start"));
  h.rows = Hid(check(H5Dopen2(histories, "rows", H5P_DEFAULT), path, "open /histories/rows"));
  h.layout = Hid(check(H5Dopen2(histories, "layout", H5P_DEFAULT), path, "open /histories/layout"));
  h.layouts = read_str_list_attr(histories, "layouts");
  std::set<std::string> names;
  for (const auto& l : h.layouts)
    for (auto& n : split_layout(l)) names.insert(std::move(n));
  for (const auto& n : names) h.datasets.push_back(open_history_dataset(histories, n, path));
}

void ResultsWriter::Impl::write_history(std::int64_t id, const EncodedHistory& given) {
  Histories& h = hist;
  if (given.arrays.empty()) {  // a run without history (a rewrite may replace one that had)
    if (h.start.ok()) h.pending[id] = HistoryIndexEntry{};
    return;
  }
  std::vector<std::string> names;
  std::size_t max_cols = 0;
  for (const auto& a : given.arrays) {
    validate_name(path, a.name, "history array");
    if (a.name.find(',') != std::string::npos)
      throw StoreError(path, "invalid history array name '" + a.name + "' (contains ',')");
    if (std::find(names.begin(), names.end(), a.name) != names.end())
      throw StoreError(path, "duplicate history array '" + a.name + "' in run " + std::to_string(id));
    if (a.rows != given.arrays.front().rows)
      throw StoreError(path, "run " + std::to_string(id) + ": history arrays of different row counts");
    names.push_back(a.name);
    max_cols = std::max(max_cols, a.cols);
  }
  const std::size_t rows = given.arrays.front().rows;
  if (h.chunk_rows == 0) {  // the first history's chunks (a copied run's: the source file's C)
    const std::size_t given_rows = given.arrays.front().chunk_rows ? given.arrays.front().chunk_rows : rows;
    h.chunk_rows.store(choose_chunk_rows(given_rows, max_cols), std::memory_order_release);
    write_i64_attr(histories, "chunk_rows", static_cast<std::int64_t>(h.chunk_rows));
  }
  const std::size_t C = h.chunk_rows;
  // Chunks cut to another size (encoded before the chunk size was known) are re-cut here.
  EncodedHistory recut;
  const EncodedHistory* enc = &given;
  for (const auto& a : given.arrays)
    if (a.rows > 0 && a.chunk_rows != C) {
      recut = encode_history(decode_history(given), given.arrays.front().level, C);
      enc = &recut;
      break;
    }
  if (!h.start.ok()) {  // the index datasets, at the first history (FORMAT.md: /histories)
    hsize_t n = static_cast<hsize_t>(n_runs);
    Hid space(H5Screate_simple(1, &n, nullptr));
    const std::int64_t fills[] = {-1, 0, -1};
    Hid* dsets[] = {&h.start, &h.rows, &h.layout};
    for (int k = 0; k < 3; ++k) {
      Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
      H5Pset_layout(dcpl, H5D_CONTIGUOUS);
      H5Pset_alloc_time(dcpl, H5D_ALLOC_TIME_EARLY);
      H5Pset_fill_time(dcpl, H5D_FILL_TIME_ALLOC);
      H5Pset_fill_value(dcpl, H5T_NATIVE_INT64, &fills[k]);
      *dsets[k] = Hid(check(H5Dcreate2(histories, kIndex[k], H5T_STD_I64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT),
                            path, std::string("create /histories/") + kIndex[k]));
    }
    // their netCDF dimension: one per run (/runs' run ids), named run_id
    Hid run_dim(netcdf_dimension(histories, "run_id", n));
    for (Hid* d : dsets)
      if (!run_dim.ok() || H5DSattach_scale(*d, run_dim, 0) < 0) fail("cannot name the dimension of the /histories index");
    write_str_attr(h.start, "description", "first row of the run's history in every history dataset (-1: none)");
    write_str_attr(h.rows, "description", "rows of the run's history");
    write_str_attr(h.layout, "description", "index into the attribute layouts of /histories (-1: none)");
  }
  // The datasets of this run's arrays: by array name, column count and unit (a trajectory's q in
  // rad and a SCARA IK run's in rad, rad, mm are two datasets).
  std::vector<HistoryDataset*> targets;
  std::vector<std::string> dnames;
  const auto taken = [&](const std::string& n) {
    return std::any_of(h.datasets.begin(), h.datasets.end(), [&](const HistoryDataset& d) { return d.name == n; }) ||
           n == "start" || n == "rows" || n == "layout" || n == "run_id" || n == "history_row" ||
           link_exists(histories, n) || link_exists(histories, n + "_column");
  };
  for (const auto& a : enc->arrays) {
    HistoryDataset* found = nullptr;
    for (auto& d : h.datasets)
      if (d.array == a.name && d.cols == a.cols && d.unit == a.unit) found = &d;
    if (!found) {
      HistoryDataset d;
      d.array = a.name;
      d.cols = a.cols;
      d.unit = a.unit;
      d.name = a.name;
      for (int k = 2; taken(d.name); ++k) d.name = a.name + "." + std::to_string(k);
      hsize_t dims[2] = {0, a.cols}, maxdims[2] = {H5S_UNLIMITED, a.cols};
      Hid space(H5Screate_simple(2, dims, a.cols > 0 ? maxdims : nullptr));
      Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
      hsize_t chunk[2] = {C, a.cols};
      if (a.cols > 0) {  // an array of no columns holds nothing: a fixed empty dataset
        H5Pset_chunk(dcpl, 2, chunk);
        H5Pset_shuffle(dcpl);
        H5Pset_deflate(dcpl, 1);
      }
      const double nan = std::numeric_limits<double>::quiet_NaN();
      H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &nan);
      d.dset = Hid(H5Dcreate2(histories, d.name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT));
      if (!d.dset.ok()) fail("cannot create /histories/" + d.name);
      write_str_attr(d.dset, "unit", a.unit);
      write_cf_units(d.dset, a.unit, a.cols);
      write_str_attr(d.dset, "array", a.name);
      // netCDF dimensions: the shared rows (history_row) and the dataset's columns (<name>_column)
      if (!h.row_dim.ok()) {
        h.row_dim = Hid(netcdf_dimension(histories, "history_row", 0, true));
        Hid rs(h.row_dim.ok() ? H5Dget_space(h.row_dim) : -1);
        if (rs.ok()) H5Sget_simple_extent_dims(rs, &h.row_dim_extent, nullptr);
      }
      Hid col_dim(netcdf_dimension(histories, d.name + "_column", a.cols));
      if (!h.row_dim.ok() || !col_dim.ok() || H5DSattach_scale(d.dset, h.row_dim, 0) < 0 ||
          H5DSattach_scale(d.dset, col_dim, 1) < 0)
        fail("cannot name the dimensions of /histories/" + d.name);
      h.datasets.push_back(std::move(d));
    }
    dnames.push_back(found ? found->name : h.datasets.back().name);
  }
  for (const auto& dn : dnames)
    for (auto& d : h.datasets)
      if (d.name == dn) targets.push_back(&d);
  const std::string layout = join(dnames);
  auto li = std::find(h.layouts.begin(), h.layouts.end(), layout);
  if (li == h.layouts.end()) {
    h.layouts.push_back(layout);
    h.layouts_dirty = true;
    li = h.layouts.end() - 1;
  }
  // The run's place: the next chunk boundary; its chunks, written as they are.
  const hsize_t start = h.used_rows;
  const hsize_t span = (rows + C - 1) / C * C;
  for (std::size_t k = 0; k < enc->arrays.size(); ++k) {
    const EncodedArray& a = enc->arrays[k];
    HistoryDataset& d = *targets[k];
    if (a.chunks.empty() || d.cols == 0) continue;
    if (d.extent < start + span) {
      hsize_t grow[2] = {std::max<hsize_t>(start + span, std::min<hsize_t>(2 * d.extent, d.extent + (hsize_t{1} << 24))),
                         d.cols};
      grow[0] = std::max<hsize_t>(grow[0], 64 * C);
      if (H5Dset_extent(d.dset, grow) < 0) fail("cannot extend /histories/" + d.name);
      d.extent = grow[0];
      if (h.row_dim.ok() && h.row_dim_extent < d.extent) {  // the dimension spans its longest dataset
        if (H5Dset_extent(h.row_dim, &d.extent) < 0) fail("cannot extend /histories/history_row");
        h.row_dim_extent = d.extent;
      }
    }
    for (std::size_t c = 0; c < a.chunks.size(); ++c) {
      hsize_t offset[2] = {start + c * C, 0};
      if (H5Dwrite_chunk(d.dset, H5P_DEFAULT, a.chunks[c].filter_mask, offset, a.chunks[c].bytes.size(),
                         a.chunks[c].bytes.data()) < 0)
        fail("cannot write /histories/" + d.name + " for run " + std::to_string(id));
    }
  }
  h.used_rows = start + span;
  h.pending[id] = HistoryIndexEntry{static_cast<std::int64_t>(start), static_cast<std::int64_t>(rows),
                                    static_cast<std::int64_t>(li - h.layouts.begin())};
}

void ResultsWriter::Impl::write_history_index() {
  Histories& h = hist;
  if (h.layouts_dirty) {
    write_str_list_attr(histories, "layouts", h.layouts);
    h.layouts_dirty = false;
  }
  if (h.used_rows != h.written_used_rows) {
    write_i64_attr(histories, "used_rows", static_cast<std::int64_t>(h.used_rows));
    h.written_used_rows = h.used_rows;
  }
  if (h.pending.empty()) return;
  std::vector<hsize_t> ids;
  std::vector<std::int64_t> v[3];
  for (auto& [id, e] : h.pending) {
    ids.push_back(static_cast<hsize_t>(id));
    v[0].push_back(e.start);
    v[1].push_back(e.rows);
    v[2].push_back(e.layout);
  }
  hsize_t k = ids.size();
  Hid mspace(H5Screate_simple(1, &k, nullptr));
  const Hid* dsets[] = {&h.start, &h.rows, &h.layout};
  for (int i = 0; i < 3; ++i) {
    Hid fs = select_rows(*dsets[i], ids);
    if (fs.get() < 0 || H5Dwrite(*dsets[i], H5T_NATIVE_INT64, mspace, fs, H5P_DEFAULT, v[i].data()) < 0)
      fail(std::string("cannot write /histories/") + kIndex[i]);
  }
  uncommitted_bytes += ids.size() * 3 * sizeof(std::int64_t);  // journaled until the commit, like the rows
  h.pending.clear();
}

void ResultsWriter::Impl::trim_histories() {
  // every dataset (and the dimension history_row) to used_rows: one row space, of one length
  for (auto& d : hist.datasets)
    if (d.cols > 0 && d.extent != hist.used_rows) {
      hsize_t dims[2] = {hist.used_rows, d.cols};
      if (H5Dset_extent(d.dset, dims) < 0) fail("cannot trim /histories/" + d.name);
      d.extent = hist.used_rows;
    }
  if (hist.row_dim.ok() && hist.row_dim_extent != hist.used_rows) {
    if (H5Dset_extent(hist.row_dim, &hist.used_rows) < 0) fail("cannot trim /histories/history_row");
    hist.row_dim_extent = hist.used_rows;
  }
}

}  // namespace ks::store
