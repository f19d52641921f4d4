#pragma once
// A serial chain (model/chain.hpp) from a URDF robot description: the joints on the path from a
// base link down to a tip link. urdfdom reads the file; nothing of it shows in this header.
#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "model/chain.hpp"
#include "robot/urdf_error.hpp"

namespace ks {

/// The chain from `base_link` to `tip_link` of the URDF text.
///  - revolute and prismatic joints become chain joints (limits from <limit>; a lower or upper the
///    <limit> omits is no limit on that side, -inf or +inf; lower >= upper given is refused); continuous joints
///    are revolute joints without limits;
///  - fixed joints are merged: the links they attach join the moving body they hang from (their
///    <inertial> merged into its mass properties), their transforms fold into the next joint's
///    origin, or into the tip frame after the last moving joint; links attached by fixed joints
///    off the path (a sensor, a tool beyond the tip) are merged likewise;
///  - the links must form a chain between base and tip: a side branch through a moving joint (off a
///    moved link, or beyond the tip) is refused when anything in it has mass or inertia (its own motion
///    cannot be simulated; make its joint fixed to merge it at its origin), and ignored when massless
///    (exact: it changes no dynamics); a mimic joint on the chain, or mimicking a chain joint, is
///    refused (the joints move independently: the coupling cannot be honoured);
///  - the text is checked before urdfdom reads it (robot/urdf_check.hpp): well-formed XML, every number
///    urdfdom converts a whole finite number (no unit suffix, inf or nan), each link the child of at
///    most one joint and no cycle; any warning or error urdfdom logs is a UrdfError too;
///  - each link's <inertial> (origin xyz rpy, mass, ixx..izz about the centre of mass in the
///    inertial frame) is expressed in its body's joint frame about the body's centre of mass;
///  - links rigidly attached to the base (before the first moving joint) carry no dynamics.
/// The chain gets `gravity` [m/s^2, base frame], the robot's name, source = `file`, and is
/// prepare()d. Throws UrdfError: XML or URDF parse failure, unknown base or tip link (naming the
/// nearest link name), tip not below base, floating or planar joints on the path, no moving joint
/// or more than kMaxJoints, a loop, a heavy side branch, a mimic joint, a mass < 0, an inertia with a
/// negative principal moment or one above the sum of the other two (a link the chain moves), zero
/// total mass, or a chain whose inertia matrix is singular (a joint moving neither mass nor inertia).
Chain parse_urdf(std::string_view text, std::string_view base_link, std::string_view tip_link,
                 const Eigen::Vector3d& gravity, std::string_view file = "<string>");

/// Read `file` and parse_urdf it. Throws UrdfError (also when the file cannot be read).
Chain load_urdf(const std::filesystem::path& file, std::string_view base_link, std::string_view tip_link,
                const Eigen::Vector3d& gravity);

}  // namespace ks
