// talus — the K0 procedure's stress (seed 000 §6.4; tension positive), the one
// formula shared by the solvers' initial state (formulations/explicit/load_control.cc) and the
// particle files of talus-mesh (mesh/prepare.cc).
#pragma once

#include <cmath>

namespace talus::loads
{
  struct K0Values
  {
    double vertical;   ///< sigma_v = -(unit weight x depth + surcharge)
    double horizontal; ///< sigma_h = K0 sigma_v
  };

  /// K0 stress at `depth` (>= 0) below the surface of a body with the given unit
  /// weight (density x |g|), under a surface surcharge (compression positive).
  inline K0Values
  k0_stress(const double unit_weight, const double depth, const double surcharge, const double K0)
  {
    const double sv = -(unit_weight * depth + surcharge);
    return {sv, K0 * sv};
  }

  /// Jaky's K0 = 1 - sin(phi) of a friction angle in degrees ('K0 = auto').
  inline double
  jaky_k0(const double friction_angle_degrees)
  {
    return 1.0 - std::sin(friction_angle_degrees * M_PI / 180.0);
  }
} // namespace talus::loads
