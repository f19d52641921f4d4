#include "store/runs_read.hpp"

#include "store/h5util.hpp"
#include "store/label_columns.hpp"

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
}  // namespace

void read_runs_typed(hid_t d, const std::string& path, const std::string& name, hid_t mtype, const RowSelection& sel,
                     void* out) {
  if (sel.size() == 0) return;
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
