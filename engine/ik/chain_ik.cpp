// Run-time dispatch of chain IK to the compiled (joint count, task) instances, and solution clustering.
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "ik/chain_ik_impl.hpp"

namespace ks::ik {

ChainIkWorkspace::ChainIkWorkspace() : summaries(std::make_unique<Summaries>()) {}
ChainIkWorkspace::~ChainIkWorkspace() = default;
ChainIkWorkspace::ChainIkWorkspace(ChainIkWorkspace&&) noexcept = default;
ChainIkWorkspace& ChainIkWorkspace::operator=(ChainIkWorkspace&&) noexcept = default;

int residual_count(ChainIkTask::Kind kind) { return chain_task_residuals(kind); }

namespace {

using Solver = void (*)(const Chain&, const ChainIkTask&, const VecN&, const Options&, ChainIkResult&,
                        ChainIkWorkspace&);

template <ChainTask T, int... I>
constexpr std::array<Solver, sizeof...(I)> solvers_for(std::integer_sequence<int, I...>) {
  return {&solve_chain_fixed<I + kMinChainJoints, T>...};
}

constexpr int kCounts = kMaxJoints - kMinChainJoints + 1;
constexpr auto kSeq = std::make_integer_sequence<int, kCounts>();
const std::array<std::array<Solver, kCounts>, 4> kSolvers{
    solvers_for<ChainTask::planar_position>(kSeq), solvers_for<ChainTask::planar_pose>(kSeq),
    solvers_for<ChainTask::spatial_position>(kSeq), solvers_for<ChainTask::spatial_pose>(kSeq)};

void unsupported(const Options& options, const VecN& q0, ChainIkResult& r) {
  r.method = options.method;
  r.status = Status::unsupported;
  r.iterations = r.rejected = r.restarts_used = 0;
  r.error = std::numeric_limits<double>::quiet_NaN();
  r.min_rcond = std::numeric_limits<double>::infinity();
  r.q = q0;
  r.F.resize(0);
  r.history.q.clear(), r.history.F.clear(), r.history.error.clear(), r.history.step.clear(),
      r.history.lambda.clear();
}

}  // namespace

void solve_chain(const Chain& chain, const ChainIkTask& task, const VecN& q0, const Options& options,
                 ChainIkResult& result, ChainIkWorkspace& workspace) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("solve_chain: " + why);
  const int n = chain.dof();
  const int kind = static_cast<int>(task.kind);
  if (n < kMinChainJoints || n > kMaxJoints || q0.size() != n || kind < 0 || kind > 3 ||
      (task.kind == ChainTask::planar_pose && !chain.planar()) || options.method == Method::analytic)
    return unsupported(options, q0, result);
  kSolvers[static_cast<std::size_t>(kind)][static_cast<std::size_t>(n - kMinChainJoints)](chain, task, q0, options,
                                                                                          result, workspace);
}

std::vector<int> cluster_solutions(const std::vector<VecN>& q, const std::vector<bool>& revolute, double tolerance) {
  std::vector<int> label(q.size(), -1);
  std::vector<std::size_t> first;  // index in q of each cluster's first member
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (!q[i].allFinite()) continue;
    for (std::size_t c = 0; c < first.size() && label[i] < 0; ++c) {
      const VecN& r = q[first[c]];
      double d = 0.0;
      for (Eigen::Index j = 0; j < q[i].size(); ++j) {
        const double dj = q[i][j] - r[j];
        d = std::max(d, std::abs(revolute[static_cast<std::size_t>(j)] ? wrap_angle(dj) : dj));
      }
      if (d <= tolerance) label[i] = static_cast<int>(c);
    }
    if (label[i] < 0) {
      label[i] = static_cast<int>(first.size());
      first.push_back(i);
    }
  }
  return label;
}

}  // namespace ks::ik
