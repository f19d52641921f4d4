#pragma once
// Internal: text columns of /runs stored as HDF5 enums (ColumnSpec::labels; FORMAT.md, /runs).
// Only store/*.cpp.
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "store/h5util.hpp"
#include "store/record.hpp"
#include "store/runs_read.hpp"

namespace ks::store::detail {

/// The code of the missing value "" in memory (read_label_codes); in the file it is the largest
/// value of the enum's base type (255 for u8, 65535 for u16).
inline constexpr std::uint16_t kMissingCode = 0xFFFF;

/// True when `labels` can be an enum column: 1 to 65534 distinct, non-empty labels.
bool enum_storable(const std::vector<std::string>& labels);
/// The file type of a labelled column (caller closes): an HDF5 enum over u8 (fewer than 255
/// labels) or u16, member i named labels[i] with value i, and the missing code (enum_file_missing)
/// named enum_missing_name(labels), so that netCDF readers can name every stored value.
hid_t enum_file_type(const std::vector<std::string>& labels);
/// The member name of the missing code: "_missing", with '_' appended while that is a label.
std::string enum_missing_name(const std::vector<std::string>& labels);
/// The name under which the enum type of /runs/<column> is committed in the root group
/// ("runs_<column>_t"): netCDF-4 readers map only committed (named) types.
std::string enum_type_name(const std::string& column);
/// Bytes of one code in the file (1 or 2).
std::size_t enum_code_bytes(std::size_t n_labels);
/// The file's missing code for `n_labels` labels (255 or 65535).
std::uint16_t enum_file_missing(std::size_t n_labels);
/// Writes the CF attributes of a labelled column on dataset `d`: flag_values (the codes),
/// flag_meanings (the labels, blanks as '_', space-separated) and _FillValue (the missing code),
/// each of the column's base type.
void write_enum_attributes(hid_t d, const std::vector<std::string>& labels, const std::string& path);
/// The labels of enum type `type` by code (member values must be 0..n-1, besides one member for
/// the missing code, which names no label). Throws StoreError (kBadColumnAttribute) naming
/// column `name` otherwise.
std::vector<std::string> enum_labels(hid_t type, const std::string& path, const std::string& name);

/// label -> code of one column, for writing.
class LabelEncoder {
 public:
  LabelEncoder() = default;
  explicit LabelEncoder(const std::vector<std::string>& labels);
  /// The file code of `value` ("" -> the missing code); false when `value` is no label.
  bool encode(const std::string& value, std::uint16_t& code) const;
  std::size_t code_bytes() const { return bytes_; }

 private:
  std::unordered_map<std::string, std::uint16_t> codes_;
  std::uint16_t missing_ = 0;
  std::size_t bytes_ = 1;
};

/// Rows `sel` of the labelled column /runs/<name>, as codes 0..n-1 or kMissingCode. Throws StoreError.
std::vector<std::uint16_t> read_label_codes(hid_t file, const std::string& path, const std::string& name,
                                            const RowSelection& sel);

}  // namespace ks::store::detail
