#include "space/space.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "methods/seed_cases.hpp"

namespace ks {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;  // the same conversion as SeedCase::options()
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr std::array<std::string_view, 3> kIkProblems{"scara", "planar3r_pose", "planar3r_position"};
constexpr std::array<std::string_view, 6> kIkMethods{"newton", "lm", "lm_adaptive", "halley_thesis", "halley",
                                                     "analytic"};
constexpr std::array<std::string_view, 3> kTrajMethods{"local_weighted", "local_unweighted", "vertex_alpha"};
constexpr std::array<std::string_view, 2> kIntegrators{"semi_implicit_euler", "rk4"};
constexpr std::array<std::string_view, 2> kInertia{"physical", "thesis_m11"};
constexpr std::array<std::string_view, 2> kZModes{"thesis", "physical"};
std::span<const std::string_view> preset_span() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const auto& c : seed_cases()) n.push_back(c.name);
    return n;
  }();
  return names;
}

bool type_matches(const Cell& c, CellType t) {
  switch (t) {
    case CellType::f64: return std::holds_alternative<double>(c);
    case CellType::i64: return std::holds_alternative<std::int64_t>(c);
    case CellType::str: return std::holds_alternative<std::string>(c);
  }
  return false;
}
}  // namespace

std::string_view to_string(BlockKind k) { return k == BlockKind::trajectory ? "trajectory" : "ik"; }
bool parse(std::string_view name, BlockKind& out) {
  if (name == "trajectory") out = BlockKind::trajectory;
  else if (name == "ik") out = BlockKind::ik;
  else return false;
  return true;
}
std::string_view to_string(InertiaForm f) { return f == InertiaForm::physical ? "physical" : "thesis_m11"; }
bool parse(std::string_view name, InertiaForm& out) {
  if (name == "physical") out = InertiaForm::physical;
  else if (name == "thesis_m11") out = InertiaForm::thesis_m11;
  else return false;
  return true;
}
std::span<const std::string_view> ik_problem_names() { return kIkProblems; }
std::span<const std::string_view> ik_method_names() { return kIkMethods; }
std::span<const std::string_view> trajectory_method_names() { return kTrajMethods; }
std::span<const std::string_view> integrator_names() { return kIntegrators; }
std::span<const std::string_view> inertia_names() { return kInertia; }
bool ik_problem_is_scara(std::string_view problem) { return problem == "scara"; }

std::vector<ParamInfo> block_params(BlockKind kind, std::size_t path_vertices) {
  using enum CellType;
  std::vector<ParamInfo> p;
  if (kind == BlockKind::trajectory) {
    p.push_back({"preset", str, FileUnit::none, preset_span(), "seed 000 Table 4 case (\"\" when none)"});
    p.push_back({"method", str, FileUnit::none, kTrajMethods, "redundancy resolution method"});
    p.push_back({"k", f64, FileUnit::none, {}, "gravity weight in the resolution"});
    p.push_back({"alpha1A", f64, FileUnit::deg, {}, "end-effector orientation at the start"});
    p.push_back({"K_N", f64, FileUnit::none, {}, "null-space damping"});
    for (std::size_t v = 2; v <= path_vertices; ++v)
      p.push_back({"vertex_alpha_" + std::to_string(v), f64, FileUnit::deg, {},
                   "orientation at vertex " + std::to_string(v) + " (vertex_alpha method)"});
    p.push_back({"integrator", str, FileUnit::none, kIntegrators, "time integrator"});
    p.push_back({"dt", f64, FileUnit::none, {}, "sample / integration step"});
    p.push_back({"torque_bound", f64, FileUnit::none, {}, "|tau_i| above this stops the run (diverged)"});
    p.push_back({"inertia", str, FileUnit::none, kInertia, "closed form of M(q)"});
  } else {
    p.push_back({"problem", str, FileUnit::none, kIkProblems, "IK problem"});
    p.push_back({"method", str, FileUnit::none, kIkMethods, "IK method"});
    p.push_back({"lambda", f64, FileUnit::none, {}, "Levenberg-Marquardt damping (lm, lm_adaptive)"});
    p.push_back({"q0_1", f64, FileUnit::deg, {}, "initial guess, joint 1"});
    p.push_back({"q0_2", f64, FileUnit::deg, {}, "initial guess, joint 2"});
    p.push_back({"q0_3", f64, FileUnit::q0_3, {}, "initial guess, joint 3 (SCARA: prismatic d)"});
    p.push_back({"target_x", f64, FileUnit::none, {}, "target x"});
    p.push_back({"target_y", f64, FileUnit::none, {}, "target y"});
    p.push_back({"target_z", f64, FileUnit::none, {}, "target z (SCARA)"});
    p.push_back({"target_alpha", f64, FileUnit::deg, {}, "target orientation (planar3r_pose)"});
    p.push_back({"tol", f64, FileUnit::none, {}, "stop when the residual norm falls below this"});
    p.push_back({"max_iter", i64, FileUnit::none, {}, "iteration cap"});
    p.push_back({"z_mode", str, FileUnit::none, kZModes, "SCARA z residual: thesis (+q3) or physical"});
  }
  return p;
}

