// The CF `units` attribute beside the engine's `unit` label: a UDUNITS-2 string, or none.
#include <sstream>

#include "store/h5util.hpp"

namespace ks::store::detail {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

}  // namespace

std::string cf_units(const std::string& unit) {
  if (unit.empty() || unit.rfind("labels:", 0) == 0) return {};
  // Labels the engine writes that UDUNITS-2 spells otherwise; the rest are UDUNITS-2 already.
  static const std::pair<const char*, const char*> spelled[] = {
      {"Nm", "N m"}, {"1/s", "s^-1"}, {"1/s^2", "s^-2"}, {"rad/s^2", "rad s^-2"}, {"m/s^2", "m s^-2"}};
  for (const auto& [label, cf] : spelled)
    if (unit == label) return cf;
  // Not expressible (E_M's kg^(1/2): UDUNITS-2 has integer powers only) or not one unit.
  for (const char* none : {"sqrt", " or ", ",", "problem"})
    if (unit.find(none) != std::string::npos) return {};
  return unit;
}

std::vector<std::string> cf_column_units(const std::string& unit, std::size_t cols) {
  std::vector<std::string> out;
  std::stringstream ss(unit);
  for (std::string part; std::getline(ss, part, ',');) out.push_back(cf_units(trim(part)));
  if (out.size() != cols) return {};
  for (const auto& u : out)
    if (u.empty()) return {};
  return out;
}

void write_cf_units(hid_t d, const std::string& unit, std::size_t cols) {
  if (const std::string u = cf_units(unit); !u.empty()) return write_str_attr(d, "units", u);
  if (cols < 2 || unit.find(',') == std::string::npos) return;
  auto per = cf_column_units(unit, cols);
  if (per.empty()) return;
  bool same = true;
  for (const auto& u : per) same = same && u == per.front();
  if (same) return write_str_attr(d, "units", per.front());
  write_str_list_attr(d, "column_units", per);
}

}  // namespace ks::store::detail
