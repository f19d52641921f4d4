// The lane probe (bench/lane_probe.hpp), an independent minimal implementation of case 1a's
// arithmetic used as a benchmark yardstick, against ks::simulate, at every lane width this processor
// runs (the formulas are arranged differently, so agreement, not equality), for the benchmark's batch
// (alpha1A spread over +-1 degree) and for a few other starts and gravity weights. Tolerances: E,
// E_M, the torque peaks, the minimum manipulability, the two integrals, the peak joint power, the
// end joint rate and the end kinetic energy to 1e-9 relative; final_alpha to 1e-9 rad; the tracking
// errors (the open-loop drift, 0.3 to 14 mm in these runs, a difference of tip and path positions of
// about 2 m) to 1e-12 m.
// The E-only probe's E is the same number as the full probe's E.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "lane_probe.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "methods/metrics/sample_metrics.hpp"

using namespace ks;

namespace {

/// The probe's metrics (both metric sets) and simulate()'s at `width` lanes for runs of 1a with these
/// alpha1A and k.
void expect_agreement(int width, const std::vector<double>& alpha, const std::vector<double>& k) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const TrajectoryOptions base = find_seed_case("1a")->options();
  const SampledPath path(seed_square(), base.dt);
  const ks_probe::ProbePath probe_path = ks_probe::seed_square_path(base.dt);
  ASSERT_EQ(probe_path.n, path.size());
  const auto run = width == 8 ? ks_probe::run_x8 : width == 4 ? ks_probe::run_x4 : ks_probe::run_x1;
  std::vector<ks_probe::ProbeResult> all(width), e_only(width);
  run(ks_probe::Metrics::all, probe_path, alpha.data(), k.data(), all.data());
  run(ks_probe::Metrics::E, probe_path, alpha.data(), k.data(), e_only.data());
  const int power = sample_metric_index("peak_joint_power"), qd = sample_metric_index("end_qd_max"),
            ke = sample_metric_index("end_kinetic_energy");
  ASSERT_TRUE(power >= 0 && qd >= 0 && ke >= 0);
  struct Row {
    const char* name;
    double probe, engine, tolerance;  // tolerance: absolute
  };
  std::vector<double> worst;
  std::vector<const char*> names;
  for (int l = 0; l < width; ++l) {
    TrajectoryOptions o = base;
    o.alpha1A = alpha[l];
    o.k = k[l];
    const TrajectoryMetrics m = simulate(arm, path, o);
    ASSERT_EQ(m.status, RunStatus::ok) << "lane " << l;
    ASSERT_EQ(m.samples, probe_path.n);
    const ks_probe::ProbeResult& p = all[l];
    EXPECT_EQ(e_only[l].E, p.E) << "width " << width << " lane " << l;
    const auto rel = [](double x) { return 1e-9 * std::abs(x); };
    const Row rows[] = {
        {"E", p.E, m.E, rel(m.E)},
        {"E_M", p.E_M, m.E_M, rel(m.E_M)},
        {"tau1_inf", p.tau_inf[0], m.tau_inf[0], rel(m.tau_inf[0])},
        {"tau2_inf", p.tau_inf[1], m.tau_inf[1], rel(m.tau_inf[1])},
        {"tau3_inf", p.tau_inf[2], m.tau_inf[2], rel(m.tau_inf[2])},
        {"min_manipulability", p.min_manipulability, m.min_manipulability, rel(m.min_manipulability)},
        {"torque_sq_integral", p.torque_sq_integral, m.torque_sq_integral, rel(m.torque_sq_integral)},
        {"power_sq_integral", p.power_sq_integral, m.power_sq_integral, rel(m.power_sq_integral)},
        {"max_tracking_error", p.max_tracking_error, m.max_tracking_error, 1e-12},
        {"mean_tracking_error", p.mean_tracking_error, m.mean_tracking_error, 1e-12},
        {"final_alpha", p.final_alpha, m.final_alpha, 1e-9},
        {"peak_joint_power", p.peak_joint_power, m.sampled[power], rel(m.sampled[power])},
        {"end_qd_max", p.end_qd_max, m.sampled[qd], rel(m.sampled[qd])},
        {"end_kinetic_energy", p.end_kinetic_energy, m.sampled[ke], rel(m.sampled[ke])},
    };
    worst.resize(std::size(rows), 0.0);
    for (std::size_t r = 0; r < std::size(rows); ++r) {
      const Row& row = rows[r];
      names.resize(std::size(rows));
      names[r] = row.name;
      EXPECT_NEAR(row.probe, row.engine, row.tolerance)
          << row.name << ": width " << width << " lane " << l << " alpha1A " << alpha[l] << " k " << k[l];
      worst[r] = std::max(worst[r], std::abs(row.probe - row.engine) / std::max(row.tolerance, 1e-300));
    }
  }
  std::printf("width %d: largest difference / tolerance:", width);
  for (std::size_t r = 0; r < worst.size(); ++r) std::printf(" %s %.1e", names[r], worst[r]);
  std::printf("\n");
}

std::vector<int> widths() {
  std::vector<int> w{1};
  if (ks_probe::runs_x4()) w.push_back(4);
  if (ks_probe::runs_x8()) w.push_back(8);
  return w;
}

}  // namespace

TEST(LaneProbe, PathIsTheSampledSeedSquare) {
  const SampledPath path(seed_square(), 1e-3);
  const ks_probe::ProbePath p = ks_probe::seed_square_path(1e-3);
  ASSERT_EQ(p.n, path.size());
  ASSERT_EQ(p.n, 2001u);
  for (std::size_t i = 0; i < p.n; ++i) {
    const double* s = path.data() + 4 * i;  // position (2), acceleration (2)
    EXPECT_NEAR(p.acc[2 * i], s[2], 1e-12) << i;
    EXPECT_NEAR(p.acc[2 * i + 1], s[3], 1e-12) << i;
    EXPECT_NEAR(p.pos[2 * i], s[0], 1e-14) << i;
    EXPECT_NEAR(p.pos[2 * i + 1], s[1], 1e-14) << i;
  }
}

TEST(LaneProbe, MetricsAgreeWithSimulateForTheBenchmarkBatch) {
  const double a0 = find_seed_case("1a")->options().alpha1A;
  for (int width : widths()) {
    std::vector<double> alpha(width), k(width, 0.0);
    for (int i = 0; i < width; ++i) alpha[i] = a0 + (i - width / 2) * 2e-3;
    expect_agreement(width, alpha, k);
  }
}

TEST(LaneProbe, MetricsAgreeWithSimulateForOtherStartsAndGravityWeights) {
  for (int width : widths()) {
    std::vector<double> alpha(width), k(width);
    for (int i = 0; i < width; ++i) {
      alpha[i] = (0.05 + 0.04 * i) * (i % 2 ? 1 : -1);  // within about +-20 degrees: ordinary runs
      k[i] = 0.1 * (i % 4);
    }
    expect_agreement(width, alpha, k);
  }
}