// ---------------------------------------------------------------------------------------------------
Block::Block(BlockSpec spec, const BlockContext& context)
    : name_(std::move(spec.name)), kind_(spec.kind), context_(context) {
  const auto infos = block_params(kind_, context_.path_vertices);
  auto col_of = [&](const std::string& n) -> std::size_t {
    for (std::size_t i = 0; i < infos.size(); ++i)
      if (infos[i].name == n) return i;
    throw std::invalid_argument("block '" + name_ + "': unknown parameter '" + n + "'");
  };
  // IK problem family (fixes the units of q0_3 and the targets).
  if (kind_ == BlockKind::ik) {
    std::vector<std::string> problems;
    for (const auto& [n, v] : spec.fixed)
      if (n == "problem" && std::holds_alternative<std::string>(v)) problems.push_back(std::get<std::string>(v));
    for (const auto& a : spec.axes)
      if (a.name == "problem")
        for (const auto& v : a.values)
          if (std::holds_alternative<std::string>(v)) problems.push_back(std::get<std::string>(v));
    if (!problems.empty()) {
      scara_ = ik_problem_is_scara(problems.front());
      for (const auto& p : problems)
        if (ik_problem_is_scara(p) != scara_)
          throw std::invalid_argument("block '" + name_ + "': problems mix scara and planar3r units");
    }
  }
  for (const auto& info : infos) {
    std::string unit;
    if (info.file_unit == FileUnit::deg) unit = "rad";
    else if (info.file_unit == FileUnit::q0_3) unit = scara_ ? "mm" : "rad";
    else if (info.name == "K_N") unit = "1/s";
    else if (info.name == "dt") unit = "s";
    else if (info.name == "torque_bound") unit = "Nm";
    else if (kind_ == BlockKind::ik && (info.name.starts_with("target_") || info.name == "tol"))
      unit = scara_ ? "mm" : "m";
    columns_.push_back({info.name, info.type, unit, info.description});
  }
  if (kind_ == BlockKind::ik && !scara_) columns_[col_of("tol")].unit = "";

  std::vector<char> used(infos.size(), 0);
  for (auto& [n, v] : spec.fixed) {
    const std::size_t c = col_of(n);
    if (used[c]) throw std::invalid_argument("block '" + name_ + "': parameter '" + n + "' given twice");
    if (!type_matches(v, infos[c].type))
      throw std::invalid_argument("block '" + name_ + "': parameter '" + n + "' has the wrong type");
    used[c] = 1;
    fixed_.emplace_back(c, std::move(v));
  }
  for (auto& a : spec.axes) {
    const std::size_t c = col_of(a.name);
    if (used[c]) throw std::invalid_argument("block '" + name_ + "': parameter '" + a.name + "' given twice");
    if (a.values.empty()) throw std::invalid_argument("block '" + name_ + "': axis '" + a.name + "' is empty");
    for (const auto& v : a.values)
      if (!type_matches(v, infos[c].type))
        throw std::invalid_argument("block '" + name_ + "': axis '" + a.name + "' has a value of the wrong type");
    used[c] = 1;
    a.unit = columns_[c].unit;
    axis_column_.push_back(c);
    axes_.push_back(std::move(a));
  }
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

void Block::resolve(std::vector<Cell>& c, std::vector<char>& set) const {
  auto put = [&](std::size_t i, Cell v) {
    if (!set[i]) {
      c[i] = std::move(v);
      set[i] = 1;
    }
  };
  if (kind_ == BlockKind::trajectory) {
    // Columns: 0 preset, 1 method, 2 k, 3 alpha1A, 4 K_N, 5.. vertex alphas, then 4 more.
    const std::size_t nva = context_.path_vertices >= 1 ? context_.path_vertices - 1 : 0;
    const std::size_t after = 5 + nva;
    put(0, std::string());
    if (const SeedCase* sc = find_seed_case(std::get<std::string>(c[0]))) {
      put(1, std::string(to_string(sc->method)));
      put(2, sc->k);
      put(3, sc->alpha1A_deg * kDeg);
      for (std::size_t v = 0; v < nva; ++v) put(5 + v, v < 4 ? sc->vertex_alpha_deg[v] * kDeg : 0.0);
    }
    put(1, std::string("local_weighted"));
    put(2, 0.0);
    put(3, 0.0);
    put(4, 0.0);
    for (std::size_t v = 0; v < nva; ++v) put(5 + v, 0.0);
    put(after, std::string(to_string(context_.integrator)));
    put(after + 1, context_.dt);
    put(after + 2, 1.0e6);
    put(after + 3, std::string(to_string(context_.inertia)));
  } else {
    // 0 problem, 1 method, 2 lambda, 3-5 q0, 6-8 target xyz, 9 target_alpha, 10 tol, 11 max_iter, 12 z_mode
    put(0, std::string("scara"));
    put(1, std::string("newton"));
    put(2, 0.1);
    if (scara_) {
      put(3, 60.0 * kDeg);
      put(4, 45.0 * kDeg);
      put(5, 50.0);
      put(6, 50.0);
      put(7, -80.0);
      put(8, 10.0);
      put(9, kNaN);
      put(12, std::string("thesis"));
    } else {
      put(3, 0.0);
      put(4, 90.0 * kDeg);
      put(5, -90.0 * kDeg);
      put(6, 1.5);
      put(7, 1.5);
      put(8, kNaN);
      put(9, 0.0);
      put(12, std::string());
    }
    put(10, 1e-6);
    put(11, std::int64_t{1000});
  }
}

std::vector<Cell> Block::params(std::uint64_t local) const {
  if (local >= runs_) throw std::out_of_range("Block::params: run index past the block's end");
  std::vector<Cell> c(columns_.size());
  std::vector<char> set(columns_.size(), 0);
  for (const auto& [col, v] : fixed_) {
    c[col] = v;
    set[col] = 1;
  }
  // Mixed-radix decoding straight into the axes' values.
  std::uint64_t rest = local;
  for (std::size_t d = dims_.size(); d-- > 0;) {
    const std::uint64_t i = rest % dims_[d].size;
    rest /= dims_[d].size;
    for (std::size_t a : dims_[d].axes) {
      c[axis_column_[a]] = axes_[a].values[i];
      set[axis_column_[a]] = 1;
    }
  }
  resolve(c, set);
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
