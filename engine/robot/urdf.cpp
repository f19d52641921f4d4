// URDF to Chain: parse with urdfdom (its console_bridge log captured for the error messages), walk
// from the tip link up to the base link, merge fixed joints, convert the inertials, check the
// result can be simulated.
#include "robot/urdf.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

#include "common/did_you_mean.hpp"
#include "robot/inertia_check.hpp"
#include "robot/urdf_check.hpp"

namespace ks {

namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// ---- the text: line numbers of named elements ----

int line_at(std::string_view text, std::size_t pos) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

// Line of the first element <tag ... name="value"> (any tag when `tag` is empty); 0 when absent.
int element_line(std::string_view text, std::string_view tag, std::string_view value) {
  for (const char quote : {'"', '\''}) {
    const std::string needle = quote + std::string(value) + quote;
    for (std::size_t pos = text.find(needle); pos != std::string_view::npos; pos = text.find(needle, pos + 1)) {
      std::size_t k = pos;  // back over: spaces, '=', spaces, then the attribute name "name"
      while (k > 0 && std::isspace(static_cast<unsigned char>(text[k - 1]))) --k;
      if (k == 0 || text[k - 1] != '=') continue;
      --k;
      while (k > 0 && std::isspace(static_cast<unsigned char>(text[k - 1]))) --k;
      if (k < 5 || text.substr(k - 4, 4) != "name" || !std::isspace(static_cast<unsigned char>(text[k - 5]))) continue;
      const std::size_t open = text.rfind('<', k);
      if (open == std::string_view::npos) continue;
      if (!tag.empty()) {
        const std::string_view rest = text.substr(open + 1);
        if (rest.substr(0, tag.size()) != tag || rest.size() == tag.size() ||
            !std::isspace(static_cast<unsigned char>(rest[tag.size()])))
          continue;
      }
      return line_at(text, open);
    }
  }
  return 0;
}


// ---- urdfdom, with its log captured ----

class LogCapture : public console_bridge::OutputHandler {
 public:
  std::vector<std::string> messages;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
  }
};

urdf::ModelInterfaceSharedPtr parse_model(const std::string& xml, std::vector<std::string>& messages) {
  static std::mutex console;  // console_bridge's output handler is process-wide
  std::lock_guard<std::mutex> lock(console);
  LogCapture capture;
  const console_bridge::LogLevel level = console_bridge::getLogLevel();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);  // warnings and errors reach `capture`
  console_bridge::useOutputHandler(&capture);
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    capture.messages.push_back(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  console_bridge::setLogLevel(level);
  messages = std::move(capture.messages);
  return model;
}

// ---- frames and mass properties ----

Frame to_frame(const urdf::Pose& pose) {
  Frame f;
  f.R = Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z).toRotationMatrix();
  f.p = V3(pose.position.x, pose.position.y, pose.position.z);
  return f;
}

// Mass, first moment and rotational inertia about the body frame's origin, body frame axes.
struct Body {
  double m = 0.0;
  V3 h = V3::Zero();
  M3 J = M3::Zero();
};

class Builder {
 public:
  Builder(std::string_view text, std::string file, const urdf::ModelInterface& model, urdf_check::LimitsOmitted omitted)
      : text_(text), file_(std::move(file)), model_(model), omitted_(std::move(omitted)) {}

  [[noreturn]] void fail(int line, const std::string& message) const { throw UrdfError(file_, line, message); }
  int link_line(const std::string& name) const { return element_line(text_, "link", name); }
  int joint_line(const std::string& name) const { return element_line(text_, "joint", name); }

  urdf::LinkConstSharedPtr find_link(std::string_view name, const char* role) const {
    if (auto link = model_.getLink(std::string(name))) return link;
    std::vector<std::string> links;
    for (const auto& [candidate, link] : model_.links_) links.push_back(candidate);
    const std::string nearest = did_you_mean(name, links);
    std::string message = std::string("unknown ") + role + " link '" + std::string(name) + "'";
    if (!nearest.empty()) message += "; did you mean '" + nearest + "'?";
    fail(0, message);
  }

