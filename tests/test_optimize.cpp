// Optimisation: the NLopt pipeline on smooth functions with known minima, determinism over
// thread counts, the constraint, the study syntax and its located errors, the HDF5 round trip, and
// the Must-show items on seed 000 (case 4 below the thesis' 48.39 Nm; case 1 sweep then polish at
// least as good as the best cell of a 0.1 deg landscape).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "methods/closed_form/seed_cases.hpp"
#include "methods/base/trajectory.hpp"
#include "optimize/optimize.hpp"
#include "runner/optimize_blocks.hpp"
#include "runner/run_study.hpp"
#include "space/space.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

using namespace ks;
namespace fs = std::filesystem;

namespace {

/// Shifted, scaled Rosenbrock in 2-D (minimum 1.5 at (0.7, 0.49)) plus a quadratic in further dims.
opt::Problem smooth(std::size_t dims) {
  opt::Problem p;
  for (std::size_t i = 0; i < dims; ++i) p.variables.push_back({"x" + std::to_string(i), "", -2.0, 3.0});
  p.objective = [](std::span<const double> x) {
    const double a = 0.7;
    double f = 1.5 + (a - x[0]) * (a - x[0]) + 10.0 * (x[1] - x[0] * x[0]) * (x[1] - x[0] * x[0]);
    for (std::size_t i = 2; i < x.size(); ++i) f += (x[i] - 0.1 * double(i)) * (x[i] - 0.1 * double(i));
    return opt::Evaluation{f, "ok"};
  };
  return p;
}

struct Pipe {
  opt::Algorithm global, local;
};

class SmoothPipeline : public ::testing::TestWithParam<Pipe> {};

TEST_P(SmoothPipeline, GlobalThenLocalFindsTheKnownMinimum) {
  const opt::Problem p = smooth(3);
  opt::PipelineOptions o;
  o.global = opt::seed_global();
  o.global->algorithm = GetParam().global;
  o.global->max_evals = 3000;
  o.local = opt::seed_local();
  o.local->algorithm = GetParam().local;
  o.local->max_evals = 3000;
  o.local->xtol_rel = 1e-10;
  o.local->ftol_abs = 1e-14;
  const opt::Summary s = opt::optimize(p, o);
  ASSERT_EQ(s.best_x.size(), 3u);
  EXPECT_NEAR(s.best_value, 1.5, 1e-6);
  EXPECT_NEAR(s.best_x[0], 0.7, 2e-3);
  EXPECT_NEAR(s.best_x[1], 0.49, 3e-3);
  EXPECT_NEAR(s.best_x[2], 0.2, 2e-3);
  ASSERT_EQ(s.stages.size(), 2u);
  EXPECT_EQ(s.stages[0].name, "global");
  EXPECT_EQ(s.stages[1].name, "local");
  EXPECT_LE(s.stages[1].best_value, s.stages[0].best_value);
  std::size_t n = 0;
  for (const auto& st : s.stages) n += st.evaluations;
  EXPECT_EQ(n, s.evaluations.size());  // every evaluation recorded, each in one stage
  std::ostringstream os;
  s.print(os);
  EXPECT_NE(os.str().find("best"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(
    Algorithms, SmoothPipeline,
    ::testing::Values(Pipe{opt::Algorithm::GN_ESCH, opt::Algorithm::LN_BOBYQA},
                      Pipe{opt::Algorithm::GN_ESCH, opt::Algorithm::LD_SLSQP},
                      Pipe{opt::Algorithm::GN_DIRECT_L, opt::Algorithm::LN_COBYLA},
                      Pipe{opt::Algorithm::GN_CRS2_LM, opt::Algorithm::LN_BOBYQA},
                      Pipe{opt::Algorithm::GN_ISRES, opt::Algorithm::LD_SLSQP},
                      Pipe{opt::Algorithm::GN_MLSL, opt::Algorithm::LN_BOBYQA}),
    [](const auto& info) {
      return std::string(opt::to_string(info.param.global)) + "_" + std::string(opt::to_string(info.param.local));
    });

TEST(Optimize, ResultsDoNotDependOnTheThreadCount) {
  const opt::Problem p = smooth(2);
  auto run = [&](int threads) {
    opt::PipelineOptions o;
    o.global = opt::seed_global();
    o.global->max_evals = 1500;
    o.local = opt::seed_local();
    o.local_starts = 4;
    o.threads = threads;
    o.seed = 7;
    return opt::optimize(p, o);
  };
  const opt::Summary a = run(1), b = run(2);
  EXPECT_EQ(a.evaluations.size(), 1500u + a.stages[1].evaluations);
  ASSERT_EQ(a.evaluations.size(), b.evaluations.size());
  for (std::size_t i = 0; i < a.evaluations.size(); ++i) {
    EXPECT_EQ(a.evaluations[i].x, b.evaluations[i].x) << i;
    EXPECT_EQ(a.evaluations[i].value, b.evaluations[i].value) << i;
    EXPECT_EQ(a.evaluations[i].start, b.evaluations[i].start) << i;
  }
  EXPECT_EQ(a.best_x, b.best_x);
  EXPECT_EQ(a.local_from.size(), 4u);
}

TEST(Optimize, GlobalIslandsRunConcurrentlyAndDeterministically) {
  const opt::Problem p = smooth(3);
  auto run = [&](int threads) {
    opt::PipelineOptions o;
    o.global = opt::seed_global();
    o.global->max_evals = 1000;
    o.global->islands = 3;
    o.local = opt::seed_local();
    o.local->algorithm = opt::Algorithm::LN_BOBYQA;
    o.local_starts = 2;
    o.threads = threads;
    return opt::optimize(p, o);
  };
  const opt::Summary a = run(1), b = run(2);
  EXPECT_EQ(a.stages[0].evaluations, 3000u);
  ASSERT_EQ(a.evaluations.size(), b.evaluations.size());
  for (std::size_t i = 0; i < a.evaluations.size(); ++i) EXPECT_EQ(a.evaluations[i].x, b.evaluations[i].x) << i;
  EXPECT_NEAR(a.best_value, 1.5, 1e-6);
}

TEST(Optimize, ConstraintIsRespectedByTheAlgorithmsThatTakeIt) {
  // min (x-1)^2 + (y-1)^2 subject to x + y <= 1: the minimum is (0.5, 0.5).
  opt::Problem p;
  p.variables = {{"x", "", -2, 2}, {"y", "", -2, 2}};
  p.objective = [](std::span<const double> x) {
    const bool feasible = x[0] + x[1] <= 1.0;
    // deterministic penalty outside, as trajectory runs do
    const double f = (x[0] - 1) * (x[0] - 1) + (x[1] - 1) * (x[1] - 1);
    return opt::Evaluation{feasible ? f : 100.0 + (x[0] + x[1] - 1), feasible ? "ok" : "infeasible"};
  };
  p.constraint = [](std::span<const double> x) { return x[0] + x[1] - 1.0; };
  for (auto alg : {opt::Algorithm::LN_COBYLA, opt::Algorithm::LD_SLSQP, opt::Algorithm::LN_BOBYQA}) {
    opt::PipelineOptions o;
    o.local = opt::seed_local();
    o.local->algorithm = alg;
    o.local->max_evals = 2000;
    p.variables[0].start = -1;
    p.variables[1].start = 0;
    const opt::Summary s = opt::optimize(p, o);
    EXPECT_EQ(s.best_status, "ok");
    EXPECT_LE(s.best_x[0] + s.best_x[1], 1.0);
    for (const auto& e : s.evaluations) EXPECT_EQ(e.status == "ok", e.constraint <= 0);
    if (!opt::supports_constraint(alg)) continue;  // BOBYQA sees only the penalty: it may stall on the boundary
    EXPECT_NEAR(s.best_x[0], 0.5, 1e-3) << opt::to_string(alg);
    EXPECT_NEAR(s.best_x[1], 0.5, 1e-3) << opt::to_string(alg);
    for (const auto& e : s.evaluations) EXPECT_TRUE(std::isfinite(e.constraint));
  }
}

TEST(Optimize, RejectsMalformedProblems) {
  opt::Problem p = smooth(2);
  opt::PipelineOptions o;
  o.global = opt::seed_local();  // a local algorithm in the global slot
  EXPECT_THROW(opt::optimize(p, o), std::invalid_argument);
  p.variables[0].upper = p.variables[0].lower;
  EXPECT_THROW(opt::optimize(p, {}), std::invalid_argument);
}

TEST(Optimize, ReachMarginMatchesTheAnalyticIk) {
  const PlanarArm3 arm = PlanarArm3::bars({1, 1, 1}, {5, 2, 1}, 0.1, 9.81);
  const Eigen::Vector2d p(1.5, 1.5);
  for (double a = -60; a <= 60; a += 0.5) {
    const bool reachable = inverse_kinematics(arm, p, a * kDeg).has_value();
    EXPECT_EQ(reach_margin(arm, p, a * kDeg) <= 0, reachable) << a;
  }
}

// ---- study syntax ---------------------------------------------------------------------------------
const char* kPolish = R"(
[robot]
inertia = "thesis_m11"
[[block]]
name = "landscape"
kind = "trajectory"
method = "local_weighted"
k = 0.0
[block.axes]
alpha1A = { from = -40, to = 40, step = 0.1 }
[[optimize]]
name = "case1"
method = "local_weighted"
k = 0.0
variables = { alpha1A = [-40, 40] }
objective = "E"
polish_from = { block = "landscape", best = 5 }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 300
xtol_rel = 1e-10
)";

TEST(OptimizeStudy, ParsesVariablesObjectiveStagesAndPresets) {
  const Study s = parse_study(std::string(kPolish) + R"(
[[optimize]]
preset = "4"
[[optimize]]
preset = "1h"
name = "h_weighted"
objective = { E = 1.0, tau_inf = 0.01 }
variables = { alpha1A = { from = -30, to = 0, start = -24 }, k = [0, 1] }
constraint = "penalty"
seed = 3
[optimize.global]
algorithm = "GN_DIRECT_L"
max_evals = 200
islands = 2
[optimize.local]
algorithm = "LN_COBYLA"
starts = 3
)", "ok.toml");
  ASSERT_EQ(s.optimizations.size(), 3u);
  const auto& a = s.optimizations[0];
  EXPECT_EQ(a.name, "case1");
  ASSERT_EQ(a.variables.size(), 1u);
  EXPECT_NEAR(a.variables[0].lower, -40 * kDeg, 1e-15);
  EXPECT_EQ(a.variables[0].unit, "rad");
  EXPECT_FALSE(a.global.has_value());
  ASSERT_TRUE(a.local.has_value());
  EXPECT_EQ(a.local->algorithm, opt::Algorithm::LN_BOBYQA);
  EXPECT_EQ(a.polish_block, "landscape");
  EXPECT_EQ(a.polish_best, 5);
  const auto& b = s.optimizations[1];  // a preset's defaults: its variables, GA-like + SQP
  EXPECT_EQ(b.name, "4");
  EXPECT_EQ(b.variables.size(), 5u);
  ASSERT_TRUE(b.global && b.local);
  EXPECT_EQ(b.global->algorithm, opt::Algorithm::GN_ESCH);
  EXPECT_EQ(b.global->population, 50);
  EXPECT_EQ(b.local->algorithm, opt::Algorithm::LD_SLSQP);
  EXPECT_EQ(b.objective_text, "E");
  const auto& c = s.optimizations[2];
  EXPECT_EQ(c.name, "h_weighted");
  EXPECT_EQ(c.objective_text, "E + 0.01*tau_inf");
  EXPECT_NEAR(c.variables[0].start, -24 * kDeg, 1e-15);
  EXPECT_EQ(c.constraint, opt::ConstraintMode::penalty);
  EXPECT_EQ(c.seed, 3u);
  EXPECT_EQ(c.local_starts, 3);
  EXPECT_EQ(c.global->algorithm, opt::Algorithm::GN_DIRECT_L);
  EXPECT_EQ(c.global->islands, 2);
}

TEST(OptimizeStudy, AnOptimisationOnlyStudyNeedsNoBlock) {
  const Study s = parse_study("[[optimize]]\npreset = \"1g\"\n", "only.toml");
  EXPECT_TRUE(s.blocks.empty());
  ASSERT_EQ(s.optimizations.size(), 1u);
  EXPECT_EQ(s.optimizations[0].variables[0].name, "alpha1A");
}

void expect_error(const std::string& text, int line, int col, const std::string& part) {
  try {
    parse_study(text, "bad.toml");
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const StudyError& e) {
    ASSERT_FALSE(e.diagnostics().empty());
    const auto& d = e.diagnostics().front();
    EXPECT_EQ(d.line, line) << e.what();
    EXPECT_EQ(d.column, col) << e.what();
    EXPECT_NE(d.message.find(part), std::string::npos) << e.what();
    EXPECT_EQ(d.str().rfind("bad.toml:" + std::to_string(line) + ":" + std::to_string(col) + ": error: ", 0), 0u);
  }
}

TEST(OptimizeStudy, ErrorsAreLocated) {
  expect_error("[[optimize]]\nname = \"x\"\nvariables = { alpha1a = [-40, 40] }\n", 3, 15, "did you mean 'alpha1A'?");
  expect_error("[[optimize]]\nname = \"x\"\nvariables = { k = [1, 0] }\n", 3, 19, "expected lower < upper");
  expect_error("[[optimize]]\nname = \"x\"\nvariables = { method = [0, 1] }\n", 3, 15, "continuous");
  expect_error("[[optimize]]\npreset = \"1h\"\n[optimize.global]\nalgorithm = \"GN_ESH\"\n", 4, 13,
               "did you mean 'GN_ESCH'?");
  expect_error("[[optimize]]\npreset = \"1h\"\n[optimize.global]\nalgorithm = \"LN_BOBYQA\"\n", 4, 13,
               "not a global algorithm");
  expect_error("[[optimize]]\npreset = \"1h\"\nobjective = \"EE\"\n", 3, 13, "did you mean 'E'?");
  expect_error("[[optimize]]\npreset = \"1h\"\npolish_from = { block = \"nope\" }\n", 3, 25, "not a [[block]]");
  expect_error("[[optimize]]\npreset = \"4\"\nvariables = { k = [0, 1] }\n", 3, 15, "no effect when method = 'vertex_alpha'");
  expect_error("[[optimize]]\npreset = \"1a\"\n", 1, 1, "not an optimised row");
  expect_error("[[optimize]]\npreset = \"1h\"\n[optimize.local]\nmax_evals = 0\n", 4, 13, "expected an integer >= 1");
}

TEST(OptimizeStudy, ShippedStudiesParse) {
  for (const char* f : {"optimize_table4.toml", "optimize_polish.toml"}) {
    const Study s = load_study(std::string(KS_SOURCE_DIR) + "/studies/" + f);
    EXPECT_FALSE(s.optimizations.empty()) << f;
  }
  const Study t = load_study(std::string(KS_SOURCE_DIR) + "/studies/optimize_table4.toml");
  ASSERT_EQ(t.optimizations.size(), 12u);
  for (const char* p : {"1b", "1d", "1f", "1g", "1h", "2b", "2d", "2f", "2g", "2h", "3", "4"}) {
    bool found = false;
    for (const auto& o : t.optimizations) found = found || o.name == p;
    EXPECT_TRUE(found) << p;
  }
}

// ---- Must show (seed 000) ---------------------------------------------------------------------------
TEST(OptimizeSeed, Case4FindsEBelowTheThesis) {
  // Physical inertia (the default): the GA-like + SQP pipeline goes below the thesis' 48.39 Nm.
  const Study s = parse_study("[[optimize]]\npreset = \"4\"\n[optimize.global]\nalgorithm = \"GN_ESCH\"\n"
                              "[optimize.local]\nalgorithm = \"LD_SLSQP\"\nstarts = 4\n", "case4.toml");
  const OptimizeResult r = run_optimization(s, 0, {});
  EXPECT_EQ(r.record.best_status, "ok");
  EXPECT_LT(r.record.best_objective, 48.39);
  EXPECT_LT(r.record.best_objective, r.value_at_thesis);
  // The thesis' inertia form: kinesweep's optimum is below its own E at the thesis' printed optimum
  // (48.46 there: the model reproduces the printed 48.39 within 0.15 %).
  const Study t = parse_study("[robot]\ninertia = \"thesis_m11\"\n[[optimize]]\npreset = \"4\"\n", "case4m11.toml");
  const OptimizeResult q = run_optimization(t, 0, {});
  EXPECT_LT(q.record.best_objective, q.value_at_thesis);
  EXPECT_NEAR(q.record.best_objective, 48.39, 0.1);
}

TEST(OptimizeSeed, Case1SweepThenPolishBeatsTheBestCellOfA01DegreeLandscape) {
  const Study s = parse_study(kPolish, "polish.toml");
  // The best cell, computed here independently of the runner.
  PlanarArm3 arm = s.robot;
  const Path2 path = s.task.path();
  double best_cell = std::numeric_limits<double>::infinity();
  for (double v : range_values(-40, 40, 0.1)) {
    TrajectoryOptions o;
    o.method = TrajectoryMethod::local_weighted;
    o.k = 0;
    o.alpha1A = v * kDeg;
    const TrajectoryMetrics m = simulate(arm, path, o);
    if (m.status == RunStatus::ok) best_cell = std::min(best_cell, m.E);
  }
  ASSERT_TRUE(std::isfinite(best_cell));
  for (int threads : {1, 2}) {
    OptimizeRunOptions oo;
    oo.threads = threads;
    const OptimizeResult r = run_optimization(s, 0, oo);
    EXPECT_LE(r.record.best_objective, best_cell) << threads;
    EXPECT_EQ(r.record.best_status, "ok");
    ASSERT_FALSE(r.record.stages.empty());
    EXPECT_EQ(r.record.stages.front().name, "sweep");
    EXPECT_DOUBLE_EQ(r.record.stages.front().best_objective, best_cell);  // the sweep stage = the landscape's best cells
    EXPECT_EQ(r.record.local_value.size(), 5u);
    for (std::size_t i = 0; i < r.record.size(); ++i)
      if (r.record.stage[i] == "sweep") {  // a landscape cell: its run id and status
        EXPECT_GE(r.record.start[i], 0);
        EXPECT_LT(r.record.start[i], 801);
        EXPECT_EQ(r.record.status[i], "ok");
      }
  }
}

TEST(OptimizeSeed, PolishStartsReadFromTheResultsFileEqualThoseEvaluatedAfresh) {
  // A landscape with ok, unreachable (|alpha1A| large) and failed cells, some failing at their first
  // sample (torque_bound 1 Nm: no samples, stop_time NaN): the starts ranked from the stored metrics
  // and statuses must be the starts ranked from fresh runs (two independent routes), all finite.
  const Study s = parse_study(R"([study]
name = "polish_routes"
histories = "none"
[[block]]
name = "landscape"
kind = "trajectory"
method = "local_unweighted"
[block.axes]
alpha1A = { from = -150, to = 150, step = 15 }
k = [0, 0.5, 1]
torque_bound = [1.0, 1e6]
[[optimize]]
name = "polish"
method = "local_unweighted"
variables = { alpha1A = [-150, 150], k = [0, 1] }
polish_from = { block = "landscape", best = 126 }
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 10
)",
                              "routes.toml");
  const std::string out = "/tmp/ks_polish_routes_" + std::to_string(::getpid()) + ".h5";
  RunRequest req;
  req.study_arg = "routes.toml";
  req.output = out;
  req.overwrite = true;
  req.quiet = true;
  req.options.histories.mode = HistoryPolicy::Mode::none;
  std::ostringstream sink;
  ASSERT_EQ(run_study(s, req, sink, sink), 0) << sink.str();
  const store::ResultsReader cells(out);
  OptimizeRunOptions from_file, fresh;
  from_file.cells = &cells;
  const auto a = best_cells(s, 0, from_file), b = best_cells(s, 0, fresh);
  ASSERT_EQ(a.size(), 126u);
  ASSERT_EQ(a.size(), b.size());
  std::set<std::string> statuses;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].run, b[i].run) << i;
    EXPECT_EQ(a[i].x, b[i].x) << i;
    EXPECT_EQ(a[i].status, b[i].status) << i;
    EXPECT_TRUE(a[i].value == b[i].value || (std::isnan(a[i].value) && std::isnan(b[i].value))) << i;
    EXPECT_TRUE(std::isfinite(a[i].value)) << i << " " << a[i].status;
    statuses.insert(a[i].status);
  }
  EXPECT_TRUE(statuses.count("ok"));
  EXPECT_TRUE(statuses.count("unreachable_start"));  // the ranking covers failed cells too
  EXPECT_TRUE(statuses.count("diverged"));
  std::filesystem::remove(out);
  std::filesystem::remove(out + ".journal");
}

