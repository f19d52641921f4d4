#pragma once
// A trajectory run's task at its place (methods/base/task_placement.hpp): the study's task moved by a rigid
// transform and its durations scaled, and seed 002's inverse-kinematics error of the moved task.
#include "methods/base/task_placement.hpp"
#include "study/study.hpp"  // StudyTask, PlanarArm3, Chain

namespace ks {

/// The task `task` at placement `p`. Inputs: the study's task (vertices [m], durations [s], planar
/// orientation angles [rad]); `planar`: the robot is planar (its task in its plane's coordinates: the
/// vertices turned about the plane's normal and moved by dx, dy; dz is not used) or spatial (each
/// vertex (x, y, z) turned about the base z and moved by dx, dy, dz; the heights written out). Output:
/// the task with every vertex placed, every planar orientation angle increased by the rotation, every
/// duration multiplied by the time scale; dt, integrator and hold_orientation as they were (a held
/// orientation is the start's, found at the placed first vertex).
StudyTask place_task(const StudyTask& task, const TaskPlacement& p, bool planar);

/// Seed 002's inverse-kinematics error of `task` (Eqs. 2.24 and 2.25's exponent): the sum over its
/// vertices of e_i = |P_i - FK(q_i)|, q_i the robot's position IK solution nearest P_i, counted when
/// e_i >= kIkErrorEpsilon (1 mm) [m]. The seed's closed-form 3R (`chain` null): |P_i - FK(q_i)| is the
/// distance from P_i to the annulus the tip reaches, radii max(0, 2 max l - sum l) .. sum l about the
/// base. A chain: Levenberg-Marquardt position solves (ik::solve_chain, lm_adaptive, joint limits
/// clamped when the robot has them) from the previous vertex's solution (the first from the
/// automatic start guess), again from that guess and then from mid-range of every limited joint when
/// the residual is 1 mm or more; e_i is the smallest residual. Deterministic: a pure function of its
/// inputs.
double task_ik_error(const StudyTask& task, const PlanarArm3& arm, const Chain* chain);

}  // namespace ks
