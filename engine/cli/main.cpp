// kinesweep: the command-line front end (run, table4, schema, robot; info, query and sensitivity read
// results files).
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/compare_command.hpp"
#include "cli/info_command.hpp"
#include "cli/query_command.hpp"
#include "cli/robot_command.hpp"
#include "cli/run_command.hpp"
#include "cli/schema_command.hpp"
#include "cli/sensitivity_command.hpp"
#include "cli/table4.hpp"
#include "common/shell_word.hpp"
#include "store/store.hpp"

#include "git_commit.hpp"  // KINESWEEP_GIT_COMMIT, generated at build time (engine/package/git_commit.cmake)

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
  if (app.got_subcommand("run")) return ks::cli::run_command(run);
  if (app.got_subcommand("info")) return ks::cli::info_command(info);
  if (app.got_subcommand("query")) return ks::cli::query_command(query);
  if (app.got_subcommand("schema")) return ks::cli::schema_command(schema);
  if (app.got_subcommand("robot")) return ks::cli::robot_command(robot, std::cout, std::cerr);
  if (app.got_subcommand("sensitivity")) return ks::cli::sensitivity_command(sensitivity);
  if (app.got_subcommand("compare")) return ks::cli::compare_command(compare);
  return 0;
}
