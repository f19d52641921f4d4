// The task as parameters: a rigid placement of the whole task (task_rotation about the base z, task_dx,
// task_dy, task_dz) and a time scale (task_time_scale). Oracles: the same task written out at its new
// place by hand (dyadic coordinates and a quarter turn, so the hand-written numbers are exact and the
// comparison bitwise); the distance from a point to an arm's reach (seed 002's IK error); quarter
// turns as swaps and negations of coordinates.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include "runner/execute.hpp"
#include "runner/run_identity.hpp"
#include "runner/schema.hpp"
#include "study/study.hpp"
#include "methods/base/task_placement.hpp"

namespace ks {
namespace {

constexpr double kQuarter = std::numbers::pi / 2.0;

/// Bit pattern of a double (NaN payloads and -0 compared as stored).
std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

/// The outcome of run 0 of block 0 of `s`.
RunOutcome run0(const Study& s) {
  RunWorkspace ws;
  return execute(Scenario::of(s), s.blocks[0].run(0), 1, ws);
}

/// Every metric of block 0 and every history array of run 0, compared bit for bit.
void expect_bitwise_equal(const Study& a, const Study& b) {
  const RunOutcome oa = run0(a), ob = run0(b);
  EXPECT_EQ(oa.status(), ob.status());
  const auto& ma = a.blocks[0].metrics();
  const auto& mb = b.blocks[0].metrics();
  ASSERT_EQ(ma.size(), mb.size());
  for (std::size_t j = 0; j < ma.size(); ++j) {
    ASSERT_EQ(ma[j].name, mb[j].name);
    const Cell ca = ma[j].get(oa), cb = mb[j].get(ob);
    if (const double* x = std::get_if<double>(&ca))
      EXPECT_EQ(bits(*x), bits(std::get<double>(cb))) << ma[j].name << ": " << *x << " vs " << std::get<double>(cb);
    else
      EXPECT_EQ(ca, cb) << ma[j].name;
  }
  ASSERT_EQ(oa.history.arrays.size(), ob.history.arrays.size());
  for (std::size_t i = 0; i < oa.history.arrays.size(); ++i) {
    const auto& x = oa.history.arrays[i];
    const auto& y = ob.history.arrays[i];
    ASSERT_EQ(x.data.size(), y.data.size()) << x.name;
    std::size_t differ = 0;
    for (std::size_t k = 0; k < x.data.size(); ++k) differ += bits(x.data[k]) != bits(y.data[k]);
    EXPECT_EQ(differ, 0u) << "history " << x.name;
  }
}

/// The seed's square turned by a quarter turn, moved by (0.25, -0.5) and done at half speed, as the
/// placement parameters give it and as written out there: (x, y) -> (-y + 0.25, x - 0.5), durations 1 s.
const char* kSquarePlaced = R"([task]
vertices = [[1.5, 1.5], [1.5, 2.0], [2.0, 2.0], [2.0, 1.5], [1.5, 1.5]]
durations = [0.5, 0.5, 0.5, 0.5]
[[block]]
name = "b"
kind = "trajectory"
method = "local_weighted"
k = 0.5
task_rotation = 1.5707963267948966
task_dx = 0.25
task_dy = -0.5
task_time_scale = 2.0
)";
const char* kSquareByHand = R"([task]
vertices = [[-1.25, 1.0], [-1.75, 1.0], [-1.75, 1.5], [-1.25, 1.5], [-1.25, 1.0]]
durations = [1.0, 1.0, 1.0, 1.0]
[[block]]
name = "b"
kind = "trajectory"
method = "local_weighted"
k = 0.5
task_dx = 0.0
)";

TEST(TaskPlacement, SeedArmPlacedEqualsWrittenOutThere) {
  const std::string start = "alpha1A = 120\n";  // the start posture (a run parameter, not the task's)
  const Study placed = parse_study(std::string(kSquarePlaced) + start, "placed.toml");
  const Study by_hand = parse_study(std::string(kSquareByHand) + start, "by_hand.toml");
  ASSERT_TRUE(placed.blocks[0].context().placement);
  EXPECT_EQ(run0(placed).status(), "ok");
  expect_bitwise_equal(placed, by_hand);
  // ik_error measured in both: every vertex within reach
  EXPECT_EQ(std::get<TrajectoryMetrics>(run0(placed).result).ik_error, 0.0);
}

