// The URDF loader (robot/urdf.hpp): the shipped robot files, fixed-joint merging against KDL
// chains built segment by segment from the same URDF, and every error it reports.
#include <gtest/gtest.h>

#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <sstream>

#include "chain_fixtures.hpp"
#include "kdl_chain.hpp"
#include "model/chain_dynamics.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

const std::string kRobots = KS_SOURCE_DIR "/studies/robots/";
const Eigen::Vector3d kGravityY(0, -9.81, 0);

// The 1-based line of the first occurrence of `needle` in `text` (the test's own search).
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t pos = text.find(needle);
  if (pos == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

// Runs f, expects a UrdfError and returns it.
template <class F>
UrdfError expect_error(F f) {
  try {
    f();
  } catch (const UrdfError& e) {
    return e;
  }
  ADD_FAILURE() << "no UrdfError thrown";
  return UrdfError("", 0, "");
}

// A planar chain of n revolute joints about z, 0.5 m links of 1 kg.
std::string planar_urdf(int n, const std::string& last_link_inertial = "") {
  std::ostringstream s;
  s << "<robot name=\"p" << n << "\">\n  <link name=\"base\"/>\n";
  for (int i = 1; i <= n; ++i) {
    s << "  <joint name=\"j" << i << "\" type=\"revolute\">\n    <parent link=\"" << (i == 1 ? "base" : "l" + std::to_string(i - 1))
      << "\"/>\n    <child link=\"l" << i << "\"/>\n    <origin xyz=\"" << (i == 1 ? 0.0 : 0.5)
      << " 0 0\"/>\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n";
    const std::string inertial = (i == n && !last_link_inertial.empty())
                                     ? last_link_inertial
                                     : "<inertial><origin xyz=\"0.25 0 0\"/><mass value=\"1\"/>"
                                       "<inertia ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.02\"/></inertial>";
    s << "  <link name=\"l" << i << "\">" << inertial << "</link>\n";
  }
  s << "</robot>\n";
  return s.str();
}

MatN mass_matrix(const Chain& c, const VecN& q) {
  ChainData d;
  MatN M;
  crba(c, d, q, M);
  return M;
}

}  // namespace

TEST(Urdf, Seed3rEqualsPlanarChainOfTheSeedArm) {
  const Chain u = load_urdf(kRobots + "seed3r.urdf", "base_link", "tool", kGravityY);
  const Chain p = planar_chain(planar_bars({1, 1, 1}, {5, 2, 1}, 0.1), 9.81);
  ASSERT_EQ(u.dof(), 3);
  EXPECT_TRUE(u.planar_fast_path);
  EXPECT_EQ(u.name, "seed3r");
  EXPECT_EQ(u.source, kRobots + "seed3r.urdf");
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(u.joints[i].name, p.joints[i].name);
    EXPECT_FALSE(u.joints[i].limited());
  }
  test::RandomJoints r;
  for (int k = 0; k < 1000; ++k) {
    const VecN q = r.q(3), qd = r.v(3);
    ChainData a, b;
    ChainState sa, sb;
    evaluate_dynamics(u, a, q, qd, sa);
    evaluate_dynamics(p, b, q, qd, sb);
    EXPECT_LT((sa.tip.p - sb.tip.p).norm() + (sa.tip.R - sb.tip.R).norm(), 1e-12);
    EXPECT_LT((sa.M - sb.M).norm(), 1e-12);
    EXPECT_LT((sa.c - sb.c).norm() + (sa.g - sb.g).norm(), 1e-12);
  }
}

