// Study files with planar robots in any plane of their base frame: the plane and the chain the study
// gets, vertices in plane or base coordinates, gravity given or defaulted (and refused where the
// default is ambiguous), the shipped studies' chains unchanged.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "study/study.hpp"
#include "study_errors.hpp"

using namespace ks;
using Eigen::Vector3d;

namespace {

const std::string kSource = KS_SOURCE_DIR;
const std::string kXz = kSource + "/tests/data/seed3r_xz.urdf";
const std::string kXy = kSource + "/studies/robots/seed3r.urdf";
const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";
const std::string kIk = "[[block]]\nname = \"b\"\nkind = \"ik\"\nproblem = \"position\"\n";

std::string robot(const std::string& urdf, const std::string& gravity = "") {
  return "[robot]\nurdf = \"" + urdf + "\"\nbase = \"base_link\"\ntip = \"tool\"\n" +
         (gravity.empty() ? "" : "gravity = " + gravity + "\n");
}

}  // namespace

TEST(StudyPlane, SeedArmInTheXzPlaneWithBaseVertices) {
  const Study s = parse_study(robot(kXz, "[0, 0, -9.81]") +
                                  "[task]\nvertices = [[1.5, 0, 1.5], [1.5, 0, 2.0], [2.0, 0, 2.0], [2.0, 0, 1.5], "
                                  "[1.5, 0, 1.5]]\ndurations = [0.5, 0.5, 0.5, 0.5]\n" + kTraj,
                              "s.toml");
  ASSERT_TRUE(s.plane.has_value());
  EXPECT_EQ(s.plane->normal(), Vector3d(0, -1, 0));
  EXPECT_EQ(s.plane->e1(), Vector3d(1, 0, 0));
  EXPECT_EQ(s.plane->e2(), Vector3d(0, 0, 1));
  ASSERT_TRUE(s.chain && s.base_chain);
  EXPECT_TRUE(s.chain->planar());
  EXPECT_FALSE(s.base_chain->planar());
  EXPECT_EQ(s.base_chain->gravity, Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.chain->gravity, Vector3d(0, -9.81, 0));  // in plane coordinates (x, z)
  EXPECT_FALSE(s.gravity_defaulted);
  // base (x, 0, z) -> plane (x, z): the seed's square
  const std::vector<Eigen::Vector2d> square = {{1.5, 1.5}, {1.5, 2.0}, {2.0, 2.0}, {2.0, 1.5}, {1.5, 1.5}};
  EXPECT_EQ(s.task.vertices, square);
  EXPECT_TRUE(s.task.z.empty());
  // plane coordinates directly, and the default path (the seed's square in plane coordinates)
  const Study p = parse_study(robot(kXz, "[0, 0, -9.81]") +
                                  "[task]\nvertices = [[1.5, 1.5], [1.5, 2.0], [2.0, 2.0], [2.0, 1.5], [1.5, 1.5]]\n" + kTraj,
                              "s.toml");
  EXPECT_EQ(p.task.vertices, square);
  EXPECT_EQ(parse_study(robot(kXz) + kTraj, "s.toml").task.vertices, square);
}

TEST(StudyPlane, VertexOffThePlaneIsLocated) {
  study_test::expect_error_at(robot(kXz, "[0, 0, -9.81]") + "[task]\nvertices = [[1.5, 0, 1.5], [1.5, 0.01, 2.0]]\n"
                                                            "durations = [1]\n" + kTraj,
                              7, 28, "off the plane");
  // a spatial robot still wants [x, y, z], a planar one [x, y] or [x, y, z]
  study_test::expect_error_at(robot(kXz, "[0, 0, -9.81]") + "[task]\nvertices = [[1.5], [1.5, 0, 2.0]]\ndurations = [1]\n" + kTraj,
                              7, 13, "[x, y, z] (base frame, on the plane)");
}

TEST(StudyPlane, VerticalPlaneDefaultsToBaseMinusZ) {
  const Study s = parse_study(robot(kXz) + kTraj, "s.toml");
  EXPECT_TRUE(s.gravity_defaulted);
  EXPECT_EQ(s.base_chain->gravity, Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.chain->gravity, Vector3d(0, -9.81, 0));
}

TEST(StudyPlane, HorizontalPlaneNeedsGravityGivenForTrajectories) {
  // the seed arm's URDF (base xy plane) without gravity: base -z would be normal to its plane
  study_test::expect_error_at(robot(kXy) + kTraj, 2, 8, "not vertical");
  // an IK study uses no gravity: accepted, with base -z
  const Study ik = parse_study(robot(kXy) + kIk, "s.toml");
  EXPECT_TRUE(ik.gravity_defaulted);
  // gravity given normal to the plane: a horizontal arm, no gravity in its plane
  const Study h = parse_study(robot(kXy, "[0, 0, -9.81]") + kTraj, "s.toml");
  EXPECT_TRUE(h.plane && h.plane->is_base_xy());
  EXPECT_TRUE(h.chain->planar());
  EXPECT_EQ(h.chain->gravity, Vector3d::Zero());
  // gravity given in the plane: the seed arm
  const Study v = parse_study(robot(kXy, "[0, -9.81, 0]") + kTraj, "s.toml");
  EXPECT_EQ(v.chain->gravity, Vector3d(0, -9.81, 0));
}

// The shipped studies' robots in the base xy plane keep their chain bit for bit; spatial ones have no
// plane; [x, y, 0] is the base point of [x, y] for the seed's 3R.
TEST(StudyPlane, ShippedStudiesAreUnchanged) {
  int planar = 0;
  for (const auto& e : std::filesystem::directory_iterator(kSource + "/studies")) {
    if (e.path().extension() != ".toml") continue;
    SCOPED_TRACE(e.path().string());
    const Study s = load_study(e.path());
    if (!s.chain) {
      ASSERT_TRUE(s.plane && s.plane->is_base_xy());
      continue;
    }
    if (!s.plane) {
      EXPECT_FALSE(s.chain->planar());
      EXPECT_EQ(s.chain, s.base_chain);
      continue;
    }
    ++planar;
    EXPECT_TRUE(s.plane->is_base_xy());
    const Chain &a = *s.chain, &b = *s.base_chain;
    ASSERT_EQ(a.dof(), b.dof());
    for (int i = 0; i < a.dof(); ++i)
      EXPECT_TRUE(a.joints[i].origin.R == b.joints[i].origin.R && a.joints[i].origin.p == b.joints[i].origin.p &&
                  a.joints[i].axis == b.joints[i].axis && a.joints[i].com == b.joints[i].com &&
                  a.joints[i].inertia == b.joints[i].inertia && a.joints[i].mass == b.joints[i].mass);
    EXPECT_TRUE(a.tip.R == b.tip.R && a.tip.p == b.tip.p && a.gravity == b.gravity);
    EXPECT_EQ(a.planar_fast_path, b.planar_fast_path);
  }
  EXPECT_GE(planar, 2);  // redundancy_4r, redundancy_5r
  const Study s = parse_study("[task]\nvertices = [[1.5, 1.5, 0], [1.5, 2.0, 0]]\ndurations = [1]\n" + kTraj, "s.toml");
  EXPECT_EQ(s.task.vertices, (std::vector<Eigen::Vector2d>{{1.5, 1.5}, {1.5, 2.0}}));
}