  // Adds `link`'s <inertial> to `body`, the link's frame being `link_in_body`.
  void add_inertial(Body& body, const urdf::Link& link, const Frame& link_in_body) const {
    if (!link.inertial) return;
    const urdf::Inertial& in = *link.inertial;
    M3 Ic;
    Ic << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    check_mass_properties(link.name, in.mass, Ic);
    const Frame f = link_in_body * to_frame(in.origin);
    const V3& c = f.p;
    body.m += in.mass;
    body.h += in.mass * c;
    body.J += f.R * Ic * f.R.transpose();
    body.J.diagonal().array() += in.mass * c.squaredNorm();
    body.J -= (in.mass * c) * c.transpose();
  }

  // Adds every link attached to `link` through fixed joints (recursively), except `skip_child`.
  // A side branch through a moving joint is refused unless it carries no mass (then ignoring it is exact).
  void add_fixed_subtree(Body& body, const urdf::Link& link, const Frame& link_in_body, const std::string& skip_child) const {
    for (const auto& joint : link.child_joints) {
      if (joint->child_link_name == skip_child) continue;
      const auto child = model_.getLink(joint->child_link_name);
      if (!child) continue;
      if (joint->type != urdf::Joint::FIXED) {
        refuse_side_branch(link, *joint, *child);
        continue;
      }
      const Frame f = link_in_body * to_frame(joint->parent_to_joint_origin_transform);
      add_inertial(body, *child, f);
      add_fixed_subtree(body, *child, f, {});
    }
  }

  Chain build(std::string_view base_name, std::string_view tip_name, const V3& gravity) const {
    const auto base = find_link(base_name, "base");
    const auto tip = find_link(tip_name, "tip");
    std::vector<urdf::JointConstSharedPtr> path;  // tip to base, then reversed
    for (urdf::LinkConstSharedPtr link = tip; link->name != base->name; link = link->getParent()) {
      if (path.size() > model_.joints_.size()) fail(link_line(tip->name), "the links above the tip form a cycle");
      if (!link->parent_joint || !link->getParent())
        fail(link_line(tip->name), "tip link '" + tip->name + "' is not below base link '" + base->name +
                                       "' (going up from it reaches the root link '" + link->name + "')");
      path.push_back(link->parent_joint);
    }
    std::reverse(path.begin(), path.end());
    refuse_mimic(path);

    Chain chain;
    chain.name = model_.getName();
    chain.source = file_;
    chain.gravity = gravity;
    std::vector<Body> bodies;
    Frame acc;  // the current link's frame in the current body's frame (the base before any joint)
    for (std::size_t k = 0; k < path.size(); ++k) {
      const urdf::Joint& joint = *path[k];
      const Frame T = to_frame(joint.parent_to_joint_origin_transform);
      switch (joint.type) {
        case urdf::Joint::FIXED:
          acc = acc * T;
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          if (static_cast<int>(bodies.size()) == kMaxJoints) {
            const auto moving = std::count_if(path.begin(), path.end(), [](const auto& j) {
              return j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::CONTINUOUS || j->type == urdf::Joint::PRISMATIC;
            });
            fail(joint_line(joint.name), "the chain from '" + base->name + "' to '" + tip->name + "' has " +
                                             std::to_string(moving) + " moving joints; at most " +
                                             std::to_string(kMaxJoints) + " are supported");
          }
          chain.joints.push_back(make_joint(joint, acc * T));
          bodies.emplace_back();
          acc = Frame{};
          break;
        }
        default:
          fail(joint_line(joint.name), "joint '" + joint.name + "' is " +
                                           (joint.type == urdf::Joint::FLOATING ? "floating"
                                            : joint.type == urdf::Joint::PLANAR ? "planar"
                                                                                : "of unknown type") +
                                           ": only revolute, continuous, prismatic and fixed joints are supported");
      }
      if (bodies.empty()) continue;  // links fixed to the base carry no dynamics
      const auto child = model_.getLink(joint.child_link_name);
      add_inertial(bodies.back(), *child, acc);
      add_fixed_subtree(bodies.back(), *child, acc, k + 1 < path.size() ? path[k + 1]->child_link_name : std::string());
    }
    if (bodies.empty())
      fail(link_line(tip->name), "no revolute, continuous or prismatic joint between base link '" + base->name +
                                     "' and tip link '" + tip->name + "'");
    chain.tip = acc;