TEST(Urdf, ShippedPlanarArms) {
  struct Arm {
    const char* file;
    std::vector<double> lengths;
  };
  for (const Arm& arm : {Arm{"planar4r.urdf", {0.9, 0.9, 0.8, 0.6}}, Arm{"planar5r.urdf", {0.8, 0.7, 0.7, 0.6, 0.4}}}) {
    const Chain c = load_urdf(kRobots + arm.file, "base_link", "tool", kGravityY);
    ASSERT_EQ(c.dof(), static_cast<int>(arm.lengths.size())) << arm.file;
    EXPECT_TRUE(c.planar_fast_path);
    double reach = 0;
    for (int i = 0; i < c.dof(); ++i) {
      reach += arm.lengths[i];
      EXPECT_NEAR(c.joints[i].mass, 4.0 * arm.lengths[i], 1e-12);
      EXPECT_NEAR(c.joints[i].upper, 170.0 * M_PI / 180.0, 1e-12);
      EXPECT_NEAR(c.joints[i].lower, -170.0 * M_PI / 180.0, 1e-12);
    }
    ChainData d;
    forward_kinematics(c, d, VecN::Zero(c.dof()));
    EXPECT_NEAR(d.tip.p.x(), reach, 1e-12);
    EXPECT_GT(reach, std::hypot(2.0, 2.0));  // the far corner of the seed's square
  }
}

TEST(Urdf, ShippedArm7) {
  const Chain c = load_urdf(kRobots + "arm7.urdf", "base_link", "tool", Eigen::Vector3d(0, 0, -9.81));
  ASSERT_EQ(c.dof(), 7);
  EXPECT_FALSE(c.planar_fast_path);
  const char* axes = "zyzyzyz";
  double mass = 0;
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(c.joints[i].axis, axes[i] == 'z' ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY());
    mass += c.joints[i].mass;
  }
  EXPECT_NEAR(mass, 4 + 4 + 3 + 2.7 + 1.7 + 1.8 + 0.3, 1e-12);
  ChainData d;
  forward_kinematics(c, d, VecN::Zero(7));
  EXPECT_NEAR(d.joint[1].p.z(), 0.34, 1e-12);                        // shoulder
  EXPECT_NEAR(d.joint[3].p.z() - d.joint[1].p.z(), 0.40, 1e-12);     // upper arm
  EXPECT_NEAR(d.joint[5].p.z() - d.joint[3].p.z(), 0.40, 1e-12);     // forearm
  EXPECT_NEAR(d.tip.p.z() - d.joint[5].p.z(), 0.126 + 0.10, 1e-12);  // flange and tool
  const Chain flange = load_urdf(kRobots + "arm7.urdf", "base_link", "flange", Eigen::Vector3d(0, 0, -9.81));
  forward_kinematics(flange, d, VecN::Zero(7));
  EXPECT_NEAR(d.tip.p.z(), 0.34 + 0.8 + 0.126, 1e-12);
}

