#include <talus/grid/nodal_space.h>
#include <talus/particles/material_point_set.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <algorithm>

namespace talus
{
  template <int dim>
  NodalSpace<dim>::NodalSpace(const BackgroundGrid<dim> &grid_, const unsigned int n_components)
    : grid(grid_)
    , n_comp(n_components)
    , fe(dealii::FE_Q<dim>(1), n_components)
    , dofs(grid_.tria)
  {}

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
              const auto g                              = cell->vertex_dof_index(v, k);
              node_dofs[std::size_t(cc.dofs[v * dim]) * n_comp + k] = g;
              const unsigned int l                      = part->global_to_local(g);
              positions[l]                              = cell->vertex(v);
              components[l]                             = k;
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

  // ------------------------------------------------------------------ ActiveSet

  template <int dim>
  ActiveSet<dim>::ActiveSet(const NodalSpace<dim> &space_)
    : space(space_)
    , pattern(std::make_unique<dealii::TrilinosWrappers::SparsityPattern>())
  {}

  template <int dim>
  ActiveSet<dim>::~ActiveSet() = default;

  template <int dim>
  template <class K>
  void
  ActiveSet<dim>::reinit(const std::vector<MaterialPointSet<dim> *> &sets)
  {
    const auto &       grid = space.grid;
    const unsigned int nc   = space.n_components();
    const auto &       relevant = space.locally_relevant_dofs();
    const auto &       owned    = space.locally_owned_dofs();

    // rows of all relevant DoFs: a point near the partition touches ghost nodes,
    // whose rows go to their owners (distribute_sparsity_pattern below)
    dealii::DynamicSparsityPattern dsp(relevant);
    Vector                         touched_dofs;
    space.reinit_vector(touched_dofs);
    std::vector<unsigned char> cell_active(grid.cells.size(), 0);
    std::vector<dealii::types::global_dof_index> cols;

    auto sink = [&](const unsigned int c, const typename K::Cell &cell, const auto &touched, const auto &pairs) {
      cell_active[c] = 1;
      for (unsigned int a = 0; a < K::n_nodes; ++a)
        {
          if (!touched[a])
            continue;
          const unsigned int ga = cell.dofs[a * dim];
          cols.clear();
          for (unsigned int b = 0; b < K::n_nodes; ++b)
            if (pairs[a * K::n_nodes + b])
              for (unsigned int k = 0; k < nc; ++k)
                cols.push_back(space.node_dof(cell.dofs[b * dim], k));
          std::sort(cols.begin(), cols.end());
          for (unsigned int k = 0; k < nc; ++k)
            {
              const auto row = space.node_dof(ga, k);
              touched_dofs(row) = 1.0;
              dsp.add_entries(row, cols.begin(), cols.end(), true);
            }
        }
    };
    for (auto *set : sets)
      {
        transfer::CollectCouplings<dim, K, decltype(sink)> op(grid, sink);
        transfer::for_each_active_cell(*set, op);
      }

    // a DoF is active if a point of any rank touches it
    touched_dofs.compress(dealii::VectorOperation::add);
    touched_dofs.update_ghost_values();
    std::vector<dealii::types::global_dof_index> act;
    const unsigned int n_local = space.partitioner()->locally_owned_size() + space.partitioner()->n_ghost_indices();
    for (unsigned int l = 0; l < n_local; ++l)
      if (touched_dofs.local_element(l) > 0)
        act.push_back(space.partitioner()->local_to_global(l));
    std::sort(act.begin(), act.end());
    active_relevant = dealii::IndexSet(space.dof_handler().n_dofs());
    active_relevant.add_indices(act.begin(), act.end());
    active_relevant.compress();
    active_owned = active_relevant & owned;
    n_active_global = dealii::Utilities::MPI::sum<unsigned long long>(active_owned.n_elements(), grid.comm);

    active_cells.clear();
    for (unsigned int c = 0; c < cell_active.size(); ++c)
      if (cell_active[c])
        active_cells.push_back(c);

    const unsigned int n_grid_local = grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    active_node.assign(n_grid_local, 0);
    for (unsigned int i = 0; i < n_grid_local; ++i)
      {
        const auto g = space.node_dof(i, 0);
        if (g != dealii::numbers::invalid_dof_index && active_relevant.is_element(g))
          active_node[i] = 1;
      }

    inactive.clear();
    inactive.reinit(relevant);
    for (const auto i : relevant)
      if (!active_relevant.is_element(i))
        inactive.add_line(i);
    inactive.close();

    // every owned row has its diagonal (an inactive row nothing else)
    for (const auto i : owned)
      dsp.add(i, i);
    dealii::SparsityTools::distribute_sparsity_pattern(dsp, owned, grid.comm, relevant);
    pattern->reinit(owned, owned, dsp, grid.comm);
  }

  template <int dim>
  dealii::AffineConstraints<double>
  ActiveSet<dim>::constraints_with(const dealii::AffineConstraints<double> &dirichlet) const
  {
    dealii::AffineConstraints<double> c;
    c.reinit(space.locally_relevant_dofs());
    for (const auto i : space.locally_relevant_dofs())
      if (!active_relevant.is_element(i))
        c.add_line(i);
      else if (dirichlet.is_constrained(i))
        {
          c.add_line(i);
          if (const auto *entries = dirichlet.get_constraint_entries(i))
            c.add_entries(i, *entries);
          c.set_inhomogeneity(i, dirichlet.get_inhomogeneity(i));
        }
    c.close();
    return c;
  }

  template <int dim>
  void
  ActiveSet<dim>::reinit_matrix(dealii::TrilinosWrappers::SparseMatrix &A) const
  {
    A.reinit(*pattern);
  }

  template class NodalSpace<2>;
  template class NodalSpace<3>;
  template class ActiveSet<2>;
  template class ActiveSet<3>;
  template void ActiveSet<2>::reinit<shape::Q1Box<2>>(const std::vector<MaterialPointSet<2> *> &);
  template void ActiveSet<3>::reinit<shape::Q1Box<3>>(const std::vector<MaterialPointSet<3> *> &);
  template void ActiveSet<2>::reinit<shape::BSpline2Box<2>>(const std::vector<MaterialPointSet<2> *> &);
  template void ActiveSet<3>::reinit<shape::BSpline2Box<3>>(const std::vector<MaterialPointSet<3> *> &);
} // namespace talus
