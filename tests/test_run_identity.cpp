// Run identities (runner/run_identity.hpp): equal for the same run whatever the study text around it
// (comments, block and key order), different as soon as a parameter or the run context differs.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "runner/run_identity.hpp"
#include "runner/schema.hpp"
#include "study/sha256.hpp"
#include "study/study.hpp"

namespace ks {
namespace {

const std::string kStudy = R"(
[study]
name = "identity"
histories = "every=10"

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
K_N = 0.5
[block.axes]
alpha1A = [-10, 0, 10]
k = [0, 0.5]

[[block]]
name = "basin"
kind = "ik"
problem = "scara"
method = "lm"
lambda = 0.01
[block.axes]
q0_1 = [10, 20]
q0_2 = [30, 60, 90]
)";

// The same runs: comments, the blocks in the other order, keys in another order, numbers spelt otherwise.
const std::string kReordered = R"(
# the same study, written otherwise
[study]
histories = "every=10"   # kept
name = "identity"

[[block]]
kind = "ik"
name = "basin"           # now first
lambda = 1e-2
method = "lm"
problem = "scara"
[block.axes]
q0_2 = [30.0, 60.0, 90.0]
q0_1 = [10.0, 20.0]

[[block]]
name = "weighted"
kind = "trajectory"
K_N = 5e-1
method = "local_weighted"
[block.axes]
alpha1A = [-10.0, 0.0, 10.0]
k = [0.0, 0.5]
)";

/// Equal cells, NaN included (bit for bit).
bool same_cells(const std::vector<Cell>& a, const std::vector<Cell>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double* x = std::get_if<double>(&a[i]);
    const double* y = std::get_if<double>(&b[i]);
    if (x && y ? std::bit_cast<std::uint64_t>(*x) != std::bit_cast<std::uint64_t>(*y) : a[i] != b[i]) return false;
  }
  return true;
}

std::vector<ContextField> context_of(const Study& s) { return run_context(s, s.histories); }
/// The digest of every part of the context (the trajectory kind reads them all).
Digest digest_of(const Study& s) { return context_digest(context_of(s), BlockKind::trajectory); }

Digest sha(const std::string& bytes) {
  Sha256 h;
  h.update(bytes);
  return h.digest();
}

/// Identities of the runs of block `name`, by local index.
std::vector<Digest> identities(const Study& s, const std::string& name) {
  const Block& b = s.blocks[s.block_index(name)];
  const BlockIdentity ids(context_of(s), b);
  std::vector<Digest> out;
  for (std::uint64_t i = 0; i < b.run_count(); ++i) out.push_back(ids.run(i));
  return out;
}

TEST(RunIdentity, SameRunsInAnotherTextHaveTheSameIdentity) {
  const Study a = parse_study(kStudy), b = parse_study(kReordered);
  ASSERT_NE(a.sha256, b.sha256);
  EXPECT_EQ(context_changes(run_context(a, a.histories), run_context(b, b.histories)), "");
  EXPECT_EQ(digest_of(a), digest_of(b));
  // q0_2 before q0_1 in b's axes: the runs come in another local order; match them by their values
  const auto wa = identities(a, "weighted"), wb = identities(b, "weighted");
  EXPECT_EQ(wa, wb);
  const Block& ba = a.blocks[a.block_index("basin")];
  const Block& bb = b.blocks[b.block_index("basin")];
  const auto ia = identities(a, "basin"), ib = identities(b, "basin");
  for (std::uint64_t i = 0; i < ba.run_count(); ++i) {
    std::uint64_t j = 0;
    while (j < bb.run_count() && !same_cells(bb.params(j), ba.params(i))) ++j;
    ASSERT_LT(j, bb.run_count());
    EXPECT_EQ(ia[i], ib[j]) << "run " << i;
  }
  // every run of a study has its own identity
  std::vector<Digest> all = wa;
  all.insert(all.end(), ia.begin(), ia.end());
  std::sort(all.begin(), all.end());
  EXPECT_EQ(std::adjacent_find(all.begin(), all.end()), all.end());
}

