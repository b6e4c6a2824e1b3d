#include <talus/particles/material_point_set.h>

namespace talus
{
  template <int dim>
  MaterialPointSet<dim>::MaterialPointSet(const BackgroundGrid<dim> &g, const std::string &name)
      : grid(g)
      , set_name(name)
  {
  }

  template <int dim>
  void
  MaterialPointSet<dim>::initialize()
  {
    handler.initialize(grid.tria, grid.mapping, layout.n_properties());
    relocator_ptr = std::make_unique<Relocator<dim>>(grid, handler);
  }

  template <int dim>
  void
  MaterialPointSet<dim>::collect_active_cells()
  {
    cells.clear();
    auto it = handler.begin();
    while (it != handler.end())
      {
        const auto   cell = it->get_surrounding_cell();
        unsigned int n    = 0;
        for (; it != handler.end() && it->get_surrounding_cell() == cell; ++it)
          ++n;
        cells.push_back({cell->active_cell_index(), n});
        grid.cells.ensure_filled(cells.back().cell); // the walks read it unchecked
      }
    count_in_cell.assign(grid.cells.size(), 0);
    cell_erased.assign(grid.cells.size(), 0);
    for (const auto &ac : cells)
      count_in_cell[ac.cell] = ac.n_particles;
    cells_changed = true;
  }

  template <int dim>
  void
  MaterialPointSet<dim>::update_active_cells()
  {
    // Mirror of deal.II 9.4's storage after local moves: a cell emptied by a
    // removal loses its list entry, a cell that receives its first particle is
    // appended at the end of the owned cells, in insertion order.
    const auto &r = *relocator_ptr;
    if (r.sorted_last || r.reordered_last)
      {
        collect_active_cells();
        return;
      }
    auto &count   = count_in_cell;
    cells_changed = false;
    // in the order the relocator applied them: a cell emptied and filled again
    // in one finish() has lost its entry and got a new one at the end
    const std::size_t n_old = cells.size();
    for (const auto &change : r.cell_changes)
      if (!change.inserted)
        {
          if (--count[change.cell] == 0)
            cell_erased[change.cell] = 1;
        }
      else if (count[change.cell]++ == 0)
        {
          cells.push_back({change.cell, 0});
          grid.cells.ensure_filled(change.cell); // filled by the relocation already
        }
    std::size_t out = 0;
    for (std::size_t i = 0; i < cells.size(); ++i)
      {
        const unsigned int c = cells[i].cell;
        if (i < n_old && cell_erased[c])
          {
            cells_changed = true;
            continue; // this entry was erased (a re-filled cell sits at the end)
          }
        cells[out++] = {c, count[c]};
      }
    cells_changed = cells_changed || cells.size() > n_old;
    cells.resize(out);
    for (const auto &change : r.cell_changes)
      cell_erased[change.cell] = 0;
  }

  template <int dim>
  bool
  MaterialPointSet<dim>::relocate(
    const std::function<void(unsigned int, const dealii::Point<dim> &, const double *)> &moved)
  {
    relocator_ptr->finish(relocation_stats, moved);
    update_active_cells();
    return relocator_ptr->sorted_last;
  }

  template <int dim>
  void
  MaterialPointSet<dim>::insert_in_order(const std::vector<unsigned int>            &cell_order,
                                         const std::vector<std::vector<SavedPoint>> &points)
  {
    const unsigned int n_props      = handler.n_properties_per_particle();
    auto               insert_group = [&](const unsigned int k) {
      for (const auto &q : points[k])
        handler.insert_particle(q.x, q.xi, q.id, grid.cell_iterator(cell_order[k]),
                                              dealii::ArrayView<const double>(q.properties, n_props));
    };
    for (std::size_t k = 0; k < cell_order.size(); ++k)
      insert_group(k);
    // deal.II's update_cached_numbers() sorts the cell groups of the storage
    // into cell order, while a run keeps them in the order its moves created (a
    // cell that receives its first point goes to the end): the walks follow
    // that order and the nodal sums with it. So, once the counts are up to
    // date, every group is taken out and inserted again, in the saved order (a
    // re-created group goes to the end of the owned cells).
    handler.update_cached_numbers();
    std::vector<typename dealii::Particles::ParticleHandler<dim>::particle_iterator> in_cell;
    for (std::size_t k = 0; k < cell_order.size(); ++k)
      {
        const auto range = handler.particles_in_cell(grid.cell_iterator(cell_order[k]));
        in_cell.clear();
        for (auto it = range.begin(); it != range.end(); ++it)
          in_cell.push_back(it);
        for (auto it = in_cell.rbegin(); it != in_cell.rend(); ++it)
          handler.remove_particle(*it);
        insert_group(k);
      }
    collect_active_cells();
  }

  template <int dim>
  bool
  MaterialPointSet<dim>::check_active_cells()
  {
    const auto kept = cells;
    // every cell of the walk has its cache entry filled (the walks read it unchecked)
    bool filled = true;
    for (const auto &ac : kept)
      filled = filled && grid.cells.is_filled(ac.cell);
    collect_active_cells();
    bool same = filled && kept.size() == cells.size();
    for (std::size_t i = 0; same && i < kept.size(); ++i)
      same = kept[i].cell == cells[i].cell && kept[i].n_particles == cells[i].n_particles;
    return same;
  }

  template class MaterialPointSet<2>;
  template class MaterialPointSet<3>;
} // namespace talus