// Fixed joints on the path and rotated joint origins: our merged chain against a KDL chain with one
// segment per URDF joint (fixed segments keep their links' inertias), as kdl_parser would build it.
TEST(Urdf, FixedJointsMergeLikeKdlSegments) {
  const std::string text = R"(<robot name="merge">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0.1 0.2 0.3" rpy="0.1 0 0.2"/></joint>
  <link name="base"><inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.2" rpy="0.3 -0.2 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <link name="l1"><inertial><origin xyz="0.1 0.02 0.05" rpy="0.2 0.1 0"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0.002" iyy="0.03" iyz="-0.001" izz="0.025"/></inertial></link>
  <joint name="bracket" type="fixed"><parent link="l1"/><child link="b1"/><origin xyz="0.3 0 0.1" rpy="0 0.5 0"/></joint>
  <link name="b1"><inertial><origin xyz="0 0.05 0"/><mass value="0.7"/>
    <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.002"/></inertial></link>
  <joint name="j2" type="prismatic"><parent link="b1"/><child link="l2"/><origin xyz="0.1 0 0" rpy="0 0 0.4"/>
    <axis xyz="1 1 0"/><limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <link name="l2"><inertial><origin xyz="0.05 0 0.02"/><mass value="1.1"/>
    <inertia ixx="0.003" ixy="0" ixz="0.0005" iyy="0.004" iyz="0" izz="0.005"/></inertial></link>
  <joint name="j3" type="continuous"><parent link="l2"/><child link="l3"/><origin xyz="0 0.2 0" rpy="-0.4 0 0"/>
    <axis xyz="0 1 0"/></joint>
  <link name="l3"><inertial><origin xyz="0 0.1 0"/><mass value="0.9"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.002"/></inertial></link>
  <joint name="wrist" type="fixed"><parent link="l3"/><child link="hand"/><origin xyz="0 0.15 0" rpy="0 0 0.3"/></joint>
  <link name="hand"><inertial><origin xyz="0.01 0.02 0.03"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="tcp" type="fixed"><parent link="hand"/><child link="tool"/><origin xyz="0 0.1 0.05" rpy="0.2 0.3 0.4"/></joint>
  <link name="tool"/>
</robot>)";
  const Eigen::Vector3d gravity(0.3, -0.4, -9.8);
  const Chain c = parse_urdf(text, "world", "tool", gravity);
  ASSERT_EQ(c.dof(), 3);
  EXPECT_EQ(c.joints[0].name, "j1");
  EXPECT_EQ(c.joints[1].type, JointType::prismatic);
  EXPECT_FALSE(c.joints[2].limited());

  // The oracle: URDF joint (origin T, axis a) -> KDL segment whose joint turns about T.M a through
  // T.p, with f_tip = T and the child link's inertial in the child link frame.
  struct Seg {
    const char* name;
    KDL::Joint::JointType type;
    KDL::Frame T;
    KDL::Vector axis;
    KDL::RigidBodyInertia I;
  };
  auto rot = [](double r, double p, double y) { return KDL::Rotation::RPY(r, p, y); };
  auto inertial = [&](double m, KDL::Vector c, KDL::Rotation R, double ixx, double ixy, double ixz, double iyy, double iyz,
                      double izz) {
    return KDL::Frame(R, c) * KDL::RigidBodyInertia(m, KDL::Vector::Zero(), KDL::RotationalInertia(ixx, iyy, izz, ixy, ixz, iyz));
  };
  const std::vector<Seg> segs = {
      {"mount", KDL::Joint::Fixed, KDL::Frame(rot(0.1, 0, 0.2), KDL::Vector(0.1, 0.2, 0.3)), KDL::Vector(0, 0, 1),
       inertial(3, KDL::Vector(0, 0, 0), KDL::Rotation::Identity(), 1, 0, 0, 1, 0, 1)},
      {"j1", KDL::Joint::RotAxis, KDL::Frame(rot(0.3, -0.2, 0.1), KDL::Vector(0, 0, 0.2)), KDL::Vector(0, 0, 1),
       inertial(2, KDL::Vector(0.1, 0.02, 0.05), rot(0.2, 0.1, 0), 0.02, 0.001, 0.002, 0.03, -0.001, 0.025)},
      {"bracket", KDL::Joint::Fixed, KDL::Frame(rot(0, 0.5, 0), KDL::Vector(0.3, 0, 0.1)), KDL::Vector(0, 0, 1),
       inertial(0.7, KDL::Vector(0, 0.05, 0), KDL::Rotation::Identity(), 0.004, 0, 0, 0.003, 0, 0.002)},
      {"j2", KDL::Joint::TransAxis, KDL::Frame(rot(0, 0, 0.4), KDL::Vector(0.1, 0, 0)), KDL::Vector(1, 1, 0) / std::sqrt(2.0),
       inertial(1.1, KDL::Vector(0.05, 0, 0.02), KDL::Rotation::Identity(), 0.003, 0, 0.0005, 0.004, 0, 0.005)},
      {"j3", KDL::Joint::RotAxis, KDL::Frame(rot(-0.4, 0, 0), KDL::Vector(0, 0.2, 0)), KDL::Vector(0, 1, 0),
       inertial(0.9, KDL::Vector(0, 0.1, 0), KDL::Rotation::Identity(), 0.002, 0, 0, 0.001, 0, 0.002)},
      {"wrist", KDL::Joint::Fixed, KDL::Frame(rot(0, 0, 0.3), KDL::Vector(0, 0.15, 0)), KDL::Vector(0, 0, 1),
       inertial(0.5, KDL::Vector(0.01, 0.02, 0.03), KDL::Rotation::Identity(), 0.001, 0, 0, 0.001, 0, 0.001)},
      {"tcp", KDL::Joint::Fixed, KDL::Frame(rot(0.2, 0.3, 0.4), KDL::Vector(0, 0.1, 0.05)), KDL::Vector(0, 0, 1),
       KDL::RigidBodyInertia::Zero()},
  };
  KDL::Chain k;
  for (const Seg& s : segs) {
    const KDL::Joint joint = s.type == KDL::Joint::Fixed ? KDL::Joint(s.name, KDL::Joint::Fixed)
                                                         : KDL::Joint(s.name, s.T.p, s.T.M * s.axis, s.type);
    k.addSegment(KDL::Segment(s.name, joint, s.T, s.I));
  }
  ASSERT_EQ(k.getNrOfJoints(), 3u);
  KDL::ChainFkSolverPos_recursive fk(k);
  KDL::ChainDynParam dyn(k, test::kdl_vector(gravity));
  test::RandomJoints r;
  for (int n = 0; n < 500; ++n) {
    VecN q = r.q(3);
    q[1] = 0.3 * q[1];
    const VecN qd = r.v(3);
    const KDL::JntArray kq = test::kdl_array(q);
    KDL::Frame kf;
    ASSERT_GE(fk.JntToCart(kq, kf), 0);
    ChainData d;
    ChainState st;
    evaluate_dynamics(c, d, q, qd, st);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(st.tip.p[a], kf.p[a], 1e-12);
      for (int b = 0; b < 3; ++b) EXPECT_NEAR(st.tip.R(a, b), kf.M(a, b), 1e-12);
    }
    KDL::JntSpaceInertiaMatrix kM(3);
    KDL::JntArray kc(3), kg(3);
    ASSERT_GE(dyn.JntToMass(kq, kM), 0);
    ASSERT_GE(dyn.JntToCoriolis(kq, test::kdl_array(qd), kc), 0);
    ASSERT_GE(dyn.JntToGravity(kq, kg), 0);
    // heap copies: GCC 12 misjudges the bounds of Eigen's vectorised norm of a bounded-size vector
    const Eigen::MatrixXd M = st.M, kMd = test::from_kdl(kM);
    const Eigen::VectorXd c = st.c, g = st.g, kcd = test::from_kdl(kc), kgd = test::from_kdl(kg);
    EXPECT_LT((M - kMd).norm(), 1e-9 * kMd.norm());
    EXPECT_LT((c - kcd).norm(), 1e-9 * (1e-12 + kcd.norm()));
    EXPECT_LT((g - kgd).norm(), 1e-9 * (1e-12 + kgd.norm()));
  }
}

