#include "store/label_columns.hpp"

#include <algorithm>
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

std::string enum_missing_name(const std::vector<std::string>& labels) {
  std::string name = "_missing";
  while (std::find(labels.begin(), labels.end(), name) != labels.end()) name += "_";
  return name;
}

hid_t enum_file_type(const std::vector<std::string>& labels) {
  hid_t t = H5Tenum_create(base_type(labels.size()));
  // H5Tenum_insert reads the value in the base type's size; little-endian hosts only (as the store)
  const auto insert = [&](const std::string& name, std::uint16_t v) { return H5Tenum_insert(t, name.c_str(), &v) >= 0; };
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (!insert(labels[i], static_cast<std::uint16_t>(i))) {
      H5Tclose(t);
      return -1;
    }
  if (!insert(enum_missing_name(labels), enum_file_missing(labels.size()))) {
    H5Tclose(t);
    return -1;
  }
  return t;
}

std::string enum_type_name(const std::string& column) { return "runs_" + column + "_t"; }

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
  // The member of the missing code (format 5 on), when there is one, names no label.
  const std::uint64_t missing = H5Tget_size(type) == 1 ? 0xFF : 0xFFFF;
  std::vector<std::pair<std::uint64_t, std::string>> members;
  for (int i = 0; i < n; ++i) {
    std::uint64_t v = 0;  // the member value in the base type's size (little-endian)
    H5Tget_member_value(type, static_cast<unsigned>(i), &v);
    char* s = H5Tget_member_name(type, static_cast<unsigned>(i));
    if (!s) throw StoreError(path, bad + ": unreadable enum member");
    members.emplace_back(v, s);
    H5free_memory(s);
  }
  const auto has_missing = std::count_if(members.begin(), members.end(), [&](const auto& m) { return m.first == missing; });
  std::vector<std::string> labels(members.size() - static_cast<std::size_t>(has_missing == 1 ? 1 : 0));
  if (labels.empty()) throw StoreError(path, bad + " is an enum without labels");
  for (auto& [v, label] : members) {
    if (v == missing && has_missing == 1) continue;
    if (v >= labels.size() || !labels[v].empty())
      throw StoreError(path, bad + " has enum member '" + label + "' = " + std::to_string(v) +
                                 " (expected the values 0.." + std::to_string(labels.size() - 1) +
                                 ", each once, and at most the missing code " + std::to_string(missing) + ")");
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
