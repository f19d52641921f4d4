#pragma once
// The best runs of a results file verified against their grid: each is computed again at dt/2 and
// dt/4 (global_spline's cubic splines also at 2K and 4K knots), and the grid convergence index of
// its key quantities (verify/gci.hpp) goes into the file's /verification table (FORMAT.md).
#include <atomic>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "store/store.hpp"
#include "study/study.hpp"
#include "verify/gci.hpp"

namespace ks {

/// A run that the verification step takes: a best good run of a group of a trajectory block.
struct BestRunRef {
  std::uint64_t run = 0;  ///< global run id
  std::size_t block = 0;  ///< index into study.blocks
  std::string method;
  std::string group;      ///< "lowest E, torque_sq_integral of method=global_spline, end_state=rest"
};

/// The metrics whose best runs are verified besides the kind's ranking objective (E): the integral
/// of tau^T tau, the other objective a comparison of methods is made by.
inline const std::vector<std::string> kVerifiedRankings{"torque_sq_integral"};

/// The runs to verify in a results file of `study` (`file`, its done runs): per trajectory block, per
/// method and, where they have an effect on the run, per end_state (a run ending at rest and one
/// free to move are not the same problem) and per inertia form (not the same robot model), and per
/// motion block, the best good run under the kind's ranking (schema/params.hpp `ranking`: lowest
/// objective, then tie, then run id) and the one of lowest value of each metric of `rank_by` (then
/// lowest run id); each run once. In block order, then by group ("block=NAME" for a motion block).
/// Throws store::StoreError when the file cannot be read.
std::vector<BestRunRef> best_runs_to_verify(const Study& study, const store::ResultsReader& file,
                                            const std::vector<std::string>& rank_by = kVerifiedRankings);

/// What the verification step computes.
struct BestRunVerifyOptions {
  int threads = 0;   ///< worker threads (0: all cores)
  GciOptions gci;    ///< Fs
  /// The /runs metrics verified (each that the block has): E, the peak torque, the integral of tau^T
  /// tau, and global_spline's objective.
  std::vector<std::string> quantities{"E", "tau_inf", "torque_sq_integral", "opt_objective"};
  /// The /runs metrics verified of a motion run: its objective, final duration, f5 and f6.
  std::vector<std::string> motion_quantities{"objective", "final_duration", "torque_sq_integral", "power_sq_integral"};
  const std::atomic<bool>* stop = nullptr;  ///< set: the runs not begun are skipped (their rows not_enough)
  /// The most samples a refined run may take (the path's duration / its dt, + 1): a longer one is not
  /// run (status not_run; its rows not_enough), as its sampled path alone would take memory in
  /// proportion (about 1e6 samples of the seed's square path: 6e6 s of motion at dt/4 = 0.25 ms).
  double max_samples = 1e6;
};
inline constexpr double kGridRatio = 2.0;  ///< the refinement ratio r of the verification grids

/// The grid studies of `runs` (from best_runs_to_verify): each trajectory run's spec computed at dt/2
/// and dt/4 (refinement "dt"), and for global_spline with cubic splines at 2K and 4K knots ("knots",
/// skipped when 4K is beyond the knots' domain); each motion run's with 2 and 4 times as many sample
/// intervals ("samples") and, when it solves with K > 0 controls, with 2K and 4K controls
/// ("controls", skipped beyond the controls' domain); in parallel (a refined trajectory run of more
/// than max_samples samples is not run); grid 3 is the stored row of `file`. One row per (run,
/// refinement, quantity); a motion row's dt is its sample step at the stored duration [s] and its
/// knots its controls per joint. The same whatever the thread count (each run is a pure function of
/// its spec).
store::VerificationTable verify_best_runs(const Study& study, const store::ResultsReader& file,
                                          const std::vector<BestRunRef>& runs, const BestRunVerifyOptions& options);

/// "E = 34.36 Nm (GCI 0.03 %)" for a row of convergence monotone or unchanged (GCI of the run as
/// stored, grid 3); "tau_inf diverges (182, 319, 573 Nm at 20, 40, 80 knots)" for divergent and
/// oscillatory rows; "E: not verified (status on dt/4: max_evaluations)" for not_enough.
std::string verification_phrase(const store::VerificationRow& row);

/// The table as `kinesweep run` prints it: per run, one line per refinement with its quantities' phrases.
void print_verification(std::ostream& out, const store::VerificationTable& table);

}  // namespace ks
