// Study files: SHA-256, located errors for every kind of bad input, the shipped studies.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "common/did_you_mean.hpp"
#include "methods/closed_form/seed_cases.hpp"
#include "study/sha256.hpp"
#include "study/study.hpp"
#include "study_errors.hpp"

using namespace ks;
using namespace ks::study_test;

namespace {

std::string studies_dir() { return std::string(KS_SOURCE_DIR) + "/studies/"; }

const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";  // lines 1-3
const std::string kIk = "[[block]]\nname = \"b\"\nkind = \"ik\"\n";
}  // namespace

// ---- SHA-256 (FIPS 180-2 appendix B) ----
TEST(Sha256, FipsVectors) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, MillionAInPiecesMatchesFips) {
  Sha256 h;
  const std::string chunk(1000, 'a');
  for (int i = 0; i < 1000; ++i) h.update(chunk);
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (auto b : h.digest()) (out += hex[b >> 4]) += hex[b & 15];
  EXPECT_EQ(out, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// ---- Errors: each kind located at its token ----
TEST(StudyErrors, TomlSyntax) { expect_error_at(kTraj + "k = \n", 4, 5, "TOML syntax"); }

TEST(StudyErrors, UnknownKeySuggestsClosest) {
  expect_error_at(kTraj + "k = 0.5\nalpha1a = 10\n", 5, 1, "did you mean 'alpha1A'?");
  expect_error_at("[study]\nname = \"x\"\nhistory = \"full\"\n" + kTraj, 3, 1, "did you mean 'histories'?");
  expect_error_at("[robt]\n" + kTraj, 1, 2, "did you mean 'robot'?");
}

TEST(StudyErrors, UnknownAxisSuggestsClosest) {
  expect_error_at(kTraj + "[block.axes]\nalpha1a = [1, 2]\n", 5, 1, "did you mean 'alpha1A'?");
}

TEST(StudyErrors, WrongType) {
  expect_error_at(kTraj + "k = \"half\"\n", 4, 5, "k is a string; expected a number");
  expect_error_at(kIk + "max_iter = 10.5\n", 4, 12, "expected an integer");
  expect_error_at(kTraj + "[block.axes]\nk = 0.5\n", 5, 5, "a single value");
}

TEST(StudyErrors, EmptyOrInvertedRanges) {
  expect_error_at(kTraj + "[block.axes]\nalpha1A = { from = 35, to = -25, step = 0.25 }\n", 5, 11, "empty range");
  expect_error_at(kTraj + "[block.axes]\nk = { from = 0, to = 1, step = 0 }\n", 5, 32, "step = 0");
  expect_error_at(kTraj + "[block.axes]\nk = { from = 0, to = 1, count = 0 }\n", 5, 33, "count = 0");
  expect_error_at(kTraj + "[block.axes]\nk = []\n", 5, 5, "empty value list");
  expect_error_at(kTraj + "[block.axes]\nk = { random = { from = 0, to = 1, count = 0, seed = 1 } }\n", 5, 44,
                  "count = 0");
}

TEST(StudyErrors, UnknownNames) {
  expect_error_at(kTraj + "method = \"local_weigted\"\n", 4, 10, "did you mean 'local_weighted'?");
  expect_error_at(kTraj + "preset = \"6a\"\n", 4, 10, "unknown preset '6a'");
  expect_error_at(kTraj + "[block.axes]\npreset = [\"1a\", \"1x\"]\n", 5, 17, "unknown preset '1x'");
  expect_error_at("[[block]]\nname = \"b\"\nkind = \"trajectroy\"\n", 3, 8, "did you mean 'trajectory'?");
  expect_error_at(kIk + "method = \"levenberg\"\n", 4, 10, "unknown method 'levenberg'");
  expect_error_at(kIk + "problem = \"scra\"\n", 4, 11, "did you mean 'scara'?");
}

TEST(StudyErrors, ParameterOfTheOtherKind) {
  expect_error_at(kTraj + "lambda = 0.1\n", 4, 1, "does not belong to a trajectory block");
  expect_error_at(kIk + "[block.axes]\nalpha1A = [1, 2]\n", 5, 1, "does not belong to an ik block");
}

TEST(StudyErrors, ZipWithUnequalLengths) {
  expect_error_at(kTraj + "zip = [[\"alpha1A\", \"k\"]]\n[block.axes]\nalpha1A = [1, 2, 3]\nk = [0, 1]\n", 4, 8,
                  "different lengths: alpha1A (3), k (2)");
  expect_error_at(kTraj + "zip = [[\"alpha1A\", \"kk\"]]\n[block.axes]\nalpha1A = [1, 2]\nk = [0, 1]\n", 4, 20,
                  "did you mean 'k'?");
}

TEST(StudyErrors, TooManyRuns) {
  const std::string t = kTraj + "[block.axes]\nalpha1A = { from = 0, to = 99, step = 1 }\nk = { from = 0, to = 1, count = 11 }\n";
  expect_error_at(t, 1, 1, "too many runs", StudyOptions{.max_runs = 1000, .robot_text = {}});
  EXPECT_NO_THROW(parse_study(t, "ok.toml", StudyOptions{.max_runs = 1100, .robot_text = {}}));
  // The default limit is 50 million; the caller raises it, [study] max_runs only lowers it.
  const std::string big = kTraj + "[block.axes]\nalpha1A = { from = 0, to = 9999, step = 1 }\n"
                                  "k = { from = 0, to = 1, count = 10000 }\n";  // 1e8 runs
  expect_error_at(big, 1, 1, "expected at most 50000000");
  EXPECT_EQ(parse_study(big, "ok.toml", StudyOptions{.max_runs = 200000000, .robot_text = {}}).run_count(), 100000000u);
  expect_error_at("[study]\nmax_runs = 200000000\n" + big, 2, 12, "a study may only lower the limit");
  // A single range with too many values is refused before it is materialised.
  expect_error_at(kTraj + "[block.axes]\nk = { from = 0, to = 1, step = 1e-12 }\n", 5, 5, "values; expected at most");
}

TEST(StudyErrors, MoreBlockMistakes) {
  expect_error_at("[[block]]\nname = \"b\"\n", 1, 1, "has no kind");
  expect_error_at(kTraj + "[[block]]\nname = \"b\"\nkind = \"ik\"\n", 5, 8, "duplicate block name 'b'");
  expect_error_at(kTraj + "k = 0.5\n[block.axes]\nk = [0, 1]\n", 4, 1, "both a fixed parameter and an axis");
  expect_error_at(kTraj + "vertex_alpha = [1, 2, 3]\n", 4, 16, "expected an array of 4 angles");
  expect_error_at(kTraj + "dt = -1\n", 4, 6, "expected dt > 0");
  // a dt that asks for more than 1e7 samples on the 2 s square, fixed or swept, and in [task]
  expect_error_at(kTraj + "dt = 1e-9\n", 4, 6, "samples on the 2 s path; expected at most");
  expect_error_at(kTraj + "[block.axes]\ndt = [1e-3, 1e-8]\n", 5, 13, "expected at most");
  expect_error_at("[task]\ndt = 1e-8\n" + kTraj, 2, 6, "samples on the 2 s path");
  expect_error_at("[study]\nhistories = \"every=0\"\n" + kTraj, 2, 13, "every=N");
  expect_error_at("[study]\nname = \"x\"\n", 1, 1, "no blocks");
  expect_error_at("[block]\nname = \"b\"\nkind = \"ik\"\n", 1, 1, "expected [[block]] tables");
  expect_error_at(kTraj + "[block.axes]\nk = { lhs = { from = 0, to = 1 } }\n", 5, 13, "no lhs settings");
}

TEST(StudyErrors, AxesARunWouldIgnoreAreRejected) {
  // lambda only matters to lm / lm_adaptive: sweeping it with newton would repeat runs.
  expect_error_at(kIk + "[block.axes]\nmethod = [\"newton\", \"lm\"]\nlambda = [0.1, 10]\n", 6, 1,
                  "has no effect when method = 'newton'");
  EXPECT_NO_THROW(parse_study(kIk + "[block.axes]\nmethod = [\"lm\", \"lm_adaptive\"]\nlambda = [0.1, 10]\n"));
  expect_error_at(kTraj + "method = \"vertex_alpha\"\n[block.axes]\nk = [0, 1]\n", 6, 1, "has no effect");
  expect_error_at(kTraj + "[block.axes]\nvertex_alpha_3 = [0, 1]\n", 5, 1, "has no effect when method = 'local_weighted'");
  expect_error_at(kIk + "problem = \"scara\"\n[block.axes]\ntarget_alpha = [0, 1]\n", 6, 1, "has no effect");
  expect_error_at(kIk + "[block.axes]\nproblem = [\"scara\", \"planar3r_pose\"]\n", 5, 21, "mixes the SCARA");
}

TEST(StudyErrors, CollectsEveryError) {
  const StudyError e = error_of(kTraj + "alpha1a = 1\nk = \"x\"\n[block.axes]\nmethod = [\"lw\"]\n");
  ASSERT_EQ(e.diagnostics().size(), 3u) << e.what();
  EXPECT_EQ(e.diagnostics()[0].line, 4);
  EXPECT_EQ(e.diagnostics()[1].line, 5);
  EXPECT_EQ(e.diagnostics()[2].line, 7);
  const std::string w = e.what();
  EXPECT_EQ(std::count(w.begin(), w.end(), '\n'), 2 + 3 * 3 + 2);  // 3 headlines, 3 lines of source each, 2 blank lines
}

TEST(StudyErrors, UnreadableFile) {
  try {
    load_study("/nonexistent/dir/x.toml");
    FAIL();
  } catch (const StudyError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/x.toml:1:1: error: cannot read", 0), 0u);
  }
}

// ---- Diagnostics as rustc shows them: the source line, a caret under the column, notes ----
// Columns count Unicode code points, as toml++ counts them (not bytes): 'ü' or '→' is one column, a tab
// is one column. The caret line counts terminal cells: a tab is shown as 4 spaces, an East Asian wide
// character takes 2 cells.
namespace {
std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> v;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

/// The first diagnostic of `text` is on `line`; rendered, it shows that line in the gutter and carets
/// under `token` (whose first occurrence in the line starts `cells` terminal cells in; default: its
/// byte offset, for ASCII lines), one per cell of the token.
StudyDiagnostic expect_caret(const std::string& text, int line, const std::string& token, int cells = -1) {
  const StudyError e = error_of(text);
  if (e.diagnostics().empty()) return {};
  const StudyDiagnostic& d = e.diagnostics().front();
  EXPECT_EQ(d.line, line) << e.what();
  const std::string source = lines_of(text).at(std::size_t(line - 1));
  const std::size_t at = source.find(token);
  EXPECT_NE(at, std::string::npos);
  if (cells < 0) cells = int(at);
  const std::string n = std::to_string(line), pad(n.size(), ' ');
  const auto r = lines_of(d.str());
  EXPECT_EQ(r.size(), 4u) << d.str();
  if (r.size() < 4) return d;
  EXPECT_EQ(r[0], d.headline());
  EXPECT_EQ(r[1], pad + " |");
  EXPECT_EQ(r[2].rfind(n + " | ", 0), 0u) << d.str();
  EXPECT_EQ(r[3], pad + " | " + std::string(std::size_t(cells), ' ') + std::string(token.size(), '^')) << d.str();
  return d;
}
}  // namespace

TEST(StudyDiagnostics, CaretUnderAnUnknownKey) {
  const std::string text = kTraj + "k = 0.5\n  alpah1A = 3\n";
  const StudyDiagnostic d = expect_caret(text, 5, "alpah1A");
  EXPECT_EQ(d.column, 3);
  EXPECT_EQ(d.str(), "bad.toml:5:3: error: " + d.message + "\n  |\n5 |   alpah1A = 3\n  |   ^^^^^^^");
}

TEST(StudyDiagnostics, CaretUnderAnUnknownAxis) {
  const StudyDiagnostic d = expect_caret(kTraj + "[block.axes]\nk = [0, 1]\n    alpha1a = [1, 2]\n", 6, "alpha1a");
  EXPECT_EQ(d.column, 5);
  EXPECT_NE(d.message.find("unknown axis 'alpha1a'"), std::string::npos);
}

TEST(StudyDiagnostics, CaretUnderABadValueInAnInlineTable) {
  const StudyDiagnostic d = expect_caret(kTraj + "[block.axes]\nk = { from = 0, to = 1, count = 2.5 }\n", 5, "2.5");
  EXPECT_EQ(d.column, 33);
  EXPECT_NE(d.message.find("count is a float; expected an integer"), std::string::npos);
  // A bad string value underlines the string with its quotes.
  expect_caret("study = { name = \"s\", histories = \"sometimes\" }\n" + kTraj, 1, "\"sometimes\"");
}

TEST(StudyDiagnostics, SourceLineIsPrintedForSyntaxErrorsToo) {
  const StudyError e = error_of(kTraj + "k = \n");
  const auto r = lines_of(e.diagnostics().front().str());
  ASSERT_EQ(r.size(), 4u) << e.what();
  EXPECT_EQ(r[2], "4 | k =");  // no trailing blank
  EXPECT_EQ(r[3], "  |     ^");
  EXPECT_EQ(e.diagnostics().front().source_line, "k = ");
}

TEST(StudyDiagnostics, MultiByteCharactersBeforeTheErrorDoNotMoveTheCaret) {
  // 'ü', '→' and 'ö' are 2, 3 and 2 bytes but one column (code point) and one cell each.
  const std::string line = "study = { description = \"Zürich → Köln\", histories = \"sometimes\" }";
  const std::string prefix = "study = { description = \"Zurich - Koln\", histories = ";  // same code points
  const StudyDiagnostic d = expect_caret(line + "\n" + kTraj, 1, "\"sometimes\"", int(prefix.size()));
  EXPECT_EQ(d.column, int(prefix.size()) + 1);                        // code points, not bytes:
  EXPECT_EQ(line.find("\"sometimes\"") + 1, prefix.size() + 1 + 4);  // the byte column would be 4 more
  // A tab is one column but shown as 4 spaces; CJK characters are one column but 2 cells wide.
  const StudyDiagnostic t = expect_caret(kTraj + "\tk = \"half\"\n", 4, "\"half\"", 4 + 4);
  EXPECT_EQ(t.column, 6);
  const std::string wide = "study = { description = \"東京\", histories = \"x\" }";
  const std::string as_columns = "study = { description = \"TK\", histories = ";   // 東京: 2 columns,
  const std::string as_cells = "study = { description = \"TOKY\", histories = ";   // 4 cells
  const StudyDiagnostic w = expect_caret(wide + "\n" + kTraj, 1, "\"x\"", int(as_cells.size()));
  EXPECT_EQ(w.column, int(as_columns.size()) + 1);
}

TEST(StudyDiagnostics, DuplicateBlockNameNotesTheFirstDefinition) {
  const StudyError e = error_of(kTraj + "[[block]]\nname = \"b\"\nkind = \"ik\"\n");
  const StudyDiagnostic& d = e.diagnostics().front();
  ASSERT_EQ(d.notes.size(), 1u) << e.what();
  EXPECT_EQ(d.notes[0].line, 2);
  EXPECT_EQ(d.notes[0].column, 8);
  EXPECT_EQ(d.str(), "bad.toml:5:8: error: duplicate block name 'b' (first at line 2); expected unique block names\n"
                     "  |\n"
                     "5 | name = \"b\"\n"
                     "  |        ^^^\n"
                     "note: bad.toml:2:8: block 'b' first defined here\n"
                     "  |\n"
                     "2 | name = \"b\"\n"
                     "  |        ^^^");
  // [[optimize]] names too, also when taken from the preset.
  const StudyError o = error_of(kTraj + "[[optimize]]\npreset = \"1g\"\n[[optimize]]\npreset = \"1g\"\n");
  ASSERT_EQ(o.diagnostics().front().notes.size(), 1u) << o.what();
  EXPECT_EQ(o.diagnostics().front().line, 6);
  EXPECT_EQ(o.diagnostics().front().notes[0].line, 4);
}

TEST(StudyDiagnostics, NotesAtTheOtherPlaceOfAConflict) {
  // fixed and an axis: the note is at the axis
  StudyError e = error_of(kTraj + "k = 0.5\n[block.axes]\nk = [0, 1]\n");
  ASSERT_EQ(e.diagnostics().front().notes.size(), 1u) << e.what();
  EXPECT_EQ(e.diagnostics().front().notes[0].line, 6);
  // vertex_alpha and vertex_alpha_3: a note at vertex_alpha_3, and one without a place
  e = error_of(kTraj + "vertex_alpha = [1, 2, 3, 4]\nvertex_alpha_3 = 7\n");
  const auto& notes = e.diagnostics().front().notes;
  ASSERT_EQ(notes.size(), 2u) << e.what();
  EXPECT_EQ(notes[0].line, 5);
  EXPECT_EQ(notes[1].line, 0);
  EXPECT_NE(std::string(e.what()).find("\n  = note: vertex_alpha = [...] is shorthand"), std::string::npos) << e.what();
  // zip groups of unequal length: each axis with its length, at its line
  e = error_of(kTraj + "zip = [[\"alpha1A\", \"k\"]]\n[block.axes]\nalpha1A = [1, 2, 3]\nk = [0, 1]\n");
  const auto& z = e.diagnostics().front().notes;
  ASSERT_EQ(z.size(), 2u) << e.what();
  EXPECT_EQ(z[0].line, 6);
  EXPECT_EQ(z[0].message, "axis 'alpha1A' has 3 values");
  EXPECT_EQ(z[1].line, 7);
  EXPECT_EQ(z[1].message, "axis 'k' has 2 values");
  // mixed SCARA / planar problems: at the first problem
  e = error_of(kIk + "[block.axes]\nproblem = [\"scara\", \"planar3r_pose\"]\n");
  ASSERT_EQ(e.diagnostics().front().notes.size(), 1u) << e.what();
  EXPECT_EQ(e.diagnostics().front().notes[0].column, 12);
  EXPECT_NE(e.diagnostics().front().notes[0].message.find("'scara'"), std::string::npos);
}

TEST(StudyDiagnostics, LongLinesAreClippedAroundTheColumn) {
  StudyDiagnostic d;
  d.file = "f.toml";
  d.line = 3;
  d.column = 301;
  d.length = 5;
  d.message = "m";
  d.source_line = std::string(300, 'a') + "TOKEN" + std::string(300, 'b');
  const auto r = lines_of(d.str());
  ASSERT_EQ(r.size(), 4u);
  const std::string shown = r[2].substr(4), carets = r[3].substr(4);
  EXPECT_EQ(shown.substr(0, 3), "...");
  EXPECT_EQ(shown.substr(shown.size() - 3), "...");
  EXPECT_LE(shown.size(), 106u);
  const std::size_t at = carets.find('^');
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(shown.substr(at, 5), "TOKEN");
  EXPECT_EQ(carets.substr(at), "^^^^^");
}

TEST(StudyDiagnostics, UnreadableFileHasNoGutter) {
  try {
    load_study("/nonexistent/dir/x.toml");
    FAIL();
  } catch (const StudyError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_FALSE(e.diagnostics().front().source_line.has_value());
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/dir/x.toml:1:1: error: cannot read the study file; expected a readable TOML file");
  }
}

TEST(EditDistance, Basics) {
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("lambda", "lambda"), 0u);
}

TEST(DidYouMean, OneRuleForEveryMessage) {
  const std::vector<std::string> c{"alpha1A", "lambda", "thesis_m11", "local_weighted", "local_unweighted"};
  EXPECT_EQ(did_you_mean("lamda", c), "lambda");            // one edit
  EXPECT_EQ(did_you_mean("ALPHA1a", c), "alpha1A");         // case-insensitive
  EXPECT_EQ(did_you_mean("local_weightd", c), "local_weighted");
  EXPECT_EQ(did_you_mean("thesis", c), "thesis_m11");       // the one candidate it begins
  EXPECT_EQ(did_you_mean("local", c), "");                  // begins two: no guess
  EXPECT_EQ(did_you_mean("zzzzzz", c), "");                 // nothing near
  EXPECT_EQ(did_you_mean("lambda", c), "");                 // the word itself
}

// ---- Defaults and metadata ----
TEST(Study, DefaultsAreTheSeeds) {
  const Study s = parse_study(kTraj, "dir/my_study.toml");
  EXPECT_EQ(s.name, "my_study");
  EXPECT_EQ(s.output, "results/my_study.h5");
  EXPECT_EQ(s.histories.mode, HistoryPolicy::Mode::full);
  const PlanarArm3 seed = PlanarArm3::seed();
  EXPECT_EQ(s.robot.l, seed.l);
  EXPECT_EQ(s.robot.m, seed.m);
  EXPECT_EQ(s.robot.I, seed.I);
  EXPECT_EQ(s.robot.inertia_form, InertiaForm::physical);
  EXPECT_EQ(s.task.vertices, seed_square().vertices());
  EXPECT_EQ(s.task.durations, seed_square().durations());
  EXPECT_EQ(s.task.dt, 1e-3);
  EXPECT_EQ(s.task.integrator, Integrator::semi_implicit_euler);
  EXPECT_EQ(s.sha256, sha256_hex(kTraj));
  ASSERT_EQ(s.blocks.size(), 1u);
  EXPECT_EQ(s.run_count(), 1u);
  const auto p = s.blocks[0].params(0);
  EXPECT_EQ(std::get<std::string>(p[s.blocks[0].column_index("method")]), "local_weighted");
  EXPECT_EQ(std::get<std::string>(p[s.blocks[0].column_index("integrator")]), "semi_implicit_euler");
  EXPECT_EQ(std::get<std::string>(p[s.blocks[0].column_index("inertia")]), "physical");
}

TEST(Study, MetadataRobotTask) {
  const Study s = parse_study(
      "[study]\nname = \"n\"\ndescription = \"d\"\noutput = \"o.h5\"\nhistories = \"every=10\"\n"
      "[robot]\nl = [1, 2, 3]\nm = [1, 1, 1]\nb = 0\ng = 10\ninertia = \"thesis_m11\"\n"
      "[task]\nvertices = [[1, 1], [1.5, 1]]\ndurations = [2]\ndt = 0.01\nintegrator = \"rk4\"\n" +
      kTraj + "vertex_alpha_2 = 10\n");
  EXPECT_EQ(s.name, "n");
  EXPECT_EQ(s.description, "d");
  EXPECT_EQ(s.output, "o.h5");
  EXPECT_EQ(s.histories.mode, HistoryPolicy::Mode::every);
  EXPECT_EQ(s.histories.stride, 10);
  EXPECT_EQ(s.histories.str(), "every=10");
  EXPECT_EQ(s.robot.l[2], 3.0);
  EXPECT_DOUBLE_EQ(s.robot.I[1], 2.0 * 2.0 / 12.0);
  EXPECT_EQ(s.robot.g, 10.0);
  EXPECT_EQ(s.robot.inertia_form, InertiaForm::thesis_m11);
  EXPECT_EQ(s.task.path().duration(), 2.0);
  const Block& b = s.blocks[0];
  // A two-vertex path has one vertex alpha column.
  EXPECT_NE(b.column_index("vertex_alpha_2"), Block::npos);
  EXPECT_EQ(b.column_index("vertex_alpha_3"), Block::npos);
  const auto p = b.params(0);
  EXPECT_EQ(std::get<double>(p[b.column_index("vertex_alpha_2")]), 10 * kDeg);
  EXPECT_EQ(std::get<double>(p[b.column_index("dt")]), 0.01);
  EXPECT_EQ(std::get<std::string>(p[b.column_index("integrator")]), "rk4");
  EXPECT_EQ(std::get<std::string>(p[b.column_index("inertia")]), "thesis_m11");
}

TEST(Study, ExplicitParametersOverrideAPreset) {
  const Study s = parse_study(kTraj + "preset = \"1h\"\nalpha1A = 10\n[block.axes]\nk = [0.5, 0.6]\n");
  const Block& b = s.blocks[0];
  EXPECT_EQ(b.run_count(), 2u);
  EXPECT_EQ(std::get<double>(b.value(0, "alpha1A")), 10 * kDeg);
  EXPECT_EQ(std::get<double>(b.value(1, "k")), 0.6);
  EXPECT_EQ(std::get<std::string>(b.value(0, "method")), "local_weighted");
  EXPECT_EQ(std::get<std::string>(b.value(0, "preset")), "1h");
  // Preset axis with a fixed override: the override wins in every run.
  const Study t = parse_study(kTraj + "k = 0.25\n[block.axes]\npreset = [\"1d\", \"2d\"]\n");
  EXPECT_EQ(std::get<double>(t.blocks[0].value(0, "k")), 0.25);
  EXPECT_EQ(std::get<double>(t.blocks[0].value(1, "k")), 0.25);
  EXPECT_EQ(std::get<double>(t.blocks[0].value(1, "alpha1A")), 15 * kDeg);
  EXPECT_EQ(std::get<std::string>(t.blocks[0].value(1, "method")), "local_unweighted");
}

// ---- The shipped studies ----
TEST(ShippedStudies, ParseWithHandCountedRuns) {
  struct Case {
    const char* file;
    std::uint64_t runs;
    std::size_t blocks;
  };
  for (const Case& c : {Case{"thesis_table4.toml", 21, 1}, Case{"landscape_alpha_k.toml", 241 * 21 * 2, 1},
                        Case{"ik_scara.toml", 2 * 6 * 13 * 13 + 3 * 13 * 13 + 1, 3},
                        Case{"ik_basins.toml", 3 * 201 * 201, 1}}) {
    SCOPED_TRACE(c.file);
    const Study s = load_study(studies_dir() + c.file);
    EXPECT_EQ(s.run_count(), c.runs);
    EXPECT_EQ(s.blocks.size(), c.blocks);
    std::ifstream in(studies_dir() + c.file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(s.text, ss.str());
    EXPECT_EQ(s.sha256, sha256_hex(ss.str()));
  }
}

TEST(ShippedStudies, LandscapeGrid) {
  const Study s = load_study(studies_dir() + "landscape_alpha_k.toml");
  const Block& b = s.blocks[0];
  EXPECT_EQ(s.histories.stride, 10);
  EXPECT_EQ(b.shape(), (std::vector<std::uint64_t>{2, 241, 21}));
  EXPECT_EQ(std::get<double>(b.axes()[1].values.front()), -25 * kDeg);
  EXPECT_EQ(std::get<double>(b.axes()[1].values.back()), 35 * kDeg);
  EXPECT_EQ(std::get<double>(b.axes()[2].values.back()), 1.0);
  EXPECT_EQ(b.axes()[1].unit, "rad");
}

TEST(ShippedStudies, IkScaraAndBasins) {
  const Study s = load_study(studies_dir() + "ik_scara.toml");
  const Block& damped = s.blocks[s.block_index("damped")];
  EXPECT_EQ(damped.shape(), (std::vector<std::uint64_t>{2, 6, 13, 13}));
  // The seed's start (60, 45) deg is in the grid.
  const std::uint64_t g[] = {0, 2, 6, 6};
  const auto p = damped.params(damped.local_index(g));
  EXPECT_NEAR(std::get<double>(p[damped.column_index("q0_1")]), std::numbers::pi / 3, 1e-15);
  EXPECT_NEAR(std::get<double>(p[damped.column_index("q0_2")]), std::numbers::pi / 4, 1e-15);
  EXPECT_EQ(std::get<double>(p[damped.column_index("lambda")]), 0.1);
  EXPECT_EQ(std::get<double>(p[damped.column_index("q0_3")]), 50.0);
  EXPECT_EQ(std::get<double>(p[damped.column_index("target_y")]), -80.0);
  EXPECT_EQ(damped.columns()[damped.column_index("q0_3")].unit, "mm");
  EXPECT_EQ(std::get<std::int64_t>(p[damped.column_index("max_iter")]), 5000);

  const Study basins = load_study(studies_dir() + "ik_basins.toml");
  const Block& b = basins.blocks[0];
  EXPECT_EQ(b.shape(), (std::vector<std::uint64_t>{3, 201, 201}));
  EXPECT_EQ(std::get<double>(b.value(0, "q0_1")), -std::numbers::pi);
  EXPECT_EQ(std::get<double>(b.value(b.run_count() - 1, "q0_2")), std::numbers::pi);
  EXPECT_EQ(std::get<std::string>(b.value(b.run_count() - 1, "method")), "halley");
}

TEST(ShippedStudies, ThesisTable4CarriesThePresets) {
  const Study s = load_study(studies_dir() + "thesis_table4.toml");
  EXPECT_EQ(s.robot.inertia_form, InertiaForm::thesis_m11);
  EXPECT_EQ(s.histories.mode, HistoryPolicy::Mode::full);
  const Block& b = s.blocks[0];
  ASSERT_EQ(b.run_count(), seed_cases().size());
  for (std::uint64_t i = 0; i < b.run_count(); ++i) {
    const SeedCase& c = seed_cases()[i];
    SCOPED_TRACE(std::string(c.name));
    const auto p = b.params(i);
    auto num = [&](const char* n) { return std::get<double>(p[b.column_index(n)]); };
    auto str = [&](const char* n) { return std::get<std::string>(p[b.column_index(n)]); };
    EXPECT_EQ(str("preset"), c.name);
    EXPECT_EQ(str("method"), to_string(c.method));
    EXPECT_EQ(num("k"), c.k);
    EXPECT_EQ(num("alpha1A"), c.alpha1A_deg * kDeg);
    EXPECT_EQ(num("alpha1A"), c.options().alpha1A);
    for (int v = 0; v < 4; ++v)
      EXPECT_EQ(num(("vertex_alpha_" + std::to_string(v + 2)).c_str()), c.vertex_alpha_deg[v] * kDeg);
    EXPECT_EQ(str("inertia"), "thesis_m11");
    EXPECT_EQ(num("K_N"), 0.0);
  }
}

TEST(ShippedStudies, ReadmeExampleParses) {
  std::ifstream in(studies_dir() + "README.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string md = ss.str();
  const auto begin = md.find("```toml\n");
  ASSERT_NE(begin, std::string::npos);
  const auto end = md.find("```\n", begin + 8);
  const Study s = parse_study(md.substr(begin + 8, end - begin - 8), "README.md");
  // 241 x 21 + 5 presets + 3 zipped pairs x 64 LHS points x 4 random + 2 x 6 x 13 x 3
  EXPECT_EQ(s.run_count(), 241u * 21 + 5 + 3 * 64 * 4 + 2 * 6 * 13 * 3);
  const Block& v = s.blocks[s.block_index("vertex_search")];
  EXPECT_EQ(v.shape(), (std::vector<std::uint64_t>{3, 64, 4}));
}

TEST(StudyErrors, ScaraAndPlanarIkBlocksAreSeparateStudies) {
  // Their q0_3, target_* and tol columns have different units (mm; rad, m): one column cannot say both.
  const std::string text = kIk + "[[block]]\nname = \"p\"\nkind = \"ik\"\nproblem = \"planar3r_pose\"\n";
  expect_error_at(text, 4, 1, "would mix units");
  const StudyError e = error_of(text);
  ASSERT_EQ(e.diagnostics().front().notes.size(), 1u);
  EXPECT_EQ(e.diagnostics().front().notes.front().line, 1);  // the first ik block
}

