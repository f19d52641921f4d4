// The IK solvers' cycle check (ik/cycle_watch.hpp) against the plain form it replaced, kept in
// ik_cycle_oracle.hpp as the oracle: the same verdict at every iterate, on random iterate sequences
// (exact returns, 2-cycles, near misses at the distance and path boundaries and at the 0.1 % error
// filter, NaN and infinite values, revolute and prismatic joints, 1 to 8 joints, every window) and on
// the iterates of real solves (the SCARA problem of studies/ik_basins.toml and studies/ik_scara.toml,
// the planar 3R arm), replayed exactly as the solver feeds the check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <type_traits>
#include <vector>

#include "common/angles.hpp"
#include "ik/cycle_watch.hpp"
#include "ik/solve.hpp"
#include "ik_cycle_oracle.hpp"
#include "space/space.hpp"

using namespace ks;
using namespace ks::ik;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Both checks fed the same iterates, started as the solver starts them.
template <int N>
struct BothWatches {
  test::PlainCycleWatch<N> plain;
  ik::detail::CycleWatch<N> fast;
  std::array<bool, N> revolute{};
  double tolerance = 1e-8;
  long steps = 0, fired = 0;

  BothWatches(int window, const std::array<bool, N>& rev, double tol, const Vec<N>& q0, double e0)
      : revolute(rev), tolerance(tol) {
    plain.window = fast.window = window;
    plain.push(q0, 0.0, e0);
    fast.push(q0, 0.0, e0);
    plain.best_error = fast.best_error = e0;
  }
  /// Push iterate q (step length, error e) to both; false (with a failure) when the verdicts differ.
  bool push(const Vec<N>& q, double step, double e, bool& verdict) {
    plain.push(q, step, e);
    fast.push(q, step, e);
    verdict = plain.returned(revolute, tolerance);
    const bool v = fast.returned(revolute, tolerance);
    ++steps;
    fired += verdict;
    EXPECT_EQ(v, verdict) << "iterate " << plain.count - 1 << ", window " << plain.window << ", tolerance "
                          << tolerance << ", q = " << q.transpose() << ", e = " << e << ", step = " << step;
    return v == verdict && plain.best_error == fast.best_error;
  }
};

// ------------------------------------------------------------------------------ random sequences

struct RandomCounts {
  long steps = 0, fired = 0, boundary = 0, boundary_fired = 0;
};

