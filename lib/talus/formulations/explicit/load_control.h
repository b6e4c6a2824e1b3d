// talus — run-time side of loads, boundary friction, prescribed velocities,
// local damping, quasi-static convergence, mass scaling, K0 stresses and stages
// for the explicit solver. The solver calls the hooks below only when the
// controller exists (Settings::active()), so none of this costs anything when
// the features are off.
//
// Step with the controller (seed 000 §4.3.7 with §5.2, §6.2-§6.5):
//   P2G mass/force (fused, solver)
//   before_nodal_solve   traction point forces -> nodal f_trac (Eq. 5.3); nodal
//                        momentum at t when friction/prescribed/damping need v_i^t
//   nodal_forces         f = f_grav + f_trac - f_int; convergence ratios (6.29,
//                        6.30) every 'check interval' steps; local damping
//                        f += -alpha |f| sign(v^t) (6.23); f /= beta (6.31)
//   a = f / m (solver)
//   nodal_accelerations  prescribed node velocities a = (vbar - v^t)/dt;
//                        friction nodes: predictor v* = v^t + dt a, rigid-wall
//                        form of Eqs. 6.4-6.21, a = (v~ - v^t)/dt
//   G2P velocity, P2G momentum (solver)
//   particle_velocities  prescribed material point velocities (momentum corrected)
//   v = p / m (solver)
//   (APIC: v^L = p^t / m + dt a, then with body conditions the APIC G2P of v_p
//   and C_p, particle_velocities, the affine P2G and v = p / m: Solver::step)
//   nodal_velocities     prescribed values, no penetration / stick at friction nodes
//
// Rigid plates (loads/rigid_plate.h, issue 37; the scene's
// 'boundary conditions/rigid plate k', s.prm.rigid_plates) ride on the same
// hooks: nodal_forces sums the plate's nodes (mass M_P, force F_P and momentum
// P_P at t along its axis; the tangential ones of a rough plate) over the ranks
// before the damping, and gives the plate its new velocity V^{t+h}: force
// control V = P_P / M_P + h (F_P + F_plate(t) + damping) / (beta M_P), the
// local damping acting on the plate's own unbalanced force; displacement
// control V = (u(t+h) - u_P) / h, reaction beta (M_P V - P_P) / h - F_P.
// nodal_accelerations gives every plate node a = (V - v_i^t) / h along the
// axis (0 - v_i^t for the tangential components of a rough plate),
// nodal_velocities sets V. Wall-held components keep their wall. Coupled
// 2-phase: the sums in nodal_forces_two_phase, V in nodal_accelerations after
// the liquid's a_L (permeable: the solid alone, the liquid flows through with
// its own a_L; impermeable: both phases move with the plate along its axis).
//
// The 2-phase single-point step (explicit_two_phase.cc, seed 000 §4.5.7) calls
// the same hooks at the same places, and they act on both phases there:
//   (its P2G pass)       traction point forces -> f_trac (begin/end_traction_scatter)
//   before_nodal_solve   v^t = the solid nodal momentum of that P2G; friction lift
//   nodal_forces_two_phase  tractions on the mixture (total stress); the
//                        convergence ratios over the mixture and the liquid
//                        (no seepage left); local/viscous damping and mass
//                        scaling are applied by the 2-phase nodal solve itself
//                        (local_damping(), viscous_damping(), s.mass_scaling)
//   nodal_accelerations  prescribed nodes: both phases get vbar; friction nodes:
//                        the solid as above, the liquid cannot flow into the
//                        (impermeable) wall and has no tangential friction
//   particle_velocities  body conditions set the solid and liquid point velocities
//   nodal_velocities     prescribed values for both phases; no penetration
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/point_forces.h>
#include <talus/loads/rigid_plate.h>
#include <talus/loads/settings.h>

#include <limits>
#include <string>
#include <vector>

namespace talus::explicit_mpm
{
  template <int dim>
  class Solver;
}

namespace talus::loads
{
  template <int dim>
  class LoadControl
  {
  public:
    using Solver = explicit_mpm::Solver<dim>;
    explicit LoadControl(const Settings<dim> &settings);

    unsigned int
    n_stages() const
    {
      return settings.stages.size();
    }
    unsigned int
    n_point_force_slots() const
    {
      return settings.max_tractions;
    }
    /// Add the traction point-force blocks (dim doubles per traction slot) to
    /// the property layout; before the ParticleHandler is initialised.
    void extend_layout(PropertyLayout<dim> &layout);
    /// Offset of the first point-force block (slot j at + j dim).
    unsigned int
    point_force_offset() const
    {
      return forces.offset();
    }
    const Stage<dim> &
    stage(const unsigned int k) const
    {
      return settings.stages[k];
    }
    bool has_convergence() const;

    /// After seeding, before the history initialisation: K0 stresses, and
    /// stage 0 applied (gravity, boundaries, mass scaling, time step).
    void initial_state(Solver &s);
    /// Apply stage k: gravity, boundary conditions, friction and prescribed
    /// nodes, traction point forces, mass scaling and the time step, baselines
    /// of the convergence ratios. `resume`: keep the solver's stage start time
    /// (restart inside a stage). Returns the absolute end time of the stage.
    double begin_stage(Solver &s, const unsigned int k, const bool resume);

