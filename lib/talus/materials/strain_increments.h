// talus — the small-strain and spin increments of one step from the
// displacement-increment gradient at a point, gu[i][j] = d du_i / d x_j (the
// rate form's input, materials/material.h): d_eps = sym(gu), d_omega = skew(gu),
// in-plane entries only in 2D (the rest stay zero).
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  /// Written on the raw entries (deal.II's SymmetricTensor<2, 3> order 00, 11,
  /// 22, 01, 02, 12): through operator[] it was an out-of-line call of ~60
  /// instructions per point in the explicit update pass (docs/scaling.md); the
  /// same arithmetic, so the same bits.
  template <int dim>
  [[gnu::always_inline]] inline void
  strain_and_spin_increments(const double (&gu)[dim][dim], Strain &d_eps, Spin &d_omega)
  {
    constexpr unsigned int raw[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (unsigned int d = 0; d < dim; ++d)
      for (unsigned int k = 0; k < dim; ++k)
        {
          if (k >= d)
            d_eps.access_raw_entry(raw[d][k]) = 0.5 * (gu[d][k] + gu[k][d]);
          d_omega[d][k] = 0.5 * (gu[d][k] - gu[k][d]);
        }
  }
} // namespace talus::materials
