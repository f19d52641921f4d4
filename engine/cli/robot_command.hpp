#pragma once
// `kinesweep robot STUDY.toml | FILE.urdf --base B --tip T [--gravity gx,gy,gz] [--format table|json]`:
// the chain a study (or a URDF file) gives, as the engine reads it: joints (type, axis and position in
// the base frame at q = 0, limits), the bodies' merged masses, centres of mass and inertias, total
// mass, gravity, the plane of a planar chain (origin, normal, in-plane axes) or "spatial", and the
// redundancy left by the study's task (by a position task for a URDF file).
#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace ks::cli {

struct RobotArgs {
  std::string file;     ///< a study (TOML) or a URDF file (.urdf, .xml)
  std::string base, tip;  ///< URDF: the chain's links
  std::string gravity;  ///< URDF: "gx,gy,gz" [m/s^2, base frame]; empty: base -z
  std::string format = "table";
};

RobotArgs& add_robot_command(CLI::App& app);
/// 0, or 2 after printing the problem (a study's FILE:LINE:COL diagnostics, a URDF's FILE:LINE: ...).
int robot_command(const RobotArgs& args, std::ostream& out, std::ostream& err);

}  // namespace ks::cli
