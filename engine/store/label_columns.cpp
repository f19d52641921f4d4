#include "store/label_columns.hpp"

#include <set>

#include "store/store.hpp"

namespace ks::store::detail {

bool enum_storable(const std::vector<std::string>& labels) {
  if (labels.empty() || labels.size() >= 0xFFFF) return false;
  std::set<std::string> seen;
  for (const std::string& l : labels)
    if (l.empty() || !seen.insert(l).second) return false;
  return true;
}

std::size_t enum_code_bytes(std::size_t n_labels) { return n_labels < 0xFF ? 1 : 2; }
std::uint16_t enum_file_missing(std::size_t n_labels) { return n_labels < 0xFF ? 0xFF : 0xFFFF; }

namespace {
hid_t base_type(std::size_t n_labels) { return enum_code_bytes(n_labels) == 1 ? H5T_STD_U8LE : H5T_STD_U16LE; }
}  // namespace

hid_t enum_file_type(const std::vector<std::string>& labels) {
  hid_t t = H5Tenum_create(base_type(labels.size()));
  for (std::size_t i = 0; i < labels.size(); ++i) {
    // H5Tenum_insert reads the value in the base type's size; little-endian hosts only (as the store)
    const std::uint16_t v = static_cast<std::uint16_t>(i);
    if (H5Tenum_insert(t, labels[i].c_str(), &v) < 0) {
      H5Tclose(t);
      return -1;
    }
  }
  return t;
}

void write_enum_attributes(hid_t d, const std::vector<std::string>& labels, const std::string& path) {
  const hid_t base = base_type(labels.size());
  std::vector<std::uint16_t> codes(labels.size());
  std::string meanings;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    codes[i] = static_cast<std::uint16_t>(i);
    std::string m = labels[i];
    for (char& ch : m)
      if (ch == ' ' || ch == '\t') ch = '_';
    meanings += (i ? " " : "") + m;
  }
  auto numeric = [&](const char* name, const std::vector<std::uint16_t>& values) {
    hsize_t n = values.size();
    Hid space(H5Screate_simple(1, &n, nullptr));
    Hid a(check(H5Acreate2(d, name, base, space, H5P_DEFAULT, H5P_DEFAULT), path, std::string("attribute ") + name));
    check(H5Awrite(a, H5T_NATIVE_UINT16, values.data()), path, std::string("write attribute ") + name);
  };
  numeric("flag_values", codes);
  write_str_attr(d, "flag_meanings", meanings);
  numeric("_FillValue", {enum_file_missing(labels.size())});
}

std::vector<std::string> enum_labels(hid_t type, const std::string& path, const std::string& name) {
  const int n = H5Tget_nmembers(type);
  const std::string bad = std::string(kBadColumnAttribute) + "/runs/" + name;
  if (n <= 0) throw StoreError(path, bad + " is an enum without members");
  std::vector<std::string> labels(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    std::uint64_t v = 0;  // the member value in the base type's size (little-endian)
    H5Tget_member_value(type, static_cast<unsigned>(i), &v);
    char* s = H5Tget_member_name(type, static_cast<unsigned>(i));
    if (!s) throw StoreError(path, bad + ": unreadable enum member");
    std::string label(s);
    H5free_memory(s);
    if (v >= labels.size() || !labels[v].empty())
      throw StoreError(path, bad + " has enum member '" + label + "' = " + std::to_string(v) +
                                 " (expected the values 0.." + std::to_string(n - 1) + ", each once)");
    labels[v] = std::move(label);
  }
  return labels;
}

LabelEncoder::LabelEncoder(const std::vector<std::string>& labels)
    : missing_(enum_file_missing(labels.size())), bytes_(enum_code_bytes(labels.size())) {
  for (std::size_t i = 0; i < labels.size(); ++i) codes_.emplace(labels[i], static_cast<std::uint16_t>(i));
}

bool LabelEncoder::encode(const std::string& value, std::uint16_t& code) const {
  if (value.empty()) {
    code = missing_;
    return true;
  }
  const auto it = codes_.find(value);
  if (it == codes_.end()) return false;
  code = it->second;
  return true;
}

std::vector<std::uint16_t> read_label_codes(hid_t file, const std::string& path, const std::string& name,
                                            const RowSelection& sel) {
  std::vector<std::uint16_t> out(sel.size());
  if (out.empty()) return out;
  Hid d(check(H5Dopen2(file, ("runs/" + name).c_str(), H5P_DEFAULT), path, "open /runs/" + name));
  Hid ft(H5Dget_type(d));
  if (H5Tget_class(ft) != H5T_ENUM) throw StoreError(path, "/runs/" + name + " is not a labelled (enum) column");
  Hid mt(H5Tget_native_type(ft, H5T_DIR_ASCEND));  // the enum itself: read without conversion
  const std::size_t bytes = H5Tget_size(ft);
  const std::uint16_t missing = bytes == 1 ? 0xFF : 0xFFFF;
  std::vector<std::uint8_t> narrow;
  void* buf = out.data();
  if (bytes == 1) {
    narrow.resize(out.size());
    buf = narrow.data();
  }
  read_runs_typed(d, path, name, mt, sel, buf);
  if (bytes == 1)
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = narrow[i];
  for (std::uint16_t& c : out)
    if (c == missing) c = kMissingCode;
  return out;
}

}  // namespace ks::store::detail
