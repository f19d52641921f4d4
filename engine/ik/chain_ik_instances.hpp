#pragma once
// Definition of solve_chain_fixed (ik/chain_ik_impl.hpp), for the .cpp files that instantiate it:
//   KS_CHAIN_IK_INSTANTIATE(ChainTask::spatial_pose)   // N = 2 .. kMaxJoints
#include "ik/chain_ik_impl.hpp"
#include "ik/solve_impl.hpp"

namespace ks::ik {

template <int N, ChainTask T>
void solve_chain_fixed(const Chain& chain, const ChainIkTask& task, const VecN& q0, const Options& options,
                       ChainIkResult& result, ChainIkWorkspace& ws) {
  constexpr int M = chain_task_residuals(T);
  ChainProblem<N, T> pb;
  pb.bind(chain, ws.data);
  pb.position = task.position;
  pb.alpha = task.alpha;
  pb.rotation = task.rotation;
  Summary<N, M>& s = ws.summaries->template get<N, T>();
  solve(pb, Vec<N>(q0), options, s);

  result.method = s.method;
  result.status = s.status;
  result.iterations = s.iterations;
  result.rejected = s.rejected;
  result.restarts_used = s.restarts_used;
  result.error = s.error;
  result.min_rcond = s.min_rcond;
  result.q = s.q;
  result.F = s.F;
  ChainIkHistory& h = result.history;
  const std::size_t rows = s.history.size();
  h.q.resize(rows), h.F.resize(rows), h.error.resize(rows), h.step.resize(rows), h.lambda.resize(rows);
  for (std::size_t k = 0; k < rows; ++k) {
    h.q[k] = s.history.q[k];
    h.F[k] = s.history.F[k];
    h.error[k] = s.history.error[k];
    h.step[k] = s.history.step[k];
    h.lambda[k] = s.history.lambda[k];
  }
}

}  // namespace ks::ik

#define KS_CHAIN_IK_INSTANTIATE_N(N, T)                                                                   \
  template void ks::ik::solve_chain_fixed<N, T>(const ks::Chain&, const ks::ik::ChainIkTask&, const ks::VecN&, \
                                                const ks::ik::Options&, ks::ik::ChainIkResult&,           \
                                                ks::ik::ChainIkWorkspace&);
#define KS_CHAIN_IK_INSTANTIATE(T)                                                          \
  KS_CHAIN_IK_INSTANTIATE_N(2, T) KS_CHAIN_IK_INSTANTIATE_N(3, T) KS_CHAIN_IK_INSTANTIATE_N(4, T) \
  KS_CHAIN_IK_INSTANTIATE_N(5, T) KS_CHAIN_IK_INSTANTIATE_N(6, T) KS_CHAIN_IK_INSTANTIATE_N(7, T) \
  KS_CHAIN_IK_INSTANTIATE_N(8, T)
