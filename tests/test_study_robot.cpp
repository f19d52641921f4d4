// [robot] in study files: the seed's 3R, n-link planar arms, URDF robots; the task against the robot;
// every bad input located at FILE:LINE:COL with what was expected.
#include <gtest/gtest.h>

#include <algorithm>

#include <filesystem>
#include <cmath>
#include <fstream>
#include <iterator>

#include "model/chain_dynamics.hpp"
#include "model/dynamics.hpp"
#include "model/kinematics.hpp"
#include "schema/params.hpp"
#include "study/study.hpp"

using namespace ks;
namespace fs = std::filesystem;

namespace {

/// A scratch folder holding a study file's neighbours (URDF files), removed at the end of the test.
class Folder {
 public:
  Folder() : dir_(fs::temp_directory_path() / ("ks_robot_" + std::to_string(::getpid()) + "_" + std::to_string(next_++))) {
    fs::create_directories(dir_);
  }
  ~Folder() { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
  std::string study() const { return (dir_ / "s.toml").string(); }

 private:
  static inline int next_ = 0;
  fs::path dir_;
};

std::string studies_dir() { return std::string(KS_SOURCE_DIR) + "/studies/"; }

const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";
const std::string kIk = "[[block]]\nname = \"b\"\nkind = \"ik\"\nproblem = \"position\"\n";

/// The parse error of `text` (as file `file`): its first diagnostic.
StudyDiagnostic first_error(const std::string& text, const std::string& file = "bad.toml") {
  try {
    parse_study(text, file);
  } catch (const StudyError& e) {
    if (!e.diagnostics().empty()) return e.diagnostics().front();
  }
  ADD_FAILURE() << "no StudyError for:\n" << text;
  return {};
}

void expect_error(const std::string& text, int line, int col, const std::string& part,
                  const std::string& file = "bad.toml") {
  const StudyDiagnostic d = first_error(text, file);
  EXPECT_EQ(d.line, line) << d.str();
  EXPECT_EQ(d.column, col) << d.str();
  EXPECT_NE(d.message.find(part), std::string::npos) << d.str();
  EXPECT_NE(d.message.find("expected"), std::string::npos) << d.str();
}

/// A two-link URDF with `joint2` of type `type2`, and a tool link after a fixed joint.
std::string two_link_urdf(const std::string& type2 = "revolute", double mass2 = 1.0) {
  const std::string i2 = mass2 > 0 ? R"(ixx="0.001" iyy="0.08" izz="0.08")" : R"(ixx="0" iyy="0" izz="0")";
  return R"(<?xml version="1.0"?>
<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0.001" iyy="0.08" izz="0.08" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value=")" + std::to_string(mass2) + R"("/><origin xyz="0.5 0 0"/>
    <inertia )" + i2 + R"( ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/></joint>
  <joint name="j2" type=")" + type2 + R"("><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="5"/></joint>
  <joint name="jt" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="1 0 0"/></joint>
</robot>
)";
}

/// The diagnostic of `text` at `line` (method = "vertex_alpha" on such a robot is an error of its own).
StudyDiagnostic error_at(const std::string& text, int line) {
  try {
    parse_study(text, "bad.toml");
  } catch (const StudyError& e) {
    for (const StudyDiagnostic& d : e.diagnostics())
      if (d.line == line) return d;
    ADD_FAILURE() << "no error at line " << line << ": " << e.what();
    return {};
  }
  ADD_FAILURE() << "no StudyError for:\n" << text;
  return {};
}

std::string replaced_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t p = text.find(from); p != std::string::npos; p = text.find(from, p + to.size())) text.replace(p, from.size(), to);
  return text;
}

}  // namespace

TEST(StudyRobot, DefaultIsTheSeedClosedForm) {
  const Study s = parse_study(kTraj, "s.toml");
  EXPECT_EQ(s.chain, nullptr);
  ASSERT_NE(s.arm_chain, nullptr);  // the position / pose IK problems' chain: the seed arm
  EXPECT_EQ(s.arm_chain->dof(), 3);
  const RobotShape r = s.robot_shape();
  EXPECT_FALSE(r.chain);
  EXPECT_EQ(r.joints, 3);
  EXPECT_TRUE(r.vertex_alpha());
}

