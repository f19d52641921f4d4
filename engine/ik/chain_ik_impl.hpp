#pragma once
// Internals of ik/chain_ik.hpp shared by its .cpp files: the workspace's summaries and the solve of
// one (joint count N, task T) instance. The chain_ik_<task>.cpp files instantiate solve_chain_fixed
// for N = 2 .. kMaxJoints (ik/chain_ik_instances.hpp); chain_ik.cpp dispatches.
#include <tuple>
#include <utility>

#include "ik/chain_ik.hpp"

namespace ks::ik {

inline constexpr int kMinChainJoints = 2;

/// The four summaries of one joint count.
template <int N>
struct ChainSummariesN {
  Summary<N, 2> planar_position;
  Summary<N, 3> planar_pose;
  Summary<N, 3> spatial_position;
  Summary<N, 6> spatial_pose;

  template <ChainTask T>
  auto& get() {
    if constexpr (T == ChainTask::planar_position) return planar_position;
    else if constexpr (T == ChainTask::planar_pose) return planar_pose;
    else if constexpr (T == ChainTask::spatial_position) return spatial_position;
    else return spatial_pose;
  }
};

template <int... I>
auto chain_summaries_tuple(std::integer_sequence<int, I...>)
    -> std::tuple<ChainSummariesN<I + kMinChainJoints>...>;

struct ChainIkWorkspace::Summaries {
  decltype(chain_summaries_tuple(std::make_integer_sequence<int, kMaxJoints - kMinChainJoints + 1>())) by_n;

  template <int N, ChainTask T>
  auto& get() {
    return std::get<N - kMinChainJoints>(by_n).template get<T>();
  }
};

/// Solve task T on a chain of N joints (the caller has checked chain.dof() == N and q0.size() == N).
/// Defined in ik/chain_ik_instances.hpp; instantiated by the chain_ik_<task>.cpp files.
template <int N, ChainTask T>
void solve_chain_fixed(const Chain& chain, const ChainIkTask& task, const VecN& q0, const Options& options,
                       ChainIkResult& result, ChainIkWorkspace& ws);

}  // namespace ks::ik
