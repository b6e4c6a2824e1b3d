// talus — kinematic conditions of the grid's walls (kinematics.h).
#include <talus/base/errors.h>
#include <talus/loads/kinematics.h>

namespace talus::loads
{
  template <int dim>
  std::vector<unsigned char>
  wall_dof_flags(const BackgroundGrid<dim> &grid, const std::vector<BoundaryCondition> &bcs)
  {
    // the face walk over the grid's DoF handler lives with the grid
    return grid.constrained_dofs(bcs);
  }

  template <int dim>
  dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<dim> &       grid,
                   const NodalSpace<dim> &           space,
                   const std::vector<unsigned char> &flags)
  {
    dealii::AffineConstraints<double> walls;
    walls.reinit(space.locally_relevant_dofs());
    for (const auto &cell : grid.tria.active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int k = 0; k < dim; ++k)
            {
              const auto &       cc = grid.cells[cell->active_cell_index()];
              const unsigned int g  = cc.dofs[v * dim + k];
              if (g == dealii::numbers::invalid_unsigned_int || !flags[g])
                continue;
              const auto i = space.node_dof(cc.dofs[v * dim], k);
              if (!walls.is_constrained(i))
                walls.add_line(i);
            }
    walls.close();
    return walls;
  }

  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<2> &, const std::vector<BoundaryCondition> &);
  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<3> &, const std::vector<BoundaryCondition> &);
  template dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<2> &, const NodalSpace<2> &, const std::vector<unsigned char> &);
  template dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<3> &, const NodalSpace<3> &, const std::vector<unsigned char> &);
} // namespace talus::loads
