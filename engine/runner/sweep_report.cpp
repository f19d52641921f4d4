// Sweep reports of several processes combined, and their bytes (see sweep.hpp).
#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>

#include "runner/sweep.hpp"

namespace ks {

void merge_reports(SweepReport& into, const SweepReport& part) {
  into.written += part.written;
  into.interrupted = into.interrupted || part.interrupted;
  for (const BlockReport& p : part.blocks) {
    auto it = std::find_if(into.blocks.begin(), into.blocks.end(), [&](const BlockReport& b) { return b.name == p.name; });
    if (it == into.blocks.end()) {
      into.blocks.push_back(p);
      continue;
    }
    for (const auto& [status, n] : p.by_status) it->by_status[status] += n;
    // the ranking rule: lower objective, then lower tie, then lower run id (rank_key's order)
    it->best.insert(it->best.end(), p.best.begin(), p.best.end());
    std::sort(it->best.begin(), it->best.end(), [](const BestRun& a, const BestRun& b) {
      return rank_key(a.value, a.tie, a.run_id) < rank_key(b.value, b.tie, b.run_id);
    });
    if (it->best.size() > 3) it->best.resize(3);
  }
  into.seed_rows.insert(into.seed_rows.end(), part.seed_rows.begin(), part.seed_rows.end());
  std::sort(into.seed_rows.begin(), into.seed_rows.end(),
            [](const SeedRow& a, const SeedRow& b) { return a.run_id < b.run_id; });
  if (into.seed_rows.size() > 1000) into.seed_rows.resize(1000);
}

namespace {

struct Writer {
  std::string out;
  void u64(std::uint64_t v) { out.append(reinterpret_cast<const char*>(&v), 8); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void str(const std::string& s) {
    u64(s.size());
    out += s;
  }
};

struct Reader {
  const std::string& in;
  std::size_t at = 0;
  std::uint64_t u64() {
    if (in.size() - at < 8) throw std::runtime_error("a sweep report's bytes end early");
    std::uint64_t v;
    std::memcpy(&v, in.data() + at, 8);
    at += 8;
    return v;
  }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string str() {
    const std::uint64_t n = u64();
    if (in.size() - at < n) throw std::runtime_error("a sweep report's bytes end early");
    std::string s = in.substr(at, n);
    at += n;
    return s;
  }
};

constexpr std::uint64_t kMagic = 0x6b7372657031ULL;  // "ksrep1"

}  // namespace

std::string encode_report(const SweepReport& r) {
  Writer w;
  w.u64(kMagic);
  w.u64(r.total), w.u64(r.written), w.u64(r.skipped), w.u64(r.interrupted ? 1 : 0), w.f64(r.elapsed_s);
  w.u64(r.blocks.size());
  for (const BlockReport& b : r.blocks) {
    w.str(b.name), w.u64(static_cast<std::uint64_t>(b.kind)), w.u64(b.runs);
    w.u64(b.by_status.size());
    for (const auto& [status, n] : b.by_status) w.str(status), w.u64(n);
    w.u64(b.best.size());
    for (const BestRun& x : b.best) w.u64(x.run_id), w.f64(x.value), w.f64(x.tie), w.str(x.label);
  }
  w.u64(r.seed_rows.size());
  for (const SeedRow& s : r.seed_rows) {
    w.u64(s.run_id), w.str(s.preset), w.str(s.inertia), w.str(s.status), w.f64(s.E);
    for (double t : s.tau) w.f64(t);
  }
  return std::move(w.out);
}

SweepReport decode_report(const std::string& bytes) {
  Reader r{bytes};
  if (r.u64() != kMagic) throw std::runtime_error("not a sweep report");
  SweepReport out;
  out.total = r.u64(), out.written = r.u64(), out.skipped = r.u64(), out.interrupted = r.u64() != 0;
  out.elapsed_s = r.f64();
  const std::uint64_t blocks = r.u64();
  for (std::uint64_t i = 0; i < blocks; ++i) {
    BlockReport b;
    b.name = r.str(), b.kind = static_cast<BlockKind>(r.u64()), b.runs = r.u64();
    for (std::uint64_t k = r.u64(); k > 0; --k) {
      std::string status = r.str();
      b.by_status[status] = r.u64();
    }
    for (std::uint64_t k = r.u64(); k > 0; --k) {
      BestRun x;
      x.run_id = r.u64(), x.value = r.f64(), x.tie = r.f64(), x.label = r.str();
      b.best.push_back(std::move(x));
    }
    out.blocks.push_back(std::move(b));
  }
  for (std::uint64_t k = r.u64(); k > 0; --k) {
    SeedRow s;
    s.run_id = r.u64(), s.preset = r.str(), s.inertia = r.str(), s.status = r.str(), s.E = r.f64();
    for (double& t : s.tau) t = r.f64();
    out.seed_rows.push_back(std::move(s));
  }
  if (r.at != bytes.size()) throw std::runtime_error("a sweep report's bytes go on past its end");
  return out;
}

}  // namespace ks
