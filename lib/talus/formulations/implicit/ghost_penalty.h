// talus — the ghost penalty of talus-implicit (linear shape functions).
//
// A grid cell at the edge of the material (its points cover part of it) has
// nodes that few points, or one, control: a point that crosses into an empty
// cell between two load steps leaves the new cell's far nodes free to cancel
// its stress, and the tangent is near-singular there. The ghost penalty (Burman
// 2010; for MPM, Coombs et al. 2020) ties such cells to their neighbours: on
// every grid face between two covered cells of which at least one is cut it
// adds
//     j(du, w) = gamma E h int_F [[grad du . n]] . [[grad w . n]] dF
// to the weak form, [[.]] the jump across the face, h the cell size normal to
// it, E the largest constrained modulus of the scene's materials, gamma
// 'implicit/ghost penalty'. It acts on the step's increment du (the grid is
// reset each step), is symmetric positive semi-definite, zero for a du that is
// linear across the face, and of the size gamma times a cell's stiffness.
//
// Covered cell: all its nodes are active. Cut cell: a covered cell with a node
// that also belongs to a grid cell holding no points. Both are read from node
// data (exchanged between ranks), so a ghost cell is classified as its owner
// classifies it. Each face is assembled once: by the rank of its lower cell
// when both are owned, else by the rank with the smaller subdomain id.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/transfer/active_set.h>

#include <deal.II/lac/affine_constraints.h>

#include <vector>

namespace dealii
{
  class DynamicSparsityPattern;
  namespace TrilinosWrappers
  {
    class SparseMatrix;
  }
} // namespace dealii

namespace talus
{
  template <int dim>
  class GhostPenalty
  {
  public:
    /// The faces of this step from the active set's node flags (call from the
    /// ActiveSet's ExtraCouplings, where the active nodes are known) and their
    /// node couplings added to `dsp` (displacement components, each with
    /// itself). Collective.
    void find_faces(const ActiveSet<dim> &active, const NodalSpace<dim> &space, dealii::DynamicSparsityPattern &dsp);

    /// r += G du and (tangent not null) tangent += G through `constraints`,
    /// G = the penalty's matrix with `stiffness` = gamma E. Compresses both.
    void assemble(const double stiffness, const NodalSpace<dim> &space,
                  const dealii::AffineConstraints<double> &constraints, const Vector &du,
                  dealii::TrilinosWrappers::SparseMatrix *tangent, Vector &residual) const;

    /// Faces this rank assembles / on all ranks (the latter from find_faces).
    unsigned int
    n_local_faces() const
    {
      return faces.size();
    }
    unsigned long long
    n_faces() const
    {
      return n_global_faces;
    }

  private:
    struct Face
    {
      unsigned int lower, upper; ///< cell indices (BackgroundGrid::cells)
      unsigned int direction;    ///< the axis normal to the face
    };
    std::vector<Face>  faces;
    unsigned long long n_global_faces = 0;

    static constexpr unsigned int n_vertices = 1u << dim;
    /// The face's nodes: the lower cell's vertices, then the upper cell's
    /// vertices beyond the face; grid local indices (component 0).
    static constexpr unsigned int n_nodes = n_vertices + n_vertices / 2;
    void face_nodes(const BackgroundGrid<dim> &grid, const Face &f, unsigned int (&nodes)[n_nodes]) const;
  };
} // namespace talus
