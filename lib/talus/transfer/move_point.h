// talus — moving a material point inside a walk: new location, new reference
// coordinates if it stays in its cell, else handed to the set's relocation.
#pragma once

#include <talus/particles/material_point_set.h>

namespace talus::transfer
{
  /// Move the point at `it` (in cell c of the box grid) by dx. Returns true if
  /// it stays in cell c (reference location updated), false if it left (the
  /// set's relocation will place it; the walk must not touch it again).
  template <int dim>
  inline bool
  move_point(MaterialPointSet<dim> &set, const BackgroundGrid<dim> &grid, const unsigned int c,
             typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it, const double (&dx)[dim])
  {
    auto               x = it->get_location();
    dealii::Point<dim> xi;
    const auto &       cc     = grid.cells[c];
    bool               inside = true;
    for (unsigned int d = 0; d < dim; ++d)
      {
        x[d] += dx[d];
        xi[d]  = (x[d] - cc.lower[d]) * cc.inv_h[d];
        inside = inside && xi[d] >= 0.0 && xi[d] <= 1.0;
      }
    it->set_location(x);
    if (inside)
      {
        it->set_reference_location(xi);
        return true;
      }
    set.leaving(it, c);
    return false;
  }
} // namespace talus::transfer
