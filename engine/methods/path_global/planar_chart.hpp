#pragma once
// The planar chart of the path-global method (methods/path_global/chain.hpp): a planar chain of n >= 3
// revolute joints on a position path has r = n - 2 redundant coordinates, the first n - 3 joint angles
// and one coordinate of the last three joints' self-motion (the tip angle alpha, or the angle psi
// along their self-motion circle as for the seed's arm, methods/path_global/closed_form.hpp). Any planar revolute
// chain maps onto a canonical one: joint i+1 sits at distance L from joint i, in the direction of
// joint i's frame turned by a fixed delta; so the last three joints are a 3R arm of lengths L1, L2, L3
// whose base moves with the first joints, and given the coordinates, the joint path is that 3R's
// closed-form inverse kinematics for the path point seen from its base (exact: tracking error at
// rounding), its rates and accelerations by differentiating the construction.
#include "methods/path_global/chain.hpp"

namespace ks {

class PlanarChartProblem final : public ChainGlobalProblem {
 public:
  /// chain: planar, revolute joints only, n >= 3, positive L1, L2, L3 (std::invalid_argument
  /// otherwise); task: planar_position, sampled at the run's dt; extension: self_motion or alpha;
  /// elbow: the last three joints' branch (sign of sin(theta2 - theta1)) for Extension::alpha.
  PlanarChartProblem(const Chain& chain, const ChainTask& task, Extension extension, Elbow elbow);

  int coordinates() const override { return n_ - 2; }
  /// s.det: L1 L2 sin(theta2 - theta1) of the last three joints' wrist solve [m^2]; q wrapped to (-pi, pi].
  void sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const override;
  void coordinates_of(std::size_t i, const VecN& q, double* z, Elbow& elbow) const override;
  /// The tip-angle chart is singular where the last three joints' wrist solve is (the arm stretched).
  bool singular(const ChainGlobalSample& s, double tolerance) const override {
    return extension_ == Extension::alpha && !(std::abs(s.det) >= tolerance);
  }
  bool wraps_angles() const override { return true; }

 private:
  Extension extension_;
  Elbow elbow_;
  int a_;  // the first of the last three joints
  double ox_[kMaxJoints], oy_[kMaxJoints], beta_[kMaxJoints], sigma_[kMaxJoints];
  double L1_, L2_, L3_, d1_, d2_, d3_, tip_angle_;
  std::vector<Eigen::Vector2d> velocity_;  // the path's velocity at each sample [m/s]
};

}  // namespace ks
