#pragma once
// The tables `kinesweep run` derives from a file's runs and stores beside them (FORMAT.md):
// /verification, the best runs against their grid, and /sensitivity, the Sobol' indices of the
// Saltelli designs. Written and read by ResultsWriter / ResultsReader (store/store.hpp).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ks::store {

/// One row of /verification (FORMAT.md): a quantity of one best run computed again on two refined
/// grids, and Roache's grid convergence index of the three (verify/gci.hpp). Grid 1 is the finest,
/// grid 3 the run as stored.
struct VerificationRow {
  std::int64_t run = 0;     ///< the run id (its /runs row)
  std::string block;        ///< the run's block
  std::string method;       ///< its method (the group it is the best of)
  std::string group;        ///< what it is the best of, as "method=local_weighted" ("column=value, ...")
  std::string quantity;     ///< a /runs metric: "E", "tau_inf", "torque_sq_integral", "opt_objective"
  std::string unit;         ///< the quantity's stored unit
  std::string refinement;   ///< "dt" (dt, dt/2, dt/4) or "knots" (K, 2K, 4K)
  double ratio = 2.0;       ///< r: the refinement ratio between consecutive grids
  std::array<double, 3> dt{};     ///< per grid (finest first) [s]
  std::array<double, 3> knots{};  ///< per grid (finest first); NaN for methods without knots
  std::array<double, 3> value{};  ///< the quantity per grid (finest first) [unit]; NaN when the run failed
  std::array<std::string, 3> status;  ///< the run's status per grid (finest first)
  std::string convergence;  ///< monotone | unchanged | oscillatory | divergent | not_enough
  double order = 0.0, extrapolated = 0.0, gci_fine = 0.0, gci_coarse = 0.0;  ///< as GciResult (NaN: none)
};
struct VerificationTable {
  double safety_factor = 1.25;  ///< Fs of the GCI
  std::vector<VerificationRow> rows;
};

/// One row of /sensitivity (FORMAT.md): one factor's first-order and total Sobol' indices for one
/// metric at one combination of a Saltelli design block's other dimensions (sensitivity/design_indices.hpp).
struct SensitivityRow {
  std::string block;             ///< the design's block
  std::string metric;            ///< the /runs metric
  std::int64_t combination = 0;  ///< the combination of the block's other dimensions, in run order
  std::string factor;            ///< the factor's axis
  std::int64_t factor_index = 0; ///< its position in the design (/designs/<block>@factors)
  double first = 0.0, first_lo = 0.0, first_hi = 0.0;  ///< S_i and its bootstrap interval (NaN: none)
  double total = 0.0, total_lo = 0.0, total_hi = 0.0;  ///< S_Ti and its bootstrap interval
  double variance = 0.0;         ///< the metric's variance over A and B [unit²]
  std::int64_t samples = 0;      ///< sample rows used
  std::int64_t dropped = 0;      ///< sample rows left out (a run failed or not done)
};
struct SensitivityTable {
  std::int64_t bootstrap = 1000;  ///< resamples behind the intervals
  double confidence = 0.95;       ///< the intervals' level
  std::int64_t seed = 1;          ///< of the resampling
  std::vector<SensitivityRow> rows;
};

}  // namespace ks::store
