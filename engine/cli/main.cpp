// kinesweep: the command-line front end (run, table4, schema, robot; info, query and sensitivity read
// results files).
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/compare_command.hpp"
#include "cli/info_command.hpp"
#include "cli/mpi_program.hpp"
#include "cli/query_command.hpp"
#include "cli/query_util.hpp"
#include "cli/robot_command.hpp"
#include "cli/run_command.hpp"
#include "cli/schema_command.hpp"
#include "cli/sensitivity_command.hpp"
#include "cli/table4.hpp"
#include "common/shell_word.hpp"
#include "runner/mpi_launch.hpp"
#include "store/store.hpp"

#include "git_commit.hpp"  // KINESWEEP_GIT_COMMIT, generated at build time (engine/package/git_commit.cmake)

namespace ks::cli {

// The subcommands' options (declared in each command's header): here, so that CLI11, a header-only
// library that costs seconds in every file that includes it, is compiled in this file only.

RunArgs& add_run_command(CLI::App& app) {
  static RunArgs a;
  auto* c = app.add_subcommand("run", "Run a study file into an HDF5 results file");
  c->add_option("study", a.study, "study file (TOML)")->required();
  c->add_option("-o,--output", a.output, "results file (default: the study's output, results/<name>.h5)");
  c->add_option("--threads", a.threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  c->add_option("--lanes", a.lanes, "trajectory runs computed side by side in SIMD lanes: 1, 4 (AVX2) or 8 (AVX-512) "
                "(default: the widest this processor runs; the results are the same bit for bit)")
      ->check(CLI::IsMember({1, 4, 8}));
  c->add_flag("--resume", a.resume, "complete only the runs missing from an existing results file");
  c->add_flag("--overwrite", a.overwrite, "replace an existing results file");
  c->add_flag("--dry-run", a.dry_run, "print the output path, runs per block, estimated size and time (from sample runs); write nothing");
  c->add_option("--histories", a.histories, "full | every=N | none (default: the study's)");
  c->add_option("--compression", a.compression, "history compression, read by HDF5's shuffle and deflate filters (default 1: runs of the top byte plane coded, the rest stored; 2-9: libdeflate on the two high planes at that level; 0: raw chunks, no filter)")
      ->check(CLI::Range(0, 9));
  c->add_option("--max-runs", a.max_runs, "the most runs a study may ask for (default 50000000; a study's max_runs may only lower it)")
      ->check(CLI::PositiveNumber);
  c->add_flag("-q,--quiet", a.quiet, "no progress display");
  c->add_flag("--no-verify-best", a.no_verify_best,
              "do not verify the best runs against the grid (dt/2, dt/4; 2K, 4K knots) at the end");
  c->add_flag("--verbose", a.verbose, "with a results-file error, HDF5's own error stack too");
  return a;
}

InfoArgs& add_info_command(CLI::App& app) {
  static InfoArgs a;
  auto* s = app.add_subcommand("info", "Summarise a results file: study, runs by block and status, best rows, "
                                       "histories, landscapes, optimisations");
  s->add_option("file", a.file, "results file (.h5); may be one a sweep is still writing")->required();
  s->add_option("--best", a.best, "best rows shown per block (default 3; N >= 0)")->check(CLI::Validator(check_count, "N>=0"));
  return a;
}

QueryArgs& add_query_command(CLI::App& app) {
  static QueryArgs a;
  auto* q = app.add_subcommand("query", "Print rows of a results file's /runs (filtered, sorted), one run's history, one "
                               "optimisation's evaluations, or the runs on a Pareto front (and its hypervolume)");
  q->add_option("file", a.file, "results file (.h5); may be one a sweep is still writing")->required();
  q->add_option("-w,--where", a.where,
                "filter, repeatable (ANDed): COL OP VALUE with OP = != < <= > >=, COL=A,B,C (any of), "
                "COL=LO..HI or LO<=COL<=HI (range), 'A | B' (either); angles in degrees unless --radians; "
                "also on --optimization evaluations")
      ->allow_extra_args(false);
  q->add_option("-c,--columns", a.columns, "comma-separated columns, or 'all' (default: table: a compact set; csv/json: all)");
  q->add_option("-s,--sort", a.sort, "sort by COL or COL:desc (repeatable or comma list; NaN last)")->allow_extra_args(false);
  q->add_option("-n,--limit", a.limit, "print at most N rows (N >= 0)")->check(CLI::Validator(check_count, "N>=0"));
  q->add_option("-f,--format", a.format, "table | csv | json (default: table; csv for --history)")
      ->check(CLI::IsMember({"table", "csv", "json"}));
  q->add_flag("--radians", a.radians, "show and filter angles in radians (as stored) instead of degrees");
  q->add_flag("--include-pending", a.include_pending, "also rows not done yet (missing values)");
  q->add_option("-g,--group-by", a.group_by, "one row per group of rows with equal COL (comma list: equal in each)");
  q->add_option("--agg", a.agg, "with --group-by, the group's columns: count, FN:COL with FN min, max, mean, median, "
                "sum, argmin, argmax (run_id of the min/max); comma list (default count)");
  q->add_option("--pareto", a.pareto,
                "the runs on the Pareto front of 2 or 3 metrics, comma list of COL, COL:min (default) or COL:max "
                "(e.g. E,min_manipulability:max): the done runs passing --where whose status is good for their kind "
                "(ok, converged) and that no other such run dominates; a run without a value (NaN) is never on it");
  q->add_option("--hypervolume", a.hypervolume,
                "with --pareto: print the front's hypervolume indicator against this reference point (one value "
                "per metric, as shown: angles in degrees unless --radians) instead of its runs");
  q->add_option("--run", a.run, "history mode: the run id");
  q->add_option("--history", a.history, "history mode: array name(s), comma list, or 'all' (default all)");
  q->add_option("--optimization", a.optimization,
                "optimisation mode: print every evaluation of /optimizations/NAME (index, stage, start, the "
                "variables, objective, constraint, status)");
  a.format.clear();
  return a;
}

SchemaArgs& add_schema_command(CLI::App& app) {
  static SchemaArgs a;
  auto* c = app.add_subcommand("schema", "List every run parameter and metric (name, type, units, domain, default)");
  c->add_option("--format", a.format, "markdown | json")->check(CLI::IsMember({"markdown", "json"}));
  return a;
}

RobotArgs& add_robot_command(CLI::App& app) {
  static RobotArgs a;
  auto* c = app.add_subcommand("robot", "Show the chain a study's robot (or a URDF file) gives: joints, masses, "
                                        "inertias, gravity, its plane or spatial, the task's redundancy");
  c->add_option("file", a.file, "study file (TOML) or URDF file (.urdf, .xml)")->required();
  c->add_option("--base", a.base, "URDF: the chain's base link");
  c->add_option("--tip", a.tip, "URDF: the chain's tip link");
  c->add_option("--gravity", a.gravity, "URDF: gx,gy,gz in m/s^2, base frame (default 0,0,-9.81: URDF's z up; "
                                        "--gravity=gx,... when gx is negative)");
  c->add_option("--format", a.format, "table | json")->check(CLI::IsMember({"table", "json"}));
  return a;
}

SensitivityArgs& add_sensitivity_command(CLI::App& app) {
  static SensitivityArgs a;
  auto* s = app.add_subcommand("sensitivity", "First-order and total Sobol' indices (bootstrap intervals) of the "
                                              "blocks run as a Saltelli design");
  s->add_option("file", a.file, "results file (.h5)")->required();
  s->add_option("--block", a.block, "only this block (default: every block with a design)");
  s->add_option("--metric", a.metrics, "metrics to analyse (default: the run kind's ranking objective, E or iterations)");
  s->add_option("--format", a.format, "table (default) or json")->check(CLI::IsMember({"table", "json"}));
  s->add_option("--bootstrap", a.bootstrap, "bootstrap resamples for the intervals (default 1000; 0: none)");
  s->add_option("--confidence", a.confidence, "the intervals' level (default 0.95)");
  s->add_option("--seed", a.seed, "seed of the resampling (default 1)")->check(CLI::NonNegativeNumber);
  return a;
}

CompareArgs& add_compare_command(CLI::App& app) {
  static CompareArgs a;
  auto* c = app.add_subcommand("compare", "Verdict table: the best good run per group (method or any column), "
                                          "per end condition and metric, with its GCI and its margin to the next group");
  c->add_option("file", a.file, "results file (.h5)")->required();
  c->add_option("--by", a.by, "the /runs column whose values are the groups (default: method)");
  c->add_option("--metric", a.metrics, "metrics to compare (default: the run kind's ranking objective, E)");
  c->add_option("--end", a.end, "rest | free: only runs ending so; any: mix them (default: each on its own)")
      ->check(CLI::IsMember({"rest", "free", "any"}));
  c->add_option("-w,--where", a.where, "only the rows where EXPR holds (kinesweep query's syntax, angles in degrees; "
                                      "repeatable: all hold), e.g. inertia=physical");
  c->add_option("--format", a.format, "table (default), json or csv")->check(CLI::IsMember({"table", "json", "csv"}));
  return a;
}

}  // namespace ks::cli

int main(int argc, char** argv) {
  // A sweep's histories travel as buffers of a few hundred KiB, made by the workers and freed by
  // the writer thread. glibc's defaults return memory to the kernel once 128 KiB lie free at the
  // heap's top and map every block over 128 KiB on its own, so such buffers' pages were faulted in
  // (and zeroed by the kernel) again and again: with full histories, most of the system time beyond
  // the write itself. Keep up to 64 MiB free, and map only blocks of 16 MiB or more.
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 16 << 20);
  CLI::App app{"kinesweep: parameter-sweep studies of redundant manipulators"};
  const std::string commit = KINESWEEP_GIT_COMMIT;
  app.set_version_flag("--version", std::string("kinesweep ") + KINESWEEP_VERSION + (commit.empty() ? "" : " (" + commit + ")"));
  ks::store::set_engine_commit(commit);
  app.require_subcommand(1);
  ks::cli::RunArgs& run = ks::cli::add_run_command(app);
  run.program = ks::command_name(argc > 0 ? argv[0] : "");
  for (int i = 0; i < argc; ++i) ks::process_command_line() += (i ? " " : "") + ks::shell_word(argv[i]);
  ks::cli::InfoArgs& info = ks::cli::add_info_command(app);
  ks::cli::QueryArgs& query = ks::cli::add_query_command(app);
  ks::cli::SchemaArgs& schema = ks::cli::add_schema_command(app);
  ks::cli::RobotArgs& robot = ks::cli::add_robot_command(app);
  ks::cli::SensitivityArgs& sensitivity = ks::cli::add_sensitivity_command(app);
  ks::cli::CompareArgs& compare = ks::cli::add_compare_command(app);
  auto* table4 = app.add_subcommand("table4", "Print seed 000's Table 4 beside kinesweep's figures (no file)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  ks::store::print_hdf5_error_stack(false);  // every command says a file's problem in one line (run: unless --verbose)
  if (table4->parsed()) {
    ks::print_table4(std::cout);
    return 0;
  }
  if (app.got_subcommand("run")) {
    // a kinesweep without MPI linked leaves a run an MPI launcher started to the one with MPI
    if (ks::cli::has_mpi_program() && ks::launched_under_mpi()) return ks::cli::exec_mpi_program(argv);
    return ks::cli::run_command(run);
  }
  if (app.got_subcommand("info")) return ks::cli::info_command(info);
  if (app.got_subcommand("query")) return ks::cli::query_command(query);
  if (app.got_subcommand("schema")) return ks::cli::schema_command(schema);
  if (app.got_subcommand("robot")) return ks::cli::robot_command(robot, std::cout, std::cerr);
  if (app.got_subcommand("sensitivity")) return ks::cli::sensitivity_command(sensitivity);
  if (app.got_subcommand("compare")) return ks::cli::compare_command(compare);
  return 0;
}