TEST(StudyRobot, PlanarArmOfFourLinksIsAChainWithPerJointColumns) {
  const Study s = parse_study("[robot]\nl = [0.9, 0.9, 0.8, 0.6]\nm = [3.6, 3.6, 3.2, 2.4]\nb = 0.06\n" + kTraj, "s.toml");
  ASSERT_NE(s.chain, nullptr);
  EXPECT_EQ(s.chain->dof(), 4);
  EXPECT_TRUE(s.chain->planar());
  // the chain's tip at q = 0 is the sum of the lengths along x (an oracle independent of the parser)
  ChainData d;
  forward_kinematics(*s.chain, d, VecN::Zero(4));
  EXPECT_NEAR(d.tip.p.x(), 3.2, 1e-12);
  const Block& b = s.blocks.front();
  for (const char* c : {"q0_1", "q0_4", "alpha1A", "k"}) EXPECT_NE(b.column_index(c), Block::npos) << c;
  for (const char* c : {"inertia", "vertex_alpha_2", "q0_5"}) EXPECT_EQ(b.column_index(c), Block::npos) << c;
  std::vector<std::string> metric_names;
  for (const MetricDef& m : b.metrics()) metric_names.push_back(m.name);
  EXPECT_NE(std::find(metric_names.begin(), metric_names.end(), "tau4_inf"), metric_names.end());
}

TEST(StudyRobot, ThreeLinksWithRecursiveDynamicsEqualTheSeedArm) {
  const Study s = parse_study("[robot]\ndynamics = \"recursive\"\n" + kTraj, "s.toml");
  ASSERT_NE(s.chain, nullptr);
  ChainData d;
  MatN M;
  const VecN q = joint_vector({0.3, -0.7, 1.1});
  crba(*s.chain, d, q, M);
  const Mat3 Mc = mass_matrix(PlanarArm3::seed(), joint_trig(Eigen::Vector3d(q.head<3>())));
  EXPECT_LT((M - MatN(Mc)).norm(), 1e-12 * Mc.norm());
}