    /// `momentum_t`: the solid nodal momentum at t when the caller has it (the
    /// 2-phase P2G), else the points' momentum is projected here when needed.
    /// With `momentum_t` the caller has also scattered the traction point forces
    /// in its own P2G pass (begin/end_traction_scatter, point_force()) and sums
    /// their work itself (f_p . dx_p over the step); else both are done here
    /// (work f_p . v_p^t dt).
    void before_nodal_solve(Solver &s, const double h, const Vector *momentum_t = nullptr);
    /// For a caller that fuses the traction scatter into its P2G pass: time
    /// factors at t, the nodal traction vector zeroed and returned (local
    /// array; nullptr without tractions); add sum_p N_i f_p to it, then call
    /// end_traction_scatter().
    double *begin_traction_scatter(Solver &s);
    void    end_traction_scatter();
    /// Traction force of a point at the time of the last before_nodal_solve
    /// (0 without tractions).
    void
    point_force(const double *P, double (&f)[dim]) const
    {
      forces.force(P, f);
    }
    bool
    any_traction() const
    {
      return forces.any();
    }
    void nodal_forces(Solver &s);
    /// 2-phase form of nodal_forces (see above), before the 2-phase nodal solve.
    void nodal_forces_two_phase(Solver &s);
    /// Local damping alpha and viscous damping alpha_v of the running stage.
    double
    local_damping() const
    {
      return current->damping;
    }
    double
    viscous_damping() const
    {
      return current->viscous_damping;
    }
    void nodal_accelerations(Solver &s);
    /// Body conditions (apply to = body): v_p of the conditioned components
    /// becomes the prescribed value at t + h. FLIP (affine = 0): the momentum
    /// change m_p dv_p is added to the nodal momentum. APIC (affine: the offset
    /// of C_p): the rows of C_p of those components become 0 (the gradient of
    /// the body's uniform prescribed velocity) and nothing is scattered: the
    /// caller projects (v_p, C_p) of all points anew (Solver::step).
    void particle_velocities(Solver &s, unsigned int affine = 0);
    /// whether a body condition acts in this stage (the same on every rank)
    bool
    has_particle_conditions() const
    {
      return !particle_conditions.empty();
    }
    void nodal_velocities(Solver &s);

    /// Contact (every body moves with its own nodal fields, explicit_mpm::Contact):
    /// the loads' share of one body's field, by the rules of the combined field
    /// with the body's mass M and momentum at t P. Local and viscous damping,
    /// then mass scaling, on its force F (the last part of nodal_forces).
    void damp_and_scale(const Solver &s, double *F, const double *M, const double *P) const;
    /// Friction walls and prescribed nodal velocities on its acceleration
    /// A = F / M (as nodal_accelerations); `wall`: the state of every friction
    /// node (0 free, 1 stick, 2 slip) for body_velocities.
    void body_accelerations(const Solver &s, double *A, const double *M, const double *P,
                            std::vector<unsigned char> &wall) const;
    /// The same conditions on its velocities V of the convective phase (as nodal_velocities).
    void body_velocities(const Solver &s, double *V, const std::vector<unsigned char> &wall) const;

    /// Rigid plates, at setup (fresh or restored run, before any output): the
    /// plate state, the checks that need the grid (InputError naming 'boundary
    /// conditions/rigid plate k': a plate holding no grid node, a plate whose
    /// axis component a fixed/roller wall holds at every one of its nodes in
    /// some stage, a node shared by two plates) and the log line of each plate.
    void setup_rigid_plates(Solver &s);
    /// series.csv values of the plates, in the order of rigid_plate_series_columns().
    std::vector<double> rigid_plate_series() const;
    /// Checkpointed plate state: per plate (displacement, velocity, force,
    /// tangential force), identical on every rank; and its restore.
    std::vector<double>           rigid_plate_state() const;
    void                          restore_rigid_plate_state(const std::vector<double> &state);
    static constexpr unsigned int rigid_plate_state_size = 4;

    /// The convergence criterion of the stage was met (and ends the stage).
    bool
    stage_converged() const
    {
      return converged;
    }
    /// After a repartition of the grid (load balancing): the nodal vectors and
    /// node lists on the new partition.
    void
    grid_changed(Solver &s)
    {
      for (Vector *v : {&trac, &vt, &lift})
        if (v->size() > 0)
          s.grid.reinit_vector(*v);
      if (current) // else the stage about to begin builds them
        build_node_lists(s);
    }
    /// The nodal momentum p^t of the points that before_nodal_solve scattered
    /// in this step (the run's P2G, affine with APIC), or nullptr if it did not
    /// scatter one: the APIC step takes it instead of a second identical pass.
    const Vector *
    point_momentum_at_t() const
    {
      return vt_scattered ? &vt : nullptr;
    }
    /// Last evaluated ratios (NaN before the first evaluation of the stage).
    double force_ratio  = std::numeric_limits<double>::quiet_NaN();
    double energy_ratio = std::numeric_limits<double>::quiet_NaN();

