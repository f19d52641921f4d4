// Robots from standard DH tables ([robot] dh, robot/dh.hpp): seed 002's planar 2R, SCARA and Puma 560
// (studies/robots/*.toml) against their hand-written URDF files and against Orocos KDL chains built
// from the same DH rows with KDL::Frame::DH (the rows read from the robot file by toml++ here, not by
// the engine): tip pose, Jacobian and RNEA torques at random (q, qd, qdd), to 1e-12.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <sstream>

#include "chain_fixtures.hpp"
#include "kdl_chain.hpp"
#include "model/chain_dynamics.hpp"
#include "model/chain_kinematics.hpp"
#include "ik/chain_ik.hpp"
#include "robot/urdf.hpp"
#include "runner/placed_task.hpp"
#include "study/study.hpp"

using namespace ks;

namespace {

const std::string kRobots = KS_SOURCE_DIR "/studies/robots/";
const std::string kIk = "[[block]]\nname = \"b\"\nkind = \"ik\"\nproblem = \"position\"\n";
constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kTol = 1e-12;  // |ours - reference| <= kTol * max(1, |reference|_inf)

/// The chain the study parser builds from `[robot] dh = "<robots>/<name>.toml"` (base frame).
Chain dh_study_chain(const std::string& name) {
  const Study s = parse_study("[robot]\ndh = \"" + kRobots + name + ".toml\"\n" + kIk, "dh.toml");
  EXPECT_TRUE(s.base_chain);
  EXPECT_EQ(s.robot_format, "dh");
  return *s.base_chain;
}

/// The robot file's rows as a KDL chain: one segment per row, KDL::Frame::DH(a, alpha, d, theta) as
/// its tip frame (KDL expresses a segment's inertia in that frame: the DH link frame, as the file).
struct KdlDh {
  KDL::Chain chain;
  Eigen::Vector3d gravity;
  std::vector<std::pair<double, double>> limits;  // [rad or m]; infinite when the row has none
};

KdlDh kdl_from_file(const std::string& name) {
  const toml::table root = toml::parse_file(kRobots + name + ".toml");
  KdlDh k;
  const auto* g = root["gravity"].as_array();
  k.gravity = Eigen::Vector3d(g->get(0)->value<double>().value(), g->get(1)->value<double>().value(),
                              g->get(2)->value<double>().value());
  for (const auto& row : *root["dh"].as_array()) {
    const toml::table& t = *row.as_table();
    const auto num = [&](const char* key) { return t[key].value<double>().value(); };
    const bool prismatic = t["type"].value<std::string>().value() == "prismatic";
    const bool fixed = t["type"].value<std::string>().value() == "fixed";
    const auto& c = *t["com"].as_array();
    const auto& in = *t["inertia"].as_table();
    const auto I = [&](const char* key) { return in[key].value<double>().value_or(0.0); };
    const KDL::RigidBodyInertia inertia(
        num("mass"), KDL::Vector(c[0].value<double>().value(), c[1].value<double>().value(), c[2].value<double>().value()),
        KDL::RotationalInertia(I("ixx"), I("iyy"), I("izz"), I("ixy"), I("ixz"), I("iyz")));
    k.chain.addSegment(KDL::Segment(KDL::Joint(fixed ? KDL::Joint::None : prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ),
                                    KDL::Frame::DH(num("a"), num("alpha") * kDegree, num("d"), num("theta") * kDegree),
                                    inertia));
    if (fixed) continue;
    const double unit = prismatic ? 1.0 : kDegree;
    const auto* lim = t["limits"].as_table();
    k.limits.emplace_back(lim ? lim->get("lower")->value<double>().value() * unit : -INFINITY,
                          lim ? lim->get("upper")->value<double>().value() * unit : INFINITY);
  }
  return k;
}

template <class A, class B>
void expect_near_all(const A& ours, const B& ref, const std::string& what) {
  ASSERT_EQ(ours.rows(), ref.rows()) << what;
  ASSERT_EQ(ours.cols(), ref.cols()) << what;
  const double scale = std::max(1.0, ref.cwiseAbs().maxCoeff());
  EXPECT_LE((ours - ref).cwiseAbs().maxCoeff(), kTol * scale) << what << "\nours:\n" << ours << "\nreference:\n" << ref;
}

Eigen::Matrix3d rotation(const KDL::Rotation& R) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  return m;
}