// A link attached off the path by a fixed joint belongs to the body it hangs from: the chain equals
// one whose link carries the combined inertial (mass sum, mass-weighted centre, parallel axes).
TEST(Urdf, SideLinksOnFixedJointsJoinTheirBody) {
  const std::string lump = "<inertial><origin xyz=\"0.25 0 0\"/><mass value=\"1\"/>"
                           "<inertia ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.02\"/></inertial>";
  std::string with_side = planar_urdf(2);
  with_side.insert(with_side.find("</robot>"),
                   "  <joint name=\"camera_mount\" type=\"fixed\"><parent link=\"l1\"/><child link=\"camera\"/>"
                   "<origin xyz=\"0.1 0.2 0\"/></joint>\n  <link name=\"camera\"><inertial><origin xyz=\"0.1 0 0\"/>"
                   "<mass value=\"3\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>\n");
  // l1: 1 kg at (0.25, 0, 0) with izz 0.02, plus 3 kg (point) at (0.2, 0.2, 0): mass 4, centre
  // (0.2125, 0.15, 0); izz about it = 0.02 + 1 (0.0375^2 + 0.15^2) + 3 (0.0125^2 + 0.05^2) = 0.051875.
  std::string combined = planar_urdf(2);
  const std::size_t at = combined.find(lump);
  combined.replace(at, lump.size(),
                   "<inertial><origin xyz=\"0.2125 0.15 0\"/><mass value=\"4\"/>"
                   "<inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.051875\"/></inertial>");
  const Chain a = parse_urdf(with_side, "base", "l2", kGravityY), b = parse_urdf(combined, "base", "l2", kGravityY);
  EXPECT_NEAR(a.joints[0].mass, 4.0, 1e-12);
  test::RandomJoints r;
  for (int n = 0; n < 100; ++n) {
    const VecN q = r.q(2);
    EXPECT_LT((mass_matrix(a, q) - mass_matrix(b, q)).norm(), 1e-12);
    ChainData d;
    VecN ga, gb;
    gravity_torques(a, d, q, ga);
    gravity_torques(b, d, q, gb);
    EXPECT_LT((ga - gb).norm(), 1e-12);
  }
}

