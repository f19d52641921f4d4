// PlanarChartProblem (methods/path_global/planar_chart.hpp): the canonical map of a planar revolute chain and
// the joint path from the coordinates.
#include "methods/path_global/planar_chart.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "common/angles.hpp"
#include "methods/path_global/closed_form.hpp"
#include "model/planar_chain_dynamics.hpp"

namespace ks {
namespace {

using V2 = Eigen::Vector2d;
constexpr double kClamp = 1.0 - 1e-12;

V2 dir(double a) { return {std::cos(a), std::sin(a)}; }
V2 perp(const V2& v) { return {-v.y(), v.x()}; }  // turned by +90 degrees
V2 turned(const V2& v, double a) {  // v rotated by a
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

}  // namespace

PlanarChartProblem::PlanarChartProblem(const Chain& chain, const ChainTask& task, Extension extension, Elbow elbow)
    : ChainGlobalProblem(chain, task), extension_(extension), elbow_(elbow), a_(chain.dof() - 3) {
  if (!planar_revolute(chain) || n_ < 3 || task.space != TaskSpace::planar_position || extension == Extension::joints)
    throw std::invalid_argument("global_spline: the planar chart needs a planar chain of 3 or more revolute joints on a "
                                "position path, and the self_motion or alpha extension");
  for (int i = 0; i < n_; ++i) {
    const ChainJoint& j = chain.joints[static_cast<std::size_t>(i)];
    ox_[i] = j.origin.p.x();
    oy_[i] = j.origin.p.y();
    beta_[i] = std::atan2(j.origin.R(1, 0), j.origin.R(0, 0));
    sigma_[i] = j.axis.z() > 0.0 ? 1.0 : -1.0;
  }
  const V2 o1(ox_[a_ + 1], oy_[a_ + 1]), o2(ox_[a_ + 2], oy_[a_ + 2]), t(chain.tip.p.x(), chain.tip.p.y());
  L1_ = o1.norm(), L2_ = o2.norm(), L3_ = t.norm();
  d1_ = std::atan2(o1.y(), o1.x()), d2_ = std::atan2(o2.y(), o2.x()), d3_ = std::atan2(t.y(), t.x());
  tip_angle_ = std::atan2(chain.tip.R(1, 0), chain.tip.R(0, 0));
  if (!(L1_ > 0 && L2_ > 0 && L3_ > 0))
    throw std::invalid_argument("global_spline: the last three joints need links of positive length");
  const SampledPath3& path = task.path;
  velocity_.reserve(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) velocity_.push_back(path.path().sample_on(path.segment(i), path.time(i)).v.head<2>());
}

void PlanarChartProblem::sample(std::size_t i, const double (*z)[3], ChainGlobalSample& s) const {
  const SampledPath3& path = task_.path;
  s.q.resize(n_), s.qd.resize(n_), s.qdd.resize(n_), s.tau.resize(n_);
  s.violation = 0.0;
  // the first joints: their frames' angles and the base of the last three, P_a, with its derivatives
  double phi = 0, phid = 0, phidd = 0;
  V2 P(ox_[0], oy_[0]), Pd(0, 0), Pdd(0, 0);
  for (int k = 0; k < a_; ++k) {
    s.q[k] = z[k][0], s.qd[k] = z[k][1], s.qdd[k] = z[k][2];
    phi += beta_[k] + sigma_[k] * z[k][0];
    phid += sigma_[k] * z[k][1];
    phidd += sigma_[k] * z[k][2];
    const V2 o = turned(V2(ox_[k + 1], oy_[k + 1]), phi);
    P += o;
    Pd += phid * perp(o);
    Pdd += phidd * perp(o) - phid * phid * o;
  }
  const V2 d = path.position(i).head<2>() - P, dd = velocity_[i] - Pd, ddd = path.acceleration(i).head<2>() - Pdd;
  // the last three joints' tip direction A (theta3) and branch
  const double* x = z[n_ - 3];
  double A, Ad, Add, beta = 0.0;
  Elbow elbow = elbow_;
  if (extension_ == Extension::self_motion) {
    ChartSample c;
    const double r = d.norm(), L = L1_ + L2_;
    const double gamma = (r * r + L3_ * L3_ - L * L) / (2.0 * L3_ * r);
    s.violation += std::max(0.0, std::abs(gamma) - 1.0) + std::max(0.0, std::abs(L1_ - L2_) - (r - L3_));
    self_motion_chart(d, dd, ddd, L, L3_, c);
    const double g = std::clamp(gamma, -kClamp, kClamp);
    if (!(std::abs(gamma) < 1.0)) c.beta[0] = std::acos(g), c.beta[1] = c.beta[2] = 0.0;  // off the chart: held at its edge
    const double sp = std::sin(x[0]), cp = std::cos(x[0]);
    A = c.phi[0] + c.beta[0] * sp;
    Ad = c.phi[1] + c.beta[1] * sp + c.beta[0] * cp * x[1];
    Add = c.phi[2] + c.beta[2] * sp + 2.0 * c.beta[1] * cp * x[1] - c.beta[0] * sp * x[1] * x[1] + c.beta[0] * cp * x[2];
    elbow = cp >= 0.0 ? Elbow::positive : Elbow::negative;
    beta = c.beta[0];
  } else {
    A = x[0] - tip_angle_ + d3_, Ad = x[1], Add = x[2];
  }
  s.alpha = A - d3_ + tip_angle_;
  // the wrist, then the 2R solve of the first two of the last three
  const V2 eA = dir(A);
  const V2 w = d - L3_ * eA, wd = dd - L3_ * Ad * perp(eA), wdd = ddd - L3_ * (Add * perp(eA) - Ad * Ad * eA);
  const double cr_raw = (w.squaredNorm() - L1_ * L1_ - L2_ * L2_) / (2.0 * L1_ * L2_);
  s.violation += std::max(0.0, std::abs(cr_raw) - 1.0);
  const bool charted = extension_ == Extension::self_motion && s.violation == 0.0;
  const double rho = charted ? self_motion_elbow(x[0], beta, d.norm(), L3_, L1_, L2_)
                             : static_cast<int>(elbow) * std::acos(std::clamp(cr_raw, -kClamp, kClamp));
  const double cr = std::cos(rho), sr = std::sin(rho);
  const double t1 = std::atan2(w.y(), w.x()) - std::atan2(L2_ * sr, L1_ + L2_ * cr), t2 = t1 + rho;
  Eigen::Matrix2d M2;
  M2 << -L1_ * std::sin(t1), -L2_ * std::sin(t2), L1_ * std::cos(t1), L2_ * std::cos(t2);
  s.det = M2.determinant();
  const Eigen::PartialPivLU<Eigen::Matrix2d> lu(M2);
  const V2 td = lu.solve(wd);
  const V2 tdd = lu.solve(wdd + L1_ * td[0] * td[0] * dir(t1) + L2_ * td[1] * td[1] * dir(t2));
  // back to the joints: phi_a = theta1 - delta1, phi_a+1 = theta2 - delta2, phi_a+2 = A - delta3
  const int a = a_;
  s.q[a] = remainder_2pi(sigma_[a] * (t1 - d1_ - phi - beta_[a]));
  s.q[a + 1] = remainder_2pi(sigma_[a + 1] * (t2 - d2_ - (t1 - d1_) - beta_[a + 1]));
  s.q[a + 2] = remainder_2pi(sigma_[a + 2] * (A - d3_ - (t2 - d2_) - beta_[a + 2]));
  s.qd[a] = sigma_[a] * (td[0] - phid), s.qd[a + 1] = sigma_[a + 1] * (td[1] - td[0]), s.qd[a + 2] = sigma_[a + 2] * (Ad - td[1]);
  s.qdd[a] = sigma_[a] * (tdd[0] - phidd), s.qdd[a + 1] = sigma_[a + 1] * (tdd[1] - tdd[0]);
  s.qdd[a + 2] = sigma_[a + 2] * (Add - tdd[1]);
  evaluate_dynamics(chain_, data_, s.q, s.qd, state_);
  s.tau = state_.M * s.qdd + state_.c + state_.g;
}

void PlanarChartProblem::coordinates_of(std::size_t i, const VecN& q, double* z, Elbow& elbow) const {
  double phi = 0;
  V2 P(ox_[0], oy_[0]);
  for (int k = 0; k < a_; ++k) {
    z[k] = q[k];
    phi += beta_[k] + sigma_[k] * q[k];
    P += turned(V2(ox_[k + 1], oy_[k + 1]), phi);
  }
  const double phia = phi + beta_[a_] + sigma_[a_] * q[a_], phib = phia + beta_[a_ + 1] + sigma_[a_ + 1] * q[a_ + 1];
  const double phic = phib + beta_[a_ + 2] + sigma_[a_ + 2] * q[a_ + 2];
  const double t1 = phia + d1_, t2 = phib + d2_, A = phic + d3_;
  elbow = std::sin(t2 - t1) >= 0.0 ? Elbow::positive : Elbow::negative;
  if (extension_ == Extension::alpha) {
    z[n_ - 3] = A - d3_ + tip_angle_;
    return;
  }
  const V2 d = task_.path.position(i).head<2>() - P;
  const double r = d.norm(), L = L1_ + L2_;
  const double gamma = std::clamp((r * r + L3_ * L3_ - L * L) / (2.0 * L3_ * r), -kClamp, kClamp);
  const double s = std::clamp(remainder_2pi(A - std::atan2(d.y(), d.x())) / std::acos(gamma), -1.0, 1.0);
  z[n_ - 3] = std::atan2(s, static_cast<int>(elbow) * std::sqrt(1.0 - s * s));
}

}  // namespace ks
