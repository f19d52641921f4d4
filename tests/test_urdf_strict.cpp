// The URDF loader's refusals of hostile input (robot/urdf.hpp, robot/urdf_check.hpp): numbers that are
// not whole finite numbers, kinematic loops, trees that are not a chain between base and tip, mimic
// joints, and mass properties no rigid body has; each a UrdfError at the line of the element at fault.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "model/chain_dynamics.hpp"
#include "robot/urdf.hpp"

using namespace ks;

namespace {

const Eigen::Vector3d kGravityY(0, -9.81, 0);
const std::string kBad = KS_SOURCE_DIR "/tests/fuzz/urdf_bad/";

int line_of(const std::string& text, const std::string& needle) {
  const std::size_t pos = text.find(needle);
  if (pos == std::string::npos) return -1;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

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

// A planar chain of n revolute joints about z, 0.5 m links of 1 kg (centre mid-link, izz 0.02).
std::string planar_urdf(int n) {
  std::ostringstream s;
  s << "<robot name=\"p" << n << "\">\n  <link name=\"base\"/>\n";
  for (int i = 1; i <= n; ++i) {
    s << "  <joint name=\"j" << i << "\" type=\"revolute\">\n    <parent link=\"" << (i == 1 ? "base" : "l" + std::to_string(i - 1))
      << "\"/>\n    <child link=\"l" << i << "\"/>\n    <origin xyz=\"" << (i == 1 ? 0.0 : 0.5)
      << " 0 0\"/>\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n";
    s << "  <link name=\"l" << i << "\">\n    <inertial><origin xyz=\"0.25 0 0\"/><mass value=\"1\"/>"
      << "<inertia ixx=\"0.001\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.02\"/></inertial>\n  </link>\n";
  }
  s << "</robot>\n";
  return s.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string with_before_end(std::string text, const std::string& more) {
  return text.insert(text.find("</robot>"), more);
}

}  // namespace

TEST(UrdfStrict, NumbersAreWholeFiniteNumbers) {
  const std::string arm = planar_urdf(2);
  struct Case {
    std::string from, to, attribute, why;
  };
  const std::vector<Case> cases = {
      {"<mass value=\"1\"/>", "<mass value=\"3.0kg\"/>", "value=\"3.0kg\"", "followed by 'kg'"},
      {"<mass value=\"1\"/>", "<mass value=\"inf\"/>", "value=\"inf\"", "not finite"},
      {"<mass value=\"1\"/>", "<mass value=\"nan\"/>", "value=\"nan\"", "not finite"},
      {"<mass value=\"1\"/>", "<mass value=\"one\"/>", "value=\"one\"", "not a number"},
      {"ixx=\"0.001\"", "ixx=\"0.0127x\"", "ixx=\"0.0127x\"", "followed by 'x'"},
      {"izz=\"0.02\"", "izz=\"1e999\"", "izz=\"1e999\"", "out of range"},
      {"<origin xyz=\"0.25 0 0\"/>", "<origin xyz=\"0.25 0\"/>", "xyz=\"0.25 0\"", "holds 2 numbers"},
      {"<origin xyz=\"0.5 0 0\"/>", "<origin xyz=\"0.5m 0 0\"/>", "xyz=\"0.5m 0 0\"", "followed by 'm'"},
      {"<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 1 0\"/>", "xyz=\"0 0 1 0\"", "holds 4 numbers"},
      {"lower=\"-3\"", "lower=\"-170deg\"", "lower=\"-170deg\"", "followed by 'deg'"},
      {"effort=\"1\"", "effort=\"-inf\"", "effort=\"-inf\"", "not finite"},
  };
  for (const Case& c : cases) {
    const std::string text = replaced(arm, c.from, c.to);
    const UrdfError e = expect_error([&] { parse_urdf(text, "base", "l2", kGravityY, "bad.urdf"); });
    EXPECT_EQ(e.file, "bad.urdf");
    EXPECT_EQ(e.line, line_of(text, c.to)) << e.what();
    EXPECT_NE(e.message.find(c.attribute), std::string::npos) << e.what();
    EXPECT_NE(e.message.find(c.why), std::string::npos) << e.what();
    EXPECT_NE(e.message.find("expected"), std::string::npos) << e.what();
  }
  // what urdfdom itself refuses (it would log the error and drop the inertial) is an error as well
  const std::string spaced = replaced(arm, "<mass value=\"1\"/>", "<mass value=\" +1.0 \"/>");
  const UrdfError u = expect_error([&] { parse_urdf(spaced, "base", "l2", kGravityY); });
  EXPECT_NE(u.message.find("l1"), std::string::npos) << u.what();
}

// urdfdom drops an <inertial> it cannot read (the link massless, exit 0): seed3r with link1's mass as
// "3.0kg" would have moved the arm with links of 0, 2 and 1 kg.
TEST(UrdfStrict, UnitSuffixedMassFileIsRefusedAtItsLine) {
  const std::string text = read(kBad + "mass_unit.urdf");
  const UrdfError e = expect_error([&] { load_urdf(kBad + "mass_unit.urdf", "base_link", "tool", kGravityY); });
  EXPECT_EQ(e.line, line_of(text, "<mass value=\"3.0kg\"/>"));
  EXPECT_NE(e.message.find("link 'link1'"), std::string::npos) << e.what();
}

TEST(UrdfStrict, LoopsAreRefusedAtOnce) {
  const auto start = std::chrono::steady_clock::now();
  // link1, already the child of j1, made the child of l3 too
  const std::string two_parents = with_before_end(
      planar_urdf(3), "  <joint name=\"close\" type=\"revolute\">\n    <parent link=\"l3\"/><child link=\"l1\"/>\n"
                      "    <axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n");
  const UrdfError a = expect_error([&] { parse_urdf(two_parents, "base", "l3", kGravityY); });
  EXPECT_EQ(a.line, line_of(two_parents, "<joint name=\"close\""));
  EXPECT_NE(a.message.find("link 'l1' is the child of joint 'j1'"), std::string::npos) << a.what();
  EXPECT_NE(a.message.find("kinematic loop"), std::string::npos) << a.what();
  // a cycle without a second parent: base made the child of l3 (no root link at all)
  const std::string cycle = with_before_end(
      planar_urdf(3), "  <joint name=\"close\" type=\"fixed\">\n    <parent link=\"l3\"/><child link=\"base\"/>\n  </joint>\n");
  const UrdfError b = expect_error([&] { parse_urdf(cycle, "base", "l3", kGravityY); });
  EXPECT_NE(b.message.find("form a cycle"), std::string::npos) << b.what();
  for (const char* j : {"'j1'", "'j2'", "'j3'", "'close'"}) EXPECT_NE(b.message.find(j), std::string::npos) << b.what();
  EXPECT_EQ(b.line, line_of(cycle, "<joint name=\"j1\""));  // the cycle's first joint in the file
  const std::string self = with_before_end(
      planar_urdf(2), "  <joint name=\"self\" type=\"fixed\">\n    <parent link=\"l2\"/><child link=\"l2\"/>\n  </joint>\n");
  const UrdfError c = expect_error([&] { parse_urdf(self, "base", "l2", kGravityY); });
  EXPECT_NE(c.message.find("attaches link 'l2' to itself"), std::string::npos) << c.what();
  // the shipped loop file (a 3R whose link1 is closed onto link3)
  const UrdfError d = expect_error([&] { load_urdf(kBad + "loop.urdf", "base_link", "tool", kGravityY); });
  EXPECT_EQ(d.line, line_of(read(kBad + "loop.urdf"), "<joint name=\"joint_close\""));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

TEST(UrdfStrict, MimicJointsAreRefused) {
  const std::string on_path = replaced(planar_urdf(3), "<child link=\"l2\"/>",
                                       "<child link=\"l2\"/>\n    <mimic joint=\"j1\" multiplier=\"2\" offset=\"0\"/>");
  const UrdfError e = expect_error([&] { parse_urdf(on_path, "base", "l3", kGravityY); });
  EXPECT_EQ(e.line, line_of(on_path, "<joint name=\"j2\""));
  EXPECT_NE(e.message.find("joint 'j2' mimics joint 'j1'"), std::string::npos) << e.what();
  EXPECT_NE(e.message.find("cannot honour the coupling"), std::string::npos) << e.what();
  // a joint off the chain (a massless pointer on the base) mimicking a chain joint
  const std::string off_path = with_before_end(
      planar_urdf(2), "  <joint name=\"pointer\" type=\"revolute\">\n    <parent link=\"base\"/><child link=\"dial\"/>\n"
                      "    <axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n"
                      "    <mimic joint=\"j2\"/>\n  </joint>\n  <link name=\"dial\"/>\n");
  const UrdfError f = expect_error([&] { parse_urdf(off_path, "base", "l2", kGravityY); });
  EXPECT_EQ(f.line, line_of(off_path, "<joint name=\"pointer\""));
  EXPECT_NE(f.message.find("mimics the chain's joint 'j2'"), std::string::npos) << f.what();
  const UrdfError g = expect_error([&] { load_urdf(kBad + "mimic.urdf", "base_link", "tool", kGravityY); });
  EXPECT_EQ(g.line, line_of(read(kBad + "mimic.urdf"), "<joint name=\"joint2\""));
}

TEST(UrdfStrict, BranchesThroughMovingJointsMustBeMassless) {
  const std::string branch = "  <joint name=\"side\" type=\"revolute\">\n    <parent link=\"l1\"/><child link=\"pod\"/>\n"
                             "    <origin xyz=\"0.2 0 0\"/><axis xyz=\"0 0 1\"/>\n"
                             "    <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\n  </joint>\n";
  const std::string heavy = with_before_end(
      planar_urdf(2), branch + "  <link name=\"pod\"><inertial><mass value=\"3\"/>"
                               "<inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>\n");
  const UrdfError e = expect_error([&] { parse_urdf(heavy, "base", "l2", kGravityY); });
  EXPECT_EQ(e.line, line_of(heavy, "<joint name=\"side\""));
  EXPECT_NE(e.message.find("link 'l1'"), std::string::npos) << e.what();
  EXPECT_NE(e.message.find("side branch through the moving joint 'side'"), std::string::npos) << e.what();
  // the heavy link behind a massless one on the branch still counts
  const std::string deeper = with_before_end(
      planar_urdf(2), branch + "  <link name=\"pod\"/>\n  <joint name=\"pod_fix\" type=\"fixed\"><parent link=\"pod\"/>"
                               "<child link=\"weight\"/></joint>\n  <link name=\"weight\"><inertial><mass value=\"3\"/>"
                               "<inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial></link>\n");
  EXPECT_NE(expect_error([&] { parse_urdf(deeper, "base", "l2", kGravityY); }).message.find("side branch"), std::string::npos);
  // links beyond the tip through a moving joint are a branch as well: l3 (1 kg) hangs from l2 through j3
  const std::string three = planar_urdf(3);
  const UrdfError t = expect_error([&] { parse_urdf(three, "base", "l2", kGravityY); });
  EXPECT_EQ(t.line, line_of(three, "<joint name=\"j3\""));
  // a massless branch changes nothing: the same M(q) as the arm without it
  const Chain with = parse_urdf(with_before_end(planar_urdf(2), branch + "  <link name=\"pod\"/>\n"), "base", "l2", kGravityY);
  const Chain without = parse_urdf(planar_urdf(2), "base", "l2", kGravityY);
  ChainData d;
  MatN Ma, Mb;
  VecN q(2);
  q << 0.3, -1.1;
  crba(with, d, q, Ma);
  crba(without, d, q, Mb);
  EXPECT_EQ((Ma - Mb).norm(), 0.0);
  const UrdfError f = expect_error([&] { load_urdf(kBad + "not_a_chain.urdf", "base_link", "tool", kGravityY); });
  EXPECT_EQ(f.line, line_of(read(kBad + "not_a_chain.urdf"), "<joint name=\"branch_joint\""));
}

TEST(UrdfStrict, MassPropertiesOfARigidBody) {
  const std::string arm = planar_urdf(2);
  const std::string l1 = "<link name=\"l1\"";
  // a negative mass
  const std::string neg = replaced(arm, "<mass value=\"1\"/>", "<mass value=\"-1\"/>");
  const UrdfError m = expect_error([&] { parse_urdf(neg, "base", "l2", kGravityY); });
  EXPECT_EQ(m.line, line_of(neg, l1));
  EXPECT_NE(m.message.find("link 'l1'"), std::string::npos) << m.what();
  EXPECT_NE(m.message.find("negative"), std::string::npos) << m.what();
  // ixx = -0.001: principal moments -0.001, 0.02, 0.02
  const std::string negi = replaced(arm, "ixx=\"0.001\"", "ixx=\"-0.001\"");
  const UrdfError i = expect_error([&] { parse_urdf(negi, "base", "l2", kGravityY); });
  EXPECT_EQ(i.line, line_of(negi, l1));
  EXPECT_NE(i.message.find("negative"), std::string::npos) << i.what();
  // 0.001, 0.02, 0.5: 0.5 > 0.021 violates the triangle inequality (a rigid body's I3 <= I1 + I2)
  const std::string tri = replaced(arm, "izz=\"0.02\"", "izz=\"0.5\"");
  const UrdfError t = expect_error([&] { parse_urdf(tri, "base", "l2", kGravityY); });
  EXPECT_EQ(t.line, line_of(tri, l1));
  EXPECT_NE(t.message.find("triangle inequality"), std::string::npos) << t.what();
  // off-diagonal terms: the inequality is on the principal moments. ixx = iyy = 0.5, ixy = 0.45,
  // izz = 0.1 has principal moments 0.05, 0.95, 0.1 (0.95 > 0.15): refused, though each diagonal
  // element is below the sum of the other two
  const std::string off = replaced(replaced(replaced(arm, "ixx=\"0.001\"", "ixx=\"0.5\""), "iyy=\"0.02\"", "iyy=\"0.5\""),
                                   "ixy=\"0\"", "ixy=\"0.45\"");
  const std::string off2 = replaced(off, "izz=\"0.02\"", "izz=\"0.1\"");
  EXPECT_NE(expect_error([&] { parse_urdf(off2, "base", "l2", kGravityY); }).message.find("triangle"), std::string::npos);
  // the limit case, a thin rod (0, I, I), is a rigid body
  const std::string rod = replaced(arm, "ixx=\"0.001\"", "ixx=\"0\"");
  EXPECT_EQ(parse_urdf(rod, "base", "l2", kGravityY).dof(), 2);
}
