// [task] waypoints = [[t, x, y(, z)], ...] and spline = "natural" | "clamped": the task a study gets
// (planar, spatial, a planar robot's base-frame form), each parse error at its line and column, the
// sampling rule on the whole spline path, and the run context that tells a spline task from a quintic one.
#include <gtest/gtest.h>

#include <algorithm>

#include "runner/run_identity.hpp"
#include "study/study.hpp"
#include "study_errors.hpp"

using namespace ks;
using study_test::expect_error_at;

namespace {

const std::string kSource = KS_SOURCE_DIR;
const std::string kTraj = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";
const std::string kScara = "[robot]\ndh = \"" + kSource + "/studies/robots/scara.toml\"\n";
const std::string kXz = "[robot]\nurdf = \"" + kSource + "/tests/data/seed3r_xz.urdf\"\nbase = \"base_link\"\n"
                        "tip = \"tool\"\ngravity = [0, 0, -9.81]\n";

/// The value of the run context's field `key` of `s`, or "(absent)".
std::string context_value(const Study& s, const std::string& key) {
  const std::vector<ContextField> c = run_context(s, s.histories, "test");
  const auto f = std::find_if(c.begin(), c.end(), [&](const ContextField& x) { return x.key == key; });
  return f == c.end() ? "(absent)" : f->value;
}

}  // namespace

TEST(StudyWaypoints, PlanarWaypointsAreTheVerticesAndTheirTimeStepsTheDurations) {
  // times from t0 = 2.5 s: the path's time 0 is the first waypoint's (2.5, 3, 4, 4.25 are exact)
  const Study s = parse_study("[task]\nwaypoints = [[2.5, 1.5, 1.5], [3, 1.5, 2.0], [4.0, 2.0, 2.0], [4.25, 2.0, 1.5]]\n" +
                                  kTraj,
                              "s.toml");
  EXPECT_EQ(s.task.shape, PathShape::clamped_spline);  // the default: at rest at both ends
  EXPECT_EQ(s.task.vertices, (std::vector<Eigen::Vector2d>{{1.5, 1.5}, {1.5, 2.0}, {2.0, 2.0}, {2.0, 1.5}}));
  EXPECT_EQ(s.task.durations, (std::vector<double>{0.5, 1.0, 0.25}));
  EXPECT_TRUE(s.task.z.empty());
  EXPECT_EQ(s.task.path().shape(), PathShape::clamped_spline);
  EXPECT_EQ(s.task.path().duration(), 1.75);
  EXPECT_EQ(s.task.sampled_spans(), std::vector<double>{1.75});
  const Study n = parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\nspline = \"natural\"\n" + kTraj, "s.toml");
  EXPECT_EQ(n.task.shape, PathShape::natural_spline);
  const Study c = parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\nspline = \"clamped\"\n" + kTraj, "s.toml");
  EXPECT_EQ(c.task.shape, PathShape::clamped_spline);
  // the vertices' form is quintic, as before
  EXPECT_EQ(parse_study(kTraj, "s.toml").task.shape, PathShape::quintic);
}

TEST(StudyWaypoints, SpatialRobotWaypointsCarryZ) {  // seed 002 section 7.3's first SCARA path
  const Study s = parse_study(kScara + "[task]\nwaypoints = [[0, 0.4, 0, -0.3], [1, 0.4, -0.1, -0.3], "
                                       "[2, 0.2, -0.1, -0.3], [3, 0.2, -0.2, -0.3], [4, 0.4, -0.25, -0.3], "
                                       "[5, 0.4, -0.2, -0.3], [6, 0.2, -0.25, -0.3]]\n" + kTraj,
                              "s.toml");
  ASSERT_EQ(s.task.vertices.size(), 7u);
  EXPECT_EQ(s.task.z, std::vector<double>(7, -0.3));
  EXPECT_EQ(s.task.durations, std::vector<double>(6, 1.0));
  EXPECT_EQ(s.task.vertex(4), Eigen::Vector3d(0.4, -0.25, -0.3));
}

TEST(StudyWaypoints, PlanarRobotBaseFrameForm) {  // an arm in the base xz plane: [t, x, 0, z] -> plane (x, z)
  const Study s = parse_study(kXz + "[task]\nwaypoints = [[0, 1.5, 0, 1.5], [0.5, 1.5, 0, 2.0], [1, 2.0, 0, 2.0]]\n" +
                                  kTraj,
                              "s.toml");
  EXPECT_EQ(s.task.vertices, (std::vector<Eigen::Vector2d>{{1.5, 1.5}, {1.5, 2.0}, {2.0, 2.0}}));
  expect_error_at(kXz + "[task]\nwaypoints = [[0, 1.5, 0, 1.5], [0.5, 1.5, 0.1, 2.0]]\n" + kTraj, 7, 32, "plane");
}

// ---- each error at its place ----
TEST(StudyWaypoints, WaypointsExcludeVerticesAndDurations) {
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\nvertices = [[1.5, 1.5], [1.5, 2.0]]\n" + kTraj,
                  3, 12, "vertices given with waypoints");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\ndurations = [1]\n" + kTraj, 3, 13,
                  "durations given with waypoints");
}

TEST(StudyWaypoints, SplineNeedsWaypointsAndAKnownKind) {
  expect_error_at("[task]\nvertices = [[1.5, 1.5], [1.5, 2.0]]\ndurations = [1]\nspline = \"natural\"\n" + kTraj, 4, 10,
                  "spline given without waypoints");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\nspline = \"clamp\"\n" + kTraj, 3, 10,
                  "unknown spline 'clamp'");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\nspline = 3\n" + kTraj, 3, 10, "spline is");
}

