// Study files that would exhaust resources, reach undefined behaviour in toml++, break HDF5 paths or
// sample the path too coarsely: each refused at FILE:LINE:COL before anything is built; and the
// messages that name the mistake (did-you-mean, the key at fault).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "study/study.hpp"
#include "study_errors.hpp"

using namespace ks;
using namespace ks::study_test;

namespace {

const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";  // lines 1-3

}  // namespace

// ---- run counts from the axes' definitions, before any value is made ----
TEST(StudyGuards, FiveHugeAxesAreRefusedFromTheirCounts) {
  // 5 axes of 4e7 values each: each within the limit alone, 1e38 runs together. Refused without
  // generating a value (the memory bound is checked end to end in test_cli_guards.py).
  std::string t = "[[block]]\nname = \"b\"\nkind = \"ik\"\n[block.axes]\n";
  for (const char* k : {"q0_1", "q0_2", "q0_3", "lambda", "tol"})
    t += std::string(k) + " = { from = 0.001, to = 1, count = 40000000 }\n";
  expect_error_at(t, 1, 1, "more than 2^64");
  expect_error_at(t, 1, 1, "kinesweep run --max-runs N raises it");
}

TEST(StudyGuards, TheStudyTotalCountsEveryBlockBeforeGeneratingTheLast) {
  const std::string b2 = "[[block]]\nname = \"c\"\nkind = \"trajectory\"\n[block.axes]\nk = { from = 0, to = 1, count = 600 }\n";
  const std::string t = kTraj + "[block.axes]\nk = { from = 0, to = 1, count = 600 }\n" + b2;
  expect_error_at(t, 6, 1, "block 'c' has 600 runs, the study 1200", StudyOptions{.max_runs = 1000, .robot_text = {}});
  EXPECT_EQ(parse_study(t, "ok.toml", StudyOptions{.max_runs = 1200, .robot_text = {}}).run_count(), 1200u);
}

TEST(StudyGuards, ZipAndLhsGroupsCountOnce) {
  const std::string zip = kTraj + "zip = [[\"alpha1A\", \"k\"]]\n[block.axes]\nalpha1A = { from = 0, to = 9, count = 10 }\n"
                                  "k = { from = 0, to = 1, count = 10 }\n";
  EXPECT_EQ(parse_study(zip, "ok.toml", StudyOptions{.max_runs = 10, .robot_text = {}}).run_count(), 10u);
  const std::string lhs = kTraj + "lhs = { count = 50, seed = 1 }\n[block.axes]\nalpha1A = { lhs = { from = 0, to = 9 } }\n"
                                  "k = { lhs = { from = 0, to = 1 } }\n";
  EXPECT_EQ(parse_study(lhs, "ok.toml", StudyOptions{.max_runs = 50, .robot_text = {}}).run_count(), 50u);
  expect_error_at(lhs, 4, 17, "lhs count = 50; expected at most 49 runs", StudyOptions{.max_runs = 49, .robot_text = {}});
  // two LHS-sized dimensions: each within the limit, their product not
  expect_error_at(lhs + "dt = [0.001, 0.002]\n", 1, 1, "has 100 runs", StudyOptions{.max_runs = 99, .robot_text = {}});
}

TEST(StudyGuards, AStudyMayLowerTheCallersLimitButNotRaiseIt) {
  const std::string t = kTraj + "[block.axes]\nk = { from = 0, to = 1, count = 11 }\n";
  expect_error_at("[study]\nmax_runs = 10\n" + t, 7, 33, "the study's max_runs; the caller allows up to 50000000");
  expect_error_at("[study]\nmax_runs = 100\n" + t, 2, 12, "above the caller's limit of 20", StudyOptions{.max_runs = 20, .robot_text = {}});
  EXPECT_EQ(parse_study("[study]\nmax_runs = 11\n" + t).run_count(), 11u);
}

