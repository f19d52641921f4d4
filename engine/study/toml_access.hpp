#pragma once
// Internal to engine/study (not included from outside it): the study parser's base. Typed reads of
// TOML values that report a located diagnostic when a value is present but wrong, source positions,
// "did you mean" suggestions, and the formatting helpers the messages share.
#include <toml++/toml.h>

#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "study/study.hpp"

namespace ks::study_parse {

/// A place in the study text: 1-based line and column (columns count Unicode code points, as toml++
/// does), and how many code points of the line a diagnostic underlines (0: to the end of the line).
struct Pos {
  int line = 1, column = 1;
  int length = 1;
};
/// The start of `r`, underlining the region when it lies on one line, else the rest of its first line.
Pos pos_of(const toml::source_region& r);

/// A table's entries in file order (toml++ tables iterate by key).
std::vector<std::pair<const toml::key*, const toml::node*>> ordered(const toml::table& t);

std::string lower(std::string_view s);
/// "; did you mean 'x'?" for the closest candidate (case-insensitive edit distance), else for the one
/// candidate the word begins (at least 3 characters), or "". Never the word itself.
std::string suggest(std::string_view word, const std::vector<std::string>& candidates);
/// A suggestion among `mine`, else among the other kind's parameters (saying so).
std::string suggest_either(std::string_view word, const std::vector<std::string>& mine,
                           const std::vector<ParamDef>& other, const std::string& other_kind);

std::string join(const std::vector<std::string>& v, std::string_view sep = ", ");
std::vector<std::string> to_strings(std::span<const std::string_view> v);
/// "a string", "an integer", ... (for "X is a string; expected a number").
std::string type_name(const toml::node& n);
/// A number as a message shows it (12 significant digits).
std::string fmt(double v);

/// Collects the diagnostics of one study text, each with its source line, and reads typed values.
class ParserCore {
 public:
  /// `text` must outlive the parser.
  ParserCore(std::string file, std::string_view text);

 protected:
  /// Record an error at `p` (or at a TOML region, node or key); the returned diagnostic takes notes
  /// (valid until the next error).
  StudyDiagnostic& error(Pos p, std::string msg);
  StudyDiagnostic& error(const toml::source_region& r, std::string msg) { return error(pos_of(r), std::move(msg)); }
  StudyDiagnostic& error(const toml::node& n, std::string msg) { return error(n.source(), std::move(msg)); }
  StudyDiagnostic& error(const toml::key& k, std::string msg) { return error(k.source(), std::move(msg)); }
  /// Add a secondary note pointing at `p` (with its source line) to `d`.
  void note(StudyDiagnostic& d, Pos p, std::string msg) const;
  /// Report keys of `t` not in `allowed` (with a suggestion).
  void check_keys(const toml::table& t, const std::vector<std::string>& allowed, std::string_view where);

  // Typed reads: the value, or nullopt (with an error when present but wrong).
  std::optional<std::string> get_string(const toml::table& t, std::string_view key, std::string_view what);
  std::optional<double> get_number(const toml::node& n, std::string_view what);
  std::optional<double> get_number(const toml::table& t, std::string_view key, std::string_view what);
  std::optional<std::int64_t> get_integer(const toml::node& n, std::string_view what);
  std::optional<std::vector<double>> get_numbers(const toml::table& t, std::string_view key, std::size_t count,
                                                 std::string_view what);
  /// The same for min_count .. max_count numbers; `expected` says what ("3 numbers [m]").
  std::optional<std::vector<double>> get_numbers(const toml::table& t, std::string_view key, std::size_t min_count,
                                                 std::size_t max_count, std::string_view what, std::string_view expected);

  std::string file_;
  std::vector<StudyDiagnostic> diags_;

 private:
  /// The text of `line` (1-based) without its line break; nullopt past the end of the text.
  std::optional<std::string> line_text(int line) const;

  std::vector<std::string_view> lines_;
};

}  // namespace ks::study_parse