/// The DH chain, the URDF chain and KDL's chain of the same rows agree: joints, limits, then tip pose,
/// Jacobian and RNEA torques at 300 random states (q within the limits where there are some).
/// `with_urdf` false: a robot file without a URDF twin (DH and KDL only).
void expect_same_robot(const std::string& name, bool with_urdf = true) {
  SCOPED_TRACE(name);
  const Chain dh = dh_study_chain(name);
  KdlDh k = kdl_from_file(name);
  const Chain urdf = with_urdf ? load_urdf(kRobots + name + ".urdf", "base_link", "tool", k.gravity) : dh;
  const int n = dh.dof();
  ASSERT_EQ(urdf.dof(), n);
  ASSERT_EQ(static_cast<int>(k.chain.getNrOfJoints()), n);
  EXPECT_EQ(dh.name, name);
  EXPECT_EQ(dh.planar_fast_path, urdf.planar_fast_path);
  EXPECT_EQ(dh.gravity, k.gravity);
  for (int i = 0; i < n; ++i) {
    const ChainJoint &a = dh.joints[i], &b = urdf.joints[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.lower, k.limits[i].first) << i;  // the same product of the same numbers
    EXPECT_EQ(a.upper, k.limits[i].second) << i;
    if (std::isfinite(a.lower)) EXPECT_NEAR(a.lower, b.lower, kTol) << i;
    else EXPECT_EQ(a.lower, b.lower) << i;
    if (std::isfinite(a.upper)) EXPECT_NEAR(a.upper, b.upper, kTol) << i;
    else EXPECT_EQ(a.upper, b.upper) << i;
    EXPECT_NEAR(a.mass, b.mass, kTol) << i;
  }
  KDL::ChainFkSolverPos_recursive fk(k.chain);
  KDL::ChainJntToJacSolver jac(k.chain);
  KDL::ChainIdSolver_RNE rne(k.chain, test::kdl_vector(k.gravity));
  test::RandomJoints r;
  for (int s = 0; s < 300; ++s) {
    VecN q = r.q(n);
    for (int i = 0; i < n; ++i) {
      if (dh.joints[i].type == JointType::prismatic) q[i] = -0.5 + 0.5 * (q[i] + 3.0) / 6.0;  // d3 in [-0.5, 0] m
      if (std::isfinite(k.limits[i].first)) q[i] = k.limits[i].first + (q[i] + 3.0) / 6.0 * (k.limits[i].second - k.limits[i].first);
    }
    const VecN qd = r.v(n), qdd = r.a(n);
    const KDL::JntArray kq = test::kdl_array(q);
    KDL::Frame tip;
    ASSERT_GE(fk.JntToCart(kq, tip), 0);
    KDL::Jacobian kj(n);
    ASSERT_GE(jac.JntToJac(kq, kj), 0);
    KDL::JntArray ktau(n);
    KDL::Wrenches f_ext(k.chain.getNrOfSegments(), KDL::Wrench::Zero());
    ASSERT_GE(rne.CartToJnt(kq, test::kdl_array(qd), test::kdl_array(qdd), f_ext, ktau), 0);
    const Eigen::Vector3d kp(tip.p.x(), tip.p.y(), tip.p.z());
    const Eigen::Matrix3d kR = rotation(tip.M);
    const Mat6N kJ = test::from_kdl(kj);
    const VecN ktau_v = test::from_kdl(ktau);
    for (const Chain* c : {&dh, &urdf}) {
      if (c == &urdf && !with_urdf) continue;
      const std::string what = std::string(c == &dh ? "DH" : "URDF") + " chain, state " + std::to_string(s);
      ChainData d;
      forward_kinematics(*c, d, q);
      expect_near_all(d.tip.p, kp, what + ": tip position");
      expect_near_all(d.tip.R, kR, what + ": tip rotation");
      Mat6N J;
      tip_jacobian(*c, d, J);
      expect_near_all(J, kJ, what + ": Jacobian");
      VecN tau;
      rnea(*c, d, q, qd, qdd, tau);
      expect_near_all(tau, ktau_v, what + ": RNEA torques");
    }
    if (::testing::Test::HasFailure()) return;
  }
}

}  // namespace

