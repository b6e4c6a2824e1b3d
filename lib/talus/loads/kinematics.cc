// talus — kinematic conditions of the grid's walls (kinematics.h).
#include <talus/base/errors.h>
#include <talus/loads/kinematics.h>

#include <algorithm>

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
  wall_constraints(const BackgroundGrid<dim> &           grid,
                   const NodalSpace<dim> &               space,
                   const std::vector<unsigned char> &    flags,
                   const std::vector<PrescribedNodeDof> *prescribed,
                   const std::vector<double> *           values)
  {
    dealii::AffineConstraints<double> walls;
    walls.reinit(space.locally_relevant_dofs());
    // prescribed DoFs first: on a node that is also on a fixed/roller wall the
    // prescribed value wins (as in talus-explicit)
    if (prescribed)
      for (std::size_t k = 0; k < prescribed->size(); ++k)
        {
          const auto &p = (*prescribed)[k];
          const auto  i = space.node_dof(p.node, p.component);
          if (walls.is_constrained(i))
            continue;
          walls.add_line(i);
          if (values)
            walls.set_inhomogeneity(i, (*values)[k]);
        }
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

  template <int dim>
  std::vector<PrescribedNodeDof>
  prescribed_node_dofs(const BackgroundGrid<dim> &                 grid,
                       const std::vector<PrescribedVelocity<dim>> &conditions,
                       const bool                                  owned_only)
  {
    using Target               = typename PrescribedVelocity<dim>::Target;
    const unsigned int n_owned = grid.partitioner->locally_owned_size();
    const unsigned int n_local = owned_only ? n_owned : n_owned + grid.partitioner->n_ghost_indices();
    std::vector<PrescribedNodeDof> out;
    std::vector<unsigned char>     seen(n_local, 0);
    for (unsigned int j = 0; j < conditions.size(); ++j)
      {
        const auto &pv = conditions[j];
        if (pv.target == Target::body)
          continue;
        std::fill(seen.begin(), seen.end(), 0);
        for (unsigned int c = 0; c < grid.cells.size(); ++c)
          {
            const auto &cc = grid.cells[c];
            if (!(cc.h[0] > 0)) // not a locally relevant cell
              continue;
            for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
              {
                const unsigned int i0 = cc.dofs[v * dim];
                if (i0 >= n_local || seen[i0])
                  continue;
                bool hit = false;
                if (pv.target == Target::region)
                  {
                    hit = true;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        const double x   = cc.lower[d] + ((v >> d) & 1u) * cc.h[d];
                        const double tol = 1e-9 * cc.h[d];
                        hit              = hit && x >= pv.lower[d] - tol && x <= pv.upper[d] + tol;
                      }
                  }
                else
                  {
                    const auto &cell = grid.cell_iterators[c];
                    for (unsigned int f = 0; f < dealii::GeometryInfo<dim>::faces_per_cell && !hit; ++f)
                      if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() == pv.boundary)
                        for (unsigned int i = 0; i < dealii::GeometryInfo<dim>::vertices_per_face; ++i)
                          hit = hit || dealii::GeometryInfo<dim>::face_to_cell_vertices(f, i) == v;
                  }
                if (!hit)
                  continue;
                seen[i0] = 1;
                for (unsigned int d = 0; d < dim; ++d)
                  if (pv.component[d])
                    out.push_back({cc.dofs[v * dim + d], i0, j, d});
              }
          }
      }
    return out;
  }

  template std::vector<PrescribedNodeDof>
  prescribed_node_dofs(const BackgroundGrid<2> &, const std::vector<PrescribedVelocity<2>> &, const bool);
  template std::vector<PrescribedNodeDof>
  prescribed_node_dofs(const BackgroundGrid<3> &, const std::vector<PrescribedVelocity<3>> &, const bool);
  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<2> &, const std::vector<BoundaryCondition> &);
  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<3> &, const std::vector<BoundaryCondition> &);
  template dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<2> &,
                   const NodalSpace<2> &,
                   const std::vector<unsigned char> &,
                   const std::vector<PrescribedNodeDof> *,
                   const std::vector<double> *);
  template dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<3> &,
                   const NodalSpace<3> &,
                   const std::vector<unsigned char> &,
                   const std::vector<PrescribedNodeDof> *,
                   const std::vector<double> *);
} // namespace talus::loads
