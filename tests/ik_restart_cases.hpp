#pragma once
// Random-start pose IK on a chain with joint limits, ours against Orocos KDL's
// ChainIkSolverPos_LMA with the same restart budget, for tests/test_ik_restarts_kdl.cpp and
// tests/bench/bench_ik_restarts.cpp.
//
// Cases (seeded, the same on every machine): targets = the tip pose (KDL's forward kinematics) of
// joint vectors uniform within the limits; starts uniform within the limits, from another stream;
// each case also carries the seed of its restarts. KDL's restarts draw their starts exactly as
// ik::solve does (ik/solve.hpp: mt19937_64 from that seed, u = ((x >> 11) + 0.5) 2^-53 per joint,
// lower + (upper - lower) u), so both solvers restart from the same configurations.
// Success is judged by KDL's forward kinematics alone: sqrt(|dp|^2 + angle(R R*^T)^2) < tolerance,
// and, where asked, the joint vector within the limits (a revolute joint may first be moved by a
// multiple of 2 pi; KDL's LMA does not know the limits).
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "ik/chain_ik.hpp"
#include "kdl_chain.hpp"

namespace ks::test {

struct RestartCase {
  VecN q0;                 ///< start, within the limits
  KDL::JntArray q0_kdl;    ///< the same
  KDL::Frame goal;         ///< target tip pose (KDL's forward kinematics of a q within the limits)
  ik::ChainIkTask task;    ///< the same target for solve_chain (spatial_pose)
  std::uint64_t seed = 0;  ///< restart seed (ik::Options::restart_seed)
};

/// One uniform draw in (0, 1) from a raw 64-bit draw (ik::solve's mapping).
inline double unit_draw(std::mt19937_64& rng) { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53; }

/// A joint vector uniform within the chain's limits (joints without finite limits: (-pi, pi)).
inline VecN draw_within(const Chain& c, std::mt19937_64& rng) {
  VecN q(c.dof());
  for (int j = 0; j < c.dof(); ++j) {
    const ChainJoint& J = c.joints[static_cast<std::size_t>(j)];
    const double u = unit_draw(rng);
    q[j] = std::isfinite(J.lower) && std::isfinite(J.upper) ? J.lower + (J.upper - J.lower) * u
                                                            : M_PI - 2.0 * M_PI * u;
  }
  return q;
}

inline std::vector<RestartCase> restart_cases(const Chain& c, int count, std::uint64_t target_seed,
                                              std::uint64_t start_seed) {
  std::mt19937_64 targets(target_seed), starts(start_seed);
  const KDL::Chain kchain = kdl_chain(c);  // the solver keeps a reference: it must outlive fk
  KDL::ChainFkSolverPos_recursive fk(kchain);
  std::vector<RestartCase> v(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    RestartCase& k = v[static_cast<std::size_t>(i)];
    const VecN q_true = draw_within(c, targets);
    k.q0 = draw_within(c, starts);
    k.q0_kdl = kdl_array(k.q0);
    fk.JntToCart(kdl_array(q_true), k.goal);
    k.task.kind = ik::ChainTask::spatial_pose;
    k.task.position = Eigen::Vector3d(k.goal.p.x(), k.goal.p.y(), k.goal.p.z());
    for (int r = 0; r < 3; ++r)
      for (int s = 0; s < 3; ++s) k.task.rotation(r, s) = k.goal.M(r, s);
    k.seed = 0x5EED000000000000ull + static_cast<std::uint64_t>(i);
  }
  return v;
}

/// q within the chain's limits, revolute joints compared mod 2 pi (with a 1e-12 slack).
inline bool within_limits(const Chain& c, const VecN& q) {
  for (int j = 0; j < c.dof(); ++j) {
    const ChainJoint& J = c.joints[static_cast<std::size_t>(j)];
    double x = q[j];
    if (J.type == JointType::revolute && std::isfinite(x)) {
      if (x < J.lower) x += 2.0 * M_PI * std::ceil((J.lower - x) / (2.0 * M_PI));
      else if (x > J.upper) x -= 2.0 * M_PI * std::ceil((x - J.upper) / (2.0 * M_PI));
    }
    if (!(x >= J.lower - 1e-12 && x <= J.upper + 1e-12)) return false;
  }
  return true;
}

/// KDL's forward kinematics as the judge of a solution.
class KdlJudge {
 public:
  explicit KdlJudge(const Chain& c) : kchain_(kdl_chain(c)), fk_(kchain_) {}
  /// sqrt(|dp|^2 + angle^2) of q against goal [m, rad]; infinity when KDL fails.
  double pose_error(const VecN& q, const KDL::Frame& goal) {
    KDL::Frame f;
    if (fk_.JntToCart(kdl_array(q), f) < 0) return INFINITY;
    const double e = std::hypot((f.p - goal.p).Norm(), KDL::diff(goal.M, f.M).Norm());
    return std::isfinite(e) ? e : INFINITY;
  }

 private:
  KDL::Chain kchain_;
  KDL::ChainFkSolverPos_recursive fk_;
};

/// KDL's ChainIkSolverPos_LMA (weights 1 on position and rotation, precision eps, max_iter per
/// attempt) with up to `restarts` restarts after an attempt KDL reports as failed (any return code
/// but E_NOERROR), drawn as ik::solve draws them.
class KdlLmaRestarts {
 public:
  KdlLmaRestarts(const Chain& c, double eps, int max_iter) : chain_(c), kchain_(kdl_chain(c)) {
    // KDL's library is built for another vector width: its solver (fixed-size Eigen members) may be
    // larger than this file's sizeof says, so it is allocated with room to spare. Its destructor
    // aborts in this mixed-alignment build ("double free"): the solver is never destroyed.
    const Eigen::Matrix<double, 6, 1> L = Eigen::Matrix<double, 6, 1>::Ones();
    box_ = new Box{KDL::ChainIkSolverPos_LMA(kchain_, L, eps, max_iter), {}};
  }
  /// Solve case k; q_out gets the last attempt's joint vector. Returns the restarts made.
  int solve(const RestartCase& k, int restarts, VecN& q_out) {
    KDL::JntArray q(static_cast<unsigned>(chain_.dof()));
    int rc = box_->s.CartToJnt(k.q0_kdl, k.goal, q);
    int used = 0;
    if (rc != KDL::SolverI::E_NOERROR && restarts > 0) {
      std::mt19937_64 rng(k.seed);
      while (rc != KDL::SolverI::E_NOERROR && used < restarts) {
        ++used;
        rc = box_->s.CartToJnt(kdl_array(draw_within(chain_, rng)), k.goal, q);
      }
    }
    q_out = from_kdl(q);
    return used;
  }

 private:
  struct Box {
    KDL::ChainIkSolverPos_LMA s;
    char spare[1024];
  };
  const Chain& chain_;
  KDL::Chain kchain_;
  Box* box_ = nullptr;
};

}  // namespace ks::test