TEST(DhRobot, Planar2rEqualsUrdfAndKdl) { expect_same_robot("planar2r"); }
TEST(DhRobot, ScaraEqualsUrdfAndKdl) { expect_same_robot("scara"); }
TEST(DhRobot, Puma560EqualsUrdfAndKdl) { expect_same_robot("puma560"); }
// Fixed rows (the wrist locked): KDL's chain of the same six rows with Joint::None for rows 4-6, its
// segments' inertias summed by KDL's own RNEA: tip pose, 3-column Jacobian and torques.
TEST(DhRobot, FixedRowsEqualKdlSegmentsWithoutJoints) {
  expect_same_robot("puma560_arm", false);
  const Chain arm = dh_study_chain("puma560_arm"), full = dh_study_chain("puma560");
  ASSERT_EQ(arm.dof(), 3);
  double m = 0.0;
  for (const ChainJoint& j : full.joints) m += j.mass;
  EXPECT_NEAR(arm.joints[0].mass + arm.joints[1].mass + arm.joints[2].mass, m, 1e-12);  // no mass lost
}

// The 2R's torques are those of the thesis's own planar model (its appendix, Listagem 5: uniform thin
// rods, written there with 0.3333 and 1.3333 for the thirds), m = 10 kg, l = 1.2 m, gravity along -y.
// Seed 002's third placement path (Section 7.3) lies in the Puma's workspace within its joint limits:
// unlimited IK solutions exist inside the limits at every vertex (the proof), so the IK error of the
// task on the limited arm is 0 (the clamped solves must find them, from one start or another).
TEST(DhRobot, Puma560ReachesSeed002sThirdPathWithinItsLimits) {
  const Chain limited = dh_study_chain("puma560");
  Chain free = limited;
  for (ChainJoint& j : free.joints) j.lower = -INFINITY, j.upper = INFINITY;
  StudyTask task;
  const double v[7][3] = {{0.4, 0.1, 0}, {0.4, 0, 0}, {0.4, 0, -0.4}, {0.4, -0.3, -0.4},
                          {0.4, -0.4, 0}, {0.4, -0.3, 0}, {0.4, -0.4, -0.4}};
  ik::Options o;
  o.method = ik::Method::lm_adaptive;
  o.tolerance = 1e-12;
  o.max_iter = 500;
  o.keep_history = false;
  ik::ChainIkWorkspace ws;
  ik::ChainIkResult r;
  ik::ChainIkTask t;
  t.kind = ik::ChainIkTask::Kind::spatial_position;
  for (const auto& p : v) {
    task.vertices.emplace_back(p[0], p[1]);
    task.z.push_back(p[2]);
    task.durations.push_back(1.0);
    t.position = Eigen::Vector3d(p[0], p[1], p[2]);
    bool inside = false;  // some unlimited solution within the limits, from a few starts
    for (double s : {0.3, -0.5, 1.0, 2.0})
      for (double e : {-2.5, -1.0, 0.5}) {
        VecN q = VecN::Constant(6, s);
        q[2] = e;
        ik::solve_chain(free, t, q, o, r, ws);
        bool within = r.error < 1e-9;
        for (int j = 0; j < 6 && within; ++j) {
          const double w = std::remainder(r.q[j] - 0.5 * (limited.joints[j].lower + limited.joints[j].upper), 2 * std::numbers::pi);
          within = std::abs(w) <= 0.5 * (limited.joints[j].upper - limited.joints[j].lower);
        }
        inside = inside || within;
      }
    EXPECT_TRUE(inside) << p[0] << " " << p[1] << " " << p[2];
  }
  task.durations.pop_back();
  EXPECT_EQ(task_ik_error(task, PlanarArm3{}, &limited), 0.0);
}

