#include "space/space.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>


namespace ks {
namespace {
bool type_matches(const Cell& c, CellType t) {
  switch (t) {
    case CellType::f64: return std::holds_alternative<double>(c);
    case CellType::i64: return std::holds_alternative<std::int64_t>(c);
    case CellType::str: return std::holds_alternative<std::string>(c);
  }
  return false;
}
std::vector<std::string> choices_of(BlockKind kind, std::string_view param) {
  const auto table = params(kind);
  const ParamDef* p = find_param(table, param);
  return p ? p->choices : std::vector<std::string>{};
}
}  // namespace

std::vector<std::string> integrator_names() { return choices_of(BlockKind::trajectory, "integrator"); }
std::vector<std::string> inertia_names() { return choices_of(BlockKind::trajectory, "inertia"); }
bool ik_problem_is_scara(std::string_view problem) {
  IkProblem p = IkProblem::scara;
  return parse(problem, p) && p == IkProblem::scara;
}

std::vector<ParamDef> block_params(BlockKind kind, std::size_t path_vertices, bool scara) {
  KindContext c;
  c.path_vertices = path_vertices;
  c.scara = scara;
  return params(kind, c);
}

// ---------------------------------------------------------------------------------------------------
Block::Block(BlockSpec spec, const KindContext& context)
    : name_(std::move(spec.name)), kind_(spec.kind), context_(context) {
  // IK problem family (fixes the units of q0_3, the targets and tol, and the defaults).
  if (kind_ == BlockKind::ik) {
    std::vector<std::string> problems;
    for (const auto& [n, v] : spec.fixed)
      if (n == "problem" && std::holds_alternative<std::string>(v)) problems.push_back(std::get<std::string>(v));
    for (const auto& a : spec.axes)
      if (a.name == "problem")
        for (const auto& v : a.values)
          if (std::holds_alternative<std::string>(v)) problems.push_back(std::get<std::string>(v));
    if (!problems.empty()) context_.scara = ik_problem_is_scara(problems.front());
    for (const auto& p : problems)
      if (ik_problem_is_scara(p) != context_.scara)
        throw std::invalid_argument("block '" + name_ + "': problems mix scara and planar3r units");
  }
  table_ = ks::params(kind_, context_);
  metrics_ = ks::metrics(kind_, context_);
  for (const ParamDef& p : table_) columns_.push_back(p.column(kind_));
  auto col_of = [&](const std::string& n) -> std::size_t {
    for (std::size_t i = 0; i < table_.size(); ++i)
      if (table_[i].name == n) return i;
    throw std::invalid_argument("block '" + name_ + "': unknown parameter '" + n + "'");
  };

  std::vector<char> used(table_.size(), 0);
  for (auto& [n, v] : spec.fixed) {
    const std::size_t c = col_of(n);
    if (used[c]) throw std::invalid_argument("block '" + name_ + "': parameter '" + n + "' given twice");
    if (!type_matches(v, table_[c].type))
      throw std::invalid_argument("block '" + name_ + "': parameter '" + n + "' has the wrong type");
    used[c] = 1;
    fixed_.emplace_back(c, std::move(v));
  }
  for (auto& a : spec.axes) {
    const std::size_t c = col_of(a.name);
    if (used[c]) throw std::invalid_argument("block '" + name_ + "': parameter '" + a.name + "' given twice");
    if (a.values.empty()) throw std::invalid_argument("block '" + name_ + "': axis '" + a.name + "' is empty");
    for (const auto& v : a.values)
      if (!type_matches(v, table_[c].type))
        throw std::invalid_argument("block '" + name_ + "': axis '" + a.name + "' has a value of the wrong type");
    used[c] = 1;
    a.unit = columns_[c].unit;
    if (table_[c].leading) leading_swept_ = true;
    axis_column_.push_back(c);
    axes_.push_back(std::move(a));
  }
  // Fixed values in table order, the leading ones first (a preset sets defaults the others override).
  std::stable_sort(fixed_.begin(), fixed_.end(), [&](const auto& x, const auto& y) {
    return std::pair(!table_[x.first].leading, x.first) < std::pair(!table_[y.first].leading, y.first);
  });
  defaults_ = default_run(kind_, context_);
  base_ = defaults_;
  for (const auto& [c, v] : fixed_) table_[c].set(base_, v);
  // Dimensions: groups first assigned, then each remaining axis alone; ordered by first axis.
  std::vector<std::size_t> group_of(axes_.size(), npos);
  std::vector<std::vector<std::size_t>> groups;
  for (const auto& g : spec.groups) {
    std::vector<std::size_t> members;
    for (const auto& n : g) {
      std::size_t idx = npos;
      for (std::size_t i = 0; i < axes_.size(); ++i)
        if (axes_[i].name == n) idx = i;
      if (idx == npos) throw std::invalid_argument("block '" + name_ + "': group names no axis '" + n + "'");
      if (group_of[idx] != npos)
        throw std::invalid_argument("block '" + name_ + "': axis '" + n + "' is in two groups");
      group_of[idx] = groups.size();
      members.push_back(idx);
    }
    if (members.empty()) continue;
    std::sort(members.begin(), members.end());
    for (std::size_t m : members)
      if (axes_[m].values.size() != axes_[members.front()].values.size())
        throw std::invalid_argument("block '" + name_ + "': zipped axes have different lengths");
    groups.push_back(std::move(members));
  }
  axis_dim_.assign(axes_.size(), npos);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (axis_dim_[i] != npos) continue;
    Dim d;
    if (group_of[i] != npos) d.axes = groups[group_of[i]];
    else d.axes = {i};
    d.size = axes_[i].values.size();
    for (std::size_t m : d.axes) axis_dim_[m] = dims_.size();
    dims_.push_back(std::move(d));
  }
  runs_ = 1;
  for (const auto& d : dims_) {
    if (d.size != 0 && runs_ > std::numeric_limits<std::uint64_t>::max() / d.size) overflow_ = true;
    runs_ *= d.size;
  }
}

