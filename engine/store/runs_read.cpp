#include "store/runs_read.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <cstring>

#include "store/h5util.hpp"
#include "store/label_columns.hpp"
#include "store/plane_codec.hpp"

namespace ks::store::detail {

namespace {
/// The file and memory dataspaces of a read of `sel` from dataset `d`.
std::pair<Hid, Hid> row_spaces(hid_t d, const RowSelection& sel) {
  Hid fs(H5Dget_space(d));
  hsize_t n = sel.size();
  if (sel.ids) {
    static_assert(sizeof(hsize_t) == sizeof(std::int64_t));
    H5Sselect_elements(fs, H5S_SELECT_SET, n, reinterpret_cast<const hsize_t*>(sel.ids->data()));
  } else {
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &sel.first, nullptr, &n, nullptr);
  }
  return {std::move(fs), Hid(H5Screate_simple(1, &n, nullptr))};
}
/// A chunked /runs column whose stored chunks this file decodes itself: its file type is `mtype`
/// (same size and byte order) and its filters are HDF5's shuffle then deflate, or one of them, or
/// none (format 4 files). Filter indices -1 when absent.
struct DirectChunks {
  hsize_t rows = 0;
  std::size_t size = 0;
  int shuffle = -1, deflate = -1;
};

bool direct_chunks(hid_t d, hid_t mtype, DirectChunks& out) {
  Hid dcpl(H5Dget_create_plist(d));
  if (!dcpl.ok() || H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_chunk(dcpl, 1, &out.rows) != 1 || out.rows == 0)
    return false;
  Hid ft(H5Dget_type(d));
  const H5T_class_t cls = H5Tget_class(ft);
  if (cls != H5T_FLOAT && cls != H5T_INTEGER && cls != H5T_ENUM) return false;
  Hid nt(H5Tget_native_type(ft, H5T_DIR_ASCEND));
  out.size = H5Tget_size(ft);
  if (H5Tequal(nt, mtype) <= 0 || H5Tget_size(nt) != out.size) return false;
  Hid base(cls == H5T_ENUM ? H5Tget_super(ft) : H5Tcopy(ft));
  Hid nbase(cls == H5T_ENUM ? H5Tget_super(nt) : H5Tcopy(nt));
  if (H5Tget_order(base) != H5Tget_order(nbase)) return false;
  const int filters = H5Pget_nfilters(dcpl);
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0, config = 0, cd[8];
    std::size_t n_cd = 8;
    char fname[64];
    const H5Z_filter_t f = H5Pget_filter2(dcpl, static_cast<unsigned>(i), &flags, &n_cd, cd, sizeof fname, fname, &config);
    if (f == H5Z_FILTER_SHUFFLE && out.shuffle < 0 && out.deflate < 0) out.shuffle = i;
    else if (f == H5Z_FILTER_DEFLATE && out.deflate < 0) out.deflate = i;
    else return false;
  }
  return true;
}

/// Chunk `index` of `d` decoded into `out` (c.rows * c.size bytes). False when it is not stored
/// (never written) or does not decode as `c` says; the caller then reads through HDF5.
bool decode_chunk(hid_t d, const DirectChunks& c, hsize_t index, unsigned char* out, std::vector<unsigned char>& stored,
                  std::vector<unsigned char>& plain) {
  hsize_t offset = index * c.rows, bytes = 0;
  std::uint32_t mask = 0;
  if (H5Dget_chunk_storage_size(d, &offset, &bytes) < 0 || bytes == 0) return false;
  stored.resize(bytes);
  if (H5Dread_chunk(d, H5P_DEFAULT, &offset, &mask, stored.data()) < 0) return false;
  const std::size_t raw = c.rows * c.size;
  const unsigned char* p = stored.data();
  std::size_t len = stored.size();
  if (c.deflate >= 0 && !(mask & (1u << c.deflate))) {
    plain.resize(raw);
    std::size_t got = 0;
    libdeflate_decompressor* z = decompressor();
    if (!z || libdeflate_zlib_decompress(z, p, len, plain.data(), raw, &got) != LIBDEFLATE_SUCCESS) return false;
    p = plain.data(), len = got;
  }
  if (len != raw) return false;
  if (c.shuffle < 0 || (mask & (1u << c.shuffle)) || c.size == 1) {
    std::memcpy(out, p, raw);
  } else if (c.size == 8) {
    const unsigned char* planes[8];
    for (int j = 0; j < 8; ++j) planes[j] = p + j * c.rows;
    unshuffle8(planes, c.rows, reinterpret_cast<double*>(out));  // (the bytes of any 8-byte type)
  } else {
    for (std::size_t j = 0; j < c.size; ++j)
      for (hsize_t i = 0; i < c.rows; ++i) out[i * c.size + j] = p[j * c.rows + i];
  }
  return true;
}