TEST(DhRobot, Planar2rIsTheThesisTwoLinkModel) {
  const Chain c = dh_study_chain("planar2r");
  const double m1 = 10, m2 = 10, l = 1.2, g = 9.81;
  test::RandomJoints r;
  for (int n = 0; n < 300; ++n) {
    const VecN q = r.q(2), qd = r.v(2), qdd = r.a(2);
    const double c1 = std::cos(q[0]), c2 = std::cos(q[1]), s2 = std::sin(q[1]), c12 = std::cos(q[0] + q[1]);
    const double dq1 = qd[0], dq2 = qd[1], ddq1 = qdd[0], ddq2 = qdd[1];
    VecN thesis(2);
    thesis[0] = m1 * l * l * ddq1 / 3 + 4 * m2 * l * l * ddq1 / 3 + m2 * l * l * ddq2 / 3 + m2 * c2 * l * l * ddq1 +
                0.5 * m2 * l * l * c2 * ddq2 - m2 * s2 * l * l * dq1 * dq2 - 0.5 * m2 * s2 * l * l * dq2 * dq2 +
                0.5 * m1 * g * l * c1 + 0.5 * m2 * g * l * c12 + m2 * g * l * c1;
    thesis[1] = m2 * l * l * ddq1 / 3 + m2 * l * l * ddq2 / 3 + 0.5 * m2 * l * l * c2 * ddq1 + 0.5 * m2 * g * l * c12 +
                0.5 * m2 * l * l * s2 * dq1 * dq1;
    ChainData d;
    VecN tau;
    rnea(c, d, q, qd, qdd, tau);
    expect_near_all(tau, thesis, "state " + std::to_string(n));
    if (::testing::Test::HasFailure()) return;
  }
}

// Offsets the shipped robots do not exercise: theta offsets on revolute joints, a prismatic joint
// with a theta and a d offset, twists other than +-90 deg, off-diagonal inertias, oblique gravity.
TEST(DhRobot, OffsetsAndPrismaticJointsMatchKdl) {
  struct Row {
    const char* type;
    double a, alpha, d, theta, mass;
    Eigen::Vector3d com;
    double ixx, iyy, izz, ixy, ixz, iyz;
  };
  const Row rows[] = {
      {"revolute", 0.1, 30, 0.2, 15, 2.0, {-0.05, 0.01, 0.02}, 0.02, 0.03, 0.025, 0.001, -0.002, 0.0015},
      {"prismatic", 0.05, -60, 0.3, 40, 1.5, {0.0, 0.02, -0.1}, 0.01, 0.012, 0.008, 0.0, 0.001, 0.0},
      {"revolute", 0.3, 90, -0.1, -70, 1.2, {-0.15, 0.0, 0.01}, 0.004, 0.02, 0.021, 0.0005, 0.0, -0.001},
      {"revolute", 0.0, -45, 0.12, 120, 0.6, {0.0, 0.03, 0.04}, 0.003, 0.002, 0.0025, 0.0, 0.0002, 0.0001},
  };
  std::ostringstream study;
  study.precision(17);
  study << "[robot]\ngravity = [0.5, -1.0, -9.7]\n";
  KDL::Chain k;
  for (const Row& r : rows) {
    study << "[[robot.dh]]\ntype = \"" << r.type << "\"\na = " << r.a << "\nalpha = " << r.alpha << "\nd = " << r.d
          << "\ntheta = " << r.theta << "\nmass = " << r.mass << "\ncom = [" << r.com.x() << ", " << r.com.y() << ", "
          << r.com.z() << "]\ninertia = { ixx = " << r.ixx << ", iyy = " << r.iyy << ", izz = " << r.izz << ", ixy = " << r.ixy
          << ", ixz = " << r.ixz << ", iyz = " << r.iyz << " }\n";
    const bool prismatic = std::string(r.type) == "prismatic";
    k.addSegment(KDL::Segment(KDL::Joint(prismatic ? KDL::Joint::TransZ : KDL::Joint::RotZ),
                              KDL::Frame::DH(r.a, r.alpha * kDegree, r.d, r.theta * kDegree),
                              KDL::RigidBodyInertia(r.mass, test::kdl_vector(r.com),
                                                    KDL::RotationalInertia(r.ixx, r.iyy, r.izz, r.ixy, r.ixz, r.iyz))));
  }
  const Study s = parse_study(study.str() + kIk, "offsets.toml");
  ASSERT_TRUE(s.base_chain);
  const Chain& c = *s.base_chain;
  ASSERT_EQ(c.dof(), 4);
  KDL::ChainFkSolverPos_recursive fk(k);
  KDL::ChainJntToJacSolver jac(k);
  KDL::ChainIdSolver_RNE rne(k, test::kdl_vector(c.gravity));
  test::RandomJoints r;
  for (int n = 0; n < 300; ++n) {
    const VecN q = r.q(4), qd = r.v(4), qdd = r.a(4);
    KDL::Frame tip;
    KDL::Jacobian kj(4);
    KDL::JntArray ktau(4);
    ASSERT_GE(fk.JntToCart(test::kdl_array(q), tip), 0);
    ASSERT_GE(jac.JntToJac(test::kdl_array(q), kj), 0);
    ASSERT_GE(rne.CartToJnt(test::kdl_array(q), test::kdl_array(qd), test::kdl_array(qdd),
                            KDL::Wrenches(k.getNrOfSegments(), KDL::Wrench::Zero()), ktau), 0);
    ChainData d;
    forward_kinematics(c, d, q);
    expect_near_all(d.tip.p, Eigen::Vector3d(tip.p.x(), tip.p.y(), tip.p.z()), "tip position");
    expect_near_all(d.tip.R, rotation(tip.M), "tip rotation");
    Mat6N J;
    tip_jacobian(c, d, J);
    expect_near_all(J, test::from_kdl(kj), "Jacobian");
    VecN tau;
    rnea(c, d, q, qd, qdd, tau);
    expect_near_all(tau, test::from_kdl(ktau), "RNEA torques");
    if (::testing::Test::HasFailure()) return;
  }
}

