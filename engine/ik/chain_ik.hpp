#pragma once
// Inverse kinematics of any serial chain (model/chain.hpp) with the solvers of ik/solve.hpp, chosen
// at run time: the chain's joint count (2 .. kMaxJoints) and the task pick one compiled instance of
// solve() over ik/chain_problems.hpp.
//
//   ChainIkWorkspace ws;                      // reuse it: no allocation per solve once warm
//   ChainIkResult r;
//   solve_chain(chain, task, q0, options, r, ws);
//
// Also: cluster_solutions, which names distinct solutions where no closed form is known.
#include <memory>
#include <vector>

#include "ik/chain_problems.hpp"
#include "ik/solve.hpp"

namespace ks::ik {

/// What the tip must reach (units: m, rad; base frame).
struct ChainIkTask {
  using Kind = ChainTask;  ///< planar_position, planar_pose, spatial_position, spatial_pose
  Kind kind = Kind::spatial_pose;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< tip position [m] (planar tasks: x, y only)
  double alpha = 0.0;                                  ///< planar_pose: tip angle about z [rad]
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< spatial_pose: tip rotation (orthonormal)
};

/// Residual vector of any task (2, 3 or 6 entries, see ik/chain_problems.hpp).
using VecF = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

/// Number of residuals of a task kind (2, 3 or 6).
int residual_count(ChainIkTask::Kind kind);

/// Iteration history of a chain solve: row k is iterate k (k = 0 the start), as ik::History.
struct ChainIkHistory {
  std::vector<VecN> q;        ///< iterate q_k (chain.dof() entries)
  std::vector<VecF> F;        ///< residual F(q_k) (residual_count entries)
  std::vector<double> error;  ///< ||F(q_k)||
  std::vector<double> step;   ///< ||q_k - q_{k-1}|| (0 at k = 0)
  std::vector<double> lambda; ///< damping used for the step to q_k (lm, lm_adaptive; 0 otherwise)
  std::size_t size() const { return q.size(); }
};

/// Outcome of one chain solve (as ik::Summary; no known-solution index: see cluster_solutions).
struct ChainIkResult {
  Method method = Method::newton;
  Status status = Status::max_iter;
  int iterations = 0;       ///< updates made (summed over all attempts: Options::restarts)
  int rejected = 0;         ///< lm_adaptive: rejected trial steps (summed over all attempts)
  int restarts_used = 0;    ///< random restarts made (ik/solve.hpp)
  double error = 0.0;       ///< ||F(q)|| (m and rad mixed for the pose tasks)
  double min_rcond = 1.0;   ///< smallest reciprocal condition of a matrix solved (inf: none was)
  VecN q;                   ///< final iterate (chain.dof() entries; converged: revolute joints whose
                            ///< limits are not enforced wrapped to (-pi, pi], see ik/solve.hpp)
  VecF F;                   ///< F(q)
  ChainIkHistory history;   ///< empty unless Options::keep_history

  bool converged() const { return status == Status::converged; }
};

/// Reusable state of solve_chain: the kinematics workspace and the per-(joint count, task) solver
/// summaries whose history capacity is kept between calls. Not shared between threads.
class ChainIkWorkspace {
 public:
  ChainIkWorkspace();
  ~ChainIkWorkspace();
  ChainIkWorkspace(ChainIkWorkspace&&) noexcept;
  ChainIkWorkspace& operator=(ChainIkWorkspace&&) noexcept;

  ChainData data;  ///< forward kinematics of the last evaluated q
  struct Summaries;
  std::unique_ptr<Summaries> summaries;  ///< one ik::Summary<N, M> per instance (chain_ik_impl.hpp)
};

/// Solve `task` for `chain` from q0 with `options` (ik/solve.hpp: method, tolerances, joint_limits
/// against the chain's [lower, upper], restarts drawn within them). \param[in] q0 start (chain.dof() entries) [rad or m].
/// \param[out] result status, final q, F, error, counts and (keep_history) the iterates.
/// Status::unsupported, without iterating, when: chain.dof() is outside 2 .. kMaxJoints, q0 has
/// another size, the task is planar_pose and the chain is not planar (Chain::planar()), the method
/// is analytic (no closed form for a general chain), or halley_thesis on a non-square task
/// (residual_count(kind) != dof). Throws std::invalid_argument when options.IsValid() fails.
void solve_chain(const Chain& chain, const ChainIkTask& task, const VecN& q0, const Options& options,
                 ChainIkResult& result, ChainIkWorkspace& workspace);

/// Greedy clustering of joint vectors into distinct solutions, deterministic and in input order:
/// q[0] opens cluster 0; each later q[i] joins the first cluster (lowest label) whose FIRST member
/// q[f] satisfies max_j |d_j| <= tolerance, d = q[i] - q[f] with revolute components wrapped to
/// (-pi, pi] (distance on the joint torus); otherwise it opens the next cluster. Labels are 0, 1, ...
/// in order of the clusters' first members. A q with a non-finite entry gets -1 and opens nothing.
/// \param q joint vectors, each of revolute.size() entries [rad or m].
/// \param revolute per joint, whether it is an angle (compared mod 2 pi).
/// \param tolerance max-norm radius [rad or m] (default 1e-3: above the spread tolerance /
///        sigma_min(J) of converged solves, far below the distance between distinct solutions away
///        from singularities).
/// \return one label per q.
std::vector<int> cluster_solutions(const std::vector<VecN>& q, const std::vector<bool>& revolute,
                                   double tolerance = 1e-3);

}  // namespace ks::ik