TEST(TaskPlacement, PlanarChainPlacedEqualsWrittenOutThere) {
  const std::string robot = "[robot]\nl = [1.0, 1.0, 0.5, 0.5]\nm = [5.0, 2.0, 0.5, 0.5]\nb = 0.1\n";
  const Study placed = parse_study(robot + kSquarePlaced, "placed.toml");
  const Study by_hand = parse_study(robot + kSquareByHand, "by_hand.toml");
  ASSERT_TRUE(placed.chain);
  const RunOutcome o = run0(placed);  // open loop at half speed: it drifts off the path, and runs to the end
  EXPECT_EQ(std::get<TrajectoryMetrics>(o.result).samples, 4001u) << o.status();
  expect_bitwise_equal(placed, by_hand);
}

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(TaskPlacement, SpatialChainPlacedEqualsWrittenOutThere) {
  StudyOptions so;
  so.robot_text = read_text(std::string(KS_SOURCE_DIR) + "/studies/robots/arm7.urdf");
  ASSERT_FALSE(so.robot_text->empty());
  const std::string robot = "[robot]\nurdf = \"robots/arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n"
                            "gravity = [0, 0, -9.81]\n";
  const std::string block = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\nK_N = 20\n";
  // (x, y, z) -> (-y - 0.25, x, z + 0.125), durations doubled
  const Study placed = parse_study(robot + R"([task]
vertices = [[0.5, -0.125, 0.375], [0.5, 0.125, 0.375], [0.5, 0.125, 0.625], [0.5, -0.125, 0.625], [0.5, -0.125, 0.375]]
durations = [1.0, 1.0, 1.0, 1.0]
integrator = "rk4"
)" + block + "task_rotation = 1.5707963267948966\ntask_dx = -0.25\ntask_dz = 0.125\ntask_time_scale = 2.0\n",
                                   "placed.toml", so);
  const Study by_hand = parse_study(robot + R"([task]
vertices = [[-0.125, 0.5, 0.5], [-0.375, 0.5, 0.5], [-0.375, 0.5, 0.75], [-0.125, 0.5, 0.75], [-0.125, 0.5, 0.5]]
durations = [2.0, 2.0, 2.0, 2.0]
integrator = "rk4"
)" + block + "task_dz = 0.0\n",
                                    "by_hand.toml", so);
  const RunOutcome o = run0(placed);
  EXPECT_EQ(std::get<TrajectoryMetrics>(o.result).ik_error, 0.0) << o.status();
  EXPECT_NE(o.status(), "out_of_reach");
  expect_bitwise_equal(placed, by_hand);
}

/// A spline task through timed waypoints (times 0, 0.5, 1.25, 2 s: uneven, so the spline is no
/// quintic in disguise), placed as kSquarePlaced places the square, and written out there by hand:
/// (x, y) -> (-y + 0.25, x - 0.5), the times doubled.
std::string waypoints_placed(const std::string& spline) {
  return "[task]\nwaypoints = [[0, 1.5, 1.5], [0.5, 1.5, 2.0], [1.25, 2.0, 2.0], [2, 2.0, 1.5]]\n" + spline +
         "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\nk = 0.5\n"
         "task_rotation = 1.5707963267948966\ntask_dx = 0.25\ntask_dy = -0.5\ntask_time_scale = 2.0\n";
}
std::string waypoints_by_hand(const std::string& spline) {
  return "[task]\nwaypoints = [[0, -1.25, 1.0], [1, -1.75, 1.0], [2.5, -1.75, 1.5], [4, -1.25, 1.5]]\n" + spline +
         "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\nk = 0.5\ntask_dx = 0.0\n";
}