// The 2R is planar in the base xy plane (the fast planar algorithms); the others are spatial.
TEST(DhRobot, PlanarityOfTheShippedRobots) {
  EXPECT_TRUE(dh_study_chain("planar2r").planar_fast_path);
  EXPECT_FALSE(dh_study_chain("scara").planar_fast_path);
  EXPECT_FALSE(dh_study_chain("puma560").planar_fast_path);
}

// The same rows written in the study ([[robot.dh]]) give the same chain, bit for bit.
TEST(DhRobot, InlineTableEqualsRobotFile) {
  std::ifstream in(kRobots + "puma560.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), study = "[robot]\n";
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("name = ", 0) == 0) continue;
    study += (line == "[[dh]]" ? "[[robot.dh]]" : line) + "\n";
  }
  const Study s = parse_study(study + kIk, "inline.toml");
  const Chain file = dh_study_chain("puma560");
  ASSERT_TRUE(s.base_chain);
  const Chain& c = *s.base_chain;
  EXPECT_EQ(c.name, "dh");
  EXPECT_TRUE(s.robot_file.empty());
  EXPECT_TRUE(s.robot_text.empty());
  ASSERT_EQ(c.dof(), file.dof());
  for (int i = 0; i < c.dof(); ++i) {
    EXPECT_EQ(c.joints[i].origin.R, file.joints[i].origin.R);
    EXPECT_EQ(c.joints[i].origin.p, file.joints[i].origin.p);
    EXPECT_EQ(c.joints[i].com, file.joints[i].com);
    EXPECT_EQ(c.joints[i].inertia, file.joints[i].inertia);
    EXPECT_EQ(c.joints[i].lower, file.joints[i].lower);
  }
  EXPECT_EQ(c.tip.R, file.tip.R);
}

