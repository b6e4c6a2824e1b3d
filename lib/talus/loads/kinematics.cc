// talus — kinematic conditions of the grid's walls (kinematics.h).
#include <talus/base/errors.h>
#include <talus/loads/kinematics.h>

#include <algorithm>
#include <set>
#include <string>

namespace talus::loads
{
  template <int dim>
  std::vector<unsigned char>
  wall_dof_flags(const BackgroundGrid<dim> &grid, const std::vector<BoundaryCondition> &bcs)
  {
    const auto &partitioner = grid.partitioner;
    std::vector<unsigned char> flag(partitioner->locally_owned_size() + partitioner->n_ghost_indices(), 0);
    std::set<dealii::types::boundary_id> used;
    for (const auto &cell : grid.dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        for (const unsigned int f : cell->face_indices())
          {
            if (!cell->face(f)->at_boundary())
              continue;
            const auto bid = cell->face(f)->boundary_id();
            for (const auto &bc : bcs)
              if (bc.id == bid)
                {
                  used.insert(bid);
                  const unsigned int normal_dir = f / 2; // box: faces 2d, 2d+1 normal to d
                  for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_face; ++v)
                    for (unsigned int comp = 0; comp < dim; ++comp)
                      if (bc.kind == BoundaryCondition::Kind::fixed || comp == normal_dir)
                        {
                          const auto gi = cell->face(f)->vertex_dof_index(v, comp);
                          flag[partitioner->global_to_local(gi)] = 1;
                        }
                }
          }
      }
    // every boundary id named must exist somewhere in the grid
    std::vector<dealii::types::boundary_id> all_ids = grid.tria.get_boundary_ids();
    for (const auto &bc : bcs)
      if (std::find(all_ids.begin(), all_ids.end(), bc.id) == all_ids.end())
        {
          std::string ids;
          for (const auto i : all_ids)
            ids += (ids.empty() ? "" : ", ") + std::to_string(i);
          throw InputError("boundary conditions: boundary id " + std::to_string(bc.id) +
                           " does not exist in the grid (ids present: " + ids + ")");
        }
    return flag;
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
