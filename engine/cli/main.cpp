// kinesweep: the command-line front end.
#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/table4.hpp"

int main(int argc, char** argv) {
  CLI::App app{"kinesweep: parameter-sweep studies of redundant manipulators"};
  app.set_version_flag("--version", std::string("kinesweep ") + KINESWEEP_VERSION);
  app.require_subcommand(1);
  auto* table4 = app.add_subcommand("table4", "Print seed 000's Table 4 beside kinesweep's figures");
  CLI11_PARSE(app, argc, argv);
  if (table4->parsed()) ks::print_table4(std::cout);
  return 0;
}
