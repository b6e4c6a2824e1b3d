// talus — kinematic conditions of the grid's walls, shared by every family
// (seed 000 §5.1): the scene's (or a stage's) 'boundary conditions' (fixed: all
// velocity components zero; roller: the normal one) become a flag per local DoF
// of the grid's vector space (the explicit nodal solve and the semi-implicit
// velocity updates skip flagged DoFs), and for the implicit families the same
// DoFs as homogeneous constraints on a NodalSpace (the increment is zero there).
// Prescribed velocities on grid nodes (a boundary id or a region of the
// 'loads/velocity k' conditions) become a list of (DoF, condition, component)
// here too; their time functions and how a family enforces them (the explicit
// a = (vbar - v^t)/h, an implicit increment constraint) stay with the family.
// Explicit-only loads (damping, mass scaling, convergence, wall friction)
// stay in the explicit family (formulations/explicit/load_control).
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/loads/settings.h>

#include <deal.II/lac/affine_constraints.h>

#include <vector>

namespace talus::loads
{
  /// One velocity component of a grid node prescribed by a condition.
  struct PrescribedNodeDof
  {
    unsigned int dof;       ///< local DoF of the grid's vector space
    unsigned int node;      ///< local DoF of the node's x component (NodalSpace::node_dof)
    unsigned int condition; ///< index into the condition list given
    unsigned int component; ///< velocity component
  };

  /// Per local DoF (owned + ghost) of the grid's vector space a flag: 1 if its
  /// velocity component is prescribed zero by one of the conditions. Throws
  /// InputError naming 'boundary conditions' for a boundary id the grid lacks.
  template <int dim>
  std::vector<unsigned char> wall_dof_flags(const BackgroundGrid<dim> &grid, const std::vector<BoundaryCondition> &bcs);

  /// The flagged DoFs as homogeneous constraints on `space` (a vector space on
  /// the grid's triangulation, whose node_dof maps the grid's DoFs), closed.
  /// With `prescribed` (from prescribed_node_dofs with owned_only = false)
  /// their DoFs get lines too (a DoF both on a wall and prescribed: the
  /// prescribed line), homogeneous, or with `values` (one per entry of
  /// `prescribed`) those inhomogeneities: the first solve of a step lifts the
  /// prescribed increment into the right-hand side, the corrections after it
  /// are homogeneous.
  template <int dim>
  dealii::AffineConstraints<double>
  wall_constraints(const BackgroundGrid<dim> &grid, const NodalSpace<dim> &space,
                   const std::vector<unsigned char> &flags, const std::vector<PrescribedNodeDof> *prescribed = nullptr,
                   const std::vector<double>                          *values  = nullptr,
                   const std::vector<dealii::types::global_dof_index> *contact = nullptr);

  /// One grid node of a unilateral contact wall (talus-implicit's 'boundary
  /// conditions/contact'): the node (local DoF of its component 0 in the grid's
  /// vector space, as PrescribedNodeDof::node), the axis of the wall's normal
  /// and the sign of the outward normal (-1 on a min face, +1 on a max face).
  struct ContactNode
  {
    unsigned int node;
    unsigned int axis;
    int          sign;
    double       wall; ///< the wall's coordinate along `axis`
  };

  /// The nodes (owned and ghost) of the box grid's faces with one of the boundary
  /// ids `ids`, each once; a node whose normal DoF is already flagged in
  /// `wall_flags` (fixed/roller walls: they win at shared corners) is left out.
  /// Throws InputError naming 'boundary conditions/contact' for an id the grid lacks.
  template <int dim>
  std::vector<ContactNode> contact_wall_nodes(const BackgroundGrid<dim>                     &grid,
                                              const std::vector<dealii::types::boundary_id> &ids,
                                              const std::vector<unsigned char>              &wall_flags);

  /// The node DoFs reached by the grid-node conditions of `conditions` (target
  /// boundary: the nodes of the faces with that id; region: the nodes inside
  /// the box, with a tolerance of 1e-9 cell sizes): the owned ones, or with
  /// `owned_only = false` all locally relevant ones (constraints of a
  /// distributed assembly must be known on the ghosts too). Body conditions
  /// (on material points) are skipped. Each node is listed once per condition.
  template <int dim>
  std::vector<PrescribedNodeDof> prescribed_node_dofs(const BackgroundGrid<dim>                  &grid,
                                                      const std::vector<PrescribedVelocity<dim>> &conditions,
                                                      const bool                                  owned_only = true);
} // namespace talus::loads
