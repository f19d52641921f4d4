#pragma once
// What a run kind means, read from the results file: its /kinds group (engine/store/FORMAT.md) records
// each kind's statuses, good statuses, ranking and key metrics as the engine that wrote the file
// declared them, so that a file written by an older or newer engine is read by its own meaning. For a
// file written before /kinds, this engine's declarations of the kind (schema/params.hpp).
#include <string>
#include <vector>

#include "store/store.hpp"

namespace ks::cli {

struct KindMeaning {
  bool known = false;                      ///< the file (or, before /kinds, this engine) declares the kind
  std::vector<std::string> statuses;       ///< every status of the kind's runs
  std::vector<std::string> good_statuses;  ///< the statuses of runs that did what the study asked
  std::vector<std::string> ranking;        ///< the objective of the best runs, then its tie-break metric
  std::vector<std::string> key_metrics;    ///< the metrics a one-line summary of a run shows

  /// The first good status ("" when unknown).
  std::string good() const { return good_statuses.empty() ? std::string() : good_statuses.front(); }
  bool is_good(const std::string& status) const;
  std::string objective() const { return ranking.empty() ? std::string() : ranking.front(); }
  std::string tie() const { return ranking.size() < 2 ? std::string() : ranking[1]; }
};

/// The meaning of kind `kind` in the file whose metadata is `meta`.
KindMeaning kind_meaning(const store::StoreMeta& meta, const std::string& kind);

/// The kinds the file declares (its /kinds, in its order), else this engine's.
std::vector<std::string> declared_kinds(const store::StoreMeta& meta);

}  // namespace ks::cli