TEST(TaskPlacement, WaypointTaskPlacedEqualsWrittenOutThere) {
  const std::string chain = "[robot]\nl = [1.0, 1.0, 0.5, 0.5]\nm = [5.0, 2.0, 0.5, 0.5]\nb = 0.1\n";
  for (const std::string spline : {"", "spline = \"natural\"\n"}) {
    // the seed's closed-form arm and a planar chain
    for (const std::string& robot : {std::string(), chain}) {
      SCOPED_TRACE(spline + robot);
      const std::string start = robot.empty() ? "alpha1A = 120\n" : "";
      const Study placed = parse_study(robot + waypoints_placed(spline) + start, "placed.toml");
      const Study by_hand = parse_study(robot + waypoints_by_hand(spline) + start, "by_hand.toml");
      ASSERT_NE(placed.task.shape, PathShape::quintic);
      ASSERT_EQ(placed.task.shape, by_hand.task.shape);
      ASSERT_TRUE(placed.blocks[0].context().placement);
      const RunOutcome o = run0(placed);
      EXPECT_EQ(std::get<TrajectoryMetrics>(o.result).samples, 4001u) << o.status();
      EXPECT_EQ(std::get<TrajectoryMetrics>(o.result).ik_error, 0.0);
      expect_bitwise_equal(placed, by_hand);
    }
  }
}

TEST(TaskPlacement, SpatialWaypointTaskPlacedEqualsWrittenOutThere) {
  StudyOptions so;
  so.robot_text = read_text(std::string(KS_SOURCE_DIR) + "/studies/robots/arm7.urdf");
  const std::string robot = "[robot]\nurdf = \"robots/arm7.urdf\"\nbase = \"base_link\"\ntip = \"tool\"\n"
                            "gravity = [0, 0, -9.81]\n";
  const std::string block = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\nK_N = 20\n";
  // (x, y, z) -> (-y - 0.25, x, z + 0.125), times doubled
  const Study placed = parse_study(robot + R"([task]
waypoints = [[0, 0.5, -0.125, 0.375], [0.75, 0.5, 0.125, 0.375], [1.5, 0.5, 0.125, 0.625], [2, 0.5, -0.125, 0.625]]
integrator = "rk4"
)" + block + "task_rotation = 1.5707963267948966\ntask_dx = -0.25\ntask_dz = 0.125\ntask_time_scale = 2.0\n",
                                   "placed.toml", so);
  const Study by_hand = parse_study(robot + R"([task]
waypoints = [[0, -0.125, 0.5, 0.5], [1.5, -0.375, 0.5, 0.5], [3, -0.375, 0.5, 0.75], [4, -0.125, 0.5, 0.75]]
integrator = "rk4"
)" + block + "task_dz = 0.0\n",
                                    "by_hand.toml", so);
  ASSERT_EQ(placed.task.shape, PathShape::clamped_spline);
  const RunOutcome o = run0(placed);
  EXPECT_EQ(std::get<TrajectoryMetrics>(o.result).ik_error, 0.0) << o.status();
  expect_bitwise_equal(placed, by_hand);
}

TEST(TaskPlacement, WaypointTaskSampledOnTheWholePath) {
  // a 0.5 s spline at dt = 1 ms: 10 samples on the path at time scale 0.02 (its 0.25 s intervals get 5
  // each: a quintic path would end undersampled), 5 at 0.01
  const Study s = parse_study("[task]\nwaypoints = [[0, 1.5, 1.5], [0.25, 1.5, 2.0], [0.5, 2.0, 2.0]]\n"
                              "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n[block.axes]\n"
                              "task_time_scale = [0.02, 0.01]\n",
                              "fast.toml");
  RunWorkspace ws;
  EXPECT_NE(execute(Scenario::of(s), s.blocks[0].run(0), 0, ws).status(), "undersampled");
  EXPECT_EQ(execute(Scenario::of(s), s.blocks[0].run(1), 0, ws).status(), "undersampled");
  const Study q = parse_study("[task]\nvertices = [[1.5, 1.5], [1.5, 2.0], [2.0, 2.0]]\ndurations = [0.25, 0.25]\n"
                              "[[block]]\nname = \"b\"\nkind = \"trajectory\"\ntask_time_scale = 0.02\n",
                              "fast.toml");
  EXPECT_EQ(execute(Scenario::of(q), q.blocks[0].run(0), 0, ws).status(), "undersampled");
}

