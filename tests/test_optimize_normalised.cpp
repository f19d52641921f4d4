// Normalised [[optimize]] objectives (seed 002 Eqs. 7.1, 7.6, 7.9): "1/metric" terms, references at the
// start design or a named design, the trade_off expansion, and their located errors. The oracle is the
// formula written out from plain runs of the same designs (execute), not the optimiser's own numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "runner/execute.hpp"
#include "runner/optimize_blocks.hpp"
#include "study/study.hpp"
#include "study_errors.hpp"

using namespace ks;
using ks::study_test::expect_error_at;

namespace {

// The seed's arm, 2 variables, a local stage short enough for a unit test.
const std::string kStudy = R"([[optimize]]
name = "place"
kind = "trajectory"
method = "local_weighted"
variables = { k = { from = 0, to = 1, start = 0.4 }, alpha1A = [-30, 30] }
objective = { "1/min_manipulability" = 1, E = 1 }
%REFERENCE%
trade_off = [0.3, 1]
[optimize.local]
algorithm = "LN_BOBYQA"
max_evals = 40
)";

Study study_with(const std::string& reference) {
  std::string t = kStudy;
  t.replace(t.find("%REFERENCE%"), 11, reference);
  return parse_study(t, "normalised.toml");
}

/// The metrics of the base block's run with k and alpha1A [rad] set: a plain run, no optimiser.
RunOutcome plain_run(const Study& s, double k, double alpha1A) {
  RunSpec r = s.optimizations.front().block().run(0);
  find_param(s.optimizations.front().block().table(), "k")->set(r, Cell(k));
  find_param(s.optimizations.front().block().table(), "alpha1A")->set(r, Cell(alpha1A));
  RunWorkspace ws;
  return execute(Scenario::of(s), r, 0, ws);
}

double metric(const RunOutcome& o, const Study& s, const std::string& name) {
  for (const MetricDef& m : s.optimizations.front().block().metrics())
    if (m.name == name) return cell_number(m.get(o));
  ADD_FAILURE() << "no metric " << name;
  return NAN;
}

double named(const std::vector<std::pair<std::string, double>>& v, const std::string& key) {
  for (const auto& [k, x] : v)
    if (k == key) return x;
  ADD_FAILURE() << "no " << key;
  return NAN;
}


}  // namespace

TEST(NormalisedObjective, TradeOffExpandsIntoOneOptimisationPerWeight) {
  const Study s = study_with("reference = \"start\"");
  ASSERT_EQ(s.optimizations.size(), 2u);
  EXPECT_EQ(s.optimizations[0].name, "place_k0.3");
  EXPECT_EQ(s.optimizations[1].name, "place_k1");
  EXPECT_DOUBLE_EQ(s.optimizations[0].objective[0].weight, 0.3);
  EXPECT_DOUBLE_EQ(s.optimizations[0].objective[1].weight, 0.7);
  EXPECT_TRUE(s.optimizations[0].objective[0].reciprocal);
  EXPECT_FALSE(s.optimizations[0].objective[1].reciprocal);
  EXPECT_EQ(s.optimizations[0].objective_text, "0.3*min_manipulability_0/min_manipulability + 0.7*E/E_0");
}

TEST(NormalisedObjective, IsTheSeedsFormulaOverPlainRuns) {
  const Study s = study_with("reference = \"start\"");
  const double k0 = 0.4, a0 = 0.0;  // the start: k's start, alpha1A's block value (0)
  const RunOutcome ref = plain_run(s, k0, a0);
  ASSERT_TRUE(ref.good());
  const double f1_0 = metric(ref, s, "min_manipulability"), E_0 = metric(ref, s, "E");

  // At the reference the normalised objective is the sum of the weights: 0.3 + 0.7.
  const opt::Problem p = make_problem(s, 0);
  const double x0[] = {k0, a0};
  EXPECT_NEAR(p.objective(x0).value, 1.0, 1e-12);
  // Elsewhere it is 0.3 f1_0 / f1 + 0.7 E / E_0 of a plain run there.
  const double x1[] = {0.5, 5.0 * std::numbers::pi / 180.0};
  const RunOutcome at = plain_run(s, x1[0], x1[1]);
  ASSERT_TRUE(at.good()) << at.status();
  const double want = 0.3 * f1_0 / metric(at, s, "min_manipulability") + 0.7 * metric(at, s, "E") / E_0;
  EXPECT_NEAR(p.objective(x1).value, want, 1e-12 * want) << p.objective(x1).status << " plain: " << at.status();

  // The stored record: the references, the weight, and the best value from the best run's metrics.
  const OptimizeResult r = run_optimization(s, 0, {});
  EXPECT_EQ(named(r.record.reference, "min_manipulability_0"), f1_0);
  EXPECT_EQ(named(r.record.reference, "E_0"), E_0);
  EXPECT_EQ(named(r.record.reference, "k_0"), k0);
  EXPECT_EQ(named(r.record.reference, "trade_off_k"), 0.3);
  const double best = 0.3 * f1_0 / named(r.record.best_metrics, "min_manipulability") +
                      0.7 * named(r.record.best_metrics, "E") / E_0;
  EXPECT_NEAR(r.record.best_objective, best, 1e-12 * best);
  EXPECT_LE(r.record.best_objective, 1.0);  // the start is evaluated: never worse than it

  // k = 1: only the reciprocal term counts.
  const opt::Problem q = make_problem(s, 1);
  EXPECT_NEAR(q.objective(x1).value, f1_0 / metric(at, s, "min_manipulability"), 1e-12);
}

TEST(NormalisedObjective, ANamedReferenceDesign) {
  const Study s = study_with("reference = { alpha1A = 20 }");  // k at its start, 0.4
  const RunOutcome ref = plain_run(s, 0.4, 20.0 * std::numbers::pi / 180.0);
  const opt::Problem p = make_problem(s, 0);
  const double x[] = {0.4, 20.0 * std::numbers::pi / 180.0};
  EXPECT_NEAR(p.objective(x).value, 1.0, 1e-12);
  const OptimizeResult r = run_optimization(s, 0, {});
  EXPECT_EQ(named(r.record.reference, "E_0"), metric(ref, s, "E"));
}

TEST(NormalisedObjective, AReferenceThatFailsIsAClearError) {
  // alpha1A = -135 deg puts the seed arm's start out of its reach: no reference to divide by.
  const Study s = study_with("reference = { alpha1A = -135 }");
  try {
    make_problem(s, 0);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("needs a good reference run"), std::string::npos) << e.what();
  }
}

TEST(NormalisedObjective, ErrorsAreLocated) {
  const std::string head = "[[optimize]]\nname = \"x\"\nvariables = { k = [0, 1] }\n";
  expect_error_at(head + "objective = { E = 1 }\nreference = \"strat\"\n", 5, 13, "did you mean 'start'?");
  expect_error_at(head + "objective = { E = 1 }\nreference = { alpha1A = 0 }\n", 5, 15, "not a variable");
  expect_error_at(head + "objective = { E = 1 }\ntrade_off = [0.5]\n", 5, 13, "the objective has 1");
  expect_error_at(head + "objective = { E = 1, tau_inf = 1 }\ntrade_off = [0.5, 1.5]\n", 5, 13, "expected 0 <= k <= 1");
  expect_error_at(head + "objective = { \"1/failure_rate\" = 1 }\n", 4, 15, "divides by a rate");
  expect_error_at(head + "objective = { \"1/EE\" = 1 }\n", 4, 15, "did you mean 'E'?");
}
