// talus — the active region of the implicit families on a NodalSpace.
//
// ActiveSet: what the material points of one or more sets touch through a
// kernel's per-point stencil (Q1: the cell's 2^dim vertices; quadratic
// B-spline: the point's 3^dim window of the cell's patch). A DoF is active if
// some point's shape value or gradient at it is non-zero; inactive DoFs are
// pinned to zero. The Trilinos sparsity couples the DoFs of nodes that share a
// point's stencil (all components with all components), plus the diagonal of
// every row; so an inactive row holds its diagonal only.
//
// A family that keeps the pattern over several steps (the semi-implicit
// pressure) asks `couplings_covered` whether the points still couple only node
// pairs the pattern holds: a point can shift its B-spline window inside its
// cell (a half-cell line) without changing the set of cells.
//
// It lives in transfer/, not next to NodalSpace in grid/: it is found by a walk
// over point sets (transfer::CollectCouplings on the cell walk, kernel stencils),
// so it depends on particles/, shape/ and transfer/, which themselves build on
// grid/.
#pragma once

#include <talus/grid/nodal_space.h>

#include <deal.II/base/index_set.h>
#include <deal.II/lac/affine_constraints.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace dealii
{
  class DynamicSparsityPattern;
}
namespace dealii::TrilinosWrappers
{
  class SparseMatrix;
  class SparsityPattern;
} // namespace dealii::TrilinosWrappers

namespace talus
{
  template <int dim>
  class MaterialPointSet;

  template <int dim>
  class ActiveSet
  {
  public:
    using size_type = dealii::types::global_dof_index;

    explicit ActiveSet(const NodalSpace<dim> &space);
    ~ActiveSet();

    /// Whether reinit records the node couplings for couplings_covered (and
    /// exchanges them between ranks): only a caller that keeps the pattern
    /// over later steps needs them.
    enum class Couplings
    {
      skip,
      record
    };

    /// Which node pairs the assembly couples: those that share a point, or
    /// (cell) every pair of nodes that the points of one cell touch, for
    /// assemblies with cell terms (the PPP cell means of mixed u-p, the cell
    /// mean of F-bar): with the B-spline, two points of a cell touch different
    /// 3^dim windows of its 4^dim patch.
    enum class Reach
    {
      point,
      cell
    };

    /// Couplings an assembly adds beyond the points' stencils (the ghost
    /// penalty's face terms): called with the pattern's rows (the locally
    /// relevant DoFs) once the active DoFs are known. Collective.
    using ExtraCouplings = std::function<void(dealii::DynamicSparsityPattern &)>;

    /// The active region of the points of `sets` (one pass over each) with the
    /// stencil of kernel K (shape::Q1Box<dim> or shape::BSpline2Box<dim>; the
    /// latter needs grid.setup_bspline_patches()), its sparsity with `reach`
    /// and `extra`. Collective.
    template <class K>
    void reinit(const std::vector<MaterialPointSet<dim> *> &sets, Couplings couplings = Couplings::skip,
                Reach reach = Reach::point, const ExtraCouplings &extra = {});

    /// Whether every point of `sets` on this rank couples only node pairs that
    /// the points (of any rank) coupled at the last reinit<K> (with
    /// Couplings::record; false after any other reinit), so that the kept
    /// sparsity and active DoFs still hold its couplings, and lies in a cell
    /// that held points then. reinit ORs each node's couplings over the ranks
    /// that hold the node, so the answer does not depend on the partition.
    /// Pairs are named by lattice offset: the grid must be a uniform box for
    /// the B-spline (as setup_bspline_patches requires); for Q1 every point
    /// touches its whole cell. One pass over the points, stencils only; not
    /// collective (combine the answers over ranks).
    template <class K>
    bool couplings_covered(const std::vector<MaterialPointSet<dim> *> &sets) const;

    /// Locally owned cells holding points of any set (active_cell_index, ascending).
    const std::vector<unsigned int> &
    cells() const
    {
      return active_cells;
    }
    /// Active DoFs among the owned and among the relevant ones.
    const dealii::IndexSet &
    active_owned_dofs() const
    {
      return active_owned;
    }
    const dealii::IndexSet &
    active_relevant_dofs() const
    {
      return active_relevant;
    }
    /// Whether a locally relevant DoF is active.
    bool
    is_active(const size_type i) const
    {
      return active_relevant.is_element(i);
    }
    size_type
    n_active_dofs() const
    {
      return n_active_global;
    }

    /// Inactive relevant DoFs pinned to zero (closed).
    const dealii::AffineConstraints<double> &
    constraints() const
    {
      return inactive;
    }
    /// The inactive constraints together with Dirichlet constraints (e.g. from
    /// NodalSpace::constraints_where). Where both constrain a DoF the pin to zero
    /// wins: no point sees an inactive node's value. The sparsity fits any such
    /// merge whose Dirichlet lines do not couple DoFs (fixed values, rollers).
    dealii::AffineConstraints<double> constraints_with(const dealii::AffineConstraints<double> &dirichlet) const;

    /// The pattern over the active region (owned rows, compressed).
    const dealii::TrilinosWrappers::SparsityPattern &
    sparsity() const
    {
      return *pattern;
    }
    void reinit_matrix(dealii::TrilinosWrappers::SparseMatrix &A) const;

    /// For transfer ops: per grid local index (component-0 DoF of a node) whether
    /// the node is active.
    bool
    node_active(const unsigned int grid_local) const
    {
      return active_node[grid_local] != 0;
    }

    const NodalSpace<dim> &space;

  private:
    std::vector<unsigned int>                                  active_cells;
    std::vector<unsigned char>                                 active_node;
    dealii::IndexSet                                           active_owned, active_relevant;
    size_type                                                  n_active_global = 0;
    dealii::AffineConstraints<double>                          inactive;
    std::unique_ptr<dealii::TrilinosWrappers::SparsityPattern> pattern;
    /// Per cell whether points held it at the last reinit (active_cells are
    /// the owned ones among them).
    std::vector<unsigned char> cell_holds_points;
    /// What reinit recorded for couplings_covered (Couplings::record): per node
    /// (grid local index) the neighbours the points of any rank coupled it to,
    /// as bits over the lattice offsets (within one stencil) from it;
    /// recorded_kernel_nodes the kernel's stencil size, 0 when not recorded.
    std::vector<std::uint64_t> node_neighbours;
    unsigned int               recorded_kernel_nodes = 0;
  };
} // namespace talus