// A robot file's text is kept with the study (stored in the results file) and read from there again.
TEST(DhRobot, RobotFileTextKeptAndReused) {
  const std::string study = "[robot]\ndh = \"" + kRobots + "scara.toml\"\n" + kIk;
  const Study s = parse_study(study, "dh.toml");
  EXPECT_EQ(s.robot_file, kRobots + "scara.toml");
  EXPECT_NE(s.robot_text.find("[[dh]]"), std::string::npos);
  StudyOptions o;
  o.robot_text = s.robot_text;
  const std::string moved = "[robot]\ndh = \"/nonexistent/scara.toml\"\n" + kIk;  // not read: the stored text is
  const Study again = parse_study(moved, "dh.toml", o);
  ASSERT_TRUE(again.base_chain);
  EXPECT_EQ(again.base_chain->joints[2].type, JointType::prismatic);
  EXPECT_EQ(again.base_chain->joints[0].inertia, s.base_chain->joints[0].inertia);
}

// ---- bad DH tables: located errors, all of them reported ----

namespace {

// A valid planar 2R written in the study; each case replaces a line (1-based) or appends rows.
const std::vector<std::string> kRows = {
    "[robot]",                                              // 1
    "gravity = [0, -9.81, 0]",                              // 2
    "[[robot.dh]]",                                         // 3
    "type = \"revolute\"",                                  // 4
    "a = 0.5",                                              // 5
    "alpha = 0",                                            // 6
    "d = 0",                                                // 7
    "theta = 0",                                            // 8
    "mass = 2",                                             // 9
    "com = [-0.25, 0, 0]",                                  // 10
    "inertia = { ixx = 0.001, iyy = 0.05, izz = 0.05 }",    // 11
    "limits = { lower = -90, upper = 90 }",                 // 12
    "[[robot.dh]]",                                         // 13
    "type = \"revolute\"",                                  // 14
    "a = 0.5",                                              // 15
    "alpha = 0",                                            // 16
    "d = 0",                                                // 17
    "theta = 0",                                            // 18
    "mass = 1",                                             // 19
    "com = [-0.25, 0, 0]",                                  // 20
    "inertia = { ixx = 0.001, iyy = 0.02, izz = 0.02 }",    // 21
};

std::string with(std::initializer_list<std::pair<int, std::string>> edits) {
  std::vector<std::string> rows = kRows;
  for (const auto& [line, text] : edits) rows[std::size_t(line - 1)] = text;
  std::string s;
  for (const std::string& r : rows) s += r + "\n";
  return s + kIk;
}

std::vector<StudyDiagnostic> errors_of(const std::string& text, const std::string& file = "bad.toml") {
  try {
    parse_study(text, file);
  } catch (const StudyError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << "no StudyError for:\n" << text;
  return {};
}

/// Some diagnostic of `text` is at file:line:col and says `part` and "; expected ".
void expect_located(const std::string& text, int line, int col, const std::string& part, const std::string& file = "bad.toml") {
  const auto diags = errors_of(text);
  std::string all;
  for (const StudyDiagnostic& d : diags) {
    all += d.str() + "\n";
    if (d.file == file && d.line == line && d.column == col && d.message.find(part) != std::string::npos) {
      EXPECT_NE(d.message.find("; expected "), std::string::npos) << d.str();
      return;
    }
  }
  ADD_FAILURE() << "no error at " << file << ":" << line << ":" << col << " saying '" << part << "' in:\n" << all;
}

}  // namespace

TEST(DhRobot, ValidTableParses) {
  const Study s = parse_study(with({}), "ok.toml");
  ASSERT_TRUE(s.base_chain);
  EXPECT_EQ(s.base_chain->dof(), 2);
  EXPECT_NEAR(s.base_chain->joints[0].upper, std::numbers::pi / 2, 1e-15);
}

TEST(DhRobot, ErrorsAreLocatedWithWhatWasExpected) {
  expect_located(with({{10, "com = [-0.25, 0]"}}), 10, 7, "an array of 2; expected an array of 3 numbers");
  expect_located(with({{4, "type = \"revolut\""}}), 4, 8, "unknown joint type 'revolut'");
  expect_located(with({{4, "type = \"revolut\""}}), 4, 8, "did you mean 'revolute'?");
  expect_located(with({{9, "mass = -2"}}), 9, 8, "mass = -2 is negative");
  expect_located(with({{11, "inertia = { ixx = -0.001, iyy = 0.05, izz = 0.05 }"}}), 11, 11, "include a negative one");
  expect_located(with({{11, "inertia = { ixx = 0.001, iyy = 0.001, izz = 0.05 }"}}), 11, 11, "triangle inequality");
  expect_located(with({{7, "# d missing"}}), 3, 1, "dh row 1 has no 'd'");
  expect_located(with({{4, "# type missing"}}), 3, 1, "dh row 1 has no 'type'");
  expect_located(with({{11, "# inertia missing"}}), 3, 1, "dh row 1 has no 'inertia'");
  expect_located(with({{12, "limits = { lower = 90, upper = -90 }"}}), 12, 20, "limits lower = 90 > upper = -90");
  expect_located(with({{12, "limits = { lower = 10, upper = 10 }"}}), 12, 20, "(a joint that cannot move)");
  expect_located(with({{12, "limits = { lower = -90, upper = 90, velocity = 0 }"}}), 12, 48, "velocity limit = 0");
  expect_located(with({{9, "mas = 2"}}), 9, 1, "unknown key 'mas' in dh row 1");
  expect_located(with({{9, "mas = 2"}}), 9, 1, "did you mean 'mass'?");
  expect_located(with({{11, "inertia = { ixx = 0.001, iyy = 0.05, izzz = 0.05 }"}}), 11, 38, "did you mean 'izz'?");
  expect_located(with({{12, "limits = { lower = -90, uper = 90 }"}}), 12, 25, "did you mean 'upper'?");
  expect_located(with({{5, "a = \"half a metre\""}}), 5, 5, "dh row 1 a is a string; expected a number");
  expect_located(with({{3, "dh = 3"}, {13, "[robot.x]"}}), 3, 6, "dh is an integer; expected 1 to 8 DH rows");
  // a joint moving neither mass nor inertia: M(q) singular, at its row
  expect_located(with({{19, "mass = 0"}, {21, "inertia = { ixx = 0, iyy = 0, izz = 0 }"}}), 13, 1,
                 "joint 'joint2' moves neither mass nor inertia");
  expect_located(with({{9, "mass = 0"}, {19, "mass = 0"}}), 3, 1, "zero total mass");
  expect_located(with({{2, "urdf = \"x.urdf\""}}), 2, 8, "urdf and dh both given");
  // a planar arm in the base xy plane given no gravity: base -z would be normal to its plane
  std::string traj = with({{2, "# no gravity"}});
  traj = traj.substr(0, traj.find("[[block]]")) + kRows[12] + "\n" + kRows[13] + "\na = 0.5\nalpha = 0\nd = 0\ntheta = 0\n" +
         "mass = 1\ncom = [-0.25, 0, 0]\ninertia = { ixx = 0.001, iyy = 0.02, izz = 0.02 }\n" +
         "[task]\nvertices = [[0.8, 0.2], [1.0, 0.2]]\ndurations = [1]\n[[block]]\nname = \"t\"\nkind = \"trajectory\"\n";
  expect_located(traj, 3, 1, "a DH robot without gravity whose chain moves in a plane that is not vertical");
  expect_located(with({{2, "l = [1, 1]"}}), 2, 5, "l describes a planar arm; expected no l with dh");
  expect_located(with({{4, "type = \"fixed\""}}), 12, 10, "dh row 1 is fixed (no joint) and has limits");
  expect_located(with({{4, "type = \"fixed\""}, {12, "# no limits"}, {14, "type = \"fixed\""}}), 3, 1,
                 "every DH row is fixed");
  expect_located(with({{4, "type = \"fxed\""}}), 4, 8, "did you mean 'fixed'?");
}

TEST(DhRobot, TooManyRowsAndRowsThatAreNotTables) {
  std::string nine = "[robot]\n";
  for (int i = 0; i < 9; ++i) nine += "[[robot.dh]]\ntype = \"revolute\"\na = 0.1\nalpha = 0\nd = 0\ntheta = 0\nmass = 1\ncom = [0, 0, 0]\ninertia = { ixx = 0.01, iyy = 0.01, izz = 0.01 }\n";
  const auto diags = errors_of(nine + kIk);
  ASSERT_FALSE(diags.empty());
  EXPECT_NE(diags.front().message.find("an array of 9; expected 1 to 8 DH rows"), std::string::npos) << diags.front().str();
  expect_located("[robot]\ndh = [1, 2]\n" + kIk, 2, 7, "dh row 1 is an integer; expected a table");
}

TEST(DhRobot, EveryErrorOfATableIsReported) {
  const auto diags = errors_of(with({{4, "type = \"revolut\""}, {9, "mass = -2"}, {12, "limits = { lower = 9, upper = 1 }"},
                                     {19, "mas = 1"}}));
  EXPECT_GE(diags.size(), 5u);  // the type, the mass, the limits, the unknown key and the missing mass
}

TEST(DhRobot, RobotFileErrorsAreLocatedInTheRobotFile) {
  const std::string dir = ::testing::TempDir();
  const std::string robot = dir + "ks_dh_bad_robot.toml", study = dir + "ks_dh_study.toml";
  std::string text = "# a robot\ngravity = [0, 0, -9.81]\n";
  for (int i = 0; i < 2; ++i) text += "[[dh]]\ntype = \"revolute\"\na = 0.3\nalpha = 90\nd = 0\ntheta = 0\nmass = 1\ncom = [0, 0, 0]\ninertia = { ixx = 0.01, iyy = 0.01, izz = 0.01 }\n";
  std::ofstream(robot) << std::string(text).replace(text.find("mass = 1", text.find("mass = 1") + 1), 8, "mas = 1");
  const std::string st = "[robot]\ndh = \"ks_dh_bad_robot.toml\"\n" + kIk;
  std::ofstream(study) << st;
  try {
    load_study(study);
    ADD_FAILURE() << "no StudyError";
  } catch (const StudyError& e) {
    bool found = false;
    for (const StudyDiagnostic& d : e.diagnostics()) {
      if (d.file != robot || d.line != 18 || d.column != 1) continue;
      found = d.message.find("unknown key 'mas' in dh row 2") != std::string::npos &&
              d.message.find("did you mean 'mass'?") != std::string::npos;
      ASSERT_FALSE(d.notes.empty());
      EXPECT_EQ(d.notes.front().file, study);  // the study's dh key
      EXPECT_EQ(d.notes.front().line, 2);
      EXPECT_EQ(d.notes.front().column, 6);
    }
    EXPECT_TRUE(found) << e.what();
  }
  const auto first_error = [&] {
    try {
      load_study(study);
    } catch (const StudyError& e) {
      if (!e.diagnostics().empty()) return e.diagnostics().front();
    }
    ADD_FAILURE() << "no StudyError";
    return StudyDiagnostic{};
  };
  std::ofstream(robot) << "[[dh]]\ntype = \"revolute\"\na = = 1\n";  // TOML syntax, in the robot file
  StudyDiagnostic d = first_error();
  EXPECT_EQ(d.file, robot);
  EXPECT_EQ(d.line, 3) << d.str();
  EXPECT_NE(d.message.find("TOML syntax"), std::string::npos) << d.str();
  std::ofstream(robot) << "gravity = [0, 0, -9.81]\n";  // no rows
  d = first_error();
  EXPECT_EQ(d.file, robot);
  EXPECT_NE(d.message.find("has no dh; expected [[dh]] tables"), std::string::npos) << d.str();
  std::filesystem::remove(robot);
  d = first_error();
  EXPECT_EQ(d.file, study);
  EXPECT_EQ(d.line, 2);
  EXPECT_EQ(d.column, 6);
  EXPECT_NE(d.message.find("cannot read the DH robot file"), std::string::npos) << d.str();
  std::filesystem::remove(study);
}