/// Rows [first, first + count) of `d` by its stored chunks, decoded here (libdeflate instead of
/// HDF5's filter pipeline: several times faster on a column scan). A chunk that cannot be decoded
/// here is read through HDF5. False when the column's layout is not one direct_chunks takes.
bool read_chunks_direct(hid_t d, const std::string& path, const std::string& name, hid_t mtype, hsize_t first,
                        hsize_t count, void* out) {
  DirectChunks c;
  if (!direct_chunks(d, mtype, c)) {
    H5Eclear2(H5E_DEFAULT);
    return false;
  }
  std::vector<unsigned char> chunk(c.rows * c.size), stored, plain;
  auto* dst = static_cast<unsigned char*>(out);
  for (hsize_t k = first / c.rows; k * c.rows < first + count; ++k) {
    const hsize_t lo = std::max(first, k * c.rows), hi = std::min(first + count, (k + 1) * c.rows);
    if (decode_chunk(d, c, k, chunk.data(), stored, plain)) {
      std::memcpy(dst + (lo - first) * c.size, chunk.data() + (lo - k * c.rows) * c.size, (hi - lo) * c.size);
      continue;
    }
    H5Eclear2(H5E_DEFAULT);
    const RowSelection part{lo, hi - lo};
    auto [fs, ms] = row_spaces(d, part);
    check(H5Dread(d, mtype, ms, fs, H5P_DEFAULT, dst + (lo - first) * c.size), path, "read /runs/" + name);
  }
  return true;
}

}  // namespace

void read_runs_typed(hid_t d, const std::string& path, const std::string& name, hid_t mtype, const RowSelection& sel,
                     void* out) {
  if (sel.size() == 0) return;
  if (!sel.ids && read_chunks_direct(d, path, name, mtype, sel.first, sel.count, out)) return;
  auto [fs, ms] = row_spaces(d, sel);
  check(H5Dread(d, mtype, ms, fs, H5P_DEFAULT, out), path, "read /runs/" + name);
}

void read_runs_numbers(hid_t file, const std::string& path, const std::string& name, hid_t mtype,
                       const RowSelection& sel, void* out) {
  if (sel.size() == 0) return;
  Hid d(check(H5Dopen2(file, ("runs/" + name).c_str(), H5P_DEFAULT), path, "open /runs/" + name));
  read_runs_typed(d, path, name, mtype, sel, out);
}

std::vector<std::string> read_runs_strings(hid_t file, const std::string& path, const std::string& name,
                                           const RowSelection& sel) {
  if (sel.size() == 0) return {};
  Hid d(check(H5Dopen2(file, ("runs/" + name).c_str(), H5P_DEFAULT), path, "open /runs/" + name));
  Hid ft(H5Dget_type(d));
  if (H5Tget_class(ft) == H5T_ENUM) {
    const std::vector<std::string> labels = enum_labels(ft, path, name);
    const std::vector<std::uint16_t> codes = read_label_codes(file, path, name, sel);
    std::vector<std::string> out(codes.size());
    for (std::size_t i = 0; i < codes.size(); ++i)
      if (codes[i] < labels.size()) out[i] = labels[codes[i]];
    return out;
  }
  auto [fs, ms] = row_spaces(d, sel);
  return read_vlen_strings(d, ms, fs, sel.size(), path, "read /runs/" + name);
}

std::vector<Record> read_runs_rows(hid_t file, const std::string& path, const std::vector<ColumnSpec>& columns,
                                   const RowSelection& sel) {
  std::vector<Record> rows(sel.size());
  for (auto& r : rows) r.cells.reserve(columns.size());
  for (const ColumnSpec& c : columns) {
    switch (c.type) {
      case CellType::f64: {
        const auto v = read_runs_column<double>(file, path, c.name, H5T_NATIVE_DOUBLE, sel);
        for (std::size_t i = 0; i < rows.size(); ++i) rows[i].cells.emplace_back(v[i]);
        break;
      }
      case CellType::i64: {
        const auto v = read_runs_column<std::int64_t>(file, path, c.name, H5T_NATIVE_INT64, sel);
        for (std::size_t i = 0; i < rows.size(); ++i) rows[i].cells.emplace_back(v[i]);
        break;
      }
      case CellType::str: {
        auto v = read_runs_strings(file, path, c.name, sel);
        for (std::size_t i = 0; i < rows.size(); ++i) rows[i].cells.emplace_back(std::move(v[i]));
        break;
      }
    }
  }
  return rows;
}

}  // namespace ks::store::detail