  private:
    const Settings<dim> &settings;
    PointForces<dim>     forces; ///< the traction slots of the points and their time factors
    const Stage<dim>    *current     = nullptr;
    unsigned int         stage_index = 0;
    double               h           = 0; ///< size of the running step
    double               stage_t0    = 0;
    unsigned int         stage_step0 = 0;
    double               settle_time = 0; ///< stage time after which all loads are constant
    bool                 converged   = false;
    double               potential0 = 0, work_loads = 0; ///< baselines of W_ext

    bool                       need_vt      = false;
    bool                       vt_scattered = false; ///< vt is this step's P2G of the points
    Vector                     trac, vt;
    std::vector<int>           component; ///< of each local DoF (-1: none)
    std::vector<unsigned char> excluded;  ///< DoFs left out of the force ratio

    struct FrictionNode
    {
      unsigned int dofs[dim];
      unsigned int axis;
      int          side;
      double       area;
      double       h;              ///< cell size normal to the wall
      bool         liquid_stopped; ///< 2-phase: liquid normal velocity into the wall removed
    };
    std::vector<FrictionNode> friction_nodes;
    /// per friction node, of the combined field: 0 free/separating, 1 stick, 2 slip
    std::vector<unsigned char> wall_state;
    /// Per grid cell: bit f set if face f lies on a friction boundary.
    std::vector<unsigned char> friction_faces;
    /// Per DoF (the normal component of a friction node): the smallest
    /// displacement away from that wall of the points in the adjacent cells,
    /// sum over ranks by min. A node whose material has moved away from the
    /// wall by more than `lift_tolerance` x the cell size is free (no contact).
    Vector                         lift;
    static constexpr double        lift_tolerance = 1e-3;
    bool                           any_friction   = false;
    std::vector<PrescribedNodeDof> prescribed_dofs;
    bool                           any_prescribed = false; ///< on any rank
    std::vector<unsigned int>      particle_conditions;    ///< indices of body velocity conditions

    double
    load_time(const unsigned int index, const bool global, const double t_abs) const
    {
      (void)index;
      return global ? t_abs : t_abs - stage_t0;
    }
    /// Rigid plates: the run state of each plate (the same on every rank).
    struct PlateRun
    {
      double displacement = 0; ///< along the axis [m]
      double velocity     = 0; ///< V^{t+h} of the last step
      double force        = 0; ///< on the material along the axis (given or reaction) [N]
      double tangential   = 0; ///< |tangential reaction| of a rough plate [N]
      double unbalanced   = 0; ///< force control: F_P + F_plate before damping (convergence ratio)
    };
    const std::vector<RigidPlate<dim>> *plates = nullptr; ///< the scene's (set by setup_rigid_plates)
    std::vector<PlateRun>               plate_run;
    std::vector<PrescribedNodeDof>      plate_dofs;        ///< owned plate DoFs that no wall of the stage holds
    std::vector<unsigned char>          plate_active;      ///< per owned DoF: active in this step
    bool                                any_plate = false; ///< the scene has rigid plates
    /// Sum the plate nodes' mass, force and momentum over the ranks and set
    /// each plate's velocity V^{t+h}, force/reaction and displacement; F: the
    /// nodal force before damping, M: the nodal mass (solid).
    void rigid_plate_balance(Solver &s, const double *F, const double *M);
    /// From the sums: each plate's V^{t+h}, force/reaction, displacement and
    /// work. `liquid` (coupled 2-phase, after the liquid's accelerations): per
    /// plate and component sum beta Mbar_L a_L over its nodes; a permeable
    /// plate moves the solid only (the liquid flows through with its own a_L),
    /// an impermeable one the solid and the liquid together along its axis.
    void                          rigid_plate_velocities(Solver &s, const double *liquid);
    static constexpr unsigned int plate_sum_size = 5 + 2 * dim;
    std::vector<double>           plate_sum; ///< per plate, summed over the ranks

    /// the friction-wall law on a field's predicted velocity P / M + h A: A
    /// corrected, the node states into `state`
    void wall_law(const Solver &s, double *A, const double *M, const double *P, unsigned char *state) const;
    /// the walls' and the prescribed nodes' conditions on a field's velocities
    void wall_and_prescribed_velocities(const Solver &s, double *V, const unsigned char *state) const;
    /// the value at t + h of a prescribed DoF
    double prescribed_value(const Solver &s, const PrescribedNodeDof &p) const;
    void   assign_tractions(Solver &s);
    void   update_factors(const Solver &s);
    void   build_node_lists(Solver &s);
    /// `lift` of the friction nodes from the points next to friction walls.
    void friction_lift(Solver &s);
    void set_time_step(Solver &s);
    /// the convergence ratios are evaluated in this step
    bool check_step(const Solver &s) const;
    /// Ratios from the local sums v = {|f_unbalanced|^2, |f_ext|^2, grid KE,
    /// gravity potential} (reduced here over the ranks); sets `converged`.
    void evaluate_convergence(const Solver &s, double (&v)[4]);
  };
} // namespace talus::loads