std::size_t Block::column_index(std::string_view param) const {
  for (std::size_t i = 0; i < columns_.size(); ++i)
    if (columns_[i].name == param) return i;
  return npos;
}

std::vector<std::uint64_t> Block::shape() const {
  std::vector<std::uint64_t> s;
  for (const auto& d : dims_) s.push_back(d.size);
  return s;
}

std::vector<std::uint64_t> Block::grid_index(std::uint64_t local) const {
  if (local >= runs_) throw std::out_of_range("Block::grid_index: run index past the block's end");
  std::vector<std::uint64_t> g(dims_.size());
  for (std::size_t d = dims_.size(); d-- > 0;) {
    g[d] = local % dims_[d].size;
    local /= dims_[d].size;
  }
  return g;
}

std::uint64_t Block::local_index(std::span<const std::uint64_t> grid) const {
  if (grid.size() != dims_.size()) throw std::invalid_argument("Block::local_index: wrong number of dims");
  std::uint64_t i = 0;
  for (std::size_t d = 0; d < dims_.size(); ++d) {
    if (grid[d] >= dims_[d].size) throw std::out_of_range("Block::local_index: index past a dim's end");
    i = i * dims_[d].size + grid[d];
  }
  return i;
}

RunSpec Block::run(std::uint64_t local) const {
  if (local >= runs_) throw std::out_of_range("Block::run: run index past the block's end");
  // Mixed-radix decoding: the value index of each dimension.
  std::uint64_t idx[64];
  std::vector<std::uint64_t> big;
  std::uint64_t* at = idx;
  if (dims_.size() > 64) {
    big.resize(dims_.size());
    at = big.data();
  }
  std::uint64_t rest = local;
  for (std::size_t d = dims_.size(); d-- > 0;) {
    at[d] = rest % dims_[d].size;
    rest /= dims_[d].size;
  }
  if (!leading_swept_) {
    RunSpec r = base_;
    for (std::size_t a = 0; a < axes_.size(); ++a)
      table_[axis_column_[a]].set(r, axes_[a].values[at[axis_dim_[a]]]);
    return r;
  }
  RunSpec r = defaults_;
  for (int pass = 0; pass < 2; ++pass) {  // leading parameters first, fixed or swept
    const bool leading = pass == 0;
    for (const auto& [c, v] : fixed_)
      if (table_[c].leading == leading) table_[c].set(r, v);
    for (std::size_t a = 0; a < axes_.size(); ++a)
      if (table_[axis_column_[a]].leading == leading) table_[axis_column_[a]].set(r, axes_[a].values[at[axis_dim_[a]]]);
  }
  return r;
}

