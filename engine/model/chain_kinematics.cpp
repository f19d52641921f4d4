// Forward kinematics, tip Jacobian and tip bias acceleration of a serial chain (base frame).
#include "model/chain_kinematics.hpp"

#include "model/chain_spatial.hpp"

namespace ks {

using detail::M3;
using detail::V3;

void forward_kinematics(const Chain& chain, ChainData& data, const VecN& q) {
  if (chain.planar_fast_path) {
    detail::PlanarPose P;
    detail::planar_pose(chain, q, P);
    detail::store_planar_pose(chain, P, data);
    return;
  }
  const int n = chain.dof();
  Frame prev;
  for (int i = 0; i < n; ++i) {
    detail::joint_frame(chain.joints[i], prev, q[i], data.joint[i], data.axis[i]);
    prev = data.joint[i];
  }
  data.tip = prev * chain.tip;
}

void tip_jacobian(const Chain& chain, const ChainData& data, Mat6N& J) {
  const int n = chain.dof();
  J.resize(6, n);
  const V3& p = data.tip.p;
  for (int i = 0; i < n; ++i) {
    const V3& a = data.axis[i];
    if (chain.joints[i].type == JointType::revolute) {
      J.col(i).head<3>() = a.cross(p - data.joint[i].p);
      J.col(i).tail<3>() = a;
    } else {
      J.col(i).head<3>() = a;
      J.col(i).tail<3>().setZero();
    }
  }
}

// The spatial velocity v = sum_i s_i qd_i and bias acceleration sum_i v_{i-1} x s_i qd_i of the
// last body (base origin), then the tip point's classical acceleration a_O + w' x p + w x v_p.
Vec6 tip_bias_acceleration(const Chain& chain, ChainData& data, const VecN& q, const VecN& qd) {
  forward_kinematics(chain, data, q);
  V3 w = V3::Zero(), v = V3::Zero(), aw = V3::Zero(), av = V3::Zero();
  for (int i = 0; i < chain.dof(); ++i) {
    V3 sw, sv;
    detail::joint_twist(chain.joints[i].type, data.axis[i], data.joint[i].p, sw, sv);
    sw *= qd[i];
    sv *= qd[i];
    aw += w.cross(sw);
    av += w.cross(sv) + v.cross(sw);
    w += sw;
    v += sv;
  }
  const V3& p = data.tip.p;
  const V3 vp = v + w.cross(p);
  Vec6 bias;
  bias.head<3>() = av + aw.cross(p) + w.cross(vp);
  bias.tail<3>() = aw;
  return bias;
}

}  // namespace ks
