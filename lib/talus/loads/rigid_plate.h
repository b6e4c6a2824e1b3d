// talus — the rigid plate (issue 37), one vocabulary for every family: a set of
// grid nodes (the nodes of a boundary id, or the nodes inside a region box)
// that moves as one rigid body along one grid axis. Either a total force drives
// it (its displacement is an unknown of the problem) or a displacement history
// does (its reaction is the answer). Frictionless: the other velocity
// components of its nodes are free; rough: they are held at zero. In the
// two-phase families the plate is permeable (p = 0 at its nodes) or
// impermeable (no relative water flux through it).
//
// This header holds what is the same in every family: the settings, their
// declaration and parsing ('boundary conditions/rigid plate k'), the nodes a
// plate holds and the series.csv columns. How a family enforces the plate
// (explicit: the plate velocity from the momentum balance of its nodes;
// implicit: one master DoF in the Newton system; semi-implicit: the momentum
// and pressure steps) stays with the family.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/loads/settings.h>
#include <talus/loads/time_function.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <string>
#include <vector>

namespace talus::loads
{
  struct PrescribedNodeDof; // loads/kinematics.h

  template <int dim>
  struct RigidPlate
  {
    enum class Target
    {
      boundary, ///< the grid nodes of the faces with `boundary`
      region    ///< the grid nodes inside the box [lower, upper]
    };
    enum class Control
    {
      force,       ///< total force given, displacement unknown
      displacement ///< displacement history given, reaction reported
    };
    Target                     target   = Target::boundary;
    dealii::types::boundary_id boundary = 0;
    dealii::Point<dim>         lower, upper;
    unsigned int               axis    = dim - 1; ///< the plate moves along this grid axis
    bool                       rough   = false;   ///< tangential components held (else free)
    Control                    control = Control::force;
    /// force control: the force the plate exerts on the material along +axis
    /// [N; per unit thickness in 2D] at f = 1 (e.g. -1e4 with axis y pushes down)
    double force = 0;
    /// displacement control: the plate's displacement along +axis [m] at f = 1
    double       displacement = 0;
    TimeFunction function; ///< f(t), absolute time
    /// two-phase families: the pore water drains through the plate (p = 0 at
    /// its nodes); false: no water crosses it relative to the plate
    bool        permeable = false;
    std::string where; ///< 'boundary conditions/rigid plate k'

    double
    force_at(const double t) const
    {
      return force * function.value(t);
    }
    double
    displacement_at(const double t) const
    {
      return displacement * function.value(t);
    }
    /// The plate's nodes as a grid-node velocity condition (the `axis`
    /// component; every component if rough), for prescribed_node_dofs.
    PrescribedVelocity<dim> node_condition() const;
  };

  /// Declare 'number of rigid plates' and the 'rigid plate k' subsections in
  /// the current subsection ('boundary conditions'); `n` from peek_rigid_plates.
  void declare_rigid_plate_parameters(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n);
  /// 'boundary conditions/number of rigid plates' read from the file before the declaration.
  unsigned int peek_rigid_plates(const std::string &prm_file);
  /// Parse the plates in the current subsection ('boundary conditions').
  /// InputError naming the entry: a box-grid boundary id that does not exist
  /// (`box_grid`; a grid file's ids are checked by check_scene_consistency),
  /// an empty region, both a force and a displacement, neither.
  template <int dim>
  std::vector<RigidPlate<dim>> parse_rigid_plate_parameters(dealii::ParameterHandler &prm, bool box_grid);

  /// The DoFs (grid vector space) of every plate's nodes, per plate in
  /// `PrescribedNodeDof::condition`: owned ones, or with owned_only = false all
  /// locally relevant ones.
  template <int dim>
  std::vector<PrescribedNodeDof> rigid_plate_node_dofs(const BackgroundGrid<dim>          &grid,
                                                       const std::vector<RigidPlate<dim>> &plates,
                                                       bool                                owned_only = true);

  /// The series.csv columns of the plates: plate_k_displacement (along its
  /// axis [m]), plate_k_force (the force the plate exerts on the material along
  /// its axis [N], given or reaction) and, for a rough plate,
  /// plate_k_tangential_force (the magnitude of the tangential reaction [N]).
  template <int dim>
  std::vector<std::string> rigid_plate_series_columns(const std::vector<RigidPlate<dim>> &plates);

  /// The checks of a box grid (grid/source = box: lower, upper, cells; face
  /// ids 2 d and 2 d + 1 the lower and upper faces normal to axis d) that need
  /// no grid, so that --check finds them: InputError naming the plate when a
  /// region plate contains no grid node, or when the fixed/roller walls hold
  /// the plate's axis component at every node it holds (a wall keeps the
  /// components it holds). A family checks the same on its grid at setup.
  template <int dim>
  void check_rigid_plates_on_box(const std::vector<RigidPlate<dim>> &plates, const dealii::Point<dim> &lower,
                                 const dealii::Point<dim> &upper, const std::vector<unsigned int> &cells,
                                 const std::vector<BoundaryCondition> &walls);

  /// InputError naming the first plate unless `plates` is empty: for a family
  /// (`tool`) that cannot honour a rigid plate, with `reason`.
  template <int dim>
  void refuse_rigid_plates(const std::vector<RigidPlate<dim>> &plates, const std::string &tool,
                           const std::string &reason);
} // namespace talus::loads