/// `sequences` random iterate sequences of N joints (revolute where the mask says so), built so that
/// returns land exactly on, just inside and just outside the distance tolerance and the path rule.
template <int N>
RandomCounts random_sequences(std::mt19937_64& rng, const std::array<bool, N>& revolute, int sequences) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), sym(-1.0, 1.0);
  std::uniform_int_distribution<int> ulps(-40, 40);
  const double tolerances[] = {1e-8, 1e-8, 1e-8, 1e-6, 1e-3, 0.3, 0.0, -1e-8, 1e-155, 1e-200, 1e160, kNaN};
  RandomCounts c;
  for (int s = 0; s < sequences; ++s) {
    const int window = std::uniform_int_distribution<int>(0, 16)(rng);
    const double tolerance = tolerances[std::uniform_int_distribution<int>(0, 11)(rng)];
    const double scale = unit(rng) < 0.5 ? 1.0 : std::pow(10.0, 6.0 * sym(rng));  // joint magnitudes
    auto fresh_q = [&] {
      Vec<N> q;
      for (int j = 0; j < N; ++j) q[j] = revolute[j] ? 4.0 * kPi * sym(rng) : scale * 100.0 * sym(rng);
      return q;
    };
    std::vector<Vec<N>> qs{fresh_q()};
    std::vector<double> es{10.0 * unit(rng) + 1e-3}, paths{0.0};
    BothWatches<N> w(window, revolute, tolerance, qs[0], es[0]);
    const int length = std::uniform_int_distribution<int>(3, 200)(rng);
    // a slowly closing 2-cycle between two centres, its gap shrinking by rho per period
    const Vec<N> a = fresh_q(), b = fresh_q();
    const double ea = es[0], gap0 = std::pow(10.0, -2.0 - 6.0 * unit(rng)), rho = 0.6 + 0.39 * unit(rng);
    const int mode_bias = std::uniform_int_distribution<int>(0, 5)(rng);  // each sequence favours one kind
    for (int k = 1; k < length; ++k) {
      const int n = static_cast<int>(qs.size());
      const int p = std::min(n, std::uniform_int_distribution<int>(1, 17)(rng));  // lag to return to
      const Vec<N>& back = qs[static_cast<std::size_t>(n - p)];
      const double e_back = es[static_cast<std::size_t>(n - p)];
      Vec<N> q = fresh_q();
      double e = 10.0 * unit(rng) + 1e-3, step = unit(rng) < 0.5 ? 1.0 + 10.0 * unit(rng) : 1e-12 + unit(rng);
      bool near_boundary = false;
      const int mode = unit(rng) < 0.5 ? mode_bias : std::uniform_int_distribution<int>(0, 8)(rng);
      switch (mode) {
        case 0:  // a fresh point, error maybe equal to an earlier one
          if (unit(rng) < 0.5) e = e_back;
          break;
        case 1: {  // an exact return (revolute joints maybe by whole turns)
          q = back;
          for (int j = 0; j < N; ++j)
            if (revolute[j] && unit(rng) < 0.3) q[j] += 2.0 * kPi * std::uniform_int_distribution<int>(-2, 2)(rng);
          e = unit(rng) < 0.7 ? e_back : e_back * (1.0 + 2e-3 * sym(rng));
          break;
        }
        case 2: case 3: {  // a near return at the distance tolerance, a few ulps either side
          Vec<N> dir;
          for (int j = 0; j < N; ++j) dir[j] = sym(rng);
          dir /= dir.norm();
          const double tol = (std::isnan(tolerance) ? 1e-8 : tolerance) * std::max(1.0, back.norm());
          const double r = std::abs(tol) * (1.0 + ulps(rng) * 0x1p-52);
          q = back + r * dir;
          for (int j = 0; j < N; ++j)
            if (revolute[j] && unit(rng) < 0.2) q[j] += 2.0 * kPi;
          e = e_back * (1.0 + 1e-4 * sym(rng));
          // the path since `back` about 1000 times the distance, or clearly longer
          const double since = paths.back() - paths[static_cast<std::size_t>(n - p)];
          step = mode == 3 ? std::max(0.0, 1000.0 * r * (1.0 + ulps(rng) * 0x1p-52) - since) : 1.0;
          near_boundary = true;
          break;
        }
        case 4: {  // the slow 2-cycle
          const double gap = gap0 * std::pow(rho, k / 2);
          q = (k % 2 ? a : b);
          for (int j = 0; j < N; ++j) q[j] += gap * sym(rng);
          e = ea * (1.0 + 1e-7 * sym(rng));
          step = (a - b).norm();
          break;
        }
        case 5: {  // the error at the 0.1 % filter's edge, the point an exact return
          q = back;
          e = e_back * (1.0 + (unit(rng) < 0.5 ? 1e-3 : -1e-3) * (1.0 + ulps(rng) * 0x1p-52));
          near_boundary = true;
          break;
        }
        case 6:  // progress: the error halves
          e = 0.4 * *std::min_element(es.begin(), es.end());
          break;
        case 7: {  // bad numbers
          const int what = std::uniform_int_distribution<int>(0, 5)(rng);
          if (what == 0) e = kNaN;
          if (what == 1) e = kInf;
          if (what == 2) q[std::uniform_int_distribution<int>(0, N - 1)(rng)] = kNaN;
          if (what == 3) q[std::uniform_int_distribution<int>(0, N - 1)(rng)] = kInf;
          if (what == 4) q = back * 1e200;
          if (what == 5) step = kNaN;
          break;
        }
        default:  // a return to a whole-turn shift of an earlier point, large angles
          q = back;
          for (int j = 0; j < N; ++j)
            if (revolute[j]) q[j] += 2.0 * kPi * std::uniform_int_distribution<int>(-1000, 1000)(rng);
          e = e_back;
          break;
      }
      bool verdict = false;
      if (!w.push(q, step, e, verdict)) return c;
      c.boundary += near_boundary;
      c.boundary_fired += near_boundary && verdict;
      qs.push_back(q);
      es.push_back(e);
      paths.push_back(w.plain.travelled);
    }
    c.steps += w.steps;
    c.fired += w.fired;
  }
  return c;
}
}  // namespace

TEST(IkCycleCheck, SameVerdictsAsThePlainFormOnRandomSequences) {
  std::mt19937_64 rng(20240611);
  RandomCounts total;
  auto add = [&](const RandomCounts& c) {
    total.steps += c.steps, total.fired += c.fired, total.boundary += c.boundary;
    total.boundary_fired += c.boundary_fired;
  };
  add(random_sequences<1>(rng, {true}, 1500));
  add(random_sequences<1>(rng, {false}, 1500));
  add(random_sequences<2>(rng, {true, false}, 1500));
  add(random_sequences<3>(rng, {true, true, false}, 3000));  // the SCARA arm
  add(random_sequences<3>(rng, {true, true, true}, 3000));
  add(random_sequences<3>(rng, {false, false, false}, 1500));
  add(random_sequences<6>(rng, {true, false, true, true, true, true}, 1500));
  add(random_sequences<8>(rng, {true, true, true, true, true, true, true, false}, 1500));
  // The sequences reach the interesting cases: many returns, near misses decided both ways.
  EXPECT_GT(total.steps, 1000000);
  EXPECT_GT(total.fired, 20000);
  EXPECT_GT(total.boundary_fired, 2000);
  EXPECT_GT(total.boundary - total.boundary_fired, 2000);
  std::cout << total.steps << " iterates, " << total.fired << " returns; near the boundaries " << total.boundary
            << ", " << total.boundary_fired << " of them returns\n";
}