TEST(TaskPlacement, QuarterTurnsAreExactAndRotationsKeepDistances) {
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p(u(gen), u(gen), u(gen));
    // the oracle: a quarter turn swaps and negates coordinates
    const Eigen::Vector3d turned[4] = {p, {-p.y(), p.x(), p.z()}, {-p.x(), -p.y(), p.z()}, {p.y(), -p.x(), p.z()}};
    for (int k = -4; k <= 4; ++k) {
      TaskPlacement t;
      t.rotation = k * kQuarter;
      const Eigen::Vector3d q = t.place(p);
      const Eigen::Vector3d& want = turned[((k % 4) + 4) % 4];
      for (int d = 0; d < 3; ++d) EXPECT_EQ(q[d], want[d]) << "k = " << k;
    }
    // any angle: a rigid motion (distances kept), and two turns compose
    TaskPlacement a, b, ab;
    a.rotation = u(gen);
    b.rotation = u(gen);
    ab.rotation = a.rotation + b.rotation;
    a.dx = b.dx = ab.dx = 0.0;
    const Eigen::Vector3d r(u(gen), u(gen), u(gen));
    EXPECT_NEAR((a.place(p) - a.place(r)).norm(), (p - r).norm(), 1e-14);
    EXPECT_NEAR((a.place(b.place(p)) - ab.place(p)).norm(), 0.0, 1e-13);
    TaskPlacement m;
    m.rotation = a.rotation;
    m.dx = 0.25;
    m.dy = -1.0;
    m.dz = 2.0;
    EXPECT_NEAR((m.place(p) - (a.place(p) + Eigen::Vector3d(0.25, -1.0, 2.0))).norm(), 0.0, 1e-14);
  }
}

/// The distance from v to the annulus radii [inner, outer] about the origin, computed here.
double off_reach(Eigen::Vector2d v, double inner, double outer) {
  const double r = std::hypot(v.x(), v.y());
  return r > outer ? r - outer : r < inner ? inner - r : 0.0;
}

TEST(TaskPlacement, OutOfReachEndsWithTheIkError) {
  const std::string task = "[task]\nvertices = [[1.5, 1.5], [1.5, 2.0], [2.0, 2.0], [2.0, 1.5], [1.5, 1.5]]\n"
                           "durations = [0.5, 0.5, 0.5, 0.5]\n";
  const std::string block = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\nmethod = \"local_weighted\"\ntask_dx = 10.0\n";
  const Eigen::Vector2d square[5] = {{1.5, 1.5}, {1.5, 2.0}, {2.0, 2.0}, {2.0, 1.5}, {1.5, 1.5}};
  double want = 0.0;
  for (const auto& v : square) want += off_reach(v + Eigen::Vector2d(10.0, 0.0), 0.0, 3.0);
  // the seed's closed-form arm (reach 3 m) and the same arm as a chain (LM's closest point)
  for (const std::string& robot :
       {std::string(), std::string("[robot]\nl = [1.0, 1.0, 1.0]\nm = [5.0, 2.0, 1.0]\ndynamics = \"recursive\"\n")}) {
    const Study s = parse_study(robot + task + block, "far.toml");
    ASSERT_EQ(s.chain != nullptr, !robot.empty());
    const RunOutcome o = run0(s);
    const auto& m = std::get<TrajectoryMetrics>(o.result);
    EXPECT_EQ(o.status(), "out_of_reach") << robot;
    EXPECT_NEAR(m.ik_error, want, 1e-9) << robot;
    EXPECT_TRUE(std::isnan(m.E));
    const StudySchema schema = make_schema(s);
    const Record row = schema.row(0, 0, s.blocks[0], s.blocks[0].run(0), o, 0.0);
    bool stored = false;
    for (std::size_t i = 0; i < schema.columns.size(); ++i)
      if (schema.columns[i].name == "ik_error") {
        stored = true;
        EXPECT_NEAR(std::get<double>(row.cells[i]), want, 1e-9);
      }
    EXPECT_TRUE(stored);
  }
  // the inner hole of an arm with a long first link: reach 0.5 .. 1.5 m; the task moved by -0.75 m
  // puts its vertices at 0.625, 0.25 (0.25 m inside the hole) and 0.625 m from the base
  const std::string hole_task = "[task]\nvertices = [[1.375, 0.0], [1.0, 0.0], [1.375, 0.0]]\ndurations = [1.0, 1.0]\n"
                                "[[block]]\nname = \"b\"\nkind = \"trajectory\"\ntask_dx = -0.75\n";
  const double want_hole = off_reach({0.625, 0.0}, 0.5, 1.5) + off_reach({0.25, 0.0}, 0.5, 1.5);
  EXPECT_EQ(want_hole, 0.25);
  for (const std::string dynamics : {"", "dynamics = \"recursive\"\n"}) {
    const Study s = parse_study("[robot]\nl = [1.0, 0.25, 0.25]\nm = [1.0, 1.0, 1.0]\n" + dynamics + hole_task, "hole.toml");
    const RunOutcome o = run0(s);
    EXPECT_EQ(o.status(), "out_of_reach") << dynamics;
    EXPECT_NEAR(std::get<TrajectoryMetrics>(o.result).ik_error, want_hole, 1e-9) << dynamics;
  }
}

