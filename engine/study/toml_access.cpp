// The study parser's base: typed TOML reads with located diagnostics, positions, suggestions and the
// formatting helpers shared by the parser's parts.
#include "study/toml_access.hpp"

#include "common/did_you_mean.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace ks {

namespace study_parse {

std::string lower(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = char(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

std::string suggest(std::string_view word, const std::vector<std::string>& candidates) {
  const std::string pick = did_you_mean(word, candidates);
  return pick.empty() ? "" : "; did you mean '" + pick + "'?";
}

std::string suggest_either(std::string_view word, const std::vector<std::string>& mine,
                           const std::vector<ParamDef>& other, const std::string& other_kind) {
  if (auto s = suggest(word, mine); !s.empty()) return s;
  std::vector<std::string> names;
  for (const auto& i : other) names.push_back(i.name);
  auto s = suggest(word, names);
  if (s.empty()) return s;
  s.pop_back();  // '?'
  return s + " (" + (other_kind == "ik" ? "an " : "a ") + other_kind + " parameter, not allowed here)?";
}

std::string join(const std::vector<std::string>& v, std::string_view sep) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += sep;
    s += v[i];
  }
  return s;
}
std::vector<std::string> to_strings(std::span<const std::string_view> v) {
  return std::vector<std::string>(v.begin(), v.end());
}

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

std::string fmt(double v) {
  std::ostringstream o;
  o.precision(12);
  o << v;
  return o.str();
}

Pos pos_of(const toml::source_region& r) {
  Pos p;
  if (r.begin.line > 0) p.line = int(r.begin.line);
  if (r.begin.column > 0) p.column = int(r.begin.column);
  if (r.begin.line > 0 && r.end.line == r.begin.line && r.end.column > r.begin.column)
    p.length = int(r.end.column - r.begin.column);  // toml++'s end is one past the region
  else if (r.begin.line > 0 && r.end.line > r.begin.line)
    p.length = 0;
  return p;
}

std::vector<std::pair<const toml::key*, const toml::node*>> ordered(const toml::table& t) {
  std::vector<std::pair<const toml::key*, const toml::node*>> v;
  for (auto&& [k, n] : t) v.emplace_back(&k, &n);
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    const auto& ra = a.first->source().begin;
    const auto& rb = b.first->source().begin;
    return std::pair(ra.line, ra.column) < std::pair(rb.line, rb.column);
  });
  return v;
}

// ---------------------------------------------------------------------------------------------------
namespace {
/// Code points in s (UTF-8: every byte that is not a continuation byte starts one).
int code_points(std::string_view s) {
  return int(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

/// `p.length`, with 0 (to the end of the line) resolved against the line's text, trailing blanks not
/// counted; at least 1.
int underline_length(const Pos& p, const std::optional<std::string>& line) {
  if (p.length > 0) return p.length;
  if (!line) return 1;
  std::string_view rest = *line;
  std::size_t i = 0;  // byte offset of code point p.column - 1
  for (int cp = 1; cp < p.column && i < rest.size(); ++cp) {
    ++i;
    while (i < rest.size() && (static_cast<unsigned char>(rest[i]) & 0xC0) == 0x80) ++i;
  }
  rest.remove_prefix(i);
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t')) rest.remove_suffix(1);
  return std::max(1, code_points(rest));
}
}  // namespace

ParserCore::ParserCore(std::string file, std::string_view text) : file_(std::move(file)) {
  for (std::size_t begin = 0;;) {
    const std::size_t end = text.find('\n', begin);
    std::string_view line = text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines_.push_back(line);
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
}

std::optional<std::string> ParserCore::line_text(int line) const {
  if (line < 1 || std::size_t(line) > lines_.size()) return std::nullopt;
  return std::string(lines_[std::size_t(line) - 1]);
}

StudyDiagnostic& ParserCore::error(Pos p, std::string msg) {
  StudyDiagnostic d;
  d.file = file_;
  d.line = p.line;
  d.column = p.column;
  d.message = std::move(msg);
  d.source_line = line_text(p.line);
  d.length = underline_length(p, d.source_line);
  diags_.push_back(std::move(d));
  return diags_.back();
}

void ParserCore::note(StudyDiagnostic& d, Pos p, std::string msg) const {
  StudyDiagnostic::Note n;
  n.line = p.line;
  n.column = p.column;
  n.message = std::move(msg);
  n.source_line = line_text(p.line);
  n.length = underline_length(p, n.source_line);
  d.notes.push_back(std::move(n));
}

void ParserCore::check_keys(const toml::table& t, const std::vector<std::string>& allowed, std::string_view where) {
  for (auto&& [k, n] : ordered(t)) {
    if (std::find(allowed.begin(), allowed.end(), k->str()) != allowed.end()) continue;
    error(*k, "unknown key '" + std::string(k->str()) + "' in " + std::string(where) + "; expected one of " +
                  join(allowed) + suggest(k->str(), allowed));
  }
}

std::optional<std::string> ParserCore::get_string(const toml::table& t, std::string_view key, std::string_view what) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  if (const auto* s = n->as_string()) return s->get();
  error(*n, std::string(what) + " is " + type_name(*n) + "; expected a string");
  return std::nullopt;
}

std::optional<double> ParserCore::get_number(const toml::node& n, std::string_view what) {
  double v;
  if (const auto* i = n.as_integer()) v = double(i->get());
  else if (const auto* f = n.as_floating_point()) v = f->get();
  else {
    error(n, std::string(what) + " is " + type_name(n) + "; expected a number");
    return std::nullopt;
  }
  if (!std::isfinite(v)) {
    error(n, std::string(what) + " is not finite; expected a finite number");
    return std::nullopt;
  }
  return v;
}

std::optional<double> ParserCore::get_number(const toml::table& t, std::string_view key, std::string_view what) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  return get_number(*n, what);
}

std::optional<std::int64_t> ParserCore::get_integer(const toml::node& n, std::string_view what) {
  if (const auto* i = n.as_integer()) return i->get();
  error(n, std::string(what) + " is " + type_name(n) + "; expected an integer");
  return std::nullopt;
}

std::optional<std::vector<double>> ParserCore::get_numbers(const toml::table& t, std::string_view key,
                                                       std::size_t count, std::string_view what) {
  return get_numbers(t, key, count, count, what, std::to_string(count) + " numbers");
}

std::optional<std::vector<double>> ParserCore::get_numbers(const toml::table& t, std::string_view key,
                                                       std::size_t min_count, std::size_t max_count,
                                                       std::string_view what, std::string_view expected) {
  const toml::node* n = t.get(key);
  if (!n) return std::nullopt;
  const auto* a = n->as_array();
  if (!a || a->size() < min_count || a->size() > max_count) {
    error(*n, std::string(what) + " is " + (a ? "an array of " + std::to_string(a->size()) : type_name(*n)) +
                  "; expected an array of " + std::string(expected));
    return std::nullopt;
  }
  std::vector<double> v;
  for (const auto& e : *a) {
    auto x = get_number(e, std::string(what) + " element");
    if (!x) return std::nullopt;
    v.push_back(*x);
  }
  return v;
}

}  // namespace study_parse
}  // namespace ks