TEST(RunIdentity, AStoredRowHasTheIdentityOfItsRun) {
  const Study s = parse_study(kStudy);
  const StudySchema schema = make_schema(s);
  for (std::size_t b = 0; b < s.blocks.size(); ++b) {
    const Block& block = s.blocks[b];
    const BlockIdentity ids(context_of(s), block);
    const Digest ctx = context_digest(context_of(s), block.kind());
    std::vector<std::string> names;
    for (const ColumnSpec& c : block.columns()) names.push_back(c.name);
    for (std::uint64_t i = 0; i < block.run_count(); ++i) {
      Record row = schema.blank;
      const auto cells = block.params(i);
      for (std::size_t p = 0; p < cells.size(); ++p) row.cells[schema.param_column[b][p]] = cells[p];
      EXPECT_EQ(ids.row(row, schema.param_column[b]), ids.run(i));
      // the documented canonical bytes, hashed, are the identity
      EXPECT_EQ(sha(run_identity_bytes(ctx, block.kind(), names, cells)), ids.run(i));
    }
  }
}

/// A value other than `c` of the same type.
Cell other(const Cell& c) {
  if (const double* d = std::get_if<double>(&c)) return std::isnan(*d) ? 1.0 : *d + 1.0;
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return *i + 1;
  return std::get<std::string>(c) + "x";
}

TEST(RunIdentity, ChangingAnyParameterChangesTheIdentity) {
  const Study s = parse_study(kStudy);
  const Digest ctx = digest_of(s);
  for (const Block& block : s.blocks) {
    std::vector<std::string> names;
    for (const ColumnSpec& c : block.columns()) names.push_back(c.name);
    const auto cells = block.params(0);
    const std::string base = run_identity_bytes(ctx, block.kind(), names, cells);
    for (std::size_t p = 0; p < cells.size(); ++p) {
      auto changed = cells;
      changed[p] = other(cells[p]);
      EXPECT_NE(sha(run_identity_bytes(ctx, block.kind(), names, changed)), sha(base)) << block.name() << " " << names[p];
    }
    // -0 and 0, two NaNs: different stored bits, different identities
    auto zero = cells, negative = cells;
    const std::size_t k = block.column_index(block.kind() == BlockKind::trajectory ? "k" : "lambda");
    zero[k] = 0.0, negative[k] = -0.0;
    EXPECT_NE(run_identity_bytes(ctx, block.kind(), names, zero), run_identity_bytes(ctx, block.kind(), names, negative));
    // the same cells under the other kind
    const BlockKind kind = block.kind() == BlockKind::trajectory ? BlockKind::ik : BlockKind::trajectory;
    EXPECT_NE(run_identity_bytes(ctx, kind, names, cells), base);
  }
  // a fixed value and an axis value changed in the study text
  const auto before = identities(s, "weighted");
  std::string t = kStudy;
  t.replace(t.find("K_N = 0.5"), 9, "K_N = 0.25");
  const auto kn = identities(parse_study(t), "weighted");
  t = kStudy;
  t.replace(t.find("k = [0, 0.5]"), 12, "k = [0, 0.75]");
  const auto axis = identities(parse_study(t), "weighted");
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_NE(kn[i], before[i]);
    if (i % 2 == 1) EXPECT_NE(axis[i], before[i]);  // k = 0.75 instead of 0.5
    else EXPECT_EQ(axis[i], before[i]);             // k = 0: the same run
  }
}

