// Test helper: writes the deterministic test study (store_testgen.cpp) into a results file, slowly
// if asked, so that tests can kill it (SIGKILL) or read the file while it is being written.
//   store_writer_helper PATH N [--delay-us D] [--flush-every K] [--flush-seconds S] [--no-shuffle] [--landscape]
//                       [--stop-after-runs K1,K2,...]   (flush, then stop itself with SIGSTOP, after K runs)
// Creates PATH, or resumes it when it exists. Prints "resumed <k>" / "created", then "finished".
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "store/store.hpp"
#include "store_testgen.hpp"

int main(int argc, char** argv) {
  using namespace ks;
  if (argc < 3) {
    std::cerr << "usage: store_writer_helper PATH N [--delay-us D] [--flush-every K] [--no-shuffle] [--landscape]\n";
    return 2;
  }
  const std::string path = argv[1];
  const std::int64_t n = std::atoll(argv[2]);
  long delay_us = 0;
  bool shuffle = true, landscape = false;
  std::vector<std::int64_t> stop_after;  // after writing this many runs: flush, then SIGSTOP itself
  store::StoreOptions opt;
  opt.flush_every_seconds = 0.05;
  for (int i = 3; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--delay-us" && i + 1 < argc) delay_us = std::atol(argv[++i]);
    else if (a == "--flush-every" && i + 1 < argc) opt.flush_every_runs = static_cast<std::size_t>(std::atol(argv[++i]));
    else if (a == "--flush-seconds" && i + 1 < argc) opt.flush_every_seconds = std::atof(argv[++i]);
    else if (a == "--no-shuffle") shuffle = false;
    else if (a == "--landscape") landscape = true;
    else if (a == "--stop-after-runs" && i + 1 < argc) {
      for (char* t = std::strtok(argv[++i], ","); t; t = std::strtok(nullptr, ",")) stop_after.push_back(std::atoll(t));
    }
  }
  try {
    std::unique_ptr<store::ResultsWriter> w;
    std::vector<char> done(static_cast<std::size_t>(n), 0);
    if (access(path.c_str(), F_OK) == 0) {
      auto r = store::ResultsWriter::open_for_resume(path, store_test::test_meta().study_sha256, opt);
      std::int64_t resumed = 0;
      for (std::int64_t id = 0; id < n; ++id)
        if (r.writer->is_done(id)) done[static_cast<std::size_t>(id)] = 1, ++resumed;
      std::cout << "resumed " << resumed << std::endl;
      w = std::move(r.writer);
    } else {
      w = store::ResultsWriter::create(path, store_test::test_meta(), store_test::test_columns(), n, opt);
      std::cout << "created" << std::endl;
    }
    std::vector<std::int64_t> order(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = i;
    if (shuffle) {  // mostly in order, with local disorder (as a pool of worker threads produces)
      std::mt19937_64 rng(12345);
      for (std::size_t i = 0; i + 1 < order.size(); i += 2)
        if (rng() % 2) std::swap(order[i], order[i + 1]);
    }
    std::int64_t written = 0;
    for (auto id : order) {
      if (done[static_cast<std::size_t>(id)]) continue;
      w->write_run(id, store_test::test_record(id), store::encode_history(store_test::test_history(id), 4, w->history_chunk_rows()));
      if (std::find(stop_after.begin(), stop_after.end(), ++written) != stop_after.end()) {
        w->flush();
        raise(SIGSTOP);  // a test reads the committed state, then lets the writer go on (SIGCONT)
      }
      if (delay_us > 0) usleep(static_cast<useconds_t>(delay_us));
    }
    w->flush();
    if (landscape) w->write_landscape(store_test::test_landscape());
    w->close();
    std::cout << "finished" << std::endl;
  } catch (const store::StoreError& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
