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
  wall_constraints(const BackgroundGrid<dim> &grid, const NodalSpace<dim> &space,
                   const std::vector<unsigned char> &flags, const std::vector<PrescribedNodeDof> *prescribed,
                   const std::vector<double> *values, const std::vector<dealii::types::global_dof_index> *contact)
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
              const auto        &cc = grid.cells[cell->active_cell_index()];
              const unsigned int g  = cc.dofs[v * dim + k];
              if (g == dealii::numbers::invalid_unsigned_int || !flags[g])
                continue;
              const auto i = space.node_dof(cc.dofs[v * dim], k);
              if (!walls.is_constrained(i))
                walls.add_line(i);
            }
    // the DoFs of the contact nodes currently in contact (homogeneous: the
    // increment is zero there; a fixed/roller wall or a prescribed DoF wins)
    if (contact)
      for (const auto i : *contact)
        if (!walls.is_constrained(i))
          walls.add_line(i);
    walls.close();
    return walls;
  }

  template <int dim>
  std::vector<ContactNode>
  contact_wall_nodes(const BackgroundGrid<dim> &grid, const std::vector<dealii::types::boundary_id> &ids,
                     const std::vector<unsigned char> &wall_flags)
  {
    std::vector<ContactNode> nodes;
    if (ids.empty())
      return nodes;
    const std::vector<dealii::types::boundary_id> all_ids = grid.tria.get_boundary_ids();
    for (const auto id : ids)
      if (std::find(all_ids.begin(), all_ids.end(), id) == all_ids.end())
        throw InputError("boundary conditions/contact: boundary id " + std::to_string(id) +
                         " does not exist in the grid");
    std::vector<unsigned char> seen(wall_flags.size(), 0);
    for (const auto &cell : grid.dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        for (const unsigned int f : cell->face_indices())
          {
            if (!cell->face(f)->at_boundary() ||
                std::find(ids.begin(), ids.end(), cell->face(f)->boundary_id()) == ids.end())
              continue;
            const unsigned int axis = f / 2; // box: faces 2d, 2d+1 normal to d
            for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_face; ++v)
              {
                const unsigned int node   = grid.partitioner->global_to_local(cell->face(f)->vertex_dof_index(v, 0));
                const unsigned int normal = grid.partitioner->global_to_local(cell->face(f)->vertex_dof_index(v, axis));
                if (seen[node] || wall_flags[normal])
                  continue;
                seen[node] = 1;
                nodes.push_back({node, axis, f % 2 ? 1 : -1, cell->face(f)->vertex(v)[axis]});
              }
          }
      }
    return nodes;
  }

  template <int dim>
  std::vector<PrescribedNodeDof>
  prescribed_node_dofs(const BackgroundGrid<dim> &grid, const std::vector<PrescribedVelocity<dim>> &conditions,
                       const bool owned_only)
  {
    using Target                           = typename PrescribedVelocity<dim>::Target;
    const unsigned int             n_owned = grid.partitioner->locally_owned_size();
    const unsigned int             n_local = owned_only ? n_owned : n_owned + grid.partitioner->n_ghost_indices();
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
                    const auto &cell = grid.cell_iterator(c);
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

  template std::vector<PrescribedNodeDof> prescribed_node_dofs(const BackgroundGrid<2> &,
                                                               const std::vector<PrescribedVelocity<2>> &, const bool);
  template std::vector<PrescribedNodeDof> prescribed_node_dofs(const BackgroundGrid<3> &,
                                                               const std::vector<PrescribedVelocity<3>> &, const bool);
  template std::vector<ContactNode>       contact_wall_nodes(const BackgroundGrid<2> &,
                                                             const std::vector<dealii::types::boundary_id> &,
                                                             const std::vector<unsigned char> &);
  template std::vector<ContactNode>       contact_wall_nodes(const BackgroundGrid<3> &,
                                                             const std::vector<dealii::types::boundary_id> &,
                                                             const std::vector<unsigned char> &);
  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<2> &, const std::vector<BoundaryCondition> &);
  template std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<3> &, const std::vector<BoundaryCondition> &);
  template dealii::AffineConstraints<double> wall_constraints(const BackgroundGrid<2> &, const NodalSpace<2> &,
                                                              const std::vector<unsigned char> &,
                                                              const std::vector<PrescribedNodeDof> *,
                                                              const std::vector<double> *,
                                                              const std::vector<dealii::types::global_dof_index> *);
  template dealii::AffineConstraints<double> wall_constraints(const BackgroundGrid<3> &, const NodalSpace<3> &,
                                                              const std::vector<unsigned char> &,
                                                              const std::vector<PrescribedNodeDof> *,
                                                              const std::vector<double> *,
                                                              const std::vector<dealii::types::global_dof_index> *);
} // namespace talus::loads
