// talus — the shared boundary conditions and loads in talus-semi-implicit
// (issue 37): the tractions of 'loads/traction k' (body face and region:
// point forces of the soil points through loads::PointForces, entering the
// grid at the body surface; boundary: nodal forces on the grid face), the
// prescribed velocities of 'loads/velocity k' on grid nodes (the soil's
// velocity in the predictor, the correction and the remap; the water's too
// unless the node drains) and the drainage conditions of
// 'boundary conditions/drainage k' (loads/drainage.h) with the pressure row of
// every node. The Solver (semi_implicit_solver.h) calls the hooks below at fixed
// places of its step; docs/semi-implicit.md 'Boundary conditions and loads'.
#pragma once

#include <talus/formulations/semi_implicit/semi_implicit.h>
#include <talus/grid/background_grid.h>
#include <talus/loads/drainage.h>
#include <talus/loads/point_forces.h>
#include <talus/loads/settings.h>
#include <talus/particles/material_point_set.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/base/parameter_handler.h>

#include <mpi.h>

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace talus::semi_implicit
{
  /// Declare 'loads' (tractions and velocity conditions, the shared
  /// vocabulary), 'boundary conditions/drainage k' and 'semi implicit/traction
  /// acts at'.
  void declare_boundary_load_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, unsigned int dim);
  /// Parse them into p.tractions, p.velocities, p.drainage (appended to the
  /// drained boundaries of the alias) and p.traction_at_surface, with the
  /// checks of this family (InputError naming the entry): a traction on a body
  /// without soil points or on a file body's face, a velocity condition on
  /// material points, ids the box grid lacks, regions outside the grid.
  template <int dim>
  void parse_boundary_load_parameters(dealii::ParameterHandler &prm, Parameters<dim> &p);

  template <int dim>
  class BoundaryLoads
  {
  public:
    static constexpr unsigned int none = static_cast<unsigned int>(-1);

    BoundaryLoads(const Parameters<dim> &prm, const BackgroundGrid<dim> &grid, MPI_Comm comm);

    /// setup: the point-force slots of the point tractions on the soil layout;
    /// `offset_field`: the soil's dim values from a point to its share of the
    /// loaded face.
    void extend_layout(PropertyLayout<dim> &layout, unsigned int offset_field);
    /// setup, after seeding (not at a restart: the points carry it): each
    /// loaded soil point's force share and face offset; the checks that need
    /// the points (a traction that selects no point, a boundary traction whose
    /// face no soil point is near). Logs one line per traction. Collective.
    void assign(MaterialPointSet<dim> &soil, const std::vector<BodyDescription<dim>> &bodies);
    /// grid_changed: the per-DoF and per-node flags (prescribed velocities,
    /// the water's components freed at a drained or pressure boundary, the
    /// drainage state of every node, the nodes of the boundary tractions);
    /// clears the water's wall hold where a boundary drains. Checks (first
    /// call) that every velocity condition holds a node.
    void grid_changed(const std::vector<unsigned int> &node_of, const std::vector<unsigned char> &component,
                      const std::vector<dealii::Point<dim>> &node_x, std::vector<unsigned char> &water_constrained);
    /// The log lines of the conditions.
    void describe(std::ostream &out) const;

    /// Start of a step over [t, t + h]: time factors (tractions at mid-step,
    /// velocities and pressures at t + h), the loaded-node marker cleared.
    void begin_step(double t, double h);

    /// Soil P2N, per point: its traction force into `f` (a grid vector field)
    /// at the body surface (the point + its offset) or at the point, and the
    /// nodes of its own stencil marked as loaded.
    template <class K>
    void
    scatter_point_traction(const unsigned int c, const dealii::Point<dim> &x, const double *P,
                           const transfer::PointStencil<dim, K> &s, transfer::PointStencil<dim, K> &surface, double *f)
    {
      if (point_forces.n_slots() == 0)
        return;
      double force[dim];
      if (!point_forces.force_if_loaded(P, force))
        return;
      s.scatter(loaded.begin(), 1.0);
      if (at_surface)
        {
          transfer::offset_stencil<dim, K>(grid, c, x, P + offset_field, surface);
          surface.scatter_vector(f, 1.0, force);
        }
      else
        s.scatter_vector(f, 1.0, force);
    }
    /// After the soil P2N's exchange: the loaded-node marker exchanged; the
    /// boundary tractions' nodal forces added to Fs (owned and ghost entries)
    /// at their face nodes that carry soil (mass above ms_cut).
    void add_boundary_tractions(Vector &Fs, const Vector &Ms, double ms_cut);
    /// Whether the points carry face offsets (moved with dF by the update).
    bool
    carries_offsets() const
    {
      return at_surface && point_forces.n_slots() > 0;
    }

    /// Predictor at local DoF i: a prescribed component moves the soil with
    /// its value; the water too, unless the node drains at this component (then
    /// its own row with the drag to the soil's velocity).
    void
    predictor(const unsigned int i, const bool has_soil, const bool has_water, const double Mw, const double Q,
              const double h, const double rhs_w, double &vs, double &vw) const
    {
      const unsigned int k = velocity_of.empty() ? none : velocity_of[i];
      if (k == none)
        return;
      const double V = velocity_value[i];
      vs             = V;
      if (!water_free[i])
        vw = has_water ? V : 0.0;
      else if (has_soil && has_water)
        vw = (rhs_w + h * Q * V) / (Mw + h * Q);
    }
    /// Correction at local DoF i (the same rule: the soil with the value, the
    /// water too where it does not drain).
    void
    correct(const unsigned int i, const double Mw, double &vs, double &vw) const
    {
      if (velocity_of.empty() || velocity_of[i] == none)
        return;
      vs = velocity_value[i];
      if (!water_free[i])
        vw = Mw > 0 ? velocity_value[i] : 0.0;
    }
    /// Whether local DoF i has a prescribed velocity.
    bool
    prescribed(const unsigned int i) const
    {
      return !velocity_of.empty() && velocity_of[i] != none;
    }
    /// MUSL remap at local DoF i: the prescribed value (as the walls' zero, A11).
    void
    remap(const unsigned int i, double &vs) const
    {
      if (!velocity_of.empty() && velocity_of[i] != none)
        vs = velocity_value[i];
    }
    /// The reaction of every velocity condition per component: the sum of
    /// `residual(i)` (the mixture's momentum residual of DoF i, the force the
    /// condition exerts on the material) over its owned DoFs. Collective.
    void reactions(const std::function<double(unsigned int)> &residual);

    /// The pressure row of the node of local DoF i (component 0): whether it
    /// is a Dirichlet row, and its increment dp. Replaces the free-surface
    /// rule (A6) with the drainage conditions and the sealing of loaded faces
    /// (docs/semi-implicit.md 'Boundary conditions and loads').
    /// Counts the Dirichlet rows of nodes with water (the pressure's references).
    std::pair<bool, double> pressure_row(unsigned int i, bool has_water, bool plate_drained, bool plate_sealed,
                                         double wet, double dry, double near_wet, double p);
    /// After the Dirichlet rows are made: if no rank has a Dirichlet row at a
    /// node with water and a condition of this file can seal the water (a
    /// loaded face, a prescribed velocity, an impermeable drainage), an
    /// InputError naming it: the pressure has no reference. Collective.
    void check_pressure_reference() const;
    /// Whether the node of local DoF i (component 0) is a node of a sealed
    /// surface (the same arguments as pressure_row): a solved free-surface
    /// node, or a dry node next to the water, whose surface is impermeable by a
    /// region's condition or by a load; a node inside the water (no dry cell)
    /// that a load reaches or an impermeable region holds is a candidate, a
    /// node of the seal where it shares a cell with a sealed surface node. The Solver gives these the surface
    /// term of the pore pressure (docs/semi-implicit.md 'A sealed surface').
    bool sealed_surface(unsigned int i, bool has_water, bool plate_drained, bool plate_sealed, double wet, double dry,
                        double near_wet) const;
    /// Whether this file can seal a surface at all (a traction, or a region's
    /// impermeable drainage); without, no node is ever sealed_surface.
    bool may_seal_surface() const;

    /// series.csv: the reactions of the velocity conditions
    /// (velocity_k_reaction_x, ... of their prescribed components).
    std::vector<std::string> series_columns() const;
    void                     series_values(std::vector<double> &v) const;
    /// For load_settlement: the point's full traction force dotted with its
    /// displacement and the force's size (0, 0 for an unloaded point).
    void settlement_weights(const double *P, double &force_dot_u, double &force) const;

  private:
    struct Row
    {
      bool   dirichlet; ///< a Dirichlet row with the increment dp
      double dp;
      bool   sealed; ///< solved, a node of a sealed surface
    };
    Row decide_row(unsigned int i, bool has_water, bool plate_drained, bool plate_sealed, double wet, double dry,
                   double near_wet, double p) const;

    const Parameters<dim>     &prm;
    const BackgroundGrid<dim> &grid;
    MPI_Comm                   comm;
    loads::PointForces<dim>    point_forces;
    unsigned int               offset_field = 0;
    bool                       at_surface   = true;
    double                     time_end     = 0; ///< t + h of the step

    // per local DoF: the velocity condition (none), its value over the step,
    // whether the water's component is free there (a draining boundary)
    std::vector<unsigned int>  velocity_of;
    std::vector<double>        velocity_value;
    std::vector<unsigned char> water_free;
    std::vector<unsigned char> dof_component; ///< the component of a local DoF
    // per node (component-0 DoF): the drainage condition of the boundary
    // kind (every water node) and of the region kind (surface nodes), none
    std::vector<unsigned int> drain_all, drain_surface;
    // boundary tractions: (local DoF, its node, traction, force at f = 1:
    // the component x the node's share of the face)
    struct NodalTraction
    {
      unsigned int dof, node, traction;
      double       force;
    };
    std::vector<NodalTraction> nodal_tractions;
    std::vector<double>        traction_factor; ///< per traction at mid-step
    Vector                     loaded;          ///< per node: > 0 reached by a loaded point or face
    std::vector<double>        reaction;        ///< per condition and component
    bool                       nodes_checked = false;
    unsigned int               n_water_rows  = 0; ///< this step's Dirichlet rows at nodes with water
  };
} // namespace talus::semi_implicit
