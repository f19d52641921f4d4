#pragma once
// The checks a URDF text passes before urdfdom reads it (urdf.cpp): the XML itself, every number
// urdfdom converts (strictly: a whole finite number, no unit suffix), and the shape of the joint
// graph (each link the child of at most one joint, no cycle). Internal to the robot part.
#include <string>

namespace ks::urdf_check {

/// Throws UrdfError (robot/urdf.hpp) at the line of the element at fault:
///  - the text is not well-formed XML (tinyxml, the parser urdfdom uses);
///  - an attribute urdfdom reads as numbers is not exactly that many finite numbers: <origin xyz rpy>,
///    <mass value>, <inertia ixx ixy ixz iyy iyz izz>, <axis xyz>, <limit lower upper velocity
///    effort>, <dynamics damping friction>, <mimic multiplier offset>, <safety_controller ...>,
///    <calibration rising falling>, <box size>, <cylinder radius length>, <sphere radius>,
///    <mesh scale> (the attribute is named, with the text found);
///  - a link is the child of two joints, or the joints form a cycle (a kinematic loop).
void check_text(const std::string& xml, const std::string& file);

}  // namespace ks::urdf_check