// ---- store -------------------------------------------------------------------------------------------
TEST(OptimizeStore, WriteAndReadBack) {
  char tmpl[] = "/tmp/ks_opt_test_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const std::string path = dir + "/o.h5";
  const Study s = parse_study("[[optimize]]\npreset = \"1g\"\n[optimize.global]\nmax_evals = 300\n[optimize.local]\n", "s.toml");
  const OptimizeResult r = run_optimization(s, 0, {});
  {
    store::StoreMeta meta;
    meta.study_name = "s";
    auto w = store::ResultsWriter::create(path, meta, {run_id_column()}, 0);
    w->write_optimization(r.record);
    w->write_optimization(r.record);  // replacing is allowed
    w->close();
  }
  store::ResultsReader rd(path);
  ASSERT_EQ(rd.optimizations(), std::vector<std::string>{"1g"});
  const store::OptimizationRecord b = rd.read_optimization("1g");
  EXPECT_EQ(b.variables, r.record.variables);
  EXPECT_EQ(b.x, r.record.x);
  EXPECT_EQ(b.value, r.record.value);
  EXPECT_EQ(b.stage, r.record.stage);
  EXPECT_EQ(b.status, r.record.status);
  EXPECT_EQ(b.start, r.record.start);
  EXPECT_EQ(b.best_objective, r.record.best_objective);
  EXPECT_EQ(b.best_x, r.record.best_x);
  EXPECT_EQ(b.stages.size(), r.record.stages.size());
  EXPECT_EQ(b.reference, r.record.reference);
  ASSERT_EQ(b.best_metrics.size(), r.record.best_metrics.size());
  for (std::size_t i = 0; i < b.best_metrics.size(); ++i) {  // NaN (a metric the task has not) reads back as NaN
    EXPECT_EQ(b.best_metrics[i].first, r.record.best_metrics[i].first);
    const double x = b.best_metrics[i].second, y = r.record.best_metrics[i].second;
    EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << b.best_metrics[i].first << ": " << x << " vs " << y;
  }
  ASSERT_EQ(b.history.arrays.size(), r.record.history.arrays.size());
  for (std::size_t i = 0; i < b.history.arrays.size(); ++i) EXPECT_EQ(b.history.arrays[i].data, r.record.history.arrays[i].data);
  EXPECT_THROW(rd.read_optimization("nope"), store::StoreError);
  fs::remove_all(dir);
}

}  // namespace