// ------------------------------------------------------------------------------ real solves

namespace {
/// A (window, cycle_tolerance) to replay a solve's iterates with, besides the solve's own.
struct Replay {
  int window;
  double tolerance;
};
const Replay kOtherReplays[] = {{16, 1e-6}, {2, 1e-8}, {5, 1e-10}, {12, 1e-4}};

struct SolveCounts {
  long solves = 0, iterates = 0, cycles = 0;
  std::map<Status, long> status;
};

/// Replay solve s (from q0 with options o, history kept) through both checks exactly as the solver
/// feeds its watch: every iterate that passed the divergence, convergence and step-floor tests.
/// With the solve's own window and tolerance the verdict must also be the solve's: `cycle` at its
/// last iterate when its status is cycle, no return anywhere else. Then with kOtherReplays.
template <int N, int M>
void replay(const Summary<N, M>& s, const std::type_identity_t<std::array<bool, N>>& revolute, const Options& o,
            SolveCounts& c) {
  ++c.solves;
  ++c.status[s.status];
  const auto& h = s.history;
  ASSERT_GE(h.size(), 1u);
  const std::size_t last = h.size() - 1;
  auto watched = [&](std::size_t k) {  // the solver's tests before it pushes iterate k
    return h.q[k].allFinite() && h.F[k].allFinite() && h.q[k].norm() <= o.divergence_bound &&
           !(h.error[k] < o.tolerance) && h.step[k] >= o.step_floor;
  };
  for (int r = -1; r < static_cast<int>(std::size(kOtherReplays)); ++r) {
    const int window = r < 0 ? std::clamp(o.cycle_window, 0, 16) : kOtherReplays[r].window;
    const double tolerance = r < 0 ? o.cycle_tolerance : kOtherReplays[r].tolerance;
    BothWatches<N> w(window, revolute, tolerance, h.q[0], h.error[0]);
    for (std::size_t k = 1; k <= last && watched(k); ++k) {
      bool verdict = false;
      ASSERT_TRUE(w.push(h.q[k], h.step[k], h.error[k], verdict)) << s.brief();
      if (r < 0) {
        ++c.iterates;
        ASSERT_EQ(verdict, k == last && s.status == Status::cycle) << "iterate " << k << ": " << s.brief();
        c.cycles += verdict;
      }
    }
  }
}

Options study_options(Method m, double lambda, int max_iter) {
  Options o;
  o.method = m;
  o.lambda = lambda;
  o.tolerance = 1e-6;
  o.max_iter = max_iter;
  return o;
}
}  // namespace

TEST(IkCycleCheck, SameVerdictsOnTheIkBasinsStudy) {
  // studies/ik_basins.toml: 3 methods x 201 x 201 starts over [-180, 180] deg, d = 50 mm, target
  // (50, -80, 10) mm. Its run prints: converged=102407 cycle=17590 singular=1206.
  ScaraPosition p;
  p.target = Vec<3>(50.0, -80.0, 10.0);
  const std::vector<double> grid = linspace_values(-180.0, 180.0, 201);
  SolveCounts c;
  Summary<3, 3> s;
  for (const Method m : {Method::newton, Method::lm, Method::halley}) {
    const Options o = study_options(m, 0.1, 1000);
    for (const double t1 : grid)
      for (const double t2 : grid) {
        solve(p, Vec<3>(t1 * kDeg, t2 * kDeg, 50.0), o, s);
        replay(s, p.revolute, o, c);
        if (HasFatalFailure()) return;
      }
  }
  EXPECT_EQ(c.solves, 121203);
  EXPECT_EQ(c.status[Status::converged], 102407);
  EXPECT_EQ(c.status[Status::cycle], 17590);
  EXPECT_EQ(c.status[Status::singular], 1206);
  EXPECT_EQ(c.cycles, 17590);
  std::cout << c.iterates << " iterates checked with the study's settings\n";
}