TEST(Urdf, ErrorUnreadableFile) {
  const UrdfError e = expect_error([] { load_urdf(kRobots + "no_such_robot.urdf", "base_link", "tool", kGravityY); });
  EXPECT_EQ(e.file, kRobots + "no_such_robot.urdf");
  EXPECT_EQ(e.line, 0);
  EXPECT_NE(e.message.find("cannot read"), std::string::npos) << e.message;
  const UrdfError d = expect_error([] { load_urdf(kRobots, "base_link", "tool", kGravityY); });
  EXPECT_NE(d.message.find("directory"), std::string::npos) << d.message;
}

TEST(Urdf, ErrorMalformedXml) {
  const std::string text = "<robot name=\"r\">\n  <link name=\"a\">\n  </lnk>\n</robot>\n";
  const UrdfError e = expect_error([&] { parse_urdf(text, "a", "a", kGravityY, "bad.urdf"); });
  EXPECT_EQ(e.file, "bad.urdf");
  EXPECT_EQ(e.line, 3);
  EXPECT_NE(e.message.find("XML"), std::string::npos) << e.message;
  EXPECT_NE(std::string(e.what()).find("bad.urdf:3: "), std::string::npos) << e.what();
}

TEST(Urdf, ErrorInvalidUrdf) {
  // a joint without a parent element: well-formed XML that urdfdom rejects
  std::string text = planar_urdf(2);
  text.replace(text.find("<parent link=\"l1\"/>"), std::string("<parent link=\"l1\"/>").size(), "");
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY); });
  EXPECT_NE(e.message.find("not a valid URDF"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("j2"), std::string::npos) << e.message;
  EXPECT_EQ(e.line, line_of(text, "<joint name=\"j2\"")) << e.message;
  const UrdfError f = expect_error([] { parse_urdf("<robt name=\"x\"/>", "a", "b", kGravityY); });
  EXPECT_NE(f.message.find("robot"), std::string::npos) << f.message;
}

TEST(Urdf, ErrorUnknownLinksSuggestTheNearest) {
  const std::string path = kRobots + "arm7.urdf";
  const UrdfError b = expect_error([&] { load_urdf(path, "base_lnk", "tool", kGravityY); });
  EXPECT_NE(b.message.find("unknown base link 'base_lnk'"), std::string::npos) << b.message;
  EXPECT_NE(b.message.find("did you mean 'base_link'"), std::string::npos) << b.message;
  const UrdfError t = expect_error([&] { load_urdf(path, "base_link", "tol", kGravityY); });
  EXPECT_NE(t.message.find("unknown tip link 'tol'"), std::string::npos) << t.message;
  EXPECT_NE(t.message.find("did you mean 'tool'"), std::string::npos) << t.message;
}

