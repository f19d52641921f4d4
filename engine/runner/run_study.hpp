#pragma once
// `kinesweep run`: one path for every way a study runs. The sweep's runs come from this process's
// threads or, when an MPI launcher started the process, from all ranks (shards merged by rank 0);
// then the leader (the process, or rank 0) runs the [[optimize]] blocks into the same file and
// prints the report. See runner/sweep_backend.hpp for the two sources.
#include <iosfwd>
#include <string>

#include "runner/run_request.hpp"
#include "runner/study_meta.hpp"

namespace ks {

/// Run the study's sweep and optimisation blocks into request.output; print the report to `out`
/// and problems to `err` (under MPI: rank 0 prints). Returns the exit code, the same on every
/// rank: 0 done, 1 results file problem, 130 interrupted.
int run_study(const Study& study, const RunRequest& request, std::ostream& out, std::ostream& err);

}  // namespace ks
