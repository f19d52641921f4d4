// ResultsWriter::write_verification / ResultsReader::read_verification: /verification, the grid
// studies of a file's best runs (see store.hpp, FORMAT.md).
#include <limits>

#include "store/reader_impl.hpp"
#include "store/store.hpp"
#include "store/table_group.hpp"

namespace ks::store {
using namespace detail;

namespace {
constexpr const char* kGroup = "verification";

template <class F>
std::vector<double> per_grid(const std::vector<VerificationRow>& rows, F field) {
  std::vector<double> v;
  for (const auto& r : rows)
    for (double x : field(r)) v.push_back(x);
  return v;
}
}  // namespace

void ResultsWriter::write_verification(const VerificationTable& t) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  Hid g = replace_group(m, kGroup,
                 "grid convergence of the best runs: each row one quantity of one run computed at three grids "
                 "(1 finest, 3 the run as stored) and Roache's grid convergence index");
  TableOut o{m, "/verification"};
  o.f64_attr(g, "safety_factor", t.safety_factor);
  const auto& rows = t.rows;
  o.i64(g, "run", column_of(rows, [](const auto& r) { return r.run; }), "the run id (row of /runs)");
  o.str(g, "block", column_of(rows, [](const auto& r) { return r.block; }), "the run's block");
  o.str(g, "method", column_of(rows, [](const auto& r) { return r.method; }), "the run's method");
  o.str(g, "group", column_of(rows, [](const auto& r) { return r.group; }), "what the run is the best of (column=value, ...)");
  o.str(g, "quantity", column_of(rows, [](const auto& r) { return r.quantity; }), "the /runs metric verified");
  o.str(g, "quantity_unit", column_of(rows, [](const auto& r) { return r.unit; }), "its unit (of value and extrapolated)");
  o.str(g, "refinement", column_of(rows, [](const auto& r) { return r.refinement; }), "dt (dt, dt/2, dt/4) or knots (K, 2K, 4K)");
  o.f64(g, "ratio", column_of(rows, [](const auto& r) { return r.ratio; }), 0, "", "refinement ratio r between consecutive grids");
  o.f64(g, "dt", per_grid(rows, [](auto& r) { return r.dt; }), 3, "s", "time step per grid (1 finest .. 3 as stored)");
  o.f64(g, "knots", per_grid(rows, [](auto& r) { return r.knots; }), 3, "",
        "spline knots per grid (1 finest .. 3 as stored); NaN for methods without knots");
  o.f64(g, "value", per_grid(rows, [](auto& r) { return r.value; }), 3, "",
        "the quantity per grid (1 finest .. 3 as stored; unit: quantity_unit); NaN when the run failed");
  {
    std::vector<std::string> s[3];
    for (const auto& r : rows)
      for (int k = 0; k < 3; ++k) s[k].push_back(r.status[static_cast<std::size_t>(k)]);
    o.str(g, "status_1", s[0], "the run's status on grid 1 (finest)");
    o.str(g, "status_2", s[1], "the run's status on grid 2");
    o.str(g, "status_3", s[2], "the run's status on grid 3 (as stored)");
  }
  o.str(g, "convergence", column_of(rows, [](const auto& r) { return r.convergence; }),
        "monotone | unchanged | oscillatory | divergent | not_enough");
  o.f64(g, "order", column_of(rows, [](const auto& r) { return r.order; }), 0, "", "observed order p (monotone only; else NaN)");
  o.f64(g, "extrapolated", column_of(rows, [](const auto& r) { return r.extrapolated; }), 0, "",
        "Richardson extrapolation of the grid-converged value (unit: quantity_unit; monotone, unchanged)");
  o.f64(g, "gci_fine", column_of(rows, [](const auto& r) { return r.gci_fine; }), 0, "",
        "grid convergence index of grid 1, relative (0.01 = 1 %)");
  o.f64(g, "gci_coarse", column_of(rows, [](const auto& r) { return r.gci_coarse; }), 0, "",
        "grid convergence index of grid 3, the run as stored, relative (0.01 = 1 %)");
  o.dimensions(g, "verification_row", "grid");
  m.do_flush();
}

VerificationTable ResultsReader::read_verification() const {
  QuietHdf5 quiet;
  VerificationTable t;
  const std::optional<TableIn> table = TableIn::open(impl_->file, impl_->path, kGroup, "run");
  if (!table) return t;
  const TableIn& in = *table;
  t.safety_factor = in.attr_f64("safety_factor", t.safety_factor);
  const std::size_t n = in.rows();
  const auto run = in.i64("run");
  auto str = [&](const char* name) { return in.str(name); };
  auto f64 = [&](const char* name, std::size_t cols) { return in.f64(name, cols); };
  const auto block = str("block"), method = str("method"), group = str("group"), quantity = str("quantity"),
             unit = str("quantity_unit"), refinement = str("refinement"), convergence = str("convergence"),
             s1 = str("status_1"), s2 = str("status_2"), s3 = str("status_3");
  const auto ratio = f64("ratio", 1), dt = f64("dt", 3), knots = f64("knots", 3), value = f64("value", 3),
             order = f64("order", 1), extrapolated = f64("extrapolated", 1), gci_fine = f64("gci_fine", 1),
             gci_coarse = f64("gci_coarse", 1);
  for (std::size_t i = 0; i < n; ++i) {
    VerificationRow r;
    r.run = run[i], r.block = block[i], r.method = method[i], r.group = group[i], r.quantity = quantity[i];
    r.unit = unit[i], r.refinement = refinement[i], r.convergence = convergence[i];
    r.status = {s1[i], s2[i], s3[i]};
    r.ratio = ratio[i];
    for (std::size_t k = 0; k < 3; ++k) r.dt[k] = dt[3 * i + k], r.knots[k] = knots[3 * i + k], r.value[k] = value[3 * i + k];
    r.order = order[i], r.extrapolated = extrapolated[i], r.gci_fine = gci_fine[i], r.gci_coarse = gci_coarse[i];
    t.rows.push_back(std::move(r));
  }
  return t;
}

}  // namespace ks::store
