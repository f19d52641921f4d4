#pragma once
// The checks a URDF text passes before urdfdom reads it (urdf.cpp): the XML itself, every number
// urdfdom converts (strictly: a whole finite number, no unit suffix), and the shape of the joint
// graph (each link the child of at most one joint, no cycle). Internal to the robot part.
#include <set>
#include <string>

namespace ks::urdf_check {

/// Elements nested deeper than this are refused before any XML parser reads the text.
inline constexpr int kMaxElementDepth = 256;

/// Throws UrdfError (robot/urdf_error.hpp) at the line of the element at fault:
///  - an element nested more than kMaxElementDepth deep (at its line and column; checked first, by
///    a scan of the markup, so that no parser recurses that deep);
///  - the text is not well-formed XML (tinyxml, the parser urdfdom uses);
///  - an attribute urdfdom reads as numbers is not exactly that many finite numbers: <origin xyz rpy>,
///    <mass value>, <inertia ixx ixy ixz iyy iyz izz>, <axis xyz>, <limit lower upper velocity
///    effort>, <dynamics damping friction>, <mimic multiplier offset>, <safety_controller ...>,
///    <calibration rising falling>, <box size>, <cylinder radius length>, <sphere radius>,
///    <mesh scale> (the attribute is named, with the text found);
///  - a link is the child of two joints, or the joints form a cycle (a kinematic loop);
///  - a revolute or prismatic joint's <limit> with lower > upper, or lower = upper (a joint that
///    cannot move), both given.
/// Returns what urdfdom's model does not tell: the <limit>s that omit lower or upper (urdfdom reads
/// an omitted bound as 0; it means no limit on that side).
struct LimitsOmitted {
  std::set<std::string> lower, upper;  ///< names of the joints whose <limit> omits lower / upper
};
LimitsOmitted check_text(const std::string& xml, const std::string& file);

}  // namespace ks::urdf_check