TEST(RunIdentity, TheContextNamesWhatChanged) {
  const Study s = parse_study(kStudy);
  const auto base = run_context(s, s.histories);
  auto changed = [&](const std::string& table) {
    const Study e = parse_study(kStudy + table);
    EXPECT_NE(digest_of(e), digest_of(s)) << table;
    return context_changes(base, run_context(e, e.histories));
  };
  const std::string robot = changed("[robot]\nm = [5.0, 2.0, 1.5]\n");
  EXPECT_NE(robot.find("the robot changed: [robot] m: [5, 2, 1] -> [5, 2, 1.5]"), std::string::npos) << robot;
  EXPECT_EQ(robot.find("task"), std::string::npos) << robot;
  const std::string dt = changed("[task]\ndt = 0.002\n");
  EXPECT_EQ(dt, "the task changed: [task] dt: 0.001 -> 0.002");
  const std::string chain = changed("[robot]\nl = [1, 1, 1, 1]\nm = [4, 3, 2, 1]\nb = 0.1\n");
  EXPECT_NE(chain.find("[robot] chain: none (the closed-form 3R) -> 4 joints"), std::string::npos) << chain;
  EXPECT_NE(context_changes(base, run_context(s, HistoryPolicy{HistoryPolicy::Mode::none, 0})).find(
                "the settings changed: [study] histories: every=10 -> none"),
            std::string::npos);
  EXPECT_NE(context_changes(base, run_context(s, s.histories, "0.0.1")).find("kinesweep version"), std::string::npos);
  // a chain's velocity and effort limits decide out_of_limits: each is part of the context
  const Study arm = parse_study(kStudy + "[robot]\nl = [1, 1, 1, 1]\nm = [4, 3, 2, 1]\nb = 0.1\n");
  const auto arm_base = run_context(arm, arm.histories);
  for (int which = 0; which < 2; ++which) {
    Study e = arm;
    auto c = std::make_shared<Chain>(*arm.chain);
    (which ? c->joints[1].effort : c->joints[1].velocity) = 3.5;
    e.chain = c;
    EXPECT_NE(digest_of(e), digest_of(arm)) << which;
    EXPECT_NE(context_changes(arm_base, run_context(e, e.histories))
                  .find(which ? "[robot] joint 2 effort limit" : "[robot] joint 2 velocity limit"),
              std::string::npos);
  }
  // the defaults written out change nothing
  EXPECT_EQ(context_changes(base, run_context(parse_study(kStudy + "[robot]\ng = 9.81\n[task]\ndt = 1e-3\n"), s.histories)), "");
}

// Each kind's identities cover the parts of the context its runs read: an edited task changes every
// trajectory run's identity and no IK run's; an edited robot or histories policy changes both.
TEST(RunIdentity, AKindsIdentitiesCoverThePartsOfTheContextItReads) {
  const Study s = parse_study(kStudy);
  const auto traj = identities(s, "weighted"), ik = identities(s, "basin");
  auto edited = [&](const std::string& table, bool trajectory_same, bool ik_same) {
    const Study e = parse_study(kStudy + table);
    const auto t = identities(e, "weighted"), i = identities(e, "basin");
    for (std::size_t r = 0; r < t.size(); ++r) EXPECT_EQ(t[r] == traj[r], trajectory_same) << table << " run " << r;
    for (std::size_t r = 0; r < i.size(); ++r) EXPECT_EQ(i[r] == ik[r], ik_same) << table << " run " << r;
  };
  edited("[task]\ndt = 0.002\n", false, true);
  edited("[task]\nvertices = [[1.4, 1.4], [1.9, 1.4], [1.9, 1.9], [1.4, 1.9], [1.4, 1.4]]\n", false, true);
  edited("[task]\nintegrator = \"rk4\"\n", false, true);
  edited("[robot]\nm = [5.0, 2.0, 1.5]\n", false, false);
  edited("[robot]\nl = [1.0, 1.2, 1.0]\n", false, false);
  {
    std::string t = kStudy;
    t.replace(t.find("every=10"), 8, "every=5");
    const Study e = parse_study(t);
    EXPECT_NE(identities(e, "weighted")[0], traj[0]);
    EXPECT_NE(identities(e, "basin")[0], ik[0]);
  }
  // the parts are the kind's declaration, read from the schema
  const auto parts = context_parts(BlockKind::ik);
  EXPECT_EQ(std::count(parts.begin(), parts.end(), "task"), 0);
  EXPECT_EQ(context_parts(BlockKind::trajectory).size(), 3u);
}

}  // namespace
}  // namespace ks
