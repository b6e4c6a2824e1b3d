// talus — the nodal spaces of the implicit families (the active region of the
// points on one: transfer/active_set.h).
//
// NodalSpace: a Q1 nodal space of n components (n = dim: displacement/velocity;
// n = 1: e.g. pore pressure) on the BackgroundGrid's triangulation, with its own
// DoFHandler, index sets and vector partitioner, and the map from the nodes of
// a kernel's stencil (named by the grid's DoF of component 0, the index every
// kernel Cell carries) to this space's DoFs.
#pragma once

#include <talus/grid/background_grid.h>

#include <deal.II/base/index_set.h>
#include <deal.II/lac/affine_constraints.h>

#include <functional>
#include <memory>
#include <vector>

namespace talus
{
  template <int dim>
  class NodalSpace
  {
  public:
    using size_type = dealii::types::global_dof_index;

    /// A space of n_components Q1 fields on grid's triangulation; setup() after
    /// grid.setup() (and again after the grid changed).
    NodalSpace(const BackgroundGrid<dim> &grid, unsigned int n_components);

    /// Distribute DoFs, build the index sets, the partitioner and the node map.
    void setup();

    unsigned int
    n_components() const
    {
      return n_comp;
    }
    const dealii::DoFHandler<dim> &
    dof_handler() const
    {
      return dofs;
    }
    const dealii::IndexSet &
    locally_owned_dofs() const
    {
      return owned;
    }
    const dealii::IndexSet &
    locally_relevant_dofs() const
    {
      return relevant;
    }
    const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &
    partitioner() const
    {
      return part;
    }
    void
    reinit_vector(Vector &v) const
    {
      v.reinit(part);
    }

    /// Global DoF of component k at the node whose grid DoF of component 0 has
    /// the local (owned + ghost) index i: grid.cells[c].dofs[v * dim] or a
    /// B-spline patch's dofs[s * dim].
    size_type
    node_dof(const unsigned int i, const unsigned int k) const
    {
      return node_dofs[i * n_comp + k];
    }

    /// Position and component of the DoF with local (owned + ghost) index i.
    const dealii::Point<dim> &
    position(const unsigned int i) const
    {
      return positions[i];
    }
    unsigned int
    component(const unsigned int i) const
    {
      return components[i];
    }

    /// Constraints (on the locally relevant DoFs, closed) u_i = value for every
    /// DoF where `prescribed(x, component, value)` returns true: Dirichlet
    /// conditions and rollers given by node position.
    dealii::AffineConstraints<double>
    constraints_where(const std::function<bool(const dealii::Point<dim> &, unsigned int, double &)> &prescribed) const;

    /// Per component, the DoFs of that component (constant modes for ML AMG).
    std::vector<std::vector<bool>> constant_modes() const;

    const BackgroundGrid<dim> &grid;

  private:
    unsigned int                                               n_comp;
    dealii::FESystem<dim>                                      fe;
    dealii::DoFHandler<dim>                                    dofs;
    dealii::IndexSet                                           owned, relevant;
    std::shared_ptr<const dealii::Utilities::MPI::Partitioner> part;
    std::vector<size_type>                                     node_dofs; // by grid local index (comp 0)
    std::vector<dealii::Point<dim>>                            positions; // by local index
    std::vector<unsigned char>                                 components;
  };
} // namespace talus
