// talus — a set of material points: one deal.II ParticleHandler with its
// property layout, the list of (cell, point count) in storage order that every
// particle walk follows, and relocation. A simulation may hold several sets on
// one grid (the double-point method: soil and water).
//
// Everything that depends on how deal.II 9.4 orders its particle storage lives
// in this class (docs/dealii-9.4-notes.md, "Storage"): the incremental update
// of the cell list after local moves and the re-creation of a saved order on
// restart. Walks over the points go through transfer::for_each_active_cell.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/particles/material_points.h>

#include <deal.II/particles/particle_handler.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace talus
{
  template <int dim>
  class MaterialPointSet
  {
  public:
    /// A cell holding points, with its point count, in storage order.
    struct ActiveCell
    {
      unsigned int cell, n_particles;
    };

    MaterialPointSet(const BackgroundGrid<dim> &grid, const std::string &name);

    /// Create the storage once `layout` is final (no point may exist yet).
    void initialize();

    const std::string &
    name() const
    {
      return set_name;
    }

    /// The properties every point of this set carries (offsets of the fields).
    PropertyLayout<dim> layout;
    /// The points. Iterate them through transfer::for_each_active_cell in the
    /// hot loops; plain iteration is fine for set-up, output and diagnostics.
    dealii::Particles::ParticleHandler<dim> handler;
    /// What relocation did so far (moves, sorts, points lost).
    RelocationStats relocation_stats;

    /// Cells with points in storage order, with their counts: the walks move
    /// one particle iterator along this list and never look cells up.
    const std::vector<ActiveCell> &
    active_cells() const
    {
      return cells;
    }

    /// Rebuild the cell list from the storage (after seeding, a deal.II sort,
    /// a restart). Fills the grid's cache entries of the listed cells (the
    /// walks and the kernels read them unchecked: CellCaches::filled_entry).
    void collect_active_cells();

    /// From inside a walk: the point at `it` left cell `c` (location updated)
    /// for the vertex neighbour `entered` (xi: its reference location there) or
    /// for none (invalid_unsigned_int); Relocator::leaving.
    void
    leaving(const typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it, const unsigned int c,
            const unsigned int entered, const dealii::Point<dim> &xi, const bool added)
    {
      relocator_ptr->leaving(it, c, entered, xi, added);
    }

    /// Move the points handed to leaving() and update the cell list. Collective.
    /// `moved(c, xi, properties)` is called for every point moved to a
    /// neighbour cell c (not for those placed by a full deal.II sort, nor for
    /// those the walk already added: `added` of leaving()). Returns
    /// true if a full deal.II sort ran (reference locations recomputed, points
    /// possibly sent to other ranks).
    bool relocate(const std::function<void(unsigned int, const dealii::Point<dim> &, const double *)> &moved = {});

    /// Whether the last collect or relocate changed the set of cells holding
    /// points (not just their counts): consumers that derive data from the
    /// cell set (active DoFs) may skip their update when it did not.
    bool
    cell_set_changed() const
    {
      return cells_changed;
    }

    Relocator<dim> &
    relocator()
    {
      return *relocator_ptr;
    }
    const Relocator<dim> &
    relocator() const
    {
      return *relocator_ptr;
    }

    /// One point of a saved state.
    struct SavedPoint
    {
      dealii::Point<dim>            x, xi;
      dealii::types::particle_index id;
      const double                 *properties;
    };
    /// Insert points into the (empty) set so that the storage ends up with the
    /// cell groups in the order given (cells[k] holds points[k]): a bitwise
    /// restart walks the points in exactly the order the saved run did.
    void insert_in_order(const std::vector<unsigned int> &cells, const std::vector<std::vector<SavedPoint>> &points);

    /// For tests: whether the incrementally kept cell list equals one read
    /// from the storage and the grid's cache entries of its cells are filled
    /// (the list is rebuilt from storage in any case).
    bool check_active_cells();

  private:
    const BackgroundGrid<dim>      &grid;
    std::string                     set_name;
    std::unique_ptr<Relocator<dim>> relocator_ptr;
    std::vector<ActiveCell>         cells;
    std::vector<unsigned int>       count_in_cell; // by active cell index
    std::vector<unsigned char>      cell_erased;
    bool                            cells_changed = true;
    void                            update_active_cells();
  };
} // namespace talus