TEST(StudyGuards, OptimizeBlocksAreBoundedPerEvaluation) {
  const std::string t = "[[optimize]]\nname = \"o\"\nobjective = \"E\"\nvariables = { k = [0, 1] }\n"
                        "local = { algorithm = \"LN_BOBYQA\", max_evals = 5 }\n[optimize.axes]\n"
                        "alpha1A = { from = 0, to = 1, count = 50 }\ndt = [0.001, 0.002]\n";
  expect_error_at(t, 1, 1, "too many runs per evaluation", StudyOptions{.max_runs = 99, .robot_text = {}});
}

// ---- the samples of a run ----
TEST(StudyGuards, TheDefaultDtIsCheckedAgainstALongPath) {
  // four 3000 s segments at the default dt = 1 ms: 1.2e7 samples per run
  const std::string task = "[task]\nvertices = [[0.9, 0.3], [1.1, 0.3], [1.1, 0.5], [0.9, 0.5], [0.9, 0.3]]\n"
                           "durations = [3000, 3000, 3000, 3000]\n";
  expect_error_at(task + kTraj, 3, 13, "the default dt = 0.001 gives 12000001 samples");
  EXPECT_NO_THROW(parse_study(task + "dt = 0.01\n" + kTraj));
  // an IK study does not sample the path
  EXPECT_NO_THROW(parse_study(task + "[[block]]\nname = \"b\"\nkind = \"ik\"\n"));
}

TEST(StudyGuards, AFixedDtMustSampleEverySegmentTenTimes) {
  // the seed's square: 0.5 s segments, so dt <= 0.05 s
  expect_error_at(kTraj + "dt = 0.2\n", 4, 6, "samples the shortest segment (0.5 s) 2.5 times");
  expect_error_at(kTraj + "dt = 10\n", 4, 6, "at least 10 samples per segment (dt <= 0.05 s");
  expect_error_at("[task]\ndt = 0.1\n" + kTraj, 2, 6, "samples the shortest segment");
  EXPECT_NO_THROW(parse_study(kTraj + "dt = 0.05\n"));
  // swept: accepted; those runs end undersampled (test_cli_guards.py)
  EXPECT_NO_THROW(parse_study(kTraj + "[block.axes]\ndt = [0.001, 0.2]\n"));
}

// ---- names that become HDF5 paths, output paths ----
TEST(StudyGuards, BlockAndOptimisationNamesAreHdf5Names) {
  expect_error_at("[[block]]\nname = \"a/b\"\nkind = \"trajectory\"\n", 2, 8, "contains '/'");
  expect_error_at("[[block]]\nname = \".\"\nkind = \"trajectory\"\n", 2, 8, "which HDF5 paths reserve");
  expect_error_at("[[block]]\nname = \"..\"\nkind = \"trajectory\"\n", 2, 8, "which HDF5 paths reserve");
  expect_error_at("[[block]]\nname = \"a\\tb\"\nkind = \"trajectory\"\n", 2, 8, "control character");
  expect_error_at(kTraj + "[[optimize]]\nname = \"x/y\"\nobjective = \"E\"\nvariables = { k = [0, 1] }\n", 5, 8,
                  "optimisation name 'x/y' contains '/'");
}

TEST(StudyGuards, OutputPathsWithControlCharactersAreRefused) {
  expect_error_at("[study]\noutput = \"a\\u0000b.h5\"\n" + kTraj, 2, 10, "a NUL character");
  expect_error_at("[study]\noutput = \"a\\nb.h5\"\n" + kTraj, 2, 10, "a control character");
}