TEST(StudyWaypoints, AtLeastTwoWaypoints) {
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5]]\n" + kTraj, 2, 13, "waypoints is an array of 1");
  expect_error_at("[task]\nwaypoints = 3\n" + kTraj, 2, 13, "waypoints is");
}

TEST(StudyWaypoints, EachWaypointHasItsArity) {
  // planar: [t, x, y] (or [t, x, y, z] on a plane robot's plane); the second waypoint at column 29
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5]]\n" + kTraj, 2, 29, "a waypoint is an array of 2");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], 1]\n" + kTraj, 2, 29, "a waypoint is");
  // a spatial robot needs [t, x, y, z]
  expect_error_at(kScara + "[task]\nwaypoints = [[0, 0.4, 0, -0.3], [1, 0.4, -0.1]]\n" + kTraj, 4, 33,
                  "a waypoint is an array of 3");
}

TEST(StudyWaypoints, NumbersAreFinite) {
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, nan, 2.0]]\n" + kTraj, 2, 33, "waypoint x is not finite");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [inf, 1.5, 2.0]]\n" + kTraj, 2, 30, "waypoint t is not finite");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, \"a\"]]\n" + kTraj, 2, 38, "waypoint y is");
  // finite times whose difference is not
  expect_error_at("[task]\nwaypoints = [[-1e308, 1.5, 1.5], [1e308, 1.5, 2.0]]\n" + kTraj, 2, 35,
                  "a finite time step");
}

TEST(StudyWaypoints, TimesStrictlyIncrease) {
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0], [1, 2.0, 2.0]]\n" + kTraj, 2, 45,
                  "waypoint time t = 1 s is not after the previous waypoint's, 1 s");
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [-0.5, 1.5, 2.0]]\n" + kTraj, 2, 30,
                  "is not after the previous waypoint's");
}

TEST(StudyWaypoints, VertexKeyedInputsCountWaypoints) {
  const std::string robot = "[robot]\nl = [1.0, 1.0, 0.5, 0.5]\nm = [5.0, 2.0, 0.5, 0.5]\nb = 0.1\n";
  expect_error_at(robot + "[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\norientation = [0, 10, 20]\n" + kTraj, 7,
                  15, "one per waypoint");
  const Study s =
      parse_study(robot + "[task]\nwaypoints = [[0, 1.5, 1.5], [1, 1.5, 2.0]]\norientation = [0, 10]\n" + kTraj, "s.toml");
  EXPECT_EQ(s.task.orientation.size(), 2u);
  // a waypoint out of the robot's reach, at that waypoint
  expect_error_at(robot + "[task]\nwaypoints = [[0, 1.5, 1.5], [1, 4.5, 2.0]]\n" + kTraj, 6, 29,
                  "waypoint 2 is");
}

TEST(StudyWaypoints, SamplingRuleAppliesToTheWholePath) {
  // 10 samples on the 1 s path: dt = 0.1 is allowed though the 0.05 s interval gets none of its own
  const Study s = parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [0.05, 1.5, 1.55], [1, 1.5, 2.0]]\ndt = 0.1\n" + kTraj,
                              "s.toml");
  EXPECT_EQ(s.task.dt, 0.1);
  expect_error_at("[task]\nwaypoints = [[0, 1.5, 1.5], [0.05, 1.5, 1.55], [1, 1.5, 2.0]]\ndt = 0.2\n" + kTraj, 3, 6,
                  "samples the 1 s spline path 5 times");
  // the same points as vertices: each segment needs its 10 samples
  expect_error_at("[task]\nvertices = [[1.5, 1.5], [1.5, 1.55], [1.5, 2.0]]\ndurations = [0.05, 0.95]\ndt = 0.1\n" + kTraj,
                  4, 6, "shortest segment");
}

TEST(StudyWaypoints, RunContextTellsASplineFromAQuintic) {
  const std::string points = "[[1.5, 1.5], [1.5, 2.0], [2.0, 2.0]]";
  const Study quintic = parse_study("[task]\nvertices = " + points + "\ndurations = [0.5, 0.5]\n" + kTraj, "s.toml");
  const Study clamped = parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [0.5, 1.5, 2.0], [1, 2.0, 2.0]]\n" + kTraj, "s.toml");
  const Study natural =
      parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [0.5, 1.5, 2.0], [1, 2.0, 2.0]]\nspline = \"natural\"\n" + kTraj,
                  "s.toml");
  EXPECT_EQ(context_value(quintic, "[task] spline"), "(absent)");  // a quintic task's context as before
  EXPECT_EQ(context_value(clamped, "[task] spline"), "clamped");
  EXPECT_EQ(context_value(natural, "[task] spline"), "natural");
  EXPECT_EQ(context_value(quintic, "[task] vertices"), context_value(clamped, "[task] vertices"));
  EXPECT_EQ(context_value(quintic, "[task] durations"), context_value(clamped, "[task] durations"));
  const auto digest = [](const Study& s) {
    return context_digest(run_context(s, s.histories, "test"), BlockKind::trajectory);
  };
  EXPECT_NE(digest(quintic), digest(clamped));
  EXPECT_NE(digest(clamped), digest(natural));
  EXPECT_NE(context_changes(run_context(quintic, quintic.histories, "test"), run_context(clamped, clamped.histories, "test"))
                .find("[task] spline"),
            std::string::npos);
}
