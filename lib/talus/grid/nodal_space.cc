#include <talus/grid/nodal_space.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>

namespace talus
{
  template <int dim>
  NodalSpace<dim>::NodalSpace(const BackgroundGrid<dim> &grid_, const unsigned int n_components)
      : grid(grid_)
      , n_comp(n_components)
      , fe(dealii::FE_Q<dim>(1), n_components)
      , dofs(grid_.tria)
  {
  }

  template <int dim>
  void
  NodalSpace<dim>::setup()
  {
    dofs.distribute_dofs(fe);
    owned = dofs.locally_owned_dofs();
    dealii::DoFTools::extract_locally_relevant_dofs(dofs, relevant);
    part = std::make_shared<dealii::Utilities::MPI::Partitioner>(owned, relevant, grid.comm);

    const unsigned int n_grid_local = grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    const unsigned int n_local      = part->locally_owned_size() + part->n_ghost_indices();
    node_dofs.assign(std::size_t(n_grid_local) * n_comp, dealii::numbers::invalid_dof_index);
    positions.assign(n_local, dealii::Point<dim>());
    components.assign(n_local, 0);
    // same triangulation: a cell of this DoFHandler has the grid cell's
    // active_cell_index, and vertex v is the kernel's node v of that cell
    for (const auto &cell : dofs.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        const auto &cc = grid.cells[cell->active_cell_index()];
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int k = 0; k < n_comp; ++k)
            {
              const auto g                                          = cell->vertex_dof_index(v, k);
              node_dofs[std::size_t(cc.dofs[v * dim]) * n_comp + k] = g;
              const unsigned int l                                  = part->global_to_local(g);
              positions[l]                                          = cell->vertex(v);
              components[l]                                         = k;
            }
      }
  }

  template <int dim>
  dealii::AffineConstraints<double>
  NodalSpace<dim>::constraints_where(
    const std::function<bool(const dealii::Point<dim> &, unsigned int, double &)> &prescribed) const
  {
    dealii::AffineConstraints<double> c;
    c.reinit(relevant);
    const unsigned int n_local = part->locally_owned_size() + part->n_ghost_indices();
    for (unsigned int l = 0; l < n_local; ++l)
      {
        double value = 0;
        if (prescribed(positions[l], components[l], value))
          {
            const auto g = part->local_to_global(l);
            c.add_line(g);
            c.set_inhomogeneity(g, value);
          }
      }
    c.close();
    return c;
  }

  template <int dim>
  std::vector<std::vector<bool>>
  NodalSpace<dim>::constant_modes() const
  {
    std::vector<std::vector<bool>> modes;
    dealii::DoFTools::extract_constant_modes(dofs, dealii::ComponentMask(n_comp, true), modes);
    return modes;
  }

  template class NodalSpace<2>;
  template class NodalSpace<3>;
} // namespace talus
