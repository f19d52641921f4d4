#pragma once
// The evaluator of the path-global method on the seed's planar 3R arm: given alpha(t) (any
// AlphaBasis and its coefficients), the joint path is the exact inverse kinematics of (path, alpha)
// at every sample (methods/path_global/alpha_basis.hpp's families share it), qd and qdd solve the
// square extended task [tip; alpha], and tau is the inverse dynamics M qdd + c + g
// (methods/path_global/sample_3r.hpp, one template for values and derivatives). The objective is a
// sum of per-sample terms, each a function of the coordinate x (alpha or psi), its rate and its
// acceleration at its sample, so its gradient is the chain rule through the basis' weights with the
// three partials per sample exact: one evaluation in forward-mode derivative numbers (model/dual.hpp)
// per sample gives the term and its three partials, whatever the number of coefficients.
#include <cstddef>
#include <limits>
#include <vector>

#include "methods/base/path_global_options.hpp"
#include "methods/base/trajectory.hpp"
#include "methods/path_global/alpha_basis.hpp"
#include "methods/path_global/objective_3r.hpp"
#include "methods/path_global/sample_3r.hpp"
#include "model/dynamics.hpp"

namespace ks {

/// The self-motion chart at a tip position p [m], velocity v [m/s] and acceleration acc [m/s^2] of a
/// 3R arm whose first two links reach L = l1 + l2 [m] and whose last is l3 [m]: phi = atan2(y, x) and
/// beta = acos(gamma) with gamma = (r^2 + l3^2 - L^2) / (2 r l3) (the law of cosines in the triangle
/// base, tip, wrist), with their time derivatives. False when beta is not within (0, pi).
bool self_motion_chart(const Vec2& p, const Vec2& v, const Vec2& acc, double L, double l3, ChartSample& c);

/// The elbow angle [rad] (theta2 of a 3R arm, the angle between its first two links) at the point
/// psi [rad] of the self-motion chart with half-arc beta [rad], the tip at distance r [m] from the
/// base, links l1, l2, l3 [m]: sign(cos psi) times its magnitude from the law of cosines, written so
/// that it keeps its precision near the stretched arm (theta2 near 0, where the chart changes branch).
/// (The planar chains' chart; the 3R evaluator takes cos and sin of theta2 from
/// self_motion_half_versine, the same quantity without an angle on the way.)
double self_motion_elbow(double psi, double beta, double r, double l3, double l1, double l2);

/// One sample of the joint path for (alpha, alpha_d, alpha_dd).
struct GlobalSample {
  bool reachable = false;  ///< the wrist is within reach of links 1 and 2 (|cos theta2| <= 1)
  double det = 0;          ///< det J3 [m^2] (l1 l2 sin theta2)
  Vec3 q, qd, qdd, tau;    ///< [rad], [rad/s], [rad/s^2], [Nm]
  Sym3 M;                  ///< M(q) [kg m^2]
  Mat23 J;                 ///< position Jacobian [m/rad]
};

class PathGlobalProblem {
 public:
  /// arm: its constants (inertia form included); path: sampled at the run's dt; elbow: the IK branch
  /// (alpha: every sample's; self_motion: the start's); singular_tolerance: |det J3| [m^2] below which
  /// a sample is singular (alpha only: the self-motion chart is regular where it is defined).
  PathGlobalProblem(const PlanarArm3& arm, const SampledPath& path, Elbow elbow, double singular_tolerance,
                    Extension extension = Extension::alpha);

  Extension extension() const { return extension_; }
  /// self_motion: whether the chart is defined at every sample (the wrist's reachable tip angles form
  /// an arc shorter than a full turn, 0 < beta < pi); always true for alpha.
  bool chart_defined() const { return chart_defined_; }
  /// The coordinate (alpha, or psi on branch `elbow`) of tip angle `alpha` at sample i.
  double coordinate(std::size_t i, double alpha, Elbow elbow) const;

  std::size_t samples() const { return path_.size(); }
  const SampledPath& path() const { return path_; }

  /// Sample i of the joint path for the coordinate x (alpha or psi) and its rate and acceleration.
  /// Fills `s` (q .. tau only when reachable).
  void sample(std::size_t i, double x, double xd, double xdd, GlobalSample& s) const;

  /// The objective at coefficients c of `basis`; `grad` (size basis.coefficients) its exact gradient
  /// when not null. Past the reach boundary the samples are taken at the boundary (cos theta2 = +-kReachClamp),
  /// so that the objective stays finite and continuous for the optimiser's trial points.
  double objective(const AlphaBasis& basis, const double* c, GlobalObjective objective, double* grad) const;

  /// The run's metrics at coefficients c (the trajectory kind's, through the per-sample accumulator),
  /// its history when `history` is given. Unreachable or singular samples end the run there with
  /// status infeasible or singular_extension.
  TrajectoryMetrics measure(const AlphaBasis& basis, const double* c, const TrajectoryOptions& o,
                            TrajectoryHistory* history) const;

  /// Extension::alpha: the reach constraints con[i] = cos(theta2_i)^2 - 1 <= 0, one per sample, and
  /// (when `jac` is not null) their gradients, row-major (samples x basis.coefficients).
  void reach(const AlphaBasis& basis, const double* c, double* con, double* jac) const;

  static constexpr double kReachClamp = 1.0 - 1e-12;

 private:
  /// What the terms read (methods/path_global/objective_3r.hpp); x, xd, xdd are the scratch arrays.
  Terms3RInput input(GlobalObjective objective) const;
  /// Samples [first, end) (at most kSampleBlock) at coefficients c into `block` (in lanes where the
  /// processor has them).
  void samples(const AlphaBasis& basis, const double* c, const Terms3RInput& in, std::size_t first, std::size_t end,
               Sample3RBlock& block) const;
  /// Sample i at the coordinate x, its rate and acceleration; `alpha` the tip angle there [rad].
  void evaluate(std::size_t i, double x, double xd, double xdd, Sample3ROf<double>& s, double& alpha) const;

  class MeasureModel;  // measure()

  PlanarArm3 arm_;
  DynamicsCoefficients dyn_;
  const SampledPath& path_;
  Elbow elbow_;
  double tolerance_;
  Extension extension_;
  std::vector<ChartSample> chart_;  // self_motion
  // the path and the chart as arrays over the samples: position, velocity, acceleration, the
  // trapezoid's weights, the chart's phi and beta and |tip|
  std::vector<double> px_, py_, vx_, vy_, ax_, ay_, weight_, phi_[3], beta_[3], r_;
  // an evaluation's scratch: the coordinates at each sample, the terms and their partials (a problem
  // belongs to one run, evaluated by one thread)
  mutable std::vector<double> x_, xd_, xdd_, term_, partial_[3];
  bool chart_defined_ = true;
};

}  // namespace ks
