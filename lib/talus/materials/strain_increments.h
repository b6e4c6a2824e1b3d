// talus — the small-strain and spin increments of one step from the
// displacement-increment gradient at a point, gu[i][j] = d du_i / d x_j (the
// rate form's input, materials/material.h): d_eps = sym(gu), d_omega = skew(gu),
// in-plane entries only in 2D (the rest stay zero).
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  template <int dim>
  inline void
  strain_and_spin_increments(const double (&gu)[dim][dim], Strain &d_eps, Spin &d_omega)
  {
    for (unsigned int d = 0; d < dim; ++d)
      for (unsigned int k = 0; k < dim; ++k)
        {
          if (k >= d)
            d_eps[d][k] = 0.5 * (gu[d][k] + gu[k][d]);
          d_omega[d][k] = 0.5 * (gu[d][k] - gu[k][d]);
        }
  }
} // namespace talus::materials
