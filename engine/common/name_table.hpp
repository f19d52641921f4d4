#pragma once
// A constexpr table of enum values and their names: the one place where a name used in study files,
// the CLI, HDF5 columns and plots is tied to its enum value.
#include <array>
#include <string_view>
#include <utility>

namespace ks {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<E, std::string_view>, N>;

/// Name of `e` in `t` ("?" when absent).
template <class E, std::size_t N>
constexpr std::string_view name_of(const NameTable<E, N>& t, E e) {
  for (const auto& [v, n] : t)
    if (v == e) return n;
  return "?";
}

/// Value named `name` in `t`; false when unknown.
template <class E, std::size_t N>
constexpr bool value_of(const NameTable<E, N>& t, std::string_view name, E& out) {
  for (const auto& [v, n] : t)
    if (n == name) {
      out = v;
      return true;
    }
  return false;
}

}  // namespace ks
