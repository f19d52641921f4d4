// ResultsWriter's landscapes (store.hpp, FORMAT.md "/landscapes"): the group, its axes as dimension
// scales, and metric datasets whose cells are streamed in with the rows of their runs.
#include <hdf5_hl.h>  // H5DS: dimension scales
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <numeric>
#include <set>

#include "store/grid_blocks.hpp"
#include "store/h5util.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

namespace {
constexpr std::size_t kPendingCells = 1 << 16;  // cells held before they are written (rows: kRowBatch)

/// `bytes` of file `in` at `from` copied to file `out` at `to` inside the kernel (copy_file_range:
/// no pass through this process's memory). False, nothing copied, when the kernel cannot copy
/// between these files; StoreError (`path`) on a failure part way.
bool kernel_copy(int in, std::uint64_t from, int out, std::uint64_t to, std::uint64_t bytes, const std::string& path) {
  auto a = static_cast<loff_t>(from), b = static_cast<loff_t>(to);
  bool first = true;
  while (bytes > 0) {
    const ssize_t n = ::copy_file_range(in, &a, out, &b, static_cast<std::size_t>(bytes), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (first && n < 0 && (errno == EXDEV || errno == EINVAL || errno == ENOSYS || errno == EOPNOTSUPP || errno == EBADF))
        return false;
      throw StoreError(path, std::string("cannot copy landscape cells: ") + (n < 0 ? std::strerror(errno) : "short copy"));
    }
    first = false;
    bytes -= static_cast<std::uint64_t>(n);
  }
  return true;
}

/// The stream of begun landscape `landscape` of `m` and its number of cells; StoreError naming `call`.
std::pair<ResultsWriter::Impl::LandscapeStream*, hsize_t> begun_stream(ResultsWriter::Impl& m, std::size_t landscape,
                                                                      const char* call) {
  if (landscape >= m.landscape_streams.size() || m.landscape_streams[landscape].metrics.empty())
    throw StoreError(m.path, std::string(call) + ": no landscape " + std::to_string(landscape));
  ResultsWriter::Impl::LandscapeStream& s = m.landscape_streams[landscape];
  return {&s, std::accumulate(s.dims.begin(), s.dims.end(), hsize_t{1}, std::multiplies<>())};
}

/// The file type of a landscape metric: f64, or for a grid of codes (flags) int8 (int16 past 127 codes).
hid_t metric_file_type(const LandscapeMetric& mt) {
  if (mt.flags.empty()) return H5T_IEEE_F64LE;
  return mt.flags.size() <= 127 ? H5T_STD_I8LE : H5T_STD_I16LE;
}

/// CF flags of a grid of codes `mt.flags`: flag_values (0..n-1, in the grid's type), flag_meanings
/// (the names, blanks as '_') and _FillValue (-1: no run).
void write_code_flags(hid_t d, const LandscapeMetric& mt) {
  hsize_t n = mt.flags.size();
  std::vector<std::int16_t> codes(mt.flags.size());
  std::string meanings;
  for (std::size_t i = 0; i < mt.flags.size(); ++i) {
    codes[i] = static_cast<std::int16_t>(i);
    std::string name = mt.flags[i];
    std::replace(name.begin(), name.end(), ' ', '_');
    meanings += (i ? " " : "") + name;
  }
  Hid space(H5Screate_simple(1, &n, nullptr));
  Hid a(H5Acreate2(d, "flag_values", metric_file_type(mt), space, H5P_DEFAULT, H5P_DEFAULT));
  if (a.ok()) H5Awrite(a, H5T_NATIVE_INT16, codes.data());
  write_str_attr(d, "flag_meanings", meanings);
  const std::int16_t missing = -1;
  Hid scalar(H5Screate(H5S_SCALAR));
  Hid f(H5Acreate2(d, "_FillValue", metric_file_type(mt), scalar, H5P_DEFAULT, H5P_DEFAULT));
  if (f.ok()) H5Awrite(f, H5T_NATIVE_INT16, &missing);
}

/// The doubles of a 1-D dataset (empty when it cannot be read).
std::vector<double> read_doubles(hid_t d) {
  Hid space(H5Dget_space(d));
  const hssize_t n = space.ok() ? H5Sget_simple_extent_npoints(space) : -1;
  std::vector<double> v(n > 0 ? static_cast<std::size_t>(n) : 0);
  if (n <= 0 || H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0) v.clear();
  return v;
}

/// The metric datasets of the existing landscape `g` when it is the grid `spec` describes: the same
/// axes (names, units, values bit for bit) and metrics (names, units, descriptions), each metric an
/// f64 dataset of shape `dims`. Empty otherwise (and for a spec without metrics).
std::vector<Hid> same_grid_metrics(hid_t g, const LandscapeSpec& spec, const std::vector<hsize_t>& dims) {
  if (spec.metrics.empty()) return {};
  std::vector<std::string> names;
  for (auto& a : spec.axes) names.push_back(a.name);
  if (read_str_list_attr(g, "axes") != names) return {};
  const auto same_axis = [&](const LandscapeAxis& a) {
    Hid d(open_axis_dataset(g, a.name));
    if (!d.ok() || read_str_attr(d, "unit") != a.unit) return false;
    const std::vector<double> v = read_doubles(d);
    return v.size() == a.values.size() && std::memcmp(v.data(), a.values.data(), v.size() * sizeof(double)) == 0;
  };
  for (auto& a : spec.axes) {
    if (!same_axis(a)) return {};
    for (auto& c : a.coordinates)
      if (!same_axis(c)) return {};
  }
  names.clear();
  for (auto& mt : spec.metrics) names.push_back(mt.name);
  if (read_str_list_attr(g, "metrics") != names) return {};
  std::vector<Hid> metrics;
  for (auto& mt : spec.metrics) {
    Hid d(H5Dopen2(g, mt.name.c_str(), H5P_DEFAULT));
    if (!d.ok() || read_str_attr(d, "unit") != mt.unit || read_str_attr(d, "description") != mt.description) return {};
    Hid type(H5Dget_type(d)), space(H5Dget_space(d));
    if (!type.ok() || H5Tequal(type, metric_file_type(mt)) <= 0 || !space.ok()) return {};
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> shape(rank > 0 ? static_cast<std::size_t>(rank) : 0);
    if (rank < 0 || (rank > 0 && H5Sget_simple_extent_dims(space, shape.data(), nullptr) < 0) || shape != dims) return {};
    metrics.push_back(std::move(d));
  }
  return metrics;
}

/// CF flags of a categorical axis (its values the codes 0..n-1): flag_values, the codes, and
/// flag_meanings, each code's label (spaces as underscores), in place of units.
void write_label_axis_flags(hid_t d, const std::string& labels, std::size_t n) {
  std::string meanings, label;
  std::vector<double> codes;
  for (std::size_t i = 0; i <= labels.size(); ++i) {
    if (i < labels.size() && labels[i] != ',') {
      label += labels[i] == ' ' ? '_' : labels[i];
      continue;
    }
    meanings += (codes.empty() ? "" : " ") + label;
    codes.push_back(static_cast<double>(codes.size()));
    label.clear();
  }
  if (codes.size() != n) return;
  hsize_t len = n;
  Hid space(H5Screate_simple(1, &len, nullptr));
  Hid a(H5Acreate2(d, "flag_values", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT));
  if (a.ok()) H5Awrite(a, H5T_NATIVE_DOUBLE, codes.data());
  write_str_attr(d, "flag_meanings", meanings);
}

}  // namespace

