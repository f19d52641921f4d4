#pragma once
// `kinesweep info FILE [--best N]`: the study (name, source hash, engine version), runs by block and
// status, the best rows per block, which histories and landscapes the file holds, and each optimisation
// (/optimizations/<name>: variables, stages, best point, the thesis' reference for a preset).
#include <string>

namespace CLI {
class App;
}

namespace ks::cli {

struct InfoArgs {
  std::string file;
  int best = 3;  ///< best rows shown per block
};

InfoArgs& add_info_command(CLI::App& app);
/// Exit codes: 0 ok, 1 file or I/O problem, 2 bad arguments.
int info_command(const InfoArgs& args);

}  // namespace ks::cli