    double total = 0.0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      ChainJoint& j = chain.joints[i];
      j.mass = b.m;
      total += b.m;
      j.com = b.m > 0.0 ? V3(b.h / b.m) : V3::Zero();
      j.inertia = b.J;
      j.inertia.diagonal().array() -= b.m * j.com.squaredNorm();
      j.inertia += (b.m * j.com) * j.com.transpose();
      j.inertia = (0.5 * (j.inertia + j.inertia.transpose())).eval();
    }
    if (!(total > 0.0))
      fail(0, "the links moved by the joints from '" + base->name + "' to '" + tip->name + "' have zero total mass");
    std::string why;
    if (!chain.IsValid(&why)) fail(0, why);
    chain.prepare();
    check_inertia_matrix(chain);
    return chain;
  }

 private:
  // A link's mass properties: mass finite and >= 0, inertia one a rigid body can have (robot/inertia_check.hpp).
  void check_mass_properties(const std::string& name, double mass, const M3& Ic) const {
    const int line = link_line(name);
    if (!std::isfinite(mass) || mass < 0.0)
      fail(line, "link '" + name + "': <mass value=\"" + num(mass) + "\"> is " + (std::isfinite(mass) ? "negative" : "not finite") +
                     "; expected a mass >= 0 [kg]");
    if (const std::string why = inertia_problem(Ic); !why.empty()) fail(line, "link '" + name + "': " + why);
  }

  static std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  // Mass or inertia anywhere in the subtree of `link` (through any joints).
  bool carries_mass(const urdf::Link& link) const {
    if (link.inertial && (link.inertial->mass != 0.0 || link.inertial->ixx != 0.0 || link.inertial->iyy != 0.0 ||
                          link.inertial->izz != 0.0))
      return true;
    for (const auto& joint : link.child_joints)
      if (const auto child = model_.getLink(joint->child_link_name); child && carries_mass(*child)) return true;
    return false;
  }

  void refuse_side_branch(const urdf::Link& link, const urdf::Joint& joint, const urdf::Link& child) const {
    if (!carries_mass(child)) return;  // a massless branch (a frame, a sensor mount) does not change the dynamics
    fail(joint_line(joint.name), "link '" + link.name + "' (moved by the chain) has a side branch through the moving joint '" +
                                     joint.name + "' to link '" + child.name +
                                     "' with mass: a serial chain cannot simulate the branch's own motion; expected a chain "
                                     "from base to tip (make '" + joint.name + "' fixed to merge the branch at its origin, "
                                     "or choose a tip at the branch's end)");
  }

  // <mimic> couples a joint to another: the chain's joints move independently, so the coupling could not be honoured.
  void refuse_mimic(const std::vector<urdf::JointConstSharedPtr>& path) const {
    for (const auto& joint : path)
      if (joint->mimic && joint->type != urdf::Joint::FIXED)
        fail(joint_line(joint->name), "joint '" + joint->name + "' mimics joint '" + joint->mimic->joint_name +
                                          "' (<mimic>): the engine moves every chain joint independently and cannot "
                                          "honour the coupling; expected independent joints (remove <mimic>, or make "
                                          "the joint fixed)");
    for (const auto& [name, joint] : model_.joints_) {
      if (!joint->mimic || joint->type == urdf::Joint::FIXED) continue;
      for (const auto& on_path : path)
        if (on_path->name == joint->mimic->joint_name && on_path->type != urdf::Joint::FIXED)
          fail(joint_line(name), "joint '" + name + "' mimics the chain's joint '" + on_path->name +
                                     "' (<mimic>): the engine cannot honour the coupling; expected no joint "
                                     "mimicking a chain joint (remove <mimic>, or make '" + name + "' fixed)");
    }
  }

  ChainJoint make_joint(const urdf::Joint& joint, const Frame& origin) const {
    ChainJoint j;
    j.name = joint.name;
    j.type = joint.type == urdf::Joint::PRISMATIC ? JointType::prismatic : JointType::revolute;
    j.origin = origin;
    const V3 axis(joint.axis.x, joint.axis.y, joint.axis.z);
    if (!(axis.norm() > 0.0) || !axis.allFinite()) fail(joint_line(joint.name), "joint '" + joint.name + "': zero axis");
    j.axis = axis.normalized();
    if (joint.type != urdf::Joint::CONTINUOUS && joint.limits) {  // an omitted lower or upper: none on that side
      if (!omitted_.lower.count(joint.name)) j.lower = joint.limits->lower;
      if (!omitted_.upper.count(joint.name)) j.upper = joint.limits->upper;
      if (!(j.lower <= j.upper))
        fail(joint_line(joint.name), "joint '" + joint.name + "': limit lower > upper");
    }
    if (joint.limits) {  // velocity and effort limit continuous joints too; 0 (a common placeholder) = none
      const double v = joint.limits->velocity, f = joint.limits->effort;
      if (std::isnan(v) || v < 0.0 || std::isnan(f) || f < 0.0)
        fail(joint_line(joint.name), "joint '" + joint.name + "': limit velocity and effort must be >= 0");
      if (v > 0.0) j.velocity = v;
      if (f > 0.0) j.effort = f;
    }
    return j;
  }

  // M must be positive definite (robot/inertia_check.hpp).
  void check_inertia_matrix(const Chain& chain) const {
    int joint = -1;
    if (const std::string why = inertia_matrix_problem(chain, &joint); !why.empty())
      fail(joint >= 0 ? joint_line(chain.joints[joint].name) : 0, why);
  }

  std::string_view text_;
  std::string file_;
  const urdf::ModelInterface& model_;
  urdf_check::LimitsOmitted omitted_;
};

}  // namespace

