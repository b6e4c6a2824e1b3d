// talus — .prm settings of loads, boundary friction, prescribed velocities,
// local damping, quasi-static convergence, mass scaling and staged calculations of the explicit solver (seed 000 §4.3.2, §5.2, §6.2,
// §6.3-§6.5). Pure data plus declaration/parsing; the run-time logic is in
// formulations/explicit/load_control.h.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/loads/time_function.h>
#include <talus/particles/material_points.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace talus::loads
{
  /// A surface traction carried by the boundary material points of a face
  /// (seed 000 Eqs. 4.28-4.29, 5.1-5.3), or by the grid nodes of a boundary id.
  template <int dim>
  struct Traction
  {
    enum class Target
    {
      body_face, ///< the outermost layer of points of a box body on one face
      region,    ///< the points whose initial position lies in a box region
      boundary,  ///< the grid nodes of the faces with `boundary` (nodal forces; not every family)
      point      ///< 'loads/point load k': the one material point nearest `position` carries `traction` (a force)
    };
    /// point: any body's points are candidates
    static constexpr unsigned int any_body = static_cast<unsigned int>(-1);
    Target                        target   = Target::body_face;
    dealii::types::boundary_id    boundary = 0;       ///< apply to = boundary
    unsigned int                  body     = 0;       ///< body face; point: the candidates' body or any_body
    unsigned int                  axis     = dim - 1; ///< normal axis of the face
    int                           side     = +1;      ///< +1: upper face, -1: lower face
    dealii::Point<dim>            lower, upper;       ///< region
    dealii::Point<dim>            position;           ///< point: where the user put it
    dealii::Tensor<1, dim> traction; ///< [Pa] (force per area); with `total` (always for a point): the resultant [N]
    bool                   total = false; ///< `traction` is the resultant over the selected points
    /// 'pressure centre' given (2D, region): a pressure `pressure` [Pa] on the
    /// arc of the circle (centre, radius) inside the region box, carried by the
    /// points within one point spacing of the circle, along the radial unit
    /// vector from the centre (docs/boundary-conditions.md, "Pressure on a circle")
    bool               radial = false;
    dealii::Point<dim> centre;
    double             radius   = 0;
    double             pressure = 0;
    /// the arc of the circle inside the region box: start angle [rad] (from the
    /// centre, atan2 convention) and angular length (2 pi: the whole circle)
    double       arc_start = 0, arc_span = 0;
    TimeFunction function;
    std::string  where;
  };

  /// Prescribed velocity on grid nodes (boundary id or region) or on the
  /// material points of a body, per component.
  template <int dim>
  struct PrescribedVelocity
  {
    enum class Target
    {
      boundary,
      region,
      body
    };
    Target                     target   = Target::boundary;
    dealii::types::boundary_id boundary = 0;
    dealii::Point<dim>         lower, upper;
    unsigned int               body = 0;
    bool                       component[dim];
    dealii::Tensor<1, dim>     velocity;
    TimeFunction               function;
    std::string                where;
  };

  struct Convergence
  {
    bool         enabled          = false;
    double       force_tolerance  = 1e-3; ///< F = |f_ext - f_int| / |f_ext| (Eq. 6.29)
    double       energy_tolerance = 1e-5; ///< E = KE / W_ext (Eq. 6.30)
    unsigned int interval         = 10;   ///< steps between evaluations
    bool         end_stage        = true;
  };

  template <int dim>
  struct Stage
  {
    std::string                             name;
    double                                  duration = 1.0;
    dealii::Tensor<1, dim>                  gravity;
    std::vector<BoundaryCondition>          boundary_conditions;
    std::vector<dealii::types::boundary_id> friction_ids;
    double                                  friction_coefficient = 0, adhesion = 0;
    std::vector<Traction<dim>>              tractions; ///< stage loads (stage time)
    std::vector<PrescribedVelocity<dim>>    velocities;
    double                                  damping         = 0; ///< local damping alpha
    double                                  viscous_damping = 0; ///< mass-proportional alpha_v [1/s]
    double                                  mass_scaling    = 1; ///< beta
    Convergence                             convergence;
    /// number of leading tractions/velocities that are global loads (top-level
    /// 'loads', evaluated at the absolute time); the rest use the stage time
    unsigned int n_global_tractions = 0, n_global_velocities = 0;
  };

  template <int dim>
  struct Settings
  {
    bool                    staged = false;
    std::vector<Stage<dim>> stages;            ///< at least one
    unsigned int            max_tractions = 0; ///< point-force slots needed per material point

    /// Whether the run needs the load controller (false: the solver runs its
    /// plain single-stage loop and nothing here costs anything).
    bool active() const;
  };

  /// Declare the entries (loads with point loads, damping, mass scaling,
  /// convergence, friction in 'boundary conditions', stages). 'body k/initial
  /// stress' is the scene's (formulations/common/initial_stress.h).
  void declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, unsigned int dim);

  /// Only the 'loads' subsection with its 'traction k' and 'point load k'
  /// entries and, with `with_velocities`, its 'velocity k' conditions
  /// (families without stages or damping: talus-implicit).
  void declare_traction_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, unsigned int dim,
                                   bool with_velocities = false);
  /// InputError naming 'loads/traction k/apply to' of the first traction on a
  /// grid boundary id, for a family (`tool`) that applies tractions through
  /// material points only, with `reason`.
  template <int dim>
  void refuse_boundary_tractions(const std::vector<Traction<dim>> &tractions, const std::string &tool,
                                 const std::string &reason);

  /// The tractions of declare_traction_parameters (global loads, absolute
  /// time), the point loads after them (Target::point; a position outside the
  /// grid [grid_lower, grid_upper] is an InputError) and, if `velocities` is
  /// given, the velocity conditions.
  template <int dim>
  std::vector<Traction<dim>>
  parse_traction_parameters(dealii::ParameterHandler &prm, const std::vector<BodyDescription<dim>> &bodies,
                            const dealii::Point<dim> &grid_lower, const dealii::Point<dim> &grid_upper,
                            std::vector<PrescribedVelocity<dim>> *velocities = nullptr);

  /// 'number of stages' and the 'stage k' subsections: name, duration, gravity,
  /// fixed/roller boundaries and the stage's own loads; `explicit_entries`
  /// adds the friction boundaries and the explicit family's switches (local and
  /// viscous damping, mass scaling, quasi-static convergence);
  /// `family_entries(prm)`, if given, declares a family's own entries inside
  /// every 'stage k'.
  void declare_stage_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, unsigned int dim,
                                bool                                                   explicit_entries,
                                const std::function<void(dealii::ParameterHandler &)> &family_entries = {});
  /// The 'stage k' subsections of declare_stage_parameters (empty when 'number
  /// of stages' is 0). `top`: the top-level stage, whose entries 'inherit' and
  /// -1 stand for and whose loads stay on as global loads in every stage.
  template <int dim>
  std::vector<Stage<dim>> parse_stages(dealii::ParameterHandler &prm, const Stage<dim> &top,
                                       const std::vector<BodyDescription<dim>> &bodies, bool explicit_entries);

  /// Parse after the solver has read its own entries (end time, gravity, the
  /// fixed/roller boundaries, the bodies and the grid's extent, which are
  /// passed in). The point loads are global tractions after the top-level ones.
  template <int dim>
  Settings<dim> parse_parameters(dealii::ParameterHandler &prm, const double end_time,
                                 const dealii::Tensor<1, dim>            &gravity,
                                 const std::vector<BoundaryCondition>    &boundary_conditions,
                                 const std::vector<BodyDescription<dim>> &bodies, const dealii::Point<dim> &grid_lower,
                                 const dealii::Point<dim> &grid_upper);
} // namespace talus::loads
