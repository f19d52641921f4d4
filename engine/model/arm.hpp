#pragma once
// Constants of the planar 3R arm (seed 000, Table 2). Pure data: no workspace, no state.
#include <array>

namespace ks {

/// Which closed form of M(q) to use.
enum class InertiaForm {
  physical,    ///< the Lagrangian M(q) (matches Orocos KDL's Newton-Euler to ~1e-13). Default.
  thesis_m11,  ///< seed 000's code as printed (Appendix I): in M11 the m3 bracket sits inside m2*(...),
               ///< so it is multiplied by m2. Not physical; it is what reproduces Table 4 to the digit.
};

/// A planar serial arm with three revolute joints about z, gravity along -y.
/// All lengths in m, masses in kg, inertias in kg m^2 (about each link's centre of mass).
struct PlanarArm3 {
  std::array<double, 3> l{1.0, 1.0, 1.0};    ///< link lengths [m]
  std::array<double, 3> m{5.0, 2.0, 1.0};    ///< link masses [kg]
  std::array<double, 3> lc{0.5, 0.5, 0.5};   ///< joint-to-centre-of-mass distances [m]
  std::array<double, 3> I{0.42083333333333334, 0.16833333333333333, 0.08416666666666667};  ///< [kg m^2]
  double g = 9.81;                           ///< gravity magnitude [m/s^2], acting along -y
  InertiaForm inertia_form = InertiaForm::physical;

  /// Uniform bars of thickness b: I_i = m_i (l_i^2 + b^2) / 12, centre of mass at l_i / 2.
  static PlanarArm3 bars(std::array<double, 3> l, std::array<double, 3> m, double b, double g = 9.81) {
    PlanarArm3 a;
    a.l = l;
    a.m = m;
    a.g = g;
    for (int i = 0; i < 3; ++i) {
      a.lc[i] = l[i] / 2.0;
      a.I[i] = m[i] * (l[i] * l[i] + b * b) / 12.0;
    }
    return a;
  }
  /// The seed's arm: l = 1 m, b = 0.1 m, m = (5, 2, 1) kg.
  static PlanarArm3 seed() { return bars({1.0, 1.0, 1.0}, {5.0, 2.0, 1.0}, 0.1); }
};

}  // namespace ks
