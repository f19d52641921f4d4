// simulate_local(): the seed's loop (Appendix F) with solves instead of inverses, fixed-size types and no
// allocation per step: the loop of methods/closed_form/kernel.hpp over one double. The per-sample
// arithmetic is written element by element: Eigen's two-lane packets on 3-vectors would load, as one
// 16-byte read, two scalars the step has just stored, and such a load cannot be forwarded from the
// store buffer (a stall of the whole step on x86).
#include "methods/base/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "methods/metrics/run_sums.hpp"
#include "methods/metrics/sample_sums.hpp"
#include "methods/base/singular_scale.hpp"
#include "methods/closed_form/batch.hpp"
#include "methods/closed_form/lanes.hpp"

namespace ks {

namespace kernel {

void stage_tasks(const Path2& path, const Profile1* unit, double t, double dt, StageTasks& out) {
  const double th = t + 0.5 * dt, t1 = t + dt;
  out.seg_h = path.segment_at(th);
  out.seg_1 = path.segment_at(t1);
  const Vec2 ah = path.sample_on(out.seg_h, th).a, a1 = path.sample_on(out.seg_1, t1).a;
  out.a_h[0] = ah[0], out.a_h[1] = ah[1], out.a_1[0] = a1[0], out.a_1[1] = a1[1];
  out.unit_h = unit ? unit->sample_on(out.seg_h, th).a[0] : 0.0;
  out.unit_1 = unit ? unit->sample_on(out.seg_1, t1).a[0] : 0.0;
}

double rest_weight(const Shared& s, double t) {
  if (!(t >= s.rest_from)) return 0.0;
  const double u = std::min(1.0, (t - s.rest_from) / s.rest_window);
  return u * u * (3.0 - 2.0 * u);
}

double unit_alpha_acceleration(const Profile1& unit, std::size_t segment, double t) {
  return unit.sample_on(segment, t).a[0];
}

void path_state(const Path2& path, const Profile1* unit, std::size_t segment, double t, PathState& out) {
  const PathSample<2> x = path.sample_on(segment, t);
  out.p[0] = x.p[0], out.p[1] = x.p[1], out.v[0] = x.v[0], out.v[1] = x.v[1];
  out.rise_p = out.rise_v = 0.0;
  if (unit) {
    const PathSample<1> u = unit->sample_on(segment, t);
    out.rise_p = u.p[0] - static_cast<double>(segment);  // the unit profile is k at vertex k
    out.rise_v = u.v[0];
  }
}

void prepare(Batch& b, int lanes, const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions* options,
             int count, TrajectoryHistory* const* histories) {
  if (count < 1 || count > lanes || lanes > kMaxLanes)
    throw std::invalid_argument("simulate_lanes: " + std::to_string(count) + " runs in " + std::to_string(lanes) +
                                " lanes");
  const Path2& path = sampled.path();
  const TrajectoryOptions& o0 = options[0];
  for (int i = 0; i < count; ++i) {
    const TrajectoryOptions& o = options[i];
    if (std::string why; !o.IsValid(&why)) throw std::invalid_argument("simulate: " + why);
    if (sampled.dt() != o.dt)
      throw std::invalid_argument("simulate: path sampled at dt = " + std::to_string(sampled.dt()) +
                                  " s, options ask for dt = " + std::to_string(o.dt) + " s");
    if (o.method == TrajectoryMethod::vertex_alpha && o.vertex_alpha.size() != path.segments())
      throw std::invalid_argument("vertex_alpha needs one alpha per vertex after the first (" +
                                  std::to_string(path.segments()) + ")");
    if (!lane_compatible(o0, o)) throw std::invalid_argument("simulate_lanes: runs that cannot share lanes");
  }
  b.count = count;
  b.dyn.emplace(arm);
  Shared& s = b.shared;
  s.arm = &arm;
  s.dyn = &*b.dyn;
  s.path = &path;
  s.method = o0.method;
  s.integrator = o0.integrator;
  s.dt = o0.dt;
  s.n = sampled.size();
  s.samples = sampled.data();
  s.segment = sampled.segments();
  s.alpha_unit = nullptr;
  s.closed_loop = o0.closed_loop();
  s.stop_on_bound = o0.on_violation == OnViolation::stop;
  const bool local = o0.method == TrajectoryMethod::local_weighted || o0.method == TrajectoryMethod::local_unweighted;
  if (local && o0.end == EndState::rest) {
    double duration = 0;
    for (double d : path.durations()) duration += d;
    s.rest_from = duration - o0.end_window;
    s.rest_window = o0.end_window;
    s.rest_gain = o0.end_gain;
  }
  const std::size_t segments = path.segments();
  if (o0.method == TrajectoryMethod::vertex_alpha) {
    std::vector<Eigen::Matrix<double, 1, 1>> v;
    for (std::size_t k = 0; k <= segments; ++k) v.emplace_back(static_cast<double>(k));
    b.alpha_unit.emplace(std::move(v), path.durations());
    s.alpha_unit = &*b.alpha_unit;
    b.alpha_rise.assign(segments * kMaxLanes, 0.0);
    b.alpha_from.assign(segments * kMaxLanes, 0.0);
  }
  Runs& L = b.runs;
  L = Runs{};
  int donor = -1;  // the first run with a reachable start: its inputs fill the idle lanes
  for (int i = 0; i < lanes; ++i) {
    L.history[i] = nullptr;
    if (i >= count) continue;
    const TrajectoryOptions& o = options[i];
    TrajectoryHistory* h = histories ? histories[i] : nullptr;
    if (h) h->prepare(s.n);
    const std::optional<Vec3> q0 = inverse_kinematics(arm, path.vertices().front(), o.alpha1A, o.elbow);
    if (!q0) continue;
    if (donor < 0) donor = i;
    L.active[i] = 1.0;
    for (int j = 0; j < 3; ++j) L.q0[j][i] = (*q0)[j];
    L.k[i] = o.k;
    L.null_damping[i] = o.null_damping;
    L.torque_bound[i] = o.torque_bound;
    L.tolerance[i] = o.singular_tolerance * singular_scale(arm_reach(arm), 2);  // (relative below 1 m)
    L.kp[i] = o.clik_kp;
    L.kd[i] = o.clik_kd;
    L.tracking_bound[i] = o.tracking_bound;
    L.orientation_bound[i] = o.orientation_bound;
    if (o.method == TrajectoryMethod::vertex_alpha) {
      // the rise of each segment, as TaskPath::sample_on takes it: vertex i + 1 - vertex i
      double prev = o.alpha1A;
      for (std::size_t k = 0; k < segments; ++k) {
        b.alpha_from[k * kMaxLanes + i] = prev;
        b.alpha_rise[k * kMaxLanes + i] = o.vertex_alpha[k] - prev;
        prev = o.vertex_alpha[k];
      }
    }
    if (h) {
      HistoryView& v = b.views[i];
      v = {h->stride, h->t.data(), h->q.data(), h->qd.data(), h->qdd.data(), h->tau.data(), h->x.data(),
           h->alpha.data(), &h->size};
      L.history[i] = &v;
      L.any_history = true;
    }
  }
  b.any_active = donor >= 0;
  if (!b.any_active) return;
  for (int i = 0; i < lanes; ++i) {
    if (L.active[i] != 0.0) continue;
    for (int j = 0; j < 3; ++j) L.q0[j][i] = L.q0[j][donor];
    L.k[i] = L.k[donor], L.null_damping[i] = L.null_damping[donor];
    L.torque_bound[i] = L.torque_bound[donor], L.tolerance[i] = L.tolerance[donor];
    L.kp[i] = L.kp[donor], L.kd[i] = L.kd[donor];
    L.tracking_bound[i] = L.tracking_bound[donor], L.orientation_bound[i] = L.orientation_bound[donor];
    for (std::size_t k = 0; k < b.alpha_rise.size() / kMaxLanes; ++k) {
      b.alpha_rise[k * kMaxLanes + i] = b.alpha_rise[k * kMaxLanes + donor];
      b.alpha_from[k * kMaxLanes + i] = b.alpha_from[k * kMaxLanes + donor];
    }
  }
  L.alpha_rise = b.alpha_rise.empty() ? nullptr : b.alpha_rise.data();
  L.alpha_from = b.alpha_from.empty() ? nullptr : b.alpha_from.data();
  b.options = options;
}

TrajectoryMetrics finish(const Batch& b, int i, const Sums& r) {
  if (b.runs.active[i] == 0.0) return not_simulated(RunStatus::unreachable_start, 3);
  RunShape shape;
  shape.orientation = b.shared.method == TrajectoryMethod::vertex_alpha;
  return finish_run(r, shape, b.options[i]);
}

}  // namespace kernel

TrajectoryMetrics simulate_local(const PlanarArm3& arm, const SampledPath& sampled, const TrajectoryOptions& o,
                                 TrajectoryHistory* history) {
  kernel::Batch b;
  kernel::prepare(b, 1, arm, sampled, &o, 1, &history);
  kernel::Sums sums;
  if (b.any_active) kernel::run<double>(b.shared, b.runs, &sums);
  return kernel::finish(b, 0, sums);
}

}  // namespace ks
