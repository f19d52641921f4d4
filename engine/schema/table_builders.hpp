#pragma once
// Helpers that build table entries from accessors to a typed run (internal to engine/schema).
#include <cmath>
#include <limits>
#include <stdexcept>

#include "schema/params.hpp"

namespace ks::schema_detail {


/// A real parameter whose value is the double `field(run)` (field: a generic lambda returning a
/// reference into the run struct).
template <class Run, class Field>
ParamDef real(std::string name, FileUnit fu, std::string unit, Domain domain, std::string description, Field field,
              EffectRule effect = {}) {
  ParamDef p;
  p.name = std::move(name);
  p.type = CellType::f64;
  p.file_unit = fu;
  p.unit = std::move(unit);
  p.domain = domain;
  p.description = std::move(description);
  p.effect = std::move(effect);
  p.get = [field](const RunSpec& r) { return Cell(double(field(std::get<Run>(r)))); };
  p.set = [field](RunSpec& r, const Cell& c) { field(std::get<Run>(r)) = cell_number(c); };
  return p;
}

/// An integer parameter (stored i64) whose value is the int `field(run)`.
template <class Run, class Field>
ParamDef integer(std::string name, std::string unit, Domain domain, std::string description, Field field,
                 EffectRule effect = {}) {
  ParamDef p;
  p.name = std::move(name);
  p.type = CellType::i64;
  p.unit = std::move(unit);
  p.domain = domain;
  p.description = std::move(description);
  p.effect = std::move(effect);
  p.get = [field](const RunSpec& r) { return Cell(std::int64_t(field(std::get<Run>(r)))); };
  p.set = [field](RunSpec& r, const Cell& c) { field(std::get<Run>(r)) = static_cast<int>(std::get<std::int64_t>(c)); };
  return p;
}

/// A text parameter naming an enum value (`to_string` / `parse` of the enum), one of `choices`.
template <class Run, class Field>
ParamDef named(std::string name, std::vector<std::string> choices, std::string description, Field field,
               EffectRule effect = {}) {
  ParamDef p;
  p.name = std::move(name);
  p.type = CellType::str;
  p.choices = std::move(choices);
  p.description = std::move(description);
  p.effect = std::move(effect);
  p.get = [field](const RunSpec& r) { return Cell(std::string(to_string(field(std::get<Run>(r))))); };
  p.set = [field, name = p.name](RunSpec& r, const Cell& c) {
    if (!parse(std::get<std::string>(c), field(std::get<Run>(r))))
      throw std::invalid_argument("unknown " + name + " '" + std::get<std::string>(c) + "'");
  };
  return p;
}

/// Names of an enum's values, from its `to_string`.
template <class E, class... V>
std::vector<std::string> names_of(V... values) {
  return {std::string(to_string(values))...};
}

/// A metric whose value is `f(result)` for the kind's result type.
template <class Result, class F>
MetricDef metric(std::string name, CellType type, std::string unit, std::string description, bool gridded, F f) {
  MetricDef m{std::move(name), type, std::move(unit), std::move(description), gridded, {}, {}, {}};
  m.get = [f](const RunOutcome& o) { return Cell(f(std::get<Result>(o.result))); };
  return m;
}

}  // namespace ks::schema_detail