std::vector<Cell> Block::params(std::uint64_t local) const {
  const RunSpec r = run(local);
  std::vector<Cell> c;
  c.reserve(table_.size());
  for (const ParamDef& p : table_) c.push_back(p.get(r));
  return c;
}

Cell Block::value(std::uint64_t local, std::size_t column) const {
  if (column >= columns_.size()) throw std::out_of_range("Block::value: no such column");
  return params(local)[column];
}

Cell Block::value(std::uint64_t local, std::string_view param) const {
  const std::size_t c = column_index(param);
  if (c == npos) throw std::out_of_range("Block::value: no parameter '" + std::string(param) + "'");
  return value(local, c);
}

std::uint64_t total_runs(std::span<const Block> blocks) {
  std::uint64_t n = 0;
  for (const auto& b : blocks) n += b.run_count();
  return n;
}

std::uint64_t first_run(std::span<const Block> blocks, std::size_t block) {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < block && i < blocks.size(); ++i) n += blocks[i].run_count();
  return n;
}

RunRef locate_run(std::span<const Block> blocks, std::uint64_t global) {
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (global < blocks[i].run_count()) return {i, global};
    global -= blocks[i].run_count();
  }
  throw std::out_of_range("locate_run: run id past the study's end");
}

// ---------------------------------------------------------------------------------------------------
double unit_open01(std::uint64_t raw) { return (double(raw >> 11) + 0.5) * 0x1.0p-53; }

std::vector<double> uniform_draws(std::uint64_t seed, std::uint64_t count, double from, double to) {
  std::mt19937_64 rng(seed);
  std::vector<double> out;
  out.reserve(count);
  for (std::uint64_t i = 0; i < count; ++i) out.push_back(from + (to - from) * unit_open01(rng()));
  return out;
}

namespace {
// Unbiased integer in [0, bound) from raw draws (rejection of the short top interval).
std::uint64_t below(std::mt19937_64& rng, std::uint64_t bound) {
  const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - (std::numeric_limits<std::uint64_t>::max() % bound);
  for (;;) {
    const std::uint64_t x = rng();
    if (x < limit) return x % bound;
  }
}
}  // namespace

std::vector<std::vector<double>> lhs_draws(std::uint64_t seed, std::uint64_t count,
                                           std::span<const std::pair<double, double>> ranges) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<double>> out;
  for (const auto& [from, to] : ranges) {
    std::vector<std::uint64_t> perm(count);
    for (std::uint64_t i = 0; i < count; ++i) perm[i] = i;
    for (std::uint64_t i = count; i > 1; --i) std::swap(perm[i - 1], perm[below(rng, i)]);
    std::vector<double> v(count);
    for (std::uint64_t i = 0; i < count; ++i)
      v[i] = from + (to - from) * ((double(perm[i]) + unit_open01(rng())) / double(count));
    out.push_back(std::move(v));
  }
  return out;
}

std::uint64_t range_count(double from, double to, double step) {
  if (!(step != 0.0) || !std::isfinite(from) || !std::isfinite(to) || !std::isfinite(step)) return 0;
  const double r = (to - from) / step;
  const double tol = 1e-9 * std::max(1.0, std::abs(r));
  if (r < -tol) return 0;
  const double n = std::floor(r + tol) + 1.0;
  if (!(n < 1.8e19)) return std::numeric_limits<std::uint64_t>::max();
  return static_cast<std::uint64_t>(n);
}

std::vector<double> range_values(double from, double to, double step) {
  const std::uint64_t n = range_count(from, to, step);
  std::vector<double> v;
  v.reserve(n);
  for (std::uint64_t i = 0; i < n; ++i) v.push_back(from + double(i) * step);
  if (n >= 2 && std::abs(v.back() - to) <= 1e-9 * std::abs(step) * std::max(1.0, double(n))) v.back() = to;
  return v;
}

std::vector<double> linspace_values(double from, double to, std::uint64_t count) {
  std::vector<double> v;
  if (count == 0) return v;
  if (count == 1) return {from};
  v.reserve(count);
  for (std::uint64_t i = 0; i < count; ++i)
    v.push_back(from + (to - from) * (double(i) / double(count - 1)));
  v.back() = to;
  return v;
}

}  // namespace ks