TEST(Urdf, ErrorTipNotBelowBase) {
  const std::string text = planar_urdf(3);
  const UrdfError e = expect_error([&] { parse_urdf(text, "l2", "l1", kGravityY); });
  EXPECT_NE(e.message.find("tip link 'l1' is not below base link 'l2'"), std::string::npos) << e.message;
  EXPECT_EQ(e.line, line_of(text, "<link name=\"l1\""));
}

TEST(Urdf, ErrorFloatingAndPlanarJoints) {
  for (const std::string type : {"floating", "planar"}) {
    std::string text = planar_urdf(3);
    const std::string from = "<joint name=\"j2\" type=\"revolute\">";
    text.replace(text.find(from), from.size(), "<joint name=\"j2\" type=\"" + type + "\">");
    const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l3", kGravityY); });
    EXPECT_NE(e.message.find("joint 'j2' is " + type), std::string::npos) << e.message;
    EXPECT_EQ(e.line, line_of(text, "<joint name=\"j2\""));
  }
}

TEST(Urdf, ErrorTooManyJoints) {
  EXPECT_EQ(parse_urdf(planar_urdf(kMaxJoints), "base", "l8", kGravityY).dof(), kMaxJoints);
  const std::string text = planar_urdf(kMaxJoints + 1);
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l9", kGravityY); });
  EXPECT_NE(e.message.find("9 moving joints; at most 8"), std::string::npos) << e.message;
  EXPECT_EQ(e.line, line_of(text, "<joint name=\"j9\""));
}

TEST(Urdf, ErrorNoMovingJoint) {
  const UrdfError e = expect_error([] { load_urdf(kRobots + "arm7.urdf", "link7", "tool", kGravityY); });
  EXPECT_NE(e.message.find("no revolute, continuous or prismatic joint"), std::string::npos) << e.message;
  const UrdfError same = expect_error([] { load_urdf(kRobots + "arm7.urdf", "tool", "tool", kGravityY); });
  EXPECT_NE(same.message.find("no revolute"), std::string::npos) << same.message;
}

TEST(Urdf, ErrorZeroMass) {
  std::string text = planar_urdf(2);
  for (std::size_t p; (p = text.find("<mass value=\"1\"/>")) != std::string::npos;)
    text.replace(p, std::string("<mass value=\"1\"/>").size(), "<mass value=\"0\"/>");
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY); });
  EXPECT_NE(e.message.find("zero total mass"), std::string::npos) << e.message;
}

TEST(Urdf, ErrorSingularInertiaMatrix) {
  // the last link massless and without inertia: joint j3 moves nothing
  const std::string text = planar_urdf(
      3, "<inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>");
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l3", kGravityY); });
  EXPECT_NE(e.message.find("singular"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("joint 'j3'"), std::string::npos) << e.message;
  EXPECT_EQ(e.line, line_of(text, "<joint name=\"j3\""));
  // a point mass on the last joint's own axis moves no inertia about it either
  const std::string on_axis = planar_urdf(
      3, "<inertial><mass value=\"1\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>");
  const UrdfError a = expect_error([&] { parse_urdf(on_axis, "base", "l3", kGravityY); });
  EXPECT_NE(a.message.find("joint 'j3'"), std::string::npos) << a.message;
}

TEST(Urdf, ErrorInvalidInertia) {
  const std::string text = planar_urdf(
      2, "<inertial><mass value=\"1\"/><inertia ixx=\"-1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial>");
  const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY); });
  EXPECT_NE(e.message.find("link 'l2'"), std::string::npos) << e.message;
  EXPECT_EQ(e.line, line_of(text, "<link name=\"l2\""));
}
