// The lane probe (bench/lane_probe.hpp), an independent minimal implementation of case 1a's
// arithmetic used as a benchmark yardstick, against ks::simulate: E per run agrees to 1e-9 relative
// at every lane width this processor runs (the formulas are arranged differently, so agreement, not
// equality), for the benchmark's batch (alpha1A spread over +-1 degree) and for a few other starts
// and gravity weights.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "lane_probe.hpp"
#include "methods/closed_form/seed_cases.hpp"

using namespace ks;

namespace {

/// E of simulate() and of the probe at `width` lanes for runs of 1a with these alpha1A and k.
void expect_agreement(int width, const std::vector<double>& alpha, const std::vector<double>& k) {
  const PlanarArm3 arm = PlanarArm3::seed();
  const TrajectoryOptions base = find_seed_case("1a")->options();
  const SampledPath path(seed_square(), base.dt);
  const ks_probe::ProbePath probe_path = ks_probe::seed_square_path(base.dt);
  ASSERT_EQ(probe_path.n, path.size());
  std::vector<double> E(width);
  (width == 8 ? ks_probe::run_x8 : width == 4 ? ks_probe::run_x4 : ks_probe::run_x1)(probe_path, alpha.data(),
                                                                                   k.data(), E.data());
  double worst = 0;
  for (int l = 0; l < width; ++l) {
    TrajectoryOptions o = base;
    o.alpha1A = alpha[l];
    o.k = k[l];
    const TrajectoryMetrics m = simulate(arm, path, o);
    ASSERT_EQ(m.status, RunStatus::ok) << "lane " << l;
    EXPECT_NEAR(E[l], m.E, 1e-9 * std::abs(m.E)) << "width " << width << " lane " << l << " alpha1A " << alpha[l]
                                                 << " k " << k[l];
    worst = std::max(worst, std::abs(E[l] - m.E) / std::abs(m.E));
  }
  std::printf("width %d: largest relative difference of E %.2e\n", width, worst);
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
  }
}

TEST(LaneProbe, EAgreesWithSimulateForTheBenchmarkBatch) {
  const double a0 = find_seed_case("1a")->options().alpha1A;
  for (int width : widths()) {
    std::vector<double> alpha(width), k(width, 0.0);
    for (int i = 0; i < width; ++i) alpha[i] = a0 + (i - width / 2) * 2e-3;
    expect_agreement(width, alpha, k);
  }
}

TEST(LaneProbe, EAgreesWithSimulateForOtherStartsAndGravityWeights) {
  for (int width : widths()) {
    std::vector<double> alpha(width), k(width);
    for (int i = 0; i < width; ++i) {
      alpha[i] = (0.05 + 0.04 * i) * (i % 2 ? 1 : -1);  // within about +-20 degrees: ordinary runs
      k[i] = 0.1 * (i % 4);
    }
    expect_agreement(width, alpha, k);
  }
}