TEST(IkCycleCheck, SameVerdictsOnTheIkScaraStudy) {
  // studies/ik_scara.toml: 13 x 13 starts (30..90 deg, 15..75 deg), every iterative method, LM over
  // six lambdas; plus the physical z mode.
  const std::vector<double> g1 = range_values(30.0, 90.0, 5.0), g2 = range_values(15.0, 75.0, 5.0);
  ASSERT_EQ(g1.size(), 13u);
  SolveCounts c;
  Summary<3, 3> s;
  for (const ScaraZ z : {ScaraZ::thesis, ScaraZ::physical}) {
    ScaraPosition p;
    p.target = Vec<3>(50.0, -80.0, 10.0);
    p.z_mode = z;
    std::vector<Options> runs;
    for (const Method m : {Method::lm, Method::lm_adaptive})
      for (const double l : {1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0}) runs.push_back(study_options(m, l, 5000));
    for (const Method m : {Method::newton, Method::halley_thesis, Method::halley}) runs.push_back(study_options(m, 0.1, 5000));
    for (const Options& o : runs)
      for (const double t1 : g1)
        for (const double t2 : g2) {
          solve(p, Vec<3>(t1 * kDeg, t2 * kDeg, 50.0), o, s);
          replay(s, p.revolute, o, c);
          if (HasFatalFailure()) return;
        }
  }
  EXPECT_EQ(c.solves, 2 * 15 * 169);
  EXPECT_GT(c.status[Status::converged], 4000);
  std::cout << c.iterates << " iterates, " << c.cycles << " cycles\n";
}

TEST(IkCycleCheck, SameVerdictsOnThePlanarArm) {
  // Pose and position-only targets of a planar 3R arm from random starts, every iterative method.
  const PlanarArm3 arm = PlanarArm3::bars({1.0, 0.8, 0.5}, {1, 1, 1}, 0.1);
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  auto angles = [&] { return Vec<3>(angle(rng), angle(rng), angle(rng)); };
  SolveCounts c;
  Summary<3, 3> s3;
  Summary<3, 2> s2;
  for (int n = 0; n < 3000; ++n) {
    const ArmPose f = forward_kinematics(arm, angles());
    PlanarPose pose;
    pose.arm = arm, pose.target = f.tip, pose.alpha = f.alpha;
    PlanarPosition position;
    position.arm = arm, position.target = f.tip;
    const Vec<3> q0 = 3.0 * angles();  // starts up to 1.5 turns out
    for (const Method m : {Method::newton, Method::lm, Method::lm_adaptive, Method::halley_thesis, Method::halley}) {
      Options o = study_options(m, 0.1, 500);
      o.tolerance = 1e-9;  // m
      solve(pose, q0, o, s3);
      replay(s3, pose.revolute, o, c);
      if (m == Method::halley_thesis) continue;  // square problems only
      solve(position, q0, o, s2);
      replay(s2, position.revolute, o, c);
      if (HasFatalFailure()) return;
    }
  }
  EXPECT_GT(c.status[Status::converged], 20000);
  std::cout << c.iterates << " iterates, " << c.cycles << " cycles, " << c.status[Status::max_iter] << " max_iter\n";
}

TEST(IkCycleCheck, TinyTolerancesAndLargeJointValues) {
  // tolerance^2 below the normal doubles (or 0): returns at about tol = tolerance * ||q|| in two
  // joints of small value while the third holds ||q|| large, a few ulps inside and outside tol.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> sym(-1.0, 1.0);
  std::uniform_int_distribution<int> ulps(-24, 24);
  long fired = 0, steps = 0;
  for (const std::array<bool, 3> revolute : {std::array<bool, 3>{true, true, false}, std::array<bool, 3>{false, false, false}})
    for (const double tolerance : {1e-150, 1e-155, 1e-158, 1e-160, 1e-170, 1e-200, 1e-300, 0.0})
      for (const double big : {1.0, 1e10, 1e40, 1e100, 1e150}) {
        const double tol = tolerance * big;  // the plain form's tolerance, up to rounding
        const double unit = tol > 0.0 ? tol : 1e-300;
        const Vec<3> base(unit * sym(rng), unit * sym(rng), big);
        BothWatches<3> w(8, revolute, tolerance, base, 1.0);
        for (int k = 1; k < 80; ++k) {
          const double a = 2.0 * kPi * std::abs(sym(rng));
          const double r = unit * (1.0 + ulps(rng) * 0x1p-52) * (k % 5 == 0 ? 0.5 : 1.0);
          const Vec<3> q = base + Vec<3>(r * std::cos(a), r * std::sin(a), 0.0);
          bool verdict = false;
          ASSERT_TRUE(w.push(q, 1.0, 1.0, verdict));
        }
        fired += w.fired, steps += w.steps;
      }
  EXPECT_GT(fired, 500);
  EXPECT_GT(steps - fired, 200);
  std::cout << steps << " iterates, " << fired << " returns\n";
}
