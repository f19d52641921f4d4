// Drives a fuzz target's entry point (fuzz_study.cpp, or fuzz_urdf.cpp for urdf_corpus_check) with
// files: each given file as it is, then every prefix cut at a line end and every single-byte deletion of
// its first 4 KiB (cheap mutations that reach the parser's error paths). Exit 0 when every input ended in
// a parse or the parser's own error (KS_CORPUS_ERROR: StudyError, UrdfError); an unexpected exception is
// reported with the input's origin and exit 1 (a crash ends the process).
//   usage: study_corpus_check FILE...   (urdf_corpus_check FILE...)
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>

#ifndef KS_CORPUS_ERROR
#define KS_CORPUS_ERROR "StudyError"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool feed(const std::string& text, const std::string& origin) {
  try {
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
    return true;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: unexpected exception: %s\n", origin.c_str(), e.what());
    return false;
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool ok = true;
  std::size_t inputs = 0;
  for (int i = 1; i < argc; ++i) {
    std::ifstream in(argv[i], std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "%s: cannot read\n", argv[i]);
      return 2;
    }
    std::stringstream buf;
    buf << in.rdbuf();
    const std::string text = buf.str(), name = argv[i];
    ok &= feed(text, name), ++inputs;
    for (std::size_t p = text.find('\n'); p != std::string::npos; p = text.find('\n', p + 1))
      ok &= feed(text.substr(0, p + 1), name + " (first " + std::to_string(p + 1) + " bytes)"), ++inputs;
    for (std::size_t d = 0; d < text.size() && d < 4096; ++d)
      ok &= feed(text.substr(0, d) + text.substr(d + 1), name + " (byte " + std::to_string(d) + " deleted)"), ++inputs;
  }
  std::printf("%zu inputs, %s\n", inputs, ok ? "every one parsed or refused with a " KS_CORPUS_ERROR : "FAILURES");
  return ok ? 0 : 1;
}
