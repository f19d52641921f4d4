#pragma once
// `kinesweep sensitivity FILE [--block B] [--metric M ...] [--format table|json]`: first-order and
// total Sobol' indices, with bootstrap intervals, of the blocks a study ran as a Saltelli design
// (/designs), one table per block, metric and combination of the block's other axes.
#include <cstdint>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace ks::cli {

struct SensitivityArgs {
  std::string file;
  std::string block;                 ///< "": every block with a design
  std::vector<std::string> metrics;  ///< empty: the kind's ranking objective
  std::string format = "table";      ///< table | json
  int bootstrap = 1000;
  double confidence = 0.95;
  std::uint64_t seed = 1;
};

SensitivityArgs& add_sensitivity_command(CLI::App& app);
/// Exit codes: 0 ok, 1 file or I/O problem (or no design), 2 bad arguments.
int sensitivity_command(const SensitivityArgs& args);

}  // namespace ks::cli