// ---- inputs toml++ 3.3 mishandles, refused before it parses ----
TEST(StudyGuards, TomlHazardsAreFoundBeforeTomlxxParses) {
  expect_error_at("[[[a]]]\n", 1, 1, "a table header's name starts with '['");
  expect_error_at(kTraj + "  [[ [a]]]\n", 4, 3, "starts with '['");
  expect_error_at("x = \xcf\x9a\n", 1, 5, "U+03DA");  // Ϛ
  expect_error_at("x = [1, \xc2\xa1]\n", 1, 9, "U+00A1");
  expect_error_at("x = [\n  1,\n  \xd2\x99\n]\n", 3, 3, "U+0499");
  // the same characters inside strings and comments, and nested arrays, are ordinary TOML
  const std::string fine = "[study]\ndescription = \"[[[a]]] \xcf\x9a\"  # \xcf\x9a [[[\n"
                           "name = '''\n[[[b]]]'''\n" + kTraj + "vertex_alpha = [[1], 2, 3, 4]\n";
  const StudyError e = error_of(fine);
  ASSERT_FALSE(e.diagnostics().empty());
  EXPECT_EQ(e.diagnostics().front().line, 8) << e.what();  // vertex_alpha's bad value, not a hazard
}

// ---- messages that name the mistake ----
TEST(StudyGuards, MessagesNameTheMistake) {
  expect_error_at("[robot]\ninertia = \"thesis\"\n" + kTraj, 2, 11, "did you mean 'thesis_m11'?");
  const StudyError every0 = error_of("[study]\nhistories = \"every=0\"\n" + kTraj);
  EXPECT_EQ(std::string(every0.what()).find("did you mean 'every=0'"), std::string::npos) << every0.what();
  EXPECT_NE(std::string(every0.what()).find("N >= 1"), std::string::npos) << every0.what();
  expect_error_at(kTraj + "[block.axes]\nk = { from = 0, to = 1, stp = 0.1 }\n", 5, 25,
                  "the unknown key 'stp' and so gives no values");
  expect_error_at(kTraj + "[block.axes]\nk = { stp = 0.1 }\n", 5, 7, "did you mean 'step'?");
}

TEST(StudyGuards, ADirectoryIsNotAStudy) {
  const auto dir = std::filesystem::temp_directory_path() / ("ks_guard_dir_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "a.toml") << kTraj;
  try {
    load_study(dir);
    ADD_FAILURE() << "a directory parsed as a study";
  } catch (const StudyError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory; expected a study file (TOML), e.g. "), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("a.toml"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// ---- what an [[optimize]] block may minimise: every numeric metric of its robot ----
TEST(StudyGuards, AnObjectiveMayBeAnyMetricOfTheRobot) {
  const std::string robot = "[robot]\nl = [1.0, 1.0, 0.5, 0.5]\nm = [5.0, 2.0, 0.5, 0.5]\nb = 0.1\n";  // lines 1-4
  auto opt = [&](const std::string& objective) {
    return robot + "[[optimize]]\nname = \"o\"\nobjective = " + objective +
           "\nvariables = { k = [0, 1] }\nlocal = { algorithm = \"LN_BOBYQA\", max_evals = 5 }\n";
  };
  // the fourth joint's peak torque of a 4R arm, and a weighted sum with a tracking metric
  const Study s = parse_study(opt("\"tau4_inf\""));
  ASSERT_EQ(s.optimizations.size(), 1u);
  EXPECT_EQ(s.optimizations[0].objective_text, "tau4_inf");
  EXPECT_EQ(parse_study(opt("{ tau4_inf = 1, max_tracking_error = 100 }")).optimizations[0].objective.size(), 2u);
  // a fifth joint it does not have: refused, naming the metrics it has
  expect_error_at(opt("\"tau5_inf\""), 7, 13, "unknown objective 'tau5_inf' for trajectory runs");
  expect_error_at(opt("\"tau5_inf\""), 7, 13, "tau4_inf");
  // text metrics (the status) are not objectives; failure_rate is
  expect_error_at(opt("\"status\""), 7, 13, "unknown objective 'status'");
  EXPECT_EQ(parse_study(opt("\"failure_rate\"")).optimizations[0].objective_text, "failure_rate");
}
