// `kinesweep query` argument parsing (see query_where.hpp).
#include "cli/query_where.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

namespace ks::cli {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) out.push_back(trim(cur)), cur.clear();
    else cur += c;
  }
  out.push_back(trim(cur));
  return out;
}

std::string unknown_column_message(const std::string& name, const RunsTable& t, const std::string& where) {
  std::string m = "unknown column '" + name + "'" + where;
  const std::string dym = did_you_mean(name, t.names());
  if (!dym.empty()) m += "; did you mean '" + dym + "'?";
  return m + "\nvalid columns: " + join(t.names(), ", ");
}

namespace {

std::optional<Op> parse_op(const std::string& s) {
  if (s == "=" || s == "==") return Op::eq;
  if (s == "!=") return Op::ne;
  if (s == "<") return Op::lt;
  if (s == "<=") return Op::le;
  if (s == ">") return Op::gt;
  if (s == ">=") return Op::ge;
  return std::nullopt;
}
Op flip(Op o) {
  switch (o) {
    case Op::lt: return Op::gt;
    case Op::le: return Op::ge;
    case Op::gt: return Op::lt;
    case Op::ge: return Op::le;
    default: return o;
  }
}

bool num_eq(double x, double v) {
  if (std::isnan(v)) return std::isnan(x);
  return x == v || std::abs(x - v) <= 1e-9 * std::max(std::abs(x), std::abs(v));
}

double parse_number(const std::string& s, const RunsColumn& c, const std::string& expr) {
  const std::string v = trim(s);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size())
    throw ArgError("--where '" + expr + "': column " + c.name + " is numeric; '" + v + "' is not a number");
  return d;
}

}  // namespace

double Selector::value(const RunsColumn& c, std::int64_t r) const {
  if (c.type == CellType::i64) return static_cast<double>(c.i[r]);
  return c.angle() && !radians ? c.f[r] * kRadToDeg : c.f[r];
}

bool Selector::test(const Condition& k, std::int64_t r) const {
  const RunsColumn& c = *k.col;
  if (c.type == CellType::str) {
    const std::string& x = c.s[r];
    switch (k.op) {
      case Op::eq: return std::find(k.strs.begin(), k.strs.end(), x) != k.strs.end();
      case Op::ne: return std::find(k.strs.begin(), k.strs.end(), x) == k.strs.end();
      case Op::lt: return x < k.strs[0];
      case Op::le: return x <= k.strs[0];
      case Op::gt: return x > k.strs[0];
      case Op::ge: return x >= k.strs[0];
    }
  }
  const double x = value(c, r);
  switch (k.op) {
    case Op::eq: return std::any_of(k.nums.begin(), k.nums.end(), [&](double v) { return num_eq(x, v); });
    case Op::ne: return std::none_of(k.nums.begin(), k.nums.end(), [&](double v) { return num_eq(x, v); });
    case Op::lt: return x < k.nums[0];
    case Op::le: return x <= k.nums[0];
    case Op::gt: return x > k.nums[0];
    case Op::ge: return x >= k.nums[0];
  }
  return false;
}

bool Selector::test(const Disjunction& d, std::int64_t r) const {
  return std::any_of(d.begin(), d.end(), [&](const Conjunction& c) {
    return std::all_of(c.begin(), c.end(), [&](const Condition& k) { return test(k, r); });
  });
}

