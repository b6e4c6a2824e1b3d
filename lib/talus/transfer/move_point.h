// talus — moving a material point inside a walk: new location, new reference
// coordinates if it stays in its cell, else handed to the set's relocation.
#pragma once

#include <talus/particles/material_point_set.h>

namespace talus::transfer
{
  /// Put the point at `it` (in cell c of the box grid) at its new location x.
  /// Returns true if it stays in cell c (reference location xi set and
  /// returned), false if it left (the set's relocation will place it; the walk
  /// must not touch it again). A point that left is looked up among the vertex
  /// neighbours of c at once, while their data are in cache from the walk
  /// (the relocation used to do it later, cold; xi: its reference location
  /// in the cell it entered). `caller_adds`: the caller adds a point that
  /// entered a locally owned cell to the nodal sums itself, so the
  /// relocation's `moved` callback skips it; `add_to` is then that cell, else
  /// invalid_unsigned_int.
  /// The leaving side of place_moved_point (a few per cent of the points per
  /// step), kept out of line: inlined into the walks it enlarged their loops
  /// enough to change their register allocation (docs/scaling.md).
  template <int dim>
  [[gnu::noinline]] bool
  place_leaving_point(MaterialPointSet<dim> &set, const BackgroundGrid<dim> &grid, const unsigned int c,
                      typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it,
                      const dealii::Point<dim> &x, dealii::Point<dim> &xi, unsigned int &add_to, const bool caller_adds)
  {
    const unsigned int entered = grid.find_cell_near(c, x, xi);
    const bool         added =
      caller_adds && entered != dealii::numbers::invalid_unsigned_int && grid.cells[entered].locally_owned;
    add_to = added ? entered : dealii::numbers::invalid_unsigned_int;
    set.leaving(it, c, entered, xi, added);
    return false;
  }

  template <int dim>
  inline bool
  place_moved_point(MaterialPointSet<dim> &set, const BackgroundGrid<dim> &grid, const unsigned int c,
                    typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it,
                    const dealii::Point<dim> &x, dealii::Point<dim> &xi, unsigned int &add_to, const bool caller_adds)
  {
    const auto &cc     = grid.cells.filled_entry(c); // a cell with points
    bool        inside = true;
    for (unsigned int d = 0; d < dim; ++d)
      {
        xi[d]  = (x[d] - cc.lower[d]) * cc.inv_h[d];
        inside = inside && xi[d] >= 0.0 && xi[d] <= 1.0;
      }
    it->set_location(x);
    if (inside)
      {
        it->set_reference_location(xi);
        return true;
      }
    return place_leaving_point(set, grid, c, it, x, xi, add_to, caller_adds);
  }

  /// The same for a caller that does not add entered points itself.
  template <int dim>
  inline bool
  place_moved_point(MaterialPointSet<dim> &set, const BackgroundGrid<dim> &grid, const unsigned int c,
                    typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it,
                    const dealii::Point<dim> &x, dealii::Point<dim> &xi)
  {
    unsigned int add_to;
    return place_moved_point(set, grid, c, it, x, xi, add_to, false);
  }

  /// Move the point at `it` (in cell c) by dx; place_moved_point.
  template <int dim>
  inline bool
  move_point(MaterialPointSet<dim> &set, const BackgroundGrid<dim> &grid, const unsigned int c,
             typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it, const double (&dx)[dim])
  {
    auto x = it->get_location();
    for (unsigned int d = 0; d < dim; ++d)
      x[d] += dx[d];
    dealii::Point<dim> xi;
    return place_moved_point(set, grid, c, it, x, xi);
  }
} // namespace talus::transfer
