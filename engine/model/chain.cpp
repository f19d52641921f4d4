// Chain predicates (planar, IsValid) and the n-link planar arm builders.
#include "model/chain.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ks {

namespace {

constexpr double kPlaneTol = 1e-12;  // exact-zero tolerance of the planarity test (unitless or m)

// A rotation about z only, and a translation in the xy plane.
bool frame_in_plane(const Frame& f) {
  const auto& R = f.R;
  return std::abs(f.p.z()) <= kPlaneTol && std::abs(R(2, 0)) <= kPlaneTol && std::abs(R(2, 1)) <= kPlaneTol &&
         std::abs(R(0, 2)) <= kPlaneTol && std::abs(R(1, 2)) <= kPlaneTol && std::abs(R(2, 2) - 1.0) <= kPlaneTol;
}

bool finite(const Eigen::Ref<const Eigen::MatrixXd>& m) { return m.allFinite(); }

bool is_rotation(const Eigen::Matrix3d& R) {
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= 1e-9 &&
         std::abs(R.determinant() - 1.0) <= 1e-9;
}

bool fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

std::string joint_label(const Chain& chain, int i) {
  std::ostringstream s;
  s << "joint " << i;
  if (!chain.joints[i].name.empty()) s << " ('" << chain.joints[i].name << "')";
  return s.str();
}

}  // namespace

bool Chain::planar() const {
  if (joints.empty() || std::abs(gravity.z()) > kPlaneTol) return false;
  for (const ChainJoint& j : joints) {
    if (!frame_in_plane(j.origin)) return false;
    if (j.type == JointType::revolute) {
      // about +z or -z (the frames only turn about z, so the joint's z is the base z)
      if (std::abs(std::abs(j.axis.z()) - 1.0) > kPlaneTol || std::abs(j.axis.x()) > kPlaneTol ||
          std::abs(j.axis.y()) > kPlaneTol)
        return false;
    } else if (std::abs(j.axis.z()) > kPlaneTol) {
      return false;
    }
  }
  return frame_in_plane(tip);
}

bool Chain::IsValid(std::string* why) const {
  const int n = dof();
  if (n < 1 || n > kMaxJoints) {
    std::ostringstream s;
    s << "the chain has " << n << " joints; 1 to " << kMaxJoints << " are supported";
    return fail(why, s.str());
  }
  if (!gravity.allFinite()) return fail(why, "gravity is not finite");
  if (!finite(tip.p) || !is_rotation(tip.R)) return fail(why, "the tip frame is not a finite rigid transform");
  for (int i = 0; i < n; ++i) {
    const ChainJoint& j = joints[i];
    const std::string who = joint_label(*this, i);
    if (!finite(j.origin.p) || !is_rotation(j.origin.R))
      return fail(why, who + ": origin is not a finite rigid transform (R must be a rotation)");
    if (!j.axis.allFinite() || std::abs(j.axis.norm() - 1.0) > 1e-9) return fail(why, who + ": axis is not a unit vector");
    if (std::isnan(j.lower) || std::isnan(j.upper) || j.lower > j.upper)
      return fail(why, who + ": limits need lower <= upper");
    if (!(j.velocity > 0.0) || !(j.effort > 0.0)) return fail(why, who + ": velocity and effort limits must be > 0");
    if (!std::isfinite(j.mass) || j.mass < 0.0) return fail(why, who + ": mass must be finite and >= 0");
    if (!finite(j.com)) return fail(why, who + ": centre of mass is not finite");
    if (!finite(j.inertia)) return fail(why, who + ": inertia is not finite");
    const double scale = std::max(1.0, j.inertia.cwiseAbs().maxCoeff());
    if ((j.inertia - j.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      return fail(why, who + ": inertia is not symmetric");
    const double lmin = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(j.inertia, Eigen::EigenvaluesOnly).eigenvalues()[0];
    if (lmin < -1e-12 * scale) return fail(why, who + ": inertia is not positive semi-definite");
  }
  return true;
}

Chain planar_chain(const std::vector<PlanarLink>& links, double g, std::string name) {
  Chain chain;
  chain.name = std::move(name);
  chain.source = "planar";
  chain.gravity = Eigen::Vector3d(0.0, -g, 0.0);
  double previous_length = 0.0;
  for (std::size_t i = 0; i < links.size(); ++i) {
    const PlanarLink& L = links[i];
    ChainJoint j;
    j.name = "joint" + std::to_string(i + 1);
    j.type = JointType::revolute;
    j.origin.p = Eigen::Vector3d(previous_length, 0.0, 0.0);
    j.axis = Eigen::Vector3d::UnitZ();
    j.lower = L.lower;
    j.upper = L.upper;
    j.velocity = L.velocity;
    j.effort = L.effort;
    j.mass = L.m;
    j.com = Eigen::Vector3d(L.lc, 0.0, 0.0);
    const double b2 = L.m > 0.0 ? std::max(0.0, 12.0 * L.I / L.m - L.l * L.l) : 0.0;
    j.inertia = Eigen::Vector3d(L.m * b2 / 6.0, L.I, L.I).asDiagonal();
    chain.joints.push_back(std::move(j));
    previous_length = L.l;
  }
  chain.tip.p = Eigen::Vector3d(previous_length, 0.0, 0.0);
  chain.prepare();
  return chain;
}

std::vector<PlanarLink> planar_bars(const std::vector<double>& l, const std::vector<double>& m, double b) {
  if (l.size() != m.size()) throw std::invalid_argument("planar_bars: as many lengths as masses are needed");
  const std::size_t n = l.size();
  std::vector<PlanarLink> links(n);
  for (std::size_t i = 0; i < n; ++i) {
    links[i].l = l[i];
    links[i].m = m[i];
    links[i].lc = l[i] / 2.0;
    links[i].I = m[i] * (l[i] * l[i] + b * b) / 12.0;
  }
  return links;
}

}  // namespace ks