TEST(TaskPlacement, ColumnsOnlyInBlocksThatPlaceTheirTask) {
  const Study s = parse_study(
      "[[block]]\nname = \"plain\"\nkind = \"trajectory\"\n"
      "[[block]]\nname = \"placed\"\nkind = \"trajectory\"\n[block.axes]\ntask_dx = [0.0, 0.25]\n",
      "cols.toml");
  EXPECT_EQ(s.blocks[0].column_index("task_dx"), Block::npos);
  EXPECT_NE(s.blocks[1].column_index("task_dx"), Block::npos);
  EXPECT_NE(s.blocks[1].column_index("task_rotation"), Block::npos);
  EXPECT_EQ(s.blocks[1].column_index("task_dz"), Block::npos);  // a planar arm
  // the identity placement leaves the run identity as it was without the columns
  const auto ctx = run_context(s, s.histories);
  const BlockIdentity plain(ctx, s.blocks[0]), placed(ctx, s.blocks[1]);
  EXPECT_EQ(plain.run(0), placed.run(0));
  EXPECT_NE(plain.run(0), placed.run(1));
}

/// The first diagnostic of a study that must not parse.
StudyDiagnostic first_error(const std::string& text) {
  try {
    parse_study(text, "bad.toml");
  } catch (const StudyError& e) {
    return e.diagnostics().front();
  }
  ADD_FAILURE() << "parsed: " << text;
  return {};
}

TEST(TaskPlacement, BadValuesAreLocated) {
  const std::string head = "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n";
  StudyDiagnostic d = first_error(head + "task_dz = 0.1\n");
  EXPECT_EQ(d.line, 4);
  EXPECT_EQ(d.column, 1);
  EXPECT_NE(d.message.find("out of the plane"), std::string::npos) << d.message;
  d = first_error(head + "[block.axes]\ntask_dz = [0.0, 0.1]\n");
  EXPECT_EQ(d.line, 5);
  EXPECT_NE(d.message.find("out of the plane"), std::string::npos) << d.message;
  d = first_error(head + "task_time_scale = 0.0\n");
  EXPECT_EQ(d.line, 4);
  EXPECT_NE(d.message.find("task_time_scale = 0; expected task_time_scale within [0.01, 100]"), std::string::npos)
      << d.message;
  d = first_error(head + "[block.axes]\ntask_dx = [0.0, 2000.0]\n");
  EXPECT_EQ(d.line, 5);
  EXPECT_NE(d.message.find("task_dx"), std::string::npos) << d.message;
  d = first_error(head + "task_rotaton = 0.1\n");
  EXPECT_EQ(d.line, 4);
  EXPECT_NE(d.message.find("did you mean 'task_rotation'"), std::string::npos) << d.message;
}

TEST(TaskPlacement, TimeScaleTooFastEndsUndersampled) {
  // 0.5 s segments at dt = 1 ms: 50 samples per segment at time scale 0.1, 5 (< 10) at 0.01
  const Study s = parse_study(
      "[[block]]\nname = \"b\"\nkind = \"trajectory\"\n[block.axes]\ntask_time_scale = [0.1, 0.01]\n", "fast.toml");
  RunWorkspace ws;
  EXPECT_NE(execute(Scenario::of(s), s.blocks[0].run(0), 0, ws).status(), "undersampled");
  EXPECT_EQ(execute(Scenario::of(s), s.blocks[0].run(1), 0, ws).status(), "undersampled");
}

}  // namespace
}  // namespace ks
