// Drives the results-file fuzz target's entry point (fuzz_results.cpp) with results files: each given
// file as it is, then simple mutations of it: cut to a few lengths (0, 1, 8, 96, 512, 2048 bytes, a
// third, a half, all but the last byte), each of 48 bytes inverted (the first 64 bytes, where the
// superblock lies, then offsets spread over the file) and the file followed by a journal holding only
// its magic and zeros. A directory argument stands for the *.h5 files in it (a missing directory is an
// error). Exit 0 when every input was read or refused; a crash, or an exception escaping the entry point,
// fails (the input's origin printed).
//   usage: results_corpus_check FILE|DIR...
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool feed(const std::string& bytes, const std::string& origin) {
  std::fprintf(stderr, "%s\n", origin.c_str());  // the input in hand, should it crash
  try {
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    return true;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: unexpected exception: %s\n", origin.c_str(), e.what());
    return false;
  }
}

/// The inputs made from one file: (bytes, description).
std::vector<std::pair<std::string, std::string>> mutations(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> out;
  out.emplace_back(text, "as it is");
  const std::size_t n = text.size();
  for (std::size_t cut : {std::size_t{0}, std::size_t{1}, std::size_t{8}, std::size_t{96}, std::size_t{512},
                          std::size_t{2048}, n / 3, n / 2, n > 0 ? n - 1 : 0})
    if (cut < n) out.emplace_back(text.substr(0, cut), "cut to " + std::to_string(cut) + " bytes");
  std::vector<std::size_t> offsets;
  for (std::size_t o = 0; o < 64; o += 4) offsets.push_back(o);
  for (std::size_t i = 1; i <= 32; ++i) offsets.push_back(n * i / 33);
  for (std::size_t o : offsets)
    if (o < n) {
      std::string t = text;
      t[o] = static_cast<char>(~static_cast<unsigned char>(t[o]));
      out.emplace_back(std::move(t), "byte " + std::to_string(o) + " inverted");
    }
  out.emplace_back(text + "KSJRNL02" + std::string(56, '\0'), "with a journal of zeros");
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path p(argv[i]);
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) {
      for (const auto& e : std::filesystem::directory_iterator(p))
        if (e.path().extension() == ".h5") files.push_back(e.path());
    } else {
      files.push_back(p);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "results_corpus_check: no results file given\n");
    return 2;
  }
  bool ok = true;
  std::size_t inputs = 0;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "%s: cannot read\n", f.c_str());
      return 2;
    }
    std::stringstream buf;
    buf << in.rdbuf();
    for (const auto& [bytes, what] : mutations(buf.str())) ok &= feed(bytes, f.string() + " (" + what + ")"), ++inputs;
  }
  std::printf("%zu inputs from %zu files, %s\n", inputs, files.size(),
              ok ? "every one read or refused" : "FAILURES");
  return ok ? 0 : 1;
}
