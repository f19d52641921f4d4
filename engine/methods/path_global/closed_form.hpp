#pragma once
// The evaluator of the path-global method on the seed's planar 3R arm: given alpha(t) (any
// AlphaBasis and its coefficients), the joint path is the exact inverse kinematics of (path, alpha)
// at every sample (methods/path_global/alpha_basis.hpp's families share it), qd and qdd solve the square extended
// task [tip; alpha] (J3 qd = [xd; alpha_d], J3 qdd = [xdd - Jd qd; alpha_dd]), and tau is the inverse
// dynamics M qdd + c + g. The objective is a sum of per-sample terms, each a function of (alpha,
// alpha_d, alpha_dd) at its sample, so its gradient is the chain rule through the basis' weights with
// the three partials per sample by central differences: seven sample evaluations per sample for the
// whole gradient, whatever the number of coefficients.
#include <cstddef>
#include <limits>
#include <vector>

#include "methods/path_global/alpha_basis.hpp"
#include "methods/base/path_global_options.hpp"
#include "methods/base/trajectory.hpp"
#include "model/dynamics.hpp"

namespace ks {

/// The self-motion chart at one sample (Extension::self_motion): alpha = phi + beta sin psi with phi
/// the tip's direction from the base and beta half the arc of tip angles the wrist can reach, and
/// their first two time derivatives [rad, rad/s, rad/s^2].
struct ChartSample {
  double phi[3], beta[3];
};

/// The self-motion chart at a tip position p [m], velocity v [m/s] and acceleration acc [m/s^2] of a
/// 3R arm whose first two links reach L = l1 + l2 [m] and whose last is l3 [m]: phi = atan2(y, x) and
/// beta = acos(gamma) with gamma = (r^2 + l3^2 - L^2) / (2 r l3) (the law of cosines in the triangle
/// base, tip, wrist), with their time derivatives. False when beta is not within (0, pi).
bool self_motion_chart(const Vec2& p, const Vec2& v, const Vec2& acc, double L, double l3, ChartSample& c);

/// The elbow angle [rad] (theta2 of a 3R arm, the angle between its first two links) at the point
/// psi [rad] of the self-motion chart with half-arc beta [rad], the tip at distance r [m] from the
/// base, links l1, l2, l3 [m]: sign(cos psi) times its magnitude from the law of cosines, written so
/// that it keeps its precision near the stretched arm (theta2 near 0, where the chart changes branch).
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

  /// The objective at coefficients c of `basis`; `grad` (size basis.coefficients) its gradient when
  /// not null. Past the reach boundary the samples are taken at the boundary (cos theta2 = +-kReachClamp),
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
  double cost(std::size_t i, double a, double ad, double add, GlobalObjective objective) const;
  /// theta2: the elbow angle when known (the self-motion chart's), NaN to solve it from the reach
  void sample_alpha(std::size_t i, double a, double ad, double add, Elbow elbow, GlobalSample& s,
                    double theta2 = std::numeric_limits<double>::quiet_NaN()) const;

  PlanarArm3 arm_;
  DynamicsCoefficients dyn_;
  const SampledPath& path_;
  std::vector<Vec2> velocity_;  // the path's velocity at each sample [m/s]
  Elbow elbow_;
  double tolerance_;
  Extension extension_;
  std::vector<ChartSample> chart_;  // self_motion
  bool chart_defined_ = true;
};

}  // namespace ks
