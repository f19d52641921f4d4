// Sweep reports combined across processes (runner/sweep_report.cpp): the report of a study's runs
// split between two sweeps, merged, equals the report of one sweep of all of them (the oracle:
// run_sweep itself); and a report survives its bytes unchanged.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <string>

#include "runner/run_study.hpp"
#include "runner/sweep.hpp"
#include "store/store.hpp"
#include "study/study.hpp"

namespace ks {
namespace {

const std::string kStudy = R"(
[study]
name = "reports"
histories = "none"

[[block]]
name = "cases"
kind = "trajectory"
[block.axes]
preset = ["1a", "1c", "2a", "2e", "5b"]

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -20, to = 30, count = 11 }
k = [0.0, 0.5]

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = { from = -150, to = 150, count = 9 }
q0_2 = [0, 60, 120]
)";

/// The report of a sweep of `study` running the run ids `keep` selects, into a new file in `dir`.
SweepReport sweep_of(const Study& study, const std::string& path, bool (*keep)(std::uint64_t)) {
  const StudySchema schema = make_schema(study);
  auto w = store::ResultsWriter::create(path, store_meta(study, study.histories), schema.columns,
                                        static_cast<std::int64_t>(study.run_count()), {.overwrite = true});
  SweepOptions o;
  o.threads = 1;
  std::uint64_t next = 0;
  o.source = [&](std::vector<std::uint64_t>& ids, std::size_t max) {
    while (next < study.run_count() && ids.size() < max) {
      if (keep(next)) ids.push_back(next);
      ++next;
    }
    return !ids.empty();
  };
  SweepReport r = run_sweep(study, schema, *w, o);
  w->close();
  store::remove_results_file(path);
  return r;
}

std::string temp(const std::string& name) { return ::testing::TempDir() + "ks_report_" + name + ".h5"; }

TEST(SweepReport, TheReportsOfTwoHalvesMergedAreTheReportOfTheWhole) {
  const Study study = parse_study(kStudy);
  const SweepReport whole = sweep_of(study, temp("whole"), [](std::uint64_t) { return true; });
  SweepReport even = sweep_of(study, temp("even"), [](std::uint64_t id) { return (id / 3) % 2 == 0; });
  const SweepReport odd = sweep_of(study, temp("odd"), [](std::uint64_t id) { return (id / 3) % 2 == 1; });
  merge_reports(even, decode_report(encode_report(odd)));
  EXPECT_EQ(even.written, whole.written);
  ASSERT_EQ(even.blocks.size(), whole.blocks.size());
  for (std::size_t b = 0; b < whole.blocks.size(); ++b) {
    EXPECT_EQ(even.blocks[b].by_status, whole.blocks[b].by_status) << whole.blocks[b].name;
    ASSERT_EQ(even.blocks[b].best.size(), whole.blocks[b].best.size()) << whole.blocks[b].name;
    for (std::size_t i = 0; i < whole.blocks[b].best.size(); ++i) {
      EXPECT_EQ(even.blocks[b].best[i].run_id, whole.blocks[b].best[i].run_id) << whole.blocks[b].name << " " << i;
      EXPECT_EQ(even.blocks[b].best[i].label, whole.blocks[b].best[i].label);
    }
  }
  ASSERT_EQ(even.seed_rows.size(), whole.seed_rows.size());
  ASSERT_EQ(whole.seed_rows.size(), 5u);
  for (std::size_t i = 0; i < whole.seed_rows.size(); ++i) {
    EXPECT_EQ(even.seed_rows[i].run_id, whole.seed_rows[i].run_id);
    EXPECT_EQ(even.seed_rows[i].preset, whole.seed_rows[i].preset);
    EXPECT_EQ(even.seed_rows[i].E, whole.seed_rows[i].E);
  }
  // the IK block's best runs tie on iterations: the tie metric (error) and then the run id decide
  EXPECT_GT(whole.blocks[2].best.size(), 1u);
}

TEST(SweepReport, BytesRoundTripAndForeignBytesAreRefused) {
  const Study study = parse_study(kStudy);
  const SweepReport r = sweep_of(study, temp("bytes"), [](std::uint64_t) { return true; });
  const std::string bytes = encode_report(r);
  EXPECT_EQ(encode_report(decode_report(bytes)), bytes);
  EXPECT_THROW(decode_report(bytes.substr(0, bytes.size() - 3)), std::runtime_error);
  EXPECT_THROW(decode_report("not a report at all"), std::runtime_error);
  EXPECT_THROW(decode_report(bytes + "x"), std::runtime_error);
}

}  // namespace
}  // namespace ks