Chain parse_urdf(std::string_view text, std::string_view base_link, std::string_view tip_link, const Eigen::Vector3d& gravity,
                 std::string_view file) {
  const std::string xml(text);
  const std::string file_name(file);
  // XML, numbers, limits, loops: located before urdfdom reads the text
  urdf_check::LimitsOmitted omitted = urdf_check::check_text(xml, file_name);
  std::vector<std::string> messages;
  const urdf::ModelInterfaceSharedPtr model = parse_model(xml, messages);
  if (!model || !messages.empty()) {  // a warning or error of urdfdom's means it dropped or guessed something
    std::string joined;
    int line = 0;
    for (const std::string& m : messages) {
      joined += (joined.empty() ? "" : "; ") + m;
      // urdfdom names the element at fault in brackets: "Joint [j1] is missing a 'parent' element"
      for (std::size_t open = m.find('['); line == 0 && open != std::string::npos; open = m.find('[', open + 1)) {
        const std::size_t close = m.find(']', open);
        if (close == std::string::npos) break;
        line = element_line(text, "", m.substr(open + 1, close - open - 1));
      }
    }
    throw UrdfError(file_name, line, "not a valid URDF robot" + (joined.empty() ? std::string() : ": " + joined));
  }
  return Builder(text, file_name, *model, std::move(omitted)).build(base_link, tip_link, gravity);
}

Chain load_urdf(const std::filesystem::path& file, std::string_view base_link, std::string_view tip_link,
                const Eigen::Vector3d& gravity) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw UrdfError(file.string(), 0, "cannot read the file: no such file");
  if (std::filesystem::is_directory(status)) throw UrdfError(file.string(), 0, "cannot read the file: it is a directory");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UrdfError(file.string(), 0, std::string("cannot read the file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw UrdfError(file.string(), 0, "cannot read the file");
  return parse_urdf(text.str(), base_link, tip_link, gravity, file.string());
}

}  // namespace ks
