// A scan of a study's text for the inputs that reach undefined behaviour in toml++ 3.3 (internal
// assertions, TOML_UNREACHABLE) before toml++ sees them: a table header whose name starts with '['
// ("[[[a]]]"), and a value that starts with a code point in U+00A1..U+0499 ("x = Ϛ"). Neither is
// valid TOML, so refusing them changes no valid study. The scan follows TOML's lexical structure
// only as far as it must to know where headers and values start: comments, the four kinds of
// string, arrays and inline tables.
#include <cstdint>
#include <vector>

#include "study/parser.hpp"

namespace ks::study_parse {

namespace {

class Scanner {
 public:
  explicit Scanner(std::string_view text) : t_(text) {}

  std::optional<TomlHazard> run() {
    while (i_ < t_.size() && !found_) {
      skip_blanks();
      if (i_ >= t_.size()) break;
      const char c = t_[i_];
      if (c == '\n') {
        newline();
      } else if (c == '#') {
        skip_comment();
      } else if (c == '[' && nest_.empty() && line_start_) {
        header();
      } else {
        statement();
      }
    }
    return found_;
  }

 private:
  void newline() {
    ++i_;
    ++line_;
    line_begin_ = i_;
    line_start_ = true;
  }
  void skip_blanks() {
    while (i_ < t_.size() && (t_[i_] == ' ' || t_[i_] == '\t' || t_[i_] == '\r')) ++i_;
  }
  void skip_comment() {
    while (i_ < t_.size() && t_[i_] != '\n') ++i_;
  }
  /// 1-based column of byte i (code points, as toml++ counts).
  int column(std::size_t i) const {
    int col = 1;
    for (std::size_t k = line_begin_; k < i; ++k)
      if ((static_cast<unsigned char>(t_[k]) & 0xC0) != 0x80) ++col;
    return col;
  }
  void report(std::size_t at, std::string msg) { found_ = TomlHazard{line_, column(at), std::move(msg)}; }

  /// [name] or [[name]]: a name that starts with '[' is reported.
  void header() {
    const std::size_t at = i_;
    ++i_;
    if (i_ < t_.size() && t_[i_] == '[') ++i_;
    skip_blanks();
    if (i_ < t_.size() && t_[i_] == '[')
      return report(at, "a table header's name starts with '['; expected [table] or [[array.of.tables]]");
    line_start_ = false;
    while (i_ < t_.size() && t_[i_] != '\n' && t_[i_] != '#') {
      if (t_[i_] == '"' || t_[i_] == '\'') string();
      else ++i_;
    }
  }

  /// A key = value line, or the rest of an array or inline table spanning lines.
  void statement() {
    line_start_ = false;
    if (nest_.empty()) expect_value_ = false;
    while (i_ < t_.size() && !found_) {
      const char c = t_[i_];
      if (c == '\n') {
        if (nest_.empty()) return;  // the next line starts afresh
        newline();
        line_start_ = false;
        continue;
      }
      if (c == '#') {
        skip_comment();
        continue;
      }
      if (c == '"' || c == '\'') {
        string();
        expect_value_ = false;
        continue;
      }
      if (expect_value_ && c != ' ' && c != '\t' && c != '\r') {
        expect_value_ = false;
        if (const std::uint32_t cp = code_point(i_); cp >= 0xA1 && cp <= 0x499)
          return report(i_, "a value starts with the character U+" + hex(cp) +
                                "; expected a TOML value (a string is written in quotes)");
      }
      if (c == '=') expect_value_ = true;
      else if (c == '[') {
        nest_.push_back('[');
        expect_value_ = true;
      } else if (c == '{') nest_.push_back('{');
      else if ((c == ']' || c == '}') && !nest_.empty()) nest_.pop_back();
      else if (c == ',' && !nest_.empty() && nest_.back() == '[') expect_value_ = true;
      ++i_;
    }
  }

  /// A string of any kind from i_ (at its quote); i_ ends after it.
  void string() {
    const char q = t_[i_];
    const bool multi = t_.substr(i_, 3) == std::string(3, q);
    i_ += multi ? 3 : 1;
    while (i_ < t_.size()) {
      const char c = t_[i_];
      if (c == '\\' && q == '"') {
        i_ += i_ + 1 < t_.size() && t_[i_ + 1] != '\n' ? 2 : 1;  // a line-ending backslash: the newline counts
        continue;
      }
      if (c == '\n') {
        if (!multi) return;  // unterminated: toml++ reports it
        newline();
        line_start_ = false;
        continue;
      }
      if (c == q && (!multi || t_.substr(i_, 3) == std::string(3, q))) {
        i_ += multi ? 3 : 1;
        while (multi && i_ < t_.size() && t_[i_] == q) ++i_;  // up to two quotes may end the content
        return;
      }
      ++i_;
    }
  }

  /// The code point starting at byte i (0 for a malformed sequence: toml++ reports those).
  std::uint32_t code_point(std::size_t i) const {
    const auto b = [&](std::size_t k) { return k < t_.size() ? static_cast<unsigned char>(t_[k]) : 0u; };
    const unsigned c = b(i);
    if (c < 0x80) return c;
    if ((c & 0xE0) == 0xC0 && (b(i + 1) & 0xC0) == 0x80) return ((c & 0x1F) << 6) | (b(i + 1) & 0x3F);
    if ((c & 0xF0) == 0xE0 && (b(i + 1) & 0xC0) == 0x80 && (b(i + 2) & 0xC0) == 0x80)
      return ((c & 0x0F) << 12) | ((b(i + 1) & 0x3F) << 6) | (b(i + 2) & 0x3F);
    return 0;
  }
  static std::string hex(std::uint32_t v) {
    static const char* digits = "0123456789ABCDEF";
    std::string s;
    for (int shift = 12; shift >= 0; shift -= 4) s += digits[(v >> shift) & 0xF];
    return s;
  }

  std::string_view t_;
  std::size_t i_ = 0, line_begin_ = 0;
  int line_ = 1;
  bool line_start_ = true, expect_value_ = false;
  std::vector<char> nest_;  // open arrays '[' and inline tables '{'
  std::optional<TomlHazard> found_;
};

}  // namespace

std::optional<TomlHazard> toml_hazard(std::string_view text) { return Scanner(text).run(); }

}  // namespace ks::study_parse
