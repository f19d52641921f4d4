#include "cli/table4.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "methods/closed_form/seed_cases.hpp"

namespace ks {

namespace {
/// Largest relative deviation [%] of (E, tau_inf) from the thesis' row.
double worst_deviation(const TrajectoryMetrics& r, const SeedCase& c) {
  const double tau[3] = {r.tau_inf[0], r.tau_inf[1], r.tau_inf[2]};
  return 100.0 * c.worst_deviation(r.E, tau);
}
}  // namespace

void print_table4(std::ostream& os) {
  PlanarArm3 thesis_arm = PlanarArm3::seed();
  thesis_arm.inertia_form = InertiaForm::thesis_m11;
  const PlanarArm3 physical_arm = PlanarArm3::seed();
  const Path2 path = seed_square();
  char line[512];
  os << "Seed 000, Table 4: thesis vs kinesweep. E = mean |tau| [Nm], t1..t3 = max |tau_i| [Nm].\n"
        "'thesis M' = the thesis' own M(q) as printed in its Appendix I (m3 bracket of M11 times m2);\n"
        "'physical M' = the Lagrangian M(q), checked against Orocos KDL. dev = worst relative deviation.\n";
  std::snprintf(line, sizeof line, "%-4s %-16s %4s %6s | %7s %8s %8s %6s | %7s %8s %8s %6s %6s | %7s %8s %8s %6s %6s | %s\n",
                "case", "method", "k", "a1A", "E", "t1", "t2", "t3", "E", "t1", "t2", "t3", "dev", "E", "t1", "t2",
                "t3", "dev", "status");
  os << std::string(34, ' ') << "| thesis (printed)               | kinesweep, thesis M                   "
     << "| kinesweep, physical M\n"
     << line;
  for (const SeedCase& c : seed_cases()) {
    const TrajectoryOptions o = c.options();
    const TrajectoryMetrics a = simulate(thesis_arm, path, o);
    const TrajectoryMetrics b = simulate(physical_arm, path, o);
    std::snprintf(line, sizeof line,
                  "%-4s %-16s %4.2f %6.1f | %7.2f %8.2f %8.2f %6.2f | %7.2f %8.2f %8.2f %6.2f %5.1f%% | %7.2f %8.2f "
                  "%8.2f %6.2f %5.1f%% | %s/%s\n",
                  std::string(c.name).c_str(), std::string(to_string(c.method)).c_str(), c.k, c.alpha1A_deg, c.E,
                  c.tau_inf[0], c.tau_inf[1], c.tau_inf[2], a.E, a.tau_inf[0], a.tau_inf[1], a.tau_inf[2],
                  worst_deviation(a, c), b.E, b.tau_inf[0], b.tau_inf[1], b.tau_inf[2], worst_deviation(b, c),
                  std::string(to_string(a.status)).c_str(), std::string(to_string(b.status)).c_str());
    os << line;
  }
}

}  // namespace ks
