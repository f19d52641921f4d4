// Study diagnostics as rustc shows errors: the headline FILE:LINE:COL: error: message, then the source
// line in a numbered gutter with a caret under the column, then the secondary notes; and StudyError,
// which lists them.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "study/study.hpp"

namespace ks {
namespace {

constexpr int kTabWidth = 4;     // a tab is shown as this many spaces
constexpr int kMaxShown = 100;   // display cells of a source line shown; longer lines are clipped
constexpr int kLeftContext = 30; // ... keeping about this many cells before the column

/// One code point as shown: its bytes (a tab as spaces) and the terminal cells it takes.
struct Glyph {
  std::string text;
  int width = 1;
};

/// Terminal cells of code point c: 0 for combining marks and zero-width characters, 2 for East Asian
/// wide characters and emoji, 1 otherwise (a subset of wcwidth, enough for study files).
int cells(char32_t c) {
  struct Range {
    char32_t lo, hi;
  };
  static constexpr Range zero[] = {{0x0300, 0x036F}, {0x1AB0, 0x1AFF}, {0x1DC0, 0x1DFF}, {0x200B, 0x200F},
                                    {0x20D0, 0x20FF}, {0xFE00, 0xFE0F}, {0xFE20, 0xFE2F}};
  static constexpr Range wide[] = {{0x1100, 0x115F},   {0x2E80, 0x303E},   {0x3041, 0x33FF},
                                   {0x3400, 0x4DBF},   {0x4E00, 0x9FFF},   {0xA000, 0xA4CF},
                                   {0xAC00, 0xD7A3},   {0xF900, 0xFAFF},   {0xFE30, 0xFE4F},
                                   {0xFF00, 0xFF60},   {0xFFE0, 0xFFE6},   {0x1F300, 0x1F64F},
                                   {0x1F900, 0x1F9FF}, {0x20000, 0x3FFFD}};
  for (const Range& r : zero)
    if (c >= r.lo && c <= r.hi) return 0;
  for (const Range& r : wide)
    if (c >= r.lo && c <= r.hi) return 2;
  return 1;
}

/// The code points of a line (UTF-8; a byte that does not start a valid sequence is one glyph of its
/// own, as the position counts cannot be trusted beyond it anyway). Control characters show as '?'.
std::vector<Glyph> glyphs(std::string_view s) {
  std::vector<Glyph> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    bool valid = n != 0 && i + n <= s.size();
    char32_t c = n == 1 ? b : n == 2 ? (b & 0x1F) : n == 3 ? (b & 0x0F) : (b & 0x07);
    for (std::size_t k = 1; valid && k < n; ++k) {
      const auto cb = static_cast<unsigned char>(s[i + k]);
      valid = (cb & 0xC0) == 0x80;
      c = (c << 6) | (cb & 0x3F);
    }
    if (!valid) n = 1;
    Glyph g;
    if (b == '\t') g = {std::string(kTabWidth, ' '), kTabWidth};
    else if (!valid || b < 0x20 || b == 0x7F) g = {"?", 1};
    else g = {std::string(s.substr(i, n)), cells(c)};
    out.push_back(std::move(g));
    i += n;
  }
  return out;
}

int digits(int v) { return int(std::to_string(v).size()); }

/// The gutter, the source line and the caret line (each preceded by a line break):
///      |
///   12 | alpah1A = 3
///      | ^^^^^^^
std::string snippet(int gutter, int line, int column, int length, const std::string& text) {
  const std::vector<Glyph> g = glyphs(text);
  const int n = int(g.size());
  std::vector<int> x(g.size() + 1, 0);  // display cell where each glyph starts
  for (int i = 0; i < n; ++i) x[i + 1] = x[i] + g[i].width;
  const int total = x[n];
  // Columns past the end of the line (an error at the line break) take one cell each.
  auto cell = [&](int index) { return index <= n ? x[std::max(index, 0)] : total + (index - n); };
  const int c0 = std::max(column, 1) - 1;
  int caret = cell(c0);
  int caret_end = std::max(caret + 1, cell(c0 + std::max(length, 1)));

  // Clip a long line to a window of kMaxShown cells around the column, marking cuts with "...".
  int first = 0, last = n;  // glyphs shown: [first, last)
  if (total > kMaxShown) {
    const int start = std::clamp(caret - kLeftContext, 0, total - kMaxShown);
    while (first < n && x[first] < start) ++first;
    last = first;
    while (last < n && x[last + 1] - x[first] <= kMaxShown) ++last;
  }
  std::string shown = first > 0 ? "..." : "";
  for (int i = first; i < last; ++i) shown += g[i].text;
  if (last < n) shown += "...";
  const int shift = x[first] - (first > 0 ? 3 : 0);
  caret -= shift;
  caret_end -= shift;
  if (last < n) caret_end = std::min(caret_end, x[last] - shift);
  caret_end = std::max(caret_end, caret + 1);

  std::string out;
  out.append(1, '\n').append(std::size_t(gutter), ' ').append(" |");
  out.append(1, '\n').append(std::size_t(gutter - digits(line)), ' ').append(std::to_string(line));
  out.append(" | ").append(shown);
  while (out.back() == ' ') out.pop_back();  // an empty source line: no trailing blank
  out.append(1, '\n').append(std::size_t(gutter), ' ').append(" | ");
  out.append(std::size_t(caret), ' ').append(std::size_t(caret_end - caret), '^');
  return out;
}

}  // namespace

std::string StudyDiagnostic::headline() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message;
}

std::string StudyDiagnostic::str() const {
  std::string out = headline();
  int gutter = digits(line);
  for (const Note& n : notes)
    if (n.line > 0 && n.source_line) gutter = std::max(gutter, digits(n.line));
  if (source_line) out += snippet(gutter, line, column, length, *source_line);
  for (const Note& n : notes) {
    if (n.line <= 0) {
      out.append(1, '\n').append(std::size_t(gutter), ' ').append(" = note: ").append(n.message);
      continue;
    }
    out += "\nnote: " + (n.file.empty() ? file : n.file) + ":" + std::to_string(n.line) + ":" + std::to_string(n.column) + ": " + n.message;
    if (n.source_line) out += snippet(gutter, n.line, n.column, n.length, *n.source_line);
  }
  return out;
}

namespace {
std::string join_diagnostics(const std::vector<StudyDiagnostic>& d) {
  std::string s, prev;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const std::string cur = d[i].str();
    if (i) s += prev.find('\n') != std::string::npos || cur.find('\n') != std::string::npos ? "\n\n" : "\n";
    s += cur;
    prev = cur;
  }
  return s;
}
}  // namespace

StudyError::StudyError(std::vector<StudyDiagnostic> diagnostics)
    : std::runtime_error(join_diagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

}  // namespace ks
