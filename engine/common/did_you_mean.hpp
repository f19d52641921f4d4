#pragma once
// The one "did you mean" rule of every message (study keys and values, URDF names, query columns and
// values): the candidate nearest to the word by case-insensitive edit distance when it is within
// max(2, |word| / 2) edits; else the one candidate the word begins (at least 3 characters).
#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace ks {

/// Levenshtein distance: insertions, deletions and substitutions of one character.
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// The candidate to suggest for `word` under the rule above, or "" (none close; or the word itself).
template <class Range>
std::string did_you_mean(std::string_view word, const Range& candidates) {
  auto lower = [](std::string_view s) {
    std::string o(s);
    for (char& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return o;
  };
  const std::string w = lower(word);
  std::size_t best = std::string::npos;
  std::string pick;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(w, lower(c));
    if (d < best) best = d, pick = std::string(c);
  }
  if (!pick.empty() && pick != word && best <= std::max<std::size_t>(2, w.size() / 2)) return pick;
  std::string start;
  int starts = 0;
  for (const auto& c : candidates)
    if (w.size() >= 3 && std::string_view(c).size() > w.size() && lower(c).starts_with(w)) start = std::string(c), ++starts;
  return starts == 1 ? start : "";
}

}  // namespace ks
