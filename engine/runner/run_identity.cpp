// Run identities and the run context (see run_identity.hpp).
#include "runner/run_identity.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <map>

#include "study/sha256.hpp"

namespace ks {

namespace {

/// Shortest text that reads back as the same double ("nan", "inf", "-0" as such).
std::string num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
template <class Seq>
std::string list(const Seq& values) {
  std::string s = "[";
  for (const auto& v : values) s += (s.size() > 1 ? ", " : "") + num(v);
  return s + "]";
}
std::string vec3(const Eigen::Vector3d& v) { return list(std::array<double, 3>{v.x(), v.y(), v.z()}); }
std::string mat3(const Eigen::Matrix3d& m) {
  std::string s = "[";
  for (int r = 0; r < 3; ++r) s += (r ? ", " : "") + vec3(m.row(r).transpose());
  return s + "]";
}
std::string frame(const Frame& f) { return "R " + mat3(f.R) + ", p " + vec3(f.p); }
std::string_view inertia_name(InertiaForm f) { return to_string(f); }

void robot_fields(const Study& s, std::vector<ContextField>& out) {
  auto add = [&](std::string key, std::string value) { out.push_back({"robot", "[robot] " + key, std::move(value)}); };
  const PlanarArm3& a = s.robot;  // the closed-form 3R (trajectory runs without a chain, planar3r IK problems)
  add("l", list(a.l));
  add("m", list(a.m));
  add("lc", list(a.lc));
  add("I", list(a.I));
  add("g", num(a.g));
  add("inertia", std::string(inertia_name(a.inertia_form)));
  if (!s.chain) {
    add("chain", "none (the closed-form 3R)");
    return;
  }
  // A chain robot ([robot] n-link arm or URDF): what its kinematics and dynamics read.
  const Chain& c = *s.chain;
  add("chain", std::to_string(c.dof()) + " joints");
  for (int j = 0; j < c.dof(); ++j) {
    const ChainJoint& q = c.joints[j];
    const std::string p = "joint " + std::to_string(j + 1) + " ";
    add(p + "type", q.type == JointType::prismatic ? "prismatic" : "revolute");
    add(p + "origin", frame(q.origin));
    add(p + "axis", vec3(q.axis));
    add(p + "limits", list(std::array<double, 2>{q.lower, q.upper}));
    // velocity and effort limits decide out_of_limits and the limit ratios; listed when the joint has
    // them (a robot without them keeps the context it had before they were listed)
    if (std::isfinite(q.velocity)) add(p + "velocity limit", num(q.velocity));
    if (std::isfinite(q.effort)) add(p + "effort limit", num(q.effort));
    add(p + "mass", num(q.mass));
    add(p + "com", vec3(q.com));
    add(p + "inertia", mat3(q.inertia));
  }
  add("tip", frame(c.tip));
  add("gravity", vec3(c.gravity));
  // (the chain of the position / pose IK problems is this chain, or the 3R above as a chain)
}

void task_fields(const Study& s, std::vector<ContextField>& out) {
  auto add = [&](std::string key, std::string value) { out.push_back({"task", "[task] " + key, std::move(value)}); };
  const StudyTask& t = s.task;
  std::string v = "[";
  for (std::size_t i = 0; i < t.vertices.size(); ++i) {
    std::vector<double> p{t.vertices[i].x(), t.vertices[i].y()};
    if (!t.z.empty()) p.push_back(i < t.z.size() ? t.z[i] : 0.0);
    v += (i ? ", " : "") + list(p);
  }
  add("vertices", v + "]");
  add("durations", list(t.durations));
  // a spline through the same points is another path; a quintic task lists no shape (its context as before)
  if (t.shape != PathShape::quintic) add("spline", std::string(to_string(t.shape)));
  add("dt", num(t.dt));
  add("integrator", t.integrator == Integrator::rk4 ? "rk4" : "semi_implicit_euler");
  add("orientation [rad]", t.hold_orientation ? "hold" : list(t.orientation));
}

void append_u64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void append_cell(std::string& out, const std::string& name, const Cell& c) {
  if (identity_neutral(name, c)) return;  // a placement at the identity: as if the column were absent
  out += name;
  out.push_back('\0');
  if (const double* d = std::get_if<double>(&c)) {
    out.push_back('f');
    append_u64(out, std::bit_cast<std::uint64_t>(*d));
  } else if (const std::int64_t* i = std::get_if<std::int64_t>(&c)) {
    out.push_back('i');
    append_u64(out, static_cast<std::uint64_t>(*i));
  } else {
    const std::string& s = std::get<std::string>(c);
    out.push_back('s');
    append_u64(out, s.size());
    out += s;
  }
}

std::string prefix_bytes(const Digest& context, BlockKind kind) {
  std::string p = "kinesweep-run-identity-1\n";
  p.append(reinterpret_cast<const char*>(context.data()), context.size());
  p += to_string(kind);
  p += '\n';
  return p;
}

Digest sha256(const std::string& bytes) {
  Sha256 h;
  h.update(bytes);
  return h.digest();
}

}  // namespace

/// The [world] (motion runs read it): each obstacle and the link radii, listed only when given (a
/// study without [world] keeps the context it had before [world] existed).
void world_fields(const Study& s, std::vector<ContextField>& out) {
  auto add = [&](std::string key, std::string value) { out.push_back({"world", "[world] " + key, std::move(value)}); };
  for (std::size_t i = 0; i < s.world.obstacles.size(); ++i) {
    const std::string k = "obstacle " + std::to_string(i + 1);
    const geometry::Obstacle& o = s.world.obstacles[i];
    if (const auto* p = std::get_if<geometry::Sphere>(&o)) add(k, "sphere centre " + vec3(p->centre) + ", radius " + num(p->radius));
    else if (const auto* b = std::get_if<geometry::Box>(&o))
      add(k, "box centre " + vec3(b->centre) + ", R " + mat3(b->rotation) + ", half " + vec3(b->half));
    else if (const auto* c = std::get_if<geometry::Capsule>(&o))
      add(k, "capsule a " + vec3(c->a) + ", b " + vec3(c->b) + ", radius " + num(c->radius));
    if (!s.world.velocities.empty() && s.world.velocities[i] != Vec3::Zero())  // fixed ones keep their field
      add(k + " velocity", vec3(s.world.velocities[i]));
  }
  if (!s.world.link_radius.empty()) add("link_radius", list(s.world.link_radius));
}

std::vector<ContextField> run_context(const Study& study, const HistoryPolicy& histories,
                                      const std::string& engine_version) {
  std::vector<ContextField> out;
  robot_fields(study, out);
  task_fields(study, out);
  world_fields(study, out);
  out.push_back({"settings", "[study] histories", histories.str()});
  out.push_back({"settings", "kinesweep version", engine_version});
  return out;
}

Digest context_digest(const std::vector<ContextField>& context, BlockKind kind) {
  const auto parts = context_parts(kind);
  Sha256 h;
  for (const ContextField& f : context) {
    if (std::find(parts.begin(), parts.end(), f.group) == parts.end()) continue;
    h.update(f.key);
    h.update(std::string_view("\0", 1));
    h.update(f.value);
    h.update("\n");
  }
  return h.digest();
}

std::string context_changes(const std::vector<ContextField>& before, const std::vector<ContextField>& after) {
  // key -> (group, value before, value after), in the order the fields come
  std::vector<std::string> keys;
  std::map<std::string, std::array<std::string, 3>> by_key;
  auto note = [&](const ContextField& f, int side) {
    auto [it, fresh] = by_key.try_emplace(f.key, std::array<std::string, 3>{f.group, "(none)", "(none)"});
    if (fresh) keys.push_back(f.key);
    it->second[side] = f.value;
  };
  for (const ContextField& f : before) note(f, 1);
  for (const ContextField& f : after) note(f, 2);
  std::vector<std::string> groups;
  std::map<std::string, std::string> clauses;
  for (const std::string& k : keys) {
    const auto& [group, was, now] = by_key[k];
    if (was == now) continue;
    std::string& c = clauses[group];
    if (c.empty()) groups.push_back(group);
    c += (c.empty() ? "" : ", ") + k + ": " + was + " -> " + now;
  }
  std::string out;
  for (const std::string& g : groups)
    out += (out.empty() ? "" : "; ") + std::string(g == "settings" ? "the settings" : "the " + g) + " changed: " +
           clauses[g];
  return out;
}

std::string run_identity_bytes(const Digest& context, BlockKind kind, const std::vector<std::string>& names,
                               const std::vector<Cell>& cells) {
  std::vector<std::size_t> order(names.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return names[a] < names[b]; });
  std::string out = prefix_bytes(context, kind);
  for (std::size_t i : order) append_cell(out, names[i], cells[i]);
  return out;
}

BlockIdentity::BlockIdentity(const std::vector<ContextField>& context, const Block& block)
    : block_(block), prefix_(prefix_bytes(context_digest(context, block.kind()), block.kind())) {
  const auto& cols = block.columns();
  order_.resize(cols.size());
  for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = i;
  std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return cols[a].name < cols[b].name; });
}

Digest BlockIdentity::of(const std::vector<Cell>& cells) const {
  std::string bytes = prefix_;
  for (std::size_t i : order_) append_cell(bytes, block_.columns()[i].name, cells[i]);
  return sha256(bytes);
}

Digest BlockIdentity::run(std::uint64_t local) const { return of(block_.params(local)); }

Digest BlockIdentity::row(const Record& row, const std::vector<std::size_t>& column) const {
  std::vector<Cell> cells;
  cells.reserve(column.size());
  for (std::size_t c : column) cells.push_back(row.cells[c]);
  return of(cells);
}

}  // namespace ks
