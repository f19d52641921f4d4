#include "cli/query_util.hpp"
#include "cli/kind_meaning.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <ostream>
#include <set>

#include "common/did_you_mean.hpp"
#include "schema/params.hpp"
#include "space/space.hpp"

namespace ks::cli {

const RunsColumn* RunsTable::find(const std::string& name) const {
  for (const auto& c : cols)
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<std::string> RunsTable::names() const {
  std::vector<std::string> out;
  for (const auto& c : cols) out.push_back(c.name);
  return out;
}

bool RunsColumn::applies_to(const std::string& kind) const {
  return kinds.empty() || std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

bool RunsColumn::missing(std::int64_t row) const {
  switch (type) {
    case CellType::f64: return std::isnan(f[row]);
    case CellType::i64: return i[row] == -1;
    case CellType::str: return s[row].empty();
  }
  return true;
}

std::string RunsTable::kind(std::int64_t row) const {
  if (kinds.size() == 1) return kinds.front();
  for (const Role role : {Role::parameter, Role::metric})
    for (const auto& c : cols)
      if (c.loaded && c.role == role && c.kinds.size() == 1 && !c.missing(row)) return c.kinds.front();
  return "";
}

void RunsTable::load_kind_columns() {
  if (kinds.size() <= 1) return;
  for (const Role role : {Role::parameter, Role::metric}) {
    std::set<std::string> seen;
    for (auto& c : cols)
      if (c.role == role && c.kinds.size() == 1 && seen.insert(c.kinds.front()).second) c.loaded = true;
  }
}

std::vector<const RunsColumn*> RunsTable::key_metrics(const std::string& kind) const {
  const KindMeaning km = kind_meaning(meta, kind);
  const auto& keys = km.key_metrics;
  std::vector<const RunsColumn*> out;
  for (const auto& c : cols) {
    if (c.role != Role::metric || !c.applies_to(kind)) continue;
    if (km.known ? std::count(keys.begin(), keys.end(), c.name) > 0 : out.size() < 3) out.push_back(&c);
  }
  return out;
}

void v1_column_roles(std::vector<ColumnSpec>& columns) {
  std::size_t vertices = 5;  // vertex_alpha_2 .. _<vertices>: a study's path may have more than the square's 5
  for (const auto& c : columns) {
    const std::string prefix = "vertex_alpha_";
    std::size_t v = 0;
    if (c.name.rfind(prefix, 0) == 0 &&
        std::from_chars(c.name.data() + prefix.size(), c.name.data() + c.name.size(), v).ec == std::errc())
      vertices = std::max(vertices, v);
  }
  std::set<std::string> names;
  for (const auto& c : columns) names.insert(c.name);
  std::map<std::string, std::pair<Role, std::string>> table;  // name -> role, kinds
  auto enter = [&](const std::string& name, Role role, const std::string& kind) {
    auto [it, fresh] = table.try_emplace(name, role, kind);
    if (!fresh) it->second.second += "," + kind;
  };
  for (const BlockKind k : block_kinds()) {
    if (k == BlockKind::motion) continue;  // format v1 predates motion runs (and shares metric names with trajectory)
    const auto& ms = metrics(k);
    if (std::none_of(ms.begin(), ms.end(), [&](const MetricDef& m) { return names.count(m.name) > 0; }))
      continue;  // no block of this kind in the file
    const std::string kind(to_string(k));
    for (const ParamDef& p : block_params(k, vertices)) enter(p.name, Role::parameter, kind);
    for (const MetricDef& m : ms) enter(m.name, Role::metric, kind);
  }
  for (auto& c : columns) {
    const auto it = table.find(c.name);
    c.role = it == table.end() ? Role::bookkeeping : it->second.first;
    c.kinds = it == table.end() ? std::string() : it->second.second;
  }
}

RunsTable runs_header(store::ResultsReader& reader) {
  RunsTable t;
  t.meta = reader.meta();
  for (const ColumnSpec& spec : reader.columns()) {
    RunsColumn c;
    c.name = spec.name;
    c.unit = spec.unit;
    c.description = spec.description;
    c.type = spec.type;
    c.role = spec.role;
    for (std::size_t at = 0; at < spec.kinds.size();) {  // "trajectory,ik" -> {"trajectory", "ik"}
      std::size_t comma = spec.kinds.find(',', at);
      if (comma == std::string::npos) comma = spec.kinds.size();
      if (comma > at) c.kinds.push_back(spec.kinds.substr(at, comma - at));
      at = comma + 1;
    }
    for (const auto& k : c.kinds)
      if (std::find(t.kinds.begin(), t.kinds.end(), k) == t.kinds.end()) t.kinds.push_back(k);
    t.cols.push_back(std::move(c));
  }
  return t;
}

void load_piece(store::ResultsReader& reader, RunsTable& t, std::int64_t first, std::int64_t count) {
  t.consistent = true;
  consistent_read(reader, [&] {
    t.first = std::min(first, reader.n_runs());
    t.ids.clear();
    t.done = reader.done_mask(first, count);  // before the columns: a row done here is complete in them
    t.n_runs = static_cast<std::int64_t>(t.done.size());
    for (RunsColumn& c : t.cols) {
      if (!c.loaded) {
        c.f.clear(), c.i.clear(), c.s.clear();
        continue;
      }
      switch (c.type) {
        case CellType::f64: c.f = reader.read_f64(c.name, first, count); break;
        case CellType::i64: c.i = reader.read_i64(c.name, first, count); break;
        case CellType::str: c.s = reader.read_str(c.name, first, count); break;
      }
    }
    t.consistent = reader.unchanged_since_open();
    return 0;
  });
}

RunsTable load_runs(store::ResultsReader& reader) {
  RunsTable t = runs_header(reader);
  load_piece(reader, t, 0, store::ResultsReader::kAll);
  return t;
}

void load_ids(store::ResultsReader& reader, RunsTable& t, const std::vector<std::int64_t>& ids) {
  const auto done = consistent_read(reader, [&] {  // the ids' done flags (one read per piece they span)
    std::vector<std::uint8_t> d;
    for (std::size_t i = 0; i < ids.size();) {
      const std::int64_t base = ids[i];
      const auto mask = reader.done_mask(base, kPieceRows);
      for (; i < ids.size() && ids[i] < base + static_cast<std::int64_t>(mask.size()); ++i)
        d.push_back(mask[static_cast<std::size_t>(ids[i] - base)]);
    }
    return d;
  });
  const std::vector<Record> rows = consistent_read(reader, [&] { return reader.read_rows(ids); });  // after the flags
  t.first = 0;
  t.ids = ids;
  t.n_runs = static_cast<std::int64_t>(ids.size());
  t.done = done;
  for (std::size_t c = 0; c < t.cols.size(); ++c) {
    RunsColumn& col = t.cols[c];
    col.f.clear(), col.i.clear(), col.s.clear();
    col.loaded = true;
    for (const Record& r : rows) {
      switch (col.type) {
        case CellType::f64: col.f.push_back(std::get<double>(r.cells[c])); break;
        case CellType::i64: col.i.push_back(std::get<std::int64_t>(r.cells[c])); break;
        case CellType::str: col.s.push_back(std::get<std::string>(r.cells[c])); break;
      }
    }
  }
}

RunsTable empty_like(const RunsTable& t) {
  RunsTable e;
  e.meta = t.meta;
  e.kinds = t.kinds;
  e.cols.reserve(t.cols.size());
  for (const RunsColumn& c : t.cols) {
    RunsColumn k;
    k.name = c.name, k.unit = c.unit, k.description = c.description;
    k.type = c.type, k.role = c.role, k.kinds = c.kinds, k.loaded = c.loaded;
    e.cols.push_back(std::move(k));
  }
  return e;
}

bool same_value(const RunsColumn& c, std::int64_t a, const RunsColumn& d, std::int64_t b) {
  switch (c.type) {
    case CellType::str: return c.s[a] == d.s[b];
    case CellType::i64: return c.i[a] == d.i[b];
    case CellType::f64: return c.f[a] == d.f[b] || (std::isnan(c.f[a]) && std::isnan(d.f[b]));
  }
  return true;
}

void append_row(RunsTable& g, const RunsTable& t, std::int64_t r, const std::vector<bool>& take) {
  for (std::size_t c = 0; c < t.cols.size(); ++c) {
    if (!take[c]) continue;
    const RunsColumn& from = t.cols[c];
    RunsColumn& to = g.cols[c];
    switch (from.type) {
      case CellType::f64: to.f.push_back(from.f[r]); break;
      case CellType::i64: to.i.push_back(from.i[r]); break;
      case CellType::str: to.s.push_back(from.s[r]); break;
    }
  }
  g.done.push_back(t.done[static_cast<std::size_t>(r)]);
  g.ids.push_back(t.row_id(r));
  ++g.n_runs;
}

std::optional<Format> parse_format(const std::string& s) {
  if (s == "table") return Format::table;
  if (s == "csv") return Format::csv;
  if (s == "json") return Format::json;
  return std::nullopt;
}

namespace {
std::string full_double(double v) {  // csv/json: round-trip precision
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  for (int prec = 15; prec <= 17; ++prec) {  // shortest text that reads back to the same double
    std::snprintf(buf, sizeof buf, "%.*g", prec, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}
std::string cell_text(const OutCell& c, bool full) {
  if (const double* d = std::get_if<double>(&c)) return full ? full_double(*d) : format_double(*d);
  if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) return std::to_string(*i);
  if (const std::string* s = std::get_if<std::string>(&c)) return *s;
  return "";
}
}  // namespace

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (unsigned char ch : s) {
    switch (ch) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      case '\r': o += "\\r"; break;
      default:
        if (ch < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", ch);
          o += b;
        } else {
          o += static_cast<char>(ch);
        }
    }
  }
  return o + "\"";
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string o = "\"";
  for (char ch : s) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return o + "\"";
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string o;
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? sep : "") + v[i];
  return o;
}

std::string check_count(std::string& value) {
  const std::string v = value.substr(std::min(value.size(), value.find_first_not_of(" \t")));
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (end != v.c_str() && d < 0) return "a count of 0 or more is expected, not " + v;
  return "";  // CLI11's conversion rejects what is no number
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  return ks::did_you_mean(word, candidates);
}

void print_out(const OutTable& t, Format f, std::ostream& os) {
  const std::size_t nc = t.names.size();
  const std::vector<std::string>& hdr = t.csv_names.size() == nc ? t.csv_names : t.names;
  if (f == Format::csv) {
    for (std::size_t c = 0; c < nc; ++c) os << (c ? "," : "") << csv_field(hdr[c]);
    os << '\n';
    for (const auto& r : t.rows) {
      for (std::size_t c = 0; c < nc; ++c) os << (c ? "," : "") << csv_field(cell_text(r[c], true));
      os << '\n';
    }
    return;
  }
  if (f == Format::json) {
    const std::vector<std::string>& keys = t.names;  // plain names; the units say what was converted
    os << "{\"columns\": [";
    for (std::size_t c = 0; c < nc; ++c) os << (c ? ", " : "") << json_string(keys[c]);
    os << "],\n \"units\": {";
    for (std::size_t c = 0; c < nc; ++c)
      os << (c ? ", " : "") << json_string(keys[c]) << ": " << json_string(c < t.units.size() ? t.units[c] : "");
    os << "},\n \"rows\": [";
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
      os << (r ? ",\n  {" : "\n  {");
      for (std::size_t c = 0; c < nc; ++c) {
        os << (c ? ", " : "") << json_string(keys[c]) << ": ";
        const OutCell& cell = t.rows[r][c];
        if (const double* d = std::get_if<double>(&cell)) os << (std::isfinite(*d) ? full_double(*d) : "null");
        else if (const std::string* s = std::get_if<std::string>(&cell)) os << json_string(*s);
        else if (std::holds_alternative<std::monostate>(cell)) os << "null";
        else os << cell_text(cell, true);
      }
      os << "}";
    }
    os << (t.rows.empty() ? "]}\n" : "\n ]}\n");
    return;
  }
  // Aligned table: header "name [unit]", strings left-aligned, numbers right-aligned.
  std::vector<std::string> head(nc);
  std::vector<std::size_t> w(nc);
  std::vector<bool> left(nc, false);
  for (std::size_t c = 0; c < nc; ++c) {
    head[c] = t.names[c];
    if (c < t.units.size() && !t.units[c].empty()) head[c] += " [" + t.units[c] + "]";
    w[c] = head[c].size();
  }
  std::vector<std::vector<std::string>> text(t.rows.size(), std::vector<std::string>(nc));
  for (std::size_t r = 0; r < t.rows.size(); ++r)
    for (std::size_t c = 0; c < nc; ++c) {
      text[r][c] = cell_text(t.rows[r][c], false);
      if (std::holds_alternative<std::string>(t.rows[r][c])) left[c] = true;
      w[c] = std::max(w[c], text[r][c].size());
    }
  auto put = [&](const std::string& s, std::size_t c) {
    const std::string pad(w[c] - std::min(w[c], s.size()), ' ');
    os << (c ? "  " : "") << (left[c] ? s + (c + 1 < nc ? pad : "") : pad + s);
  };
  for (std::size_t c = 0; c < nc; ++c) put(head[c], c);
  os << '\n';
  for (std::size_t c = 0; c < nc; ++c) put(std::string(w[c], '-'), c);
  os << '\n';
  for (const auto& row : text) {
    for (std::size_t c = 0; c < nc; ++c) put(row[c], c);
    os << '\n';
  }
}

}  // namespace ks::cli
