#pragma once
// The rule a run parameter's value must satisfy, written once next to the field it constrains (see
// TrajectoryOptions, ik::Options) and read by the field's IsValid, the study parser and the schema
// listings (`kinesweep schema`, FORMAT.md).
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <string_view>

namespace ks {

struct Domain {
  enum class Rule { any, positive, nonnegative, at_least, within };
  Rule rule = Rule::any;
  double bound = 0.0;  ///< at_least, within: the smallest value allowed
  double upper = 0.0;  ///< within: the largest value allowed

  static constexpr Domain any() { return {}; }
  static constexpr Domain positive() { return {Rule::positive, 0.0}; }
  static constexpr Domain nonnegative() { return {Rule::nonnegative, 0.0}; }
  static constexpr Domain at_least(double v) { return {Rule::at_least, v}; }
  static constexpr Domain within(double lo, double hi) { return {Rule::within, lo, hi}; }

  /// True when v satisfies the rule (NaN only satisfies `any`).
  constexpr bool holds(double v) const {
    switch (rule) {
      case Rule::any: return true;
      case Rule::positive: return v > 0.0;
      case Rule::nonnegative: return v >= 0.0;
      case Rule::at_least: return v >= bound;
      case Rule::within: return v >= bound && v <= upper;
    }
    return false;
  }
  /// The rule applied to `name`: "name > 0", "name >= 0", "name >= 1"; "" for any.
  std::string str(std::string_view name) const {
    char b[64];  // two %.12g values: at most 2 x 19 characters and the brackets
    switch (rule) {
      case Rule::any: return "";
      case Rule::positive: return std::string(name) + " > 0";
      case Rule::nonnegative: return std::string(name) + " >= 0";
      case Rule::at_least: std::snprintf(b, sizeof b, "%.12g", bound); return std::string(name) + " >= " + b;
      case Rule::within:
        std::snprintf(b, sizeof b, "[%.12g, %.12g]", bound, upper);
        return std::string(name) + " within " + b;
    }
    return "";
  }
  /// "" when v holds, else "name = v; expected <rule>" (v as the user wrote it).
  std::string problem(std::string_view name, double v) const {
    if (holds(v)) return "";
    char b[32];
    std::snprintf(b, sizeof b, "%.12g", v);
    return std::string(name) + " = " + b + "; expected " + str(name);
  }
};

/// One field of an options struct, for IsValid: its name, value and rule.
struct FieldRule {
  const char* name;
  double value;
  Domain rule;
};
/// True when every field is finite and within its rule; otherwise false, with `why` (when given)
/// naming the first field that is not and its rule.
inline bool fields_valid(std::initializer_list<FieldRule> fields, std::string* why) {
  for (const FieldRule& f : fields) {
    std::string p = std::isfinite(f.value) ? f.rule.problem(f.name, f.value)
                                           : std::string(f.name) + " is not finite; expected a finite number";
    if (p.empty()) continue;
    if (why) *why = std::move(p);
    return false;
  }
  return true;
}

}  // namespace ks
