// Fuzz target for the study parser: any bytes as a study file's text. A well-formed study parses; any
// other input must end in a StudyError (a located diagnostic) -- never a crash, a hang, undefined
// behaviour or another exception. Built with libFuzzer under clang (-DKINESWEEP_FUZZ=ON); the same
// entry point is driven by study_corpus_check (any compiler) over the seed corpus studies/*.toml.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "study/study.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)ks::parse_study(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.toml");
  } catch (const ks::StudyError&) {
    // the expected answer to a malformed study
  }
  return 0;
}
