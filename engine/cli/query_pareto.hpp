#pragma once
// `kinesweep query FILE --pareto M1[:min|max],M2[,M3] [--where ...] [--hypervolume R1,R2[,R3]]`: the runs
// on the Pareto front of 2 or 3 metrics (engine/pareto) among the done runs that pass --where and
// whose status is a good status of their kind (the file's /kinds); a run without a value of one of
// the metrics (NaN) is never on the front. With --hypervolume, the front's hypervolume indicator
// against that reference point instead of its runs. Values as query shows them (angles in degrees
// unless --radians), so are the reference's.
#include "cli/query_command.hpp"
#include "cli/query_util.hpp"
#include "store/store.hpp"

namespace ks::cli {

/// Prints the front (a table of its runs, through table_mode: --columns, --sort, --limit, --format)
/// or its hypervolume. Throws ArgError on a bad argument (an unknown metric: the located
/// did-you-mean message of the other options).
int pareto_mode(const QueryArgs& a, store::ResultsReader& reader, Format fmt);

}  // namespace ks::cli
