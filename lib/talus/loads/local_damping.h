// talus — local (non-viscous) damping of seed 000 §6.3: at every degree of
// freedom f_damp = -alpha |f| v/|v| (Eq. 6.23 for the 1-phase solid; Eqs.
// 6.25/6.28 for the liquid and solid of the 2-phase formulation use the same
// form with their own unbalanced force and velocity). Shared by the
// formulations: call it on the unbalanced nodal force before the division by
// the nodal mass.
#pragma once

#include <cmath>

namespace talus::loads
{
  /// Damping force at one DoF: -alpha |f| sign(v) (0 for v = 0).
  inline double
  local_damping_force(const double alpha, const double f_unbalanced, const double v)
  {
    return v > 0 ? -alpha * std::abs(f_unbalanced) : (v < 0 ? alpha * std::abs(f_unbalanced) : 0.0);
  }

  /// In place on the DoFs listed in `dofs`: F[i] += -alpha |F[i]| sign(V[i])
  /// (F holds the unbalanced force f_ext - f_int, V the nodal velocity).
  template <typename IndexRange>
  inline void
  apply_local_damping(const double alpha, const IndexRange &dofs, const double *V, double *F)
  {
    for (const unsigned int i : dofs)
      F[i] += local_damping_force(alpha, F[i], V[i]);
  }
} // namespace talus::loads