std::size_t ResultsWriter::begin_landscape(const LandscapeSpec& spec) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  m.touched = true;
  validate_name(m.path, spec.block, "landscape block");
  std::vector<hsize_t> dims;
  std::set<std::string> names;
  std::vector<std::string> axis_names, metric_names;
  for (auto& a : spec.axes) {
    validate_name(m.path, a.name, "landscape axis");
    if (!names.insert(a.name).second) throw StoreError(m.path, "landscape " + spec.block + ": duplicate name " + a.name);
    if (a.values.empty()) throw StoreError(m.path, "landscape " + spec.block + ": axis " + a.name + " has no values");
    dims.push_back(a.values.size());
    axis_names.push_back(a.name);
    for (auto& c : a.coordinates) {
      validate_name(m.path, c.name, "landscape coordinate");
      if (!names.insert(c.name).second) throw StoreError(m.path, "landscape " + spec.block + ": duplicate name " + c.name);
      if (c.values.size() != a.values.size())
        throw StoreError(m.path, "landscape " + spec.block + ": coordinate " + c.name + " has " +
                                     std::to_string(c.values.size()) + " values along " + a.name + " of " +
                                     std::to_string(a.values.size()));
    }
  }
  for (auto& mt : spec.metrics) {
    validate_name(m.path, mt.name, "landscape metric");
    if (!names.insert(mt.name).second) throw StoreError(m.path, "landscape " + spec.block + ": duplicate name " + mt.name);
    metric_names.push_back(mt.name);
  }
  for (auto& s : m.landscape_streams)  // a landscape begun again (a re-run block) starts afresh
    if (s.block == spec.block) s = {};
  const bool exists = link_exists(m.landscapes, spec.block);
  if (exists && m.begun_landscapes.insert(spec.block).second) {
    // In the file before this writer (a resumed sweep): kept, cells and all, when it is this very
    // grid. Its cells are those of committed rows, which the sweep writes again. Replacing it would
    // give the new metrics the space the old ones free, in the committed part of the file, so that
    // their NaN fill (8 bytes a cell and metric) would wait in the journal's memory until the commit.
    Hid g(H5Gopen2(m.landscapes, spec.block.c_str(), H5P_DEFAULT));
    std::vector<Hid> metrics;
    if (g.ok()) {
      try {
        metrics = same_grid_metrics(g, spec, dims);
      } catch (const StoreError&) {  // an attribute that cannot be read: not this grid
        metrics.clear();
      }
    }
    H5Eclear2(H5E_DEFAULT);
    if (!metrics.empty()) {
      Impl::LandscapeStream stream;
      stream.block = spec.block;
      stream.dims = dims;
      stream.metrics = std::move(metrics);
      m.landscape_streams.push_back(std::move(stream));
      return m.landscape_streams.size() - 1;
    }
  }
  m.begun_landscapes.insert(spec.block);
  if (exists && H5Ldelete(m.landscapes, spec.block.c_str(), H5P_DEFAULT) < 0)
    m.fail("cannot replace /landscapes/" + spec.block);
  m.freed_space = m.freed_space || exists;
  Hid g(H5Gcreate2(m.landscapes, spec.block.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  if (!g.ok()) m.fail("cannot create /landscapes/" + spec.block);
  write_str_list_attr(g, "axes", axis_names);
  write_str_list_attr(g, "metrics", metric_names);
  // Each axis is an HDF5 dimension scale attached to its dimension of every metric, so that netCDF
  // readers (xarray with h5netcdf) see named dimensions with these values as coordinates.
  std::vector<Hid> axis_dsets;
  std::string coordinate_names;  // of every sampled dimension: the metrics' CF `coordinates`
  for (auto& a : spec.axes) {
    hsize_t n = a.values.size();
    Hid space(H5Screate_simple(1, &n, nullptr));
    const std::string dname = axis_dataset_name(a.name);
    Hid d(H5Dcreate2(g, dname.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    if (!d.ok() || H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.values.data()) < 0)
      m.fail("cannot write landscape axis " + a.name);
    write_str_attr(d, "unit", a.unit);
    write_cf_units(d, a.unit);  // CF units, which xarray's plots label axes with
    if (a.unit.rfind("labels:", 0) == 0) write_label_axis_flags(d, a.unit.substr(7), a.values.size());
    write_str_attr(d, "kind", "axis");
    if (H5DSset_scale(d, dname.c_str()) < 0) m.fail("cannot make landscape axis " + a.name + " a dimension scale");
    if (!a.coordinates.empty()) {
      // A sampled dimension: its index, and one CF auxiliary coordinate variable per parameter along it.
      std::vector<std::string> params;
      for (auto& c : a.coordinates) params.push_back(c.name);
      write_str_list_attr(d, "parameters", params);
      write_str_attr(d, "long_name", "sample index");
      for (auto& c : a.coordinates) {
        const std::string cname = axis_dataset_name(c.name);
        Hid cd(H5Dcreate2(g, cname.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
        if (!cd.ok() || H5Dwrite(cd, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, c.values.data()) < 0)
          m.fail("cannot write landscape coordinate " + c.name);
        write_str_attr(cd, "unit", c.unit);
        write_cf_units(cd, c.unit);
        if (c.unit.rfind("labels:", 0) == 0) write_label_axis_flags(cd, c.unit.substr(7), c.values.size());
        write_str_attr(cd, "kind", "coordinate");
        if (H5DSattach_scale(cd, d, 0) < 0) m.fail("cannot attach landscape axis " + a.name + " to " + c.name);
        coordinate_names += (coordinate_names.empty() ? "" : " ") + cname;
      }
    }
    axis_dsets.push_back(std::move(d));
  }
  // Metrics: contiguous, allocated (and filled with NaN) when their first cell is written, so a
  // block never reached takes no space. Not chunked: the file's chunk B-trees have nodes of two
  // entries (H5Pset_istore_k(1), sized for the histories' one-chunk arrays), and such a tree grows
  // about one level per chunk, past HDF5's limit of 255 levels at a few hundred chunks.
  Impl::LandscapeStream stream;
  stream.block = spec.block;
  stream.dims = dims;
  stream.fresh = !m.freed_space;
  // A dense landscape in a new part of the file: allocated now, never filled (every cell is written
  // before the next commit, which checks it: do_flush).
  const bool unfilled = spec.dense && stream.fresh && !dims.empty();
  if (unfilled)
    stream.unwritten = std::accumulate(dims.begin(), dims.end(), hsize_t{1}, std::multiplies<>()) * spec.metrics.size();
  Hid dcpl(H5Pcreate(H5P_DATASET_CREATE));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!dcpl.ok() || H5Pset_layout(dcpl, H5D_CONTIGUOUS) < 0 ||
      H5Pset_alloc_time(dcpl, unfilled ? H5D_ALLOC_TIME_EARLY : H5D_ALLOC_TIME_LATE) < 0 ||
      H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &nan) < 0 ||
      H5Pset_fill_time(dcpl, unfilled ? H5D_FILL_TIME_NEVER : H5D_FILL_TIME_ALLOC) < 0)
    m.fail("cannot set up landscape " + spec.block);
  Hid code_dcpl(H5Pcopy(dcpl));  // grids of codes: -1 where there is none
  const std::int16_t no_code = -1;
  if (!code_dcpl.ok() || H5Pset_fill_value(code_dcpl, H5T_NATIVE_INT16, &no_code) < 0)
    m.fail("cannot set up landscape " + spec.block);
  for (auto& mt : spec.metrics) {
    Hid space(dims.empty() ? H5Screate(H5S_SCALAR)
                           : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
    Hid d(H5Dcreate2(g, mt.name.c_str(), metric_file_type(mt), space, H5P_DEFAULT, mt.flags.empty() ? dcpl : code_dcpl,
                     H5P_DEFAULT));
    if (!d.ok()) m.fail("cannot create landscape metric " + mt.name);
    write_str_attr(d, "unit", mt.unit);
    write_cf_units(d, mt.unit);
    if (!mt.flags.empty()) write_code_flags(d, mt);
    if (!coordinate_names.empty()) write_str_attr(d, "coordinates", coordinate_names);
    write_str_attr(d, "description", mt.description);
    write_str_attr(d, "long_name", mt.description);
    if (!mt.display_name.empty()) write_str_attr(d, "display_name", mt.display_name);
    write_str_attr(d, "kind", "metric");
    write_str_list_attr(d, "axes", axis_names);
    for (std::size_t i = 0; i < axis_dsets.size(); ++i)
      if (H5DSattach_scale(d, axis_dsets[i], static_cast<unsigned>(i)) < 0)
        m.fail("cannot attach landscape axis " + axis_names[i] + " to metric " + mt.name);
    stream.metrics.push_back(std::move(d));
  }
  m.landscape_streams.push_back(std::move(stream));
  return m.landscape_streams.size() - 1;
}

void ResultsWriter::write_landscape_cell(std::size_t landscape, std::uint64_t cell, const double* values) {
  Impl& m = *impl_;
  m.usable();
  const auto [stream, cells] = begun_stream(m, landscape, "write_landscape_cell");
  Impl::LandscapeStream& s = *stream;
  if (cell >= cells)
    throw StoreError(m.path, "landscape " + s.block + ": cell " + std::to_string(cell) + " of " + std::to_string(cells));
  s.cells.push_back(cell);
  s.values.insert(s.values.end(), values, values + s.metrics.size());
  if (s.cells.size() >= kPendingCells) {
    QuietHdf5 quiet;
    m.write_landscape_cells();
  }
  if (m.uncommitted_bytes >= Impl::kMaxUncommittedBytes) {  // cells written again into a kept landscape
    QuietHdf5 quiet;
    m.do_flush();
  }
}

void ResultsWriter::write_landscape_range(std::size_t landscape, std::uint64_t first, std::uint64_t count,
                                          const std::vector<const double*>& values) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  const auto [stream, cells] = begun_stream(m, landscape, "write_landscape_range");
  Impl::LandscapeStream& s = *stream;
  if (s.dims.empty() && first + count <= cells && values.size() == s.metrics.size()) {  // a block without axes: one cell
    std::vector<double> cell(s.metrics.size());
    for (std::uint64_t c = 0; c < count; ++c) {
      for (std::size_t mt = 0; mt < values.size(); ++mt) cell[mt] = values[mt][c];
      write_landscape_cell(landscape, first + c, cell.data());
    }
    return;
  }
  if (first > cells || count > cells - first || values.size() != s.metrics.size() || s.dims.empty())
    throw StoreError(m.path, "landscape " + s.block + ": cells " + std::to_string(first) + " + " +
                                 std::to_string(count) + " of " + std::to_string(cells));
  m.write_landscape_cells();  // the cells set one by one before these
  for (std::size_t mt = 0; mt < s.metrics.size(); ++mt)
    if (!write_consecutive(s.metrics[mt], s.dims, first, count, values[mt])) m.fail("cannot write landscape cells of " + s.block);
  s.written(count * s.metrics.size());
  if (!s.fresh) m.uncommitted_bytes += count * s.metrics.size() * sizeof(double);
  if (m.uncommitted_bytes >= Impl::kMaxUncommittedBytes) m.do_flush();
}

bool ResultsWriter::copy_landscape(std::size_t landscape, const std::vector<const ResultsReader*>& sources,
                                   const std::int32_t* owner) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  const auto [stream, cells] = begun_stream(m, landscape, "copy_landscape");
  Impl::LandscapeStream& s = *stream;
  if (s.dims.empty()) return false;
  // Each source's datasets of this landscape's metrics (by the names of ours), of our shape.
  std::vector<char> used(sources.size(), 0);
  for (hsize_t c = 0; c < cells; ++c)
    if (owner[c] >= 0) {
      if (static_cast<std::size_t>(owner[c]) >= sources.size()) return false;
      used[static_cast<std::size_t>(owner[c])] = 1;
    }
  std::vector<std::vector<Hid>> in(sources.size());
  for (std::size_t k = 0; k < sources.size(); ++k) {
    if (!used[k]) continue;
    const auto file = static_cast<hid_t>(sources[k]->raw_file_id());
    for (const Hid& ours : s.metrics) {
      char name[512];
      const ssize_t len = H5Iget_name(ours, name, sizeof name);
      if (len <= 0 || static_cast<std::size_t>(len) >= sizeof name || !link_exists(file, name)) return false;
      Hid d(H5Dopen2(file, name, H5P_DEFAULT));
      Hid space(d.ok() ? H5Dget_space(d) : -1);
      Hid type(d.ok() ? H5Dget_type(d) : -1);
      std::vector<hsize_t> shape(s.dims.size());
      Hid our_type(H5Dget_type(ours));
      if (!space.ok() || !type.ok() || !our_type.ok() || H5Tequal(type, our_type) <= 0 ||
          H5Sget_simple_extent_ndims(space) != static_cast<int>(shape.size()) ||
          H5Sget_simple_extent_dims(space, shape.data(), nullptr) < 0 || shape != s.dims)
        return false;
      in[k].push_back(std::move(d));
    }
  }
  H5Eclear2(H5E_DEFAULT);
  m.write_landscape_cells();  // the cells set one by one before these
  // A dense landscape (allocated, never written, past the committed size, where the journal driver
  // writes straight to the file) takes the sources' bytes by file offset, copied by the kernel,
  // when every source's bytes on disk are its committed state and every grid has its address.
  const std::size_t n_metrics = s.metrics.size();
  bool by_offset = s.unwritten > 0;
  const int out_fd = by_offset ? file_descriptor(m.file) : -1;
  std::vector<haddr_t> to(n_metrics, HADDR_UNDEF);
  std::vector<std::vector<haddr_t>> from_at(sources.size());
  std::vector<int> in_fd(sources.size(), -1);
  // A grid smaller than HDF5's small-data block (an int8 grid of codes, a small f64 grid) comes
  // from a block HDF5 may have reserved before the last commit, where the journal holds the pages:
  // such grids go through HDF5.
  hsize_t small = 2048;  // HDF5's default
  {
    Hid fapl(H5Fget_access_plist(m.file));
    if (fapl.ok()) H5Pget_small_data_block_size(fapl, &small);
  }
  for (std::size_t mt = 0; mt < n_metrics && by_offset; ++mt) {
    Hid type(H5Dget_type(s.metrics[mt]));
    by_offset = type.ok() && cells * H5Tget_size(type) >= small;
    to[mt] = H5Dget_offset(s.metrics[mt]);
  }
  for (std::size_t k = 0; k < sources.size() && by_offset; ++k) {
    if (!used[k]) continue;
    in_fd[k] = sources[k]->bytes_are_committed_state() ? file_descriptor(static_cast<hid_t>(sources[k]->raw_file_id())) : -1;
    for (const Hid& d : in[k]) from_at[k].push_back(H5Dget_offset(d));
    by_offset = in_fd[k] >= 0 && std::none_of(from_at[k].begin(), from_at[k].end(), [](haddr_t a) { return a == HADDR_UNDEF; });
  }
  by_offset = by_offset && out_fd >= 0 && std::none_of(to.begin(), to.end(), [](haddr_t a) { return a == HADDR_UNDEF; });
  H5Eclear2(H5E_DEFAULT);
  // By ranges of one owner, in pieces of kPiece cells: a write of many megabytes at once is several
  // times slower than the same bytes in pieces of this size (measured on Linux 6, ext4).
  constexpr hsize_t kPiece = hsize_t{1} << 16;  // cells moved at once (512 KiB)
  std::vector<double> v;
  for (hsize_t lo = 0; lo < cells;) {
    hsize_t hi = lo + 1;  // [lo, hi): one owner, at most kPiece cells
    while (hi < cells && hi - lo < kPiece && owner[hi] == owner[lo]) ++hi;
    if (owner[lo] >= 0) {
      const auto k = static_cast<std::size_t>(owner[lo]);
      for (std::size_t mt = 0; mt < n_metrics && by_offset; ++mt) {
        Hid type(H5Dget_type(s.metrics[mt]));
        const std::uint64_t w = type.ok() ? H5Tget_size(type) : 0;  // bytes of a cell
        by_offset = w > 0 && kernel_copy(in_fd[k], from_at[k][mt] + lo * w, out_fd, to[mt] + lo * w, (hi - lo) * w, m.path);
      }
      if (!by_offset) {  // the kernel cannot copy between these files: through HDF5 (all metrics again)
        v.resize(hi - lo);
        for (std::size_t mt = 0; mt < n_metrics; ++mt)
          if (!read_consecutive(in[k][mt], s.dims, lo, hi - lo, v.data()) ||
              !write_consecutive(s.metrics[mt], s.dims, lo, hi - lo, v.data()))
            m.fail("cannot copy the landscape cells of " + s.block);
      }
      s.written((hi - lo) * n_metrics);
      if (!s.fresh) m.uncommitted_bytes += (hi - lo) * n_metrics * sizeof(double);
      if (m.uncommitted_bytes >= Impl::kMaxUncommittedBytes) m.do_flush();
    }
    lo = hi;
  }
  return true;
}

void ResultsWriter::Impl::write_landscape_cells() {
  for (LandscapeStream& s : landscape_streams) {
    if (s.cells.empty()) continue;
    // ascending cells, the last value written for a cell kept
    std::vector<std::size_t> keep(s.cells.size());
    std::iota(keep.begin(), keep.end(), 0);
    if (!std::is_sorted(s.cells.begin(), s.cells.end(), std::less_equal<>())) {  // not already strictly ascending
      std::vector<std::size_t> order = std::move(keep);
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.cells[a] < s.cells[b]; });
      keep.clear();
      for (std::size_t i = 0; i < order.size(); ++i)
        if (i + 1 == order.size() || s.cells[order[i + 1]] != s.cells[order[i]]) keep.push_back(order[i]);
    }
    const std::size_t metrics = s.metrics.size(), n = keep.size();
    std::vector<double> v(n);
    for (std::size_t mt = 0; mt < metrics; ++mt) {
      for (std::size_t i = 0; i < n; ++i) v[i] = s.values[keep[i] * metrics + mt];
      if (s.dims.empty()) {  // the one cell of a block without axes
        if (!write_cells(s.metrics[mt], H5S_ALL, H5S_ALL, v.data(), 1))
          fail("cannot write landscape cells of " + s.block);
        continue;
      }
      // one write per hyperslab block of each run of consecutive cells (simple selections only)
      for (std::size_t i = 0; i < n;) {
        std::size_t j = i + 1;
        while (j < n && s.cells[keep[j]] == s.cells[keep[j - 1]] + 1) ++j;
        if (!write_consecutive(s.metrics[mt], s.dims, s.cells[keep[i]], j - i, v.data() + i))
          fail("cannot write landscape cells of " + s.block);
        i = j;
      }
    }
    s.written(n * metrics);
    if (!s.fresh) uncommitted_bytes += n * metrics * sizeof(double);
    s.cells.clear();
    s.values.clear();
  }
}

void ResultsWriter::write_landscape(const LandscapeSpec& spec) {
  const std::size_t cells = std::accumulate(spec.axes.begin(), spec.axes.end(), std::size_t{1},
                                            [](std::size_t n, const LandscapeAxis& a) { return n * a.values.size(); });
  for (auto& mt : spec.metrics)
    if (mt.grid.size() != cells)
      throw StoreError(impl_->path, "landscape " + spec.block + ": metric " + mt.name + " has " +
                                        std::to_string(mt.grid.size()) + " values, the axes span " + std::to_string(cells));
  const std::size_t h = begin_landscape(spec);
  std::vector<double> values(spec.metrics.size());
  for (std::size_t c = 0; c < cells; ++c) {
    for (std::size_t mt = 0; mt < values.size(); ++mt) values[mt] = spec.metrics[mt].grid[c];
    write_landscape_cell(h, c, values.data());
  }
  flush();
}

}  // namespace ks::store
