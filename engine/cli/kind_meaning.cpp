// A run kind's meaning from the file's /kinds (cli/kind_meaning.hpp).
#include "cli/kind_meaning.hpp"

#include <algorithm>

#include "schema/params.hpp"

namespace ks::cli {

namespace {
template <class Range>
std::vector<std::string> strings(const Range& range) {
  return std::vector<std::string>(range.begin(), range.end());
}
}  // namespace

bool KindMeaning::is_good(const std::string& status) const {
  return std::find(good_statuses.begin(), good_statuses.end(), status) != good_statuses.end();
}

KindMeaning kind_meaning(const store::StoreMeta& meta, const std::string& kind) {
  KindMeaning out;
  if (!meta.kinds.empty()) {
    for (const store::KindMeta& k : meta.kinds) {
      if (k.name != kind) continue;
      out.known = true;
      for (const auto& [name, values] : k.lists) {
        if (name == "statuses") out.statuses = values;
        if (name == "good_statuses") out.good_statuses = values;
        if (name == "ranking") out.ranking = values;
        if (name == "key_metrics") out.key_metrics = values;
      }
    }
    return out;
  }
  BlockKind b{};
  if (!parse(kind, b)) return out;
  out.known = true;
  out.statuses = strings(statuses(b));
  out.good_statuses = {out.statuses.front()};
  const Ranking r = ranking(b);
  out.ranking = {std::string(r.objective)};
  if (!r.tie.empty()) out.ranking.emplace_back(r.tie);
  out.key_metrics = strings(key_metrics(b));
  return out;
}

std::vector<std::string> declared_kinds(const store::StoreMeta& meta) {
  std::vector<std::string> out;
  for (const store::KindMeta& k : meta.kinds) out.push_back(k.name);
  if (out.empty())
    for (const BlockKind b : block_kinds()) out.emplace_back(to_string(b));
  return out;
}

}  // namespace ks::cli
