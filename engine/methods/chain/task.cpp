// The history buffers of a chain's run (methods/chain/task.hpp).
#include "methods/chain/task.hpp"

namespace ks {

void ChainHistory::prepare(std::size_t samples, int joints, int position_rows) {
  const Eigen::Index n = static_cast<Eigen::Index>((samples + stride - 1) / stride + 1);
  if (t.size() < n || q.rows() != joints || x.rows() != position_rows) {
    t.resize(n);
    q.resize(joints, n);
    qd.resize(joints, n);
    qdd.resize(joints, n);
    tau.resize(joints, n);
    x.resize(position_rows, n);
    alpha.resize(n);
  }
  size = 0;
}

}  // namespace ks
