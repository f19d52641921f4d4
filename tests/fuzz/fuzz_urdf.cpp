// Fuzz target for the URDF reader: any bytes as a URDF file's text, read as the chain from link
// base_link to link tool (the names the seed corpus, studies/robots/*.urdf, uses). A URDF describing a
// chain the engine can simulate gives a Chain; any other input must end in a UrdfError -- never a crash,
// a hang, unbounded memory, undefined behaviour or another exception. Built with libFuzzer under clang
// (-DKINESWEEP_FUZZ=ON); urdf_corpus_check drives the same entry point with any compiler.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "robot/urdf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)ks::parse_urdf(std::string_view(reinterpret_cast<const char*>(data), size), "base_link", "tool",
                         Eigen::Vector3d(0, 0, -9.81), "fuzz.urdf");
  } catch (const ks::UrdfError&) {
    // the expected answer to a malformed or unsupported robot
  }
  return 0;
}