namespace {

Disjunction parse_alternative(const std::string& expr, const RunsTable& t) {
  std::vector<std::string> operands, ops;
  std::string cur;
  for (std::size_t i = 0; i < expr.size();) {
    if (std::string("<>=!").find(expr[i]) != std::string::npos) {
      std::size_t j = i;
      while (j < expr.size() && std::string("<>=!").find(expr[j]) != std::string::npos) ++j;
      operands.push_back(trim(cur));
      cur.clear();
      ops.push_back(expr.substr(i, j - i));
      i = j;
    } else {
      cur += expr[i++];
    }
  }
  operands.push_back(trim(cur));
  const std::string syntax =
      "; expected COL OP VALUE (OP one of = != < <= > >=), COL=A,B,C, COL=LO..HI, LO<=COL<=HI, or "
      "alternatives A | B";
  if (ops.empty() || ops.size() > 2) throw ArgError("--where '" + expr + "': cannot parse" + syntax);
  std::vector<Op> o;
  for (auto& s : ops) {
    auto p = parse_op(s);
    if (!p) throw ArgError("--where '" + expr + "': unknown operator '" + s + "'" + syntax);
    o.push_back(*p);
  }
  for (auto& s : operands)
    if (s.empty()) throw ArgError("--where '" + expr + "': missing operand" + syntax);

  auto make = [&](const RunsColumn* c, Op op, const std::string& rhs) {
    Disjunction out;
    const bool str = c->type == CellType::str;
    const auto dots = rhs.find("..");
    if (!str && dots != std::string::npos && (op == Op::eq || op == Op::ne)) {
      const double lo = parse_number(rhs.substr(0, dots), *c, expr), hi = parse_number(rhs.substr(dots + 2), *c, expr);
      if (op == Op::eq) {
        out.push_back({{c, Op::ge, {lo}, {}}, {c, Op::le, {hi}, {}}});
      } else {
        out.push_back({{c, Op::lt, {lo}, {}}});
        out.push_back({{c, Op::gt, {hi}, {}}});
      }
      return out;
    }
    Condition k{c, op, {}, {}};
    const auto values = (op == Op::eq || op == Op::ne) ? split(rhs, ',') : std::vector<std::string>{rhs};
    for (auto& v : values) {
      if (str) k.strs.push_back(v);
      else k.nums.push_back(parse_number(v, *c, expr));
    }
    out.push_back({k});
    return out;
  };

  if (o.size() == 1) {
    if (const RunsColumn* c = t.find(operands[0])) return make(c, o[0], operands[1]);
    if (const RunsColumn* c = t.find(operands[1]); c && o[0] != Op::eq && o[0] != Op::ne)
      return make(c, flip(o[0]), operands[0]);
    throw ArgError(unknown_column_message(operands[0], t, " in --where '" + expr + "'"));
  }
  const RunsColumn* c = t.find(operands[1]);
  if (!c) throw ArgError(unknown_column_message(operands[1], t, " in --where '" + expr + "'"));
  const bool up = (o[0] == Op::lt || o[0] == Op::le) && (o[1] == Op::lt || o[1] == Op::le);
  const bool down = (o[0] == Op::gt || o[0] == Op::ge) && (o[1] == Op::gt || o[1] == Op::ge);
  if (!up && !down) throw ArgError("--where '" + expr + "': a range needs two < / <= (or two > / >=)" + syntax);
  const Disjunction a = make(c, flip(o[0]), operands[0]), b = make(c, o[1], operands[2]);
  Disjunction both;  // (a1 | a2 ...) & (b1 | b2 ...), distributed
  for (const Conjunction& x : a)
    for (const Conjunction& y : b) {
      both.push_back(x);
      both.back().insert(both.back().end(), y.begin(), y.end());
    }
  return both;
}

}  // namespace

Disjunction parse_where(const std::string& expr, const RunsTable& t) {
  Disjunction out;
  for (const std::string& part : split(expr, '|')) {
    if (part.empty())
      throw ArgError("--where '" + expr + "': an empty alternative; expected A | B with a condition on each side");
    const Disjunction d = parse_alternative(part, t);
    out.insert(out.end(), d.begin(), d.end());
  }
  return out;
}

std::vector<Condition> all_conditions(const std::vector<Disjunction>& filters) {
  std::vector<Condition> out;
  for (const Disjunction& d : filters)
    for (const Conjunction& c : d) out.insert(out.end(), c.begin(), c.end());
  return out;
}

void collect_held(const std::vector<Condition>& conditions, const RunsTable& t, bool include_pending, HeldValues& held) {
  for (const Condition& k : conditions) {
    if (k.col->type != CellType::str || (k.op != Op::eq && k.op != Op::ne)) continue;
    std::set<std::string>& h = held[k.col];
    for (std::int64_t r = 0; r < t.n_runs; ++r)
      if (include_pending || t.done[static_cast<std::size_t>(r)]) h.insert(k.col->s[r]);
  }
}

std::vector<std::string> unheld_value_notes(const std::vector<Condition>& conditions, const HeldValues& held_by) {
  std::vector<std::string> notes;
  std::set<std::pair<const RunsColumn*, std::string>> said;
  for (const Condition& k : conditions) {
    const auto it = held_by.find(k.col);
    if (it == held_by.end() || it->second.empty()) continue;  // no row at all: nothing to hint at
    const std::set<std::string>& held = it->second;  // the values the rows in question hold
    for (const std::string& v : k.strs) {
      if (held.count(v) || !said.insert({k.col, v}).second) continue;
      std::string m = "no row has " + k.col->name + " = '" + v + "'";
      const std::vector<std::string> values(held.begin(), held.end());
      const std::string dym = did_you_mean(v, values);
      if (!dym.empty()) m += "; did you mean '" + dym + "'?";
      else if (!values.empty() && values.size() <= 12) m += " (values: " + join(values, ", ") + ")";
      notes.push_back(m);
    }
  }
  return notes;
}

std::vector<std::string> unheld_value_notes(const std::vector<Condition>& conditions, const RunsTable& t,
                                            bool include_pending) {
  HeldValues held;
  collect_held(conditions, t, include_pending, held);
  return unheld_value_notes(conditions, held);
}

}  // namespace ks::cli