TEST(StudyRobot, PlanarArmErrorsAreLocated) {
  expect_error("[robot]\nl = [1, 1, 1, 1]\n" + kTraj, 2, 5, "m is not given");
  expect_error("[robot]\nl = [1, 1, 1, 1]\nm = [1, 1, 1]\n" + kTraj, 3, 5, "expected an array of 4 numbers");
  expect_error("[robot]\nl = [1]\nm = [1]\n" + kTraj, 2, 5, "expected an array of 2 to 8");
  expect_error("[robot]\nl = [1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + kTraj, 2, 5, "expected an array of 2 to 8");
  expect_error("[robot]\nl = [1, 1, 1, 1]\nm = [1, 1, 1, 1]\nlimits = [[0, 1], [0, 1], [0, 1], [2, 1]]\n" + kTraj, 4,
               35, "expected lower < upper");
  expect_error("[robot]\nl = [1, 1, 1, 1]\nm = [1, 1, 1, 1]\ninertia = \"thesis_m11\"\n" + kTraj, 4, 11,
               "closed form of the seed's 3R");
  expect_error("[robot]\nl = [1, 1, 1, 1]\nm = [1, 1, 1, 1]\ndynamics = \"closed_form\"\n" + kTraj, 4, 12,
               "seed's 3-link arm");
  expect_error("[robot]\nbase = \"b\"\n" + kTraj, 2, 8, "URDF robots");
}

TEST(StudyRobot, VertexOutOfReachIsLocated) {
  // a 4-link arm of total length 1.2 m cannot reach the seed's square (2.1 m away)
  expect_error("[robot]\nl = [0.3, 0.3, 0.3, 0.3]\nm = [1, 1, 1, 1]\n[task]\nvertices = [[0.5, 0.5], [1.5, 1.5]]\n"
               "durations = [1]\n" + kTraj,
               5, 25, "robot's reach");
}

TEST(StudyRobot, RedundancyAndVertexAlphaAreCheckedAgainstTheRobot) {
  // two links on a planar position path: no redundancy left
  expect_error("[robot]\nl = [1.5, 1.5]\nm = [1, 1]\n" + kTraj, 4, 1, "its start fixes the tip angle too");
  // vertex_alpha is the seed's 3-joint baseline
  expect_error("[robot]\nl = [0.8, 0.8, 0.7, 0.5]\nm = [1, 1, 1, 1]\n" + kTraj + "method = \"vertex_alpha\"\n", 7, 10,
               "not for a planar arm of more than 3 joints");
  expect_error("[robot]\nl = [0.8, 0.8, 0.7, 0.5]\nm = [1, 1, 1, 1]\n" + kTraj + "[block.axes]\npreset = [\"1a\", \"3\"]\n",
               8, 1, "the preset axis includes it");
  // global_spline on a chain: planar revolute arms; the seed's vertex family and start are its 3R's
  expect_error("[robot]\nl = [0.8, 0.8, 0.7, 0.5]\nm = [1, 1, 1, 1]\n" + kTraj +
                   "method = \"global_spline\"\nglobal_start = \"vertex\"\n",
               8, 16, "the seed's vertex family");
  expect_error("[robot]\nl = [0.8, 0.8, 0.7, 0.5]\nm = [1, 1, 1, 1]\n" + kTraj +
                   "method = \"global_spline\"\n[block.axes]\nspline = [\"cubic\", \"vertex_quintic\"]\n",
               9, 1, "the spline axis includes it");
}

TEST(StudyRobot, UrdfRobotLoadsRelativeToTheStudy) {
  Folder f;
  f.write("two.urdf", two_link_urdf());
  const Study s = parse_study("[robot]\nurdf = \"two.urdf\"\nbase = \"base\"\ntip = \"tool\"\n" + kIk, f.study());
  ASSERT_NE(s.chain, nullptr);
  EXPECT_EQ(s.chain->dof(), 2);
  EXPECT_TRUE(s.chain->planar());
  // gravity not given: base -z (URDF's z up), normal to this arm's base xy plane (an IK study needs none)
  EXPECT_EQ(s.base_chain->gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.chain->gravity, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.robot_text, two_link_urdf());
  EXPECT_EQ(s.robot_file, "two.urdf");
  // the URDF is part of the study's identity (resume refuses another robot)
  f.write("two.urdf", two_link_urdf("revolute", 2.0));
  const Study s2 = parse_study("[robot]\nurdf = \"two.urdf\"\nbase = \"base\"\ntip = \"tool\"\n" + kIk, f.study());
  EXPECT_NE(s.sha256, s2.sha256);
}

TEST(StudyRobot, UrdfErrorsAreLocatedInTheStudy) {
  Folder f;
  f.write("two.urdf", two_link_urdf());
  f.write("floating.urdf", two_link_urdf("floating"));
  f.write("planar.urdf", two_link_urdf("planar"));
  f.write("massless.urdf", two_link_urdf("revolute", 0.0));
  f.write("broken.urdf", "<robot name=\"x\"><link name=\"a\"></robot>");
  const std::string file = f.study();
  auto robot = [](const std::string& urdf, const std::string& base, const std::string& tip) {
    return "[robot]\nurdf = \"" + urdf + "\"\nbase = \"" + base + "\"\ntip = \"" + tip + "\"\n" + kIk;
  };
  expect_error(robot("missing.urdf", "base", "tool"), 2, 8, "cannot read the URDF file", file);
  expect_error(robot("broken.urdf", "base", "tool"), 2, 8, "broken.urdf", file);
  expect_error(robot("two.urdf", "bsae", "tool"), 3, 8, "base", file);
  expect_error(robot("two.urdf", "base", "tol"), 4, 7, "tool", file);   // did you mean 'tool'
  expect_error(robot("two.urdf", "tool", "base"), 2, 8, "base", file);  // the tip is not below the base
  expect_error(robot("floating.urdf", "base", "tool"), 2, 8, "floating", file);
  expect_error(robot("planar.urdf", "base", "tool"), 2, 8, "planar", file);
  expect_error("[robot]\nurdf = \"two.urdf\"\ntip = \"tool\"\n" + kIk, 2, 8, "without base", file);
  expect_error("[robot]\nurdf = \"two.urdf\"\nbase = \"base\"\ntip = \"tool\"\nl = [1, 1, 1]\n" + kIk, 5, 5,
               "describes a planar arm", file);
}

TEST(StudyRobot, MasslessTipIsASingularChain) {
  Folder f;
  f.write("massless.urdf", two_link_urdf("revolute", 0.0));
  const StudyDiagnostic d =
      first_error("[robot]\nurdf = \"massless.urdf\"\nbase = \"base\"\ntip = \"tool\"\n" + kIk, f.study());
  EXPECT_EQ(d.line, 2) << d.str();
  EXPECT_NE(d.message.find("expected"), std::string::npos) << d.str();
}

TEST(StudyRobot, SpatialTaskNeedsThreeCoordinatesAndHoldsOrientation) {
  const std::string robot = "[robot]\nurdf = \"" + studies_dir() + "robots/arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n";
  const Study s = parse_study(robot + "[task]\nvertices = [[0.5, -0.1, 0.5], [0.5, 0.1, 0.5]]\ndurations = [1]\n"
                                      "orientation = \"hold\"\n" + kTraj, "s.toml");
  ASSERT_NE(s.chain, nullptr);
  EXPECT_EQ(s.chain->dof(), 7);
  EXPECT_FALSE(s.chain->planar());
  EXPECT_NEAR(s.chain->gravity.z(), -9.81, 1e-15);  // spatial: -z unless gravity is given
  EXPECT_TRUE(s.task.hold_orientation);
  EXPECT_DOUBLE_EQ(s.task.vertex(1).z(), 0.5);
  expect_error(robot + "[task]\nvertices = [[0.5, -0.1], [0.5, 0.1]]\ndurations = [1]\n" + kTraj, 6, 13,
               "expected [x, y, z]");
  expect_error(robot + "[task]\nvertices = [[0.5, -0.1, 0.5], [0.5, 0.1, 0.5]]\ndurations = [1]\norientation = [0, 0]\n" +
                   kTraj,
               8, 15, "expected \"hold\"");
}

// Found by the study parser's fuzz target: a Table 4 preset optimised on a robot without the seed
// arm's alpha1A (a URDF chain) read the block's column table out of range; it is a located error.
TEST(StudyRobot, SeedPresetOptimisationNeedsTheSeedArmsParameters) {
  const std::string text = "[robot]\nurdf = \"robots/arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n"
                           "[task]\nvertices = [[0.5, 0, 0.6], [0.5, 0.2, 0.6], [0.5, 0.2, 0.8], [0.5, 0, 0.6]]\ndurations = [1, 1, 1]\n"
                           "[[optimize]]\npreset = \"1h\"\n[optimize.local]\nalgorithm = \"LN_BOBYQA\"\nmax_evals = 10\n";
  const StudyDiagnostic d = first_error(text, KS_SOURCE_DIR "/studies/found.toml");
  EXPECT_EQ(d.line, 8) << d.str();
  EXPECT_NE(d.message.find("preset '1h' optimises alpha1A"), std::string::npos) << d.str();
  EXPECT_NE(d.message.find("expected variables"), std::string::npos) << d.str();
}

// vertex_alpha = [...] is shorthand for vertex_alpha_2 .. vertex_alpha_5 (the seed square's vertices):
// taken where the robot has those parameters (a planar 3-joint arm on a position path), refused at the
// key elsewhere -- in a [[block]] and in an [[optimize]], never a crash.
TEST(StudyRobot, VertexAlphaShorthandOnEveryRobotKind) {
  const std::string block = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"vertex_alpha\"\n"
                            "vertex_alpha = [10, 20, 30, 40]\n";
  const std::string optimize = "[[optimize]]\nname = \"o\"\nkind = \"trajectory\"\nmethod = \"vertex_alpha\"\n"
                               "vertex_alpha = [10, 20, 30, 40]\nvariables = { alpha1A = [-180, 180] }\n"
                               "[optimize.local]\nalgorithm = \"LN_BOBYQA\"\nmax_evals = 10\n";
  const std::string urdf = "[robot]\nurdf = \"" + studies_dir() + "robots/";
  struct Robot {
    std::string text;  // [robot] or nothing
    bool takes;
  };
  const std::vector<Robot> robots = {
      {"", true},                                                                       // the seed's closed form
      {"[robot]\nl = [1, 1, 1]\nm = [5, 2, 1]\ndynamics = \"recursive\"\n", true},      // an n-link arm of 3
      {"[robot]\nl = [0.9, 0.9, 0.8, 0.6]\nm = [3.6, 3.6, 3.2, 2.4]\nb = 0.06\n", false},  // of 4
      {urdf + "seed3r.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\ngravity = [0, -9.81, 0]\n", true},
      {urdf + "planar4r.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\ngravity = [0, -9.81, 0]\n", false},
  };
  for (const Robot& r : robots) {
    const int key_line = 5 + static_cast<int>(std::count(r.text.begin(), r.text.end(), '\n'));  // vertex_alpha's
    for (const std::string& table : {block, optimize}) {
      SCOPED_TRACE(r.text + table);
      if (r.takes) {
        const Study s = parse_study(r.text + table, "s.toml");
        const Block& b = table == block ? s.blocks.front() : s.optimizations.front().block();
        EXPECT_NEAR(std::get<double>(b.value(0, "vertex_alpha_3")), 20 * M_PI / 180, 1e-15);
        EXPECT_NEAR(std::get<double>(b.value(0, "vertex_alpha_5")), 40 * M_PI / 180, 1e-15);
      } else {
        const StudyDiagnostic d = error_at(r.text + table, key_line);
        EXPECT_EQ(d.column, 1) << d.str();
        EXPECT_NE(d.message.find("not for a planar arm of 4 joints"), std::string::npos) << d.str();
        EXPECT_NE(d.message.find("expected no vertex_alpha"), std::string::npos) << d.str();
      }
    }
  }
  // the 7-DOF arm: a spatial robot
  const std::string arm7 = urdf + "arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n[task]\n"
                                  "vertices = [[0.5, -0.1, 0.4], [0.5, 0.1, 0.4]]\ndurations = [1]\n";
  for (const std::string& table : {block, optimize}) {
    const StudyDiagnostic d = error_at(arm7 + replaced_all(table, "[10, 20, 30, 40]", "[10]"), 12);
    EXPECT_NE(d.message.find("not for a spatial robot"), std::string::npos) << d.str();
  }
}

// A robot in error is the only error: its task and blocks are not checked against another robot.
TEST(StudyRobot, RobotErrorHasNoFollowOnErrors) {
  Folder f;
  f.write("bad.urdf", std::string(std::istreambuf_iterator<char>(std::ifstream(std::string(KS_SOURCE_DIR) +
                                                                              "/tests/fuzz/urdf_bad/mass_unit.urdf").rdbuf()),
                                  {}));
  const std::string text = "[robot]\nurdf = \"bad.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n[task]\n"
                           "vertices = [[0.5, -0.1, 0.4], [0.5, 0.1, 0.4]]\ndurations = [1]\n" + kTraj + "q0_7 = 10\n";
  try {
    parse_study(text, f.study());
    ADD_FAILURE() << "no error";
  } catch (const StudyError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u) << e.what();
    EXPECT_EQ(e.diagnostics()[0].line, 2);
    EXPECT_NE(e.diagnostics()[0].message.find("bad.urdf:"), std::string::npos) << e.what();
    EXPECT_NE(e.diagnostics()[0].message.find("3.0kg"), std::string::npos) << e.what();
  }
}

// The reach bound: the sum of the offsets between successive joints from the first joint to the tip
// (in the plane for a planar chain). Lengths from the robots' own descriptions.
TEST(StudyRobot, VertexBeyondTheReachBoundOfEveryRobotKind) {
  const std::string two = "durations = [1]\n" + kTraj;
  // the seed's closed form: links of 1 m, reach 3 m; (3.5, 0) is 3.5 m away
  const StudyDiagnostic seed = first_error("[task]\nvertices = [[1, 0], [3.5, 0]]\n" + two);
  EXPECT_EQ(seed.line, 2);
  EXPECT_EQ(seed.column, 21);
  EXPECT_NE(seed.message.find("vertex 2 is 3.5 m from the first joint's axis"), std::string::npos) << seed.str();
  EXPECT_NE(seed.message.find("at most 3 m"), std::string::npos) << seed.str();
  // an n-link arm: 0.9 + 0.9 + 0.8 + 0.6 = 3.2 m
  const std::string arm4 = "[robot]\nl = [0.9, 0.9, 0.8, 0.6]\nm = [3.6, 3.6, 3.2, 2.4]\nb = 0.06\n";
  EXPECT_NE(first_error(arm4 + "[task]\nvertices = [[1, 0], [0, 3.3]]\n" + two).message.find("at most 3.2 m"),
            std::string::npos);
  EXPECT_NO_THROW(parse_study(arm4 + "[task]\nvertices = [[1, 0], [0, 3.1]]\n" + two, "s.toml"));
  // planar4r.urdf, the same lengths
  const std::string p4 = "[robot]\nurdf = \"" + studies_dir() + "robots/planar4r.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\ngravity = [0, -9.81, 0]\n";
  EXPECT_NE(first_error(p4 + "[task]\nvertices = [[1, 0], [3.3, 0]]\n" + two).message.find("at most 3.2 m"), std::string::npos);
  EXPECT_NO_THROW(parse_study(p4 + "[task]\nvertices = [[1, 0], [3.1, 0]]\n" + two, "s.toml"));
  // arm7.urdf: joint a1 at z = 0.15; then 0.19 + 4 x 0.2 + 0.081 + 0.045 + 0.10 = 1.216 m to the tool
  const std::string a7 = "[robot]\nurdf = \"" + studies_dir() + "robots/arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n";
  const StudyDiagnostic far = first_error(a7 + "[task]\nvertices = [[0.5, 0, 0.6], [0.9, 0, 1.35]]\n" + two);
  EXPECT_EQ(far.line, 6);
  EXPECT_EQ(far.column, 28);
  EXPECT_NE(far.message.find("vertex 2 is 1.5 m from the first joint,"), std::string::npos) << far.str();  // (0.9, 1.2)
  EXPECT_NE(far.message.find("at most 1.216 m"), std::string::npos) << far.str();
  EXPECT_NO_THROW(parse_study(a7 + "[task]\nvertices = [[0.5, 0, 0.6], [0.5, 0, 1.2]]\n" + two, "s.toml"));  // 1.163 m
}
