// talus — implicit updated-Lagrangian MPM (seed 001, Iaconeta 2019; Kratos MPM):
// every step the grid is reset, mass, velocity and acceleration are projected
// from the points, Newton-Raphson solves the Newmark-discretised momentum
// balance for the nodal displacement increment, and the converged increment is
// carried back to the points (Algorithm 1). Static analysis drops the inertia.
// The time loop (formulations/common/time_loop.h) drives it; a step whose
// Newton iteration fails is cut back by the loop. The Solver's parts:
// implicit_parameters.cc (the .prm), implicit_setup.cc (set-up, stages,
// plates' DoFs, description; instantiates the Solver), implicit_step.cc
// (advance_by: a driver of the step's phases), implicit_assembly.cc (residual,
// tangent, linear solves), implicit_constraints.cc (contact walls on the
// nodes, the step's constraints, prescribed DoFs and reactions),
// implicit_output.cc (series, files, checkpoints, summary).
#pragma once

#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/probes.h>
#include <talus/formulations/common/simulation.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/formulations/implicit/ghost_penalty.h>
#include <talus/formulations/implicit/newmark.h>
#include <talus/formulations/implicit/newton.h>
#include <talus/formulations/implicit/point_contact.h>
#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/materials/neo_hookean.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/point_forces.h>
#include <talus/loads/rigid_plate.h>
#include <talus/loads/settings.h>
#include <talus/particles/material_point_set.h>
#include <talus/shape/with_kernel.h>
#include <talus/solvers/linear_solver.h>
#include <talus/transfer/active_set.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <limits>
#include <memory>
#include <sstream>
#include <type_traits>
#include <string>
#include <vector>

namespace talus::implicit_mpm
{
  /// The .prm of talus-implicit: the shared scene and run sections and the
  /// subsections 'implicit', 'newton' and 'linear solver'.
  template <int dim>
  struct Parameters : SceneParameters<dim>, RunParameters<dim>
  {
    enum class Analysis
    {
      quasi_static, ///< no inertia; time is a load parameter
      dynamic       ///< Newmark
    };
    Analysis analysis = Analysis::dynamic;
    /// mixed u-p (seed 001 ch. 5): nodal pressure as a second field, PPP stabilisation
    bool   mixed_up      = false;
    double stabilisation = 1; ///< alpha of Eq. 5.15 (mixed u-p)
    /// 2D only: axisymmetric about the y axis (x = radius >= 0; seed 001 App. C):
    /// V_p and m_p of a point are those of its ring (2 pi r x the seeded area),
    /// dF_zz = r_{n+1} / r_n is the hoop stretch (docs/implicit.md)
    bool axisymmetric = false;
    /// 'numerics/volumetric stabilisation = f-bar' (irreducible form): each point's model sees
    /// dFbar = (jbar / j)^(1/dim) dF, jbar the volume-weighted mean det dF of its grid cell,
    /// with the exact tangent (docs/implicit.md, "F-bar")
    bool fbar = false;
    // 'numerics/shape function' (SceneParameters::bspline()): the kernel of every grid transfer
    double time_step = 0; ///< > 0 (required)
    double gamma = 0.5, beta = 0.25;
    /// 'damping/viscous damping': C = alpha M (mass-proportional Rayleigh damping) [1/s]
    double rayleigh_alpha = 0;
    /// 'damping/stiffness damping': C += beta K, stiffness-proportional Rayleigh damping [s], K the
    /// material + geometric tangent at the start of the step (frozen within it)
    double rayleigh_beta = 0;
    /// 'implicit/mass matrix = consistent': the inertia and damping with
    /// M_ij = sum_p m_p N_i N_j (per component) instead of its row sums; the
    /// projection of v_p and a_p to the nodes stays lumped (docs/implicit.md)
    bool consistent_mass = false;
    /// static: body forces grow linearly from 0 at t = 0 to full at the end time
    bool ramp_loads = true;
    /// Every traction of the run, one point-force slot each: first the
    /// top-level 'loads/traction k' (global, absolute time), then each stage's
    /// own ('stage k/loads', stage time). Dead loads carried by boundary points,
    /// assigned once on the seeded state.
    std::vector<loads::Traction<dim>> tractions;
    /// per traction slot: the stage that owns it, or -1 for a global load
    std::vector<int> traction_stage;
    /// 'loads/velocity k' on grid nodes (boundary | region): the displacement
    /// increment of each step, integrated over the step, imposed on those DoFs
    /// (the top-level ones; a stage's list is in stages[k].velocities)
    std::vector<loads::PrescribedVelocity<dim>> velocities;
    /// The stages (one built from the top-level entries without 'number of
    /// stages'): gravity, fixed/roller walls, velocity conditions, duration.
    std::vector<loads::Stage<dim>> stages;
    std::vector<double>            stage_time_steps; ///< per stage (> 0)
    bool                           staged = false;
    /// 'boundary conditions/contact': unilateral contact walls (grid faces) whose
    /// nodes are held while the wall pushes on them and released when it would
    /// pull (active set inside the step; docs/implicit.md "Contact floor")
    std::vector<dealii::types::boundary_id> contact_ids;
    /// 'boundary conditions/contact friction': true = no slip (the tangential
    /// components of a node in contact are held too), false = frictionless or
    /// Coulomb (contact_mu > 0: stick / slip per node or point)
    bool contact_no_slip = true;
    /// 'boundary conditions/contact passes': active-set passes per step at most
    unsigned int contact_passes = 10;
    /// 'boundary conditions/contact gap': a node is held only while the material
    /// next to it is within this fraction of a cell of the wall
    double contact_gap = 0.1;
    /// 'boundary conditions/contact method = points': the 'contact' walls act on
    /// the material points by a penalty inside Newton (point_contact.h) instead
    /// of holding grid nodes (docs/implicit.md "Contact walls on the points")
    bool contact_on_points = false;
    /// 'boundary conditions/contact penalty': k_n = penalty x M V_p / h^2 (points)
    double contact_penalty = 1;
    /// the Coulomb coefficient of 'contact friction' (+inf: no slip, 0: frictionless)
    double contact_mu = std::numeric_limits<double>::infinity();
    /// 'rigid footing': a rigid plane of finite span pressed into the material at
    /// a prescribed rate, acting on the points by the contact penalty
    /// (point_contact.h); its reaction is the footing force
    struct Footing
    {
      bool         enabled = false;
      unsigned int axis    = 1; ///< normal axis
      int          sign    = 1; ///< +1: the footing is on the upper side of its base
      double       level = 0, velocity = 0, penalty = 1;
      double       lower[2] = {0, 0}, upper[2] = {0, 0};
      double       friction = std::numeric_limits<double>::infinity(); ///< rough: no slip; smooth: 0
    } footing;
    /// 'implicit/velocity regions follow': the region of each 'velocity k' with
    /// 'apply to = region' moves with the displacement it has prescribed so far
    /// (a rigid plate pressed into the material keeps acting on the nodes at its
    /// current position); false: the nodes are fixed in space
    bool moving_velocity_regions = false;
    /// 'implicit/negligible nodal mass': the DoFs (displacement and, in u-p,
    /// pressure) of an active node whose lumped mass is below this fraction of
    /// the largest nodal mass are held at zero increment for the step (0: off)
    double negligible_mass = 0;
    /// 'implicit/ghost penalty': gamma of the face term (ghost_penalty.h); 0: off
    double ghost_penalty = 0;
    /// 'implicit/carry start imbalance': a static step solves r(du) = r(0) at
    /// the previous load level
    bool carry_imbalance = false;
    /// The largest share of all the forces on the nodes (loads and reactions,
    /// summed magnitudes) the held negligible-mass DoFs may carry at a converged
    /// step; above it the run stops (exit 3) with the figures.
    double              negligible_load_limit = 0.01;
    NewtonSettings      newton;
    LinearSolverOptions linear;
  };

  /// Declare the complete .prm of talus-implicit (`prm_file` gives the counts).
  void declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file);
  /// Read and validate (InputError naming the entry).
  template <int dim>
  Parameters<dim> parse_parameters(dealii::ParameterHandler &prm);
  /// --check: parse and validate everything without building the scene.
  void check_scene(dealii::ParameterHandler &prm, const std::string &prm_file);
  /// Run the tool (dispatch on the dimension); returns the exit code.
  int run(dealii::ParameterHandler &prm, const std::string &prm_file);

  /// Newton figures of the last step (log, series.csv).
  struct StepReport
  {
    unsigned int iterations = 0, linear_iterations = 0;
    double       residual_first = 0, residual_last = 0, observed_order = 0;
    double       increment_order = 0; ///< observed order of the increments |du_k|
    std::string  history;             ///< residual norms of the iterations, for the log
    /// contact walls: Newton solves (passes) of the step, nodes released and
    /// put (back) in contact over its passes, nodes in contact at its end
    unsigned int contact_passes = 0, contact_released = 0, contact_added = 0, contact_nodes = 0;
    /// Coulomb contact walls on the nodes: nodes slipping at the step's end
    unsigned int contact_slipping = 0;
    /// contact walls on the points: the converged step's contact figures
    PointContactStats point_contact;
    /// 'loads/velocity k': the force the prescribed nodes exert on the material
    /// at the converged step (the residual f_int - f_ext at their DoFs), summed
    /// over the nodes of all conditions, per component
    double prescribed_force[3] = {0, 0, 0};
    /// 'implicit/negligible nodal mass': displacement DoFs held this step and
    /// their share of all the forces on the nodes at the converged step
    unsigned int held_dofs       = 0;
    double       held_load_share = 0;
  };

  template <int dim>
  class Solver : public Simulation<dim>
  {
  public:
    TALUS_SIMULATION_MEMBERS;

    Solver(const Parameters<dim> &prm, MPI_Comm comm);
    ~Solver();

    /// Grid, spaces, points, constraints. Collective.
    void setup();

    unsigned long long
    n_points() const
    {
      return points.handler.n_global_particles();
    }

    /// For tests: the tangent against central differences of the residual at
    /// the iterate du = `scale` x a pseudo-random field (constrained DoFs 0), in
    /// a pseudo-random direction, for a step of size h from the current state:
    /// |K v - (r(du + eps v) - r(du - eps v)) / (2 eps)| / |K v|, the larger of
    /// the displacement rows' and (mixed u-p) the pressure rows'. Collective.
    /// Mixed u-p: the pressure components of the iterate are `pressure_scale` x
    /// the pseudo-random field.
    double tangent_error(const double h, const double scale, const double eps, const double pressure_scale = 1.0);

    // ---- the Formulation interface
    std::string
    tool_name() const override
    {
      return "talus-implicit";
    }
    void describe(std::ostream &out) const override;
    unsigned int
    n_stages() const override
    {
      return prm.stages.size();
    }
    double                   begin_stage(const unsigned int k, const bool first, const bool resumed) override;
    StepOutcome              advance_by(const double h) override;
    void                     check_stability() const override;
    std::vector<std::string> series_columns() const override;
    std::vector<double>      series_values(const bool after_step) override;
    void                     write_vtu(const unsigned int counter) override;
    std::string              write_checkpoint() override;
    void                     rewrite_records() override;
    void                     finish(const std::string &series_csv) override;
    void                     summary(const LoopTimings &timings) override;

    const Parameters<dim>  &prm;
    MaterialPointSet<dim>  &points; ///< the Simulation's one point set
    NodalSpace<dim>         space;
    ActiveSet<dim>          active;
    Newmark                 newmark;
    loads::PointForces<dim> point_forces;
    StepReport              last;

  private:
    bool
    dynamic() const
    {
      return prm.analysis == Parameters<dim>::Analysis::dynamic;
    }
    /// The ramp of the current stage at time t (static with 'ramp loads': the
    /// fraction of the stage's duration elapsed, at most 1; else 1).
    double load_factor(const double t) const;
    /// Static analysis with constant loads ('ramp loads = false'): the load
    /// level reached at the stage's last converged step (0 at the stage's
    /// start, 1 once a step of the full size has converged). Not a function of
    /// time: a cut-back step must apply less load, or it retries the same problem.
    double load_level = 0;
    /// The level a step of size h goes to: the ramp at t + h; with constant
    /// loads the full load for a step of the full size (min(dt, the stage's
    /// rest)), else load_level + (1 - load_level) h / that size (a cut-back
    /// step takes that share of the rest of the load).
    double step_load_level(const double h) const;
    /// With constant loads at the full level and nothing else depending on the
    /// step (no prescribed motion, plates, footing or traction time function
    /// still changing): a cut-back would replay the failed step exactly.
    bool cut_back_replays() const;
    /// The body force at time t, and the traction factors of point_forces set
    /// for t (a static ramp takes the gravity from the previous stage's to this
    /// stage's and the stage's own tractions from 0 to full over the stage).
    dealii::Tensor<1, dim> apply_loads_at(const double t, const double r);
    /// Walls, prescribed nodes and the condition report of stage k.
    void enter_stage(const unsigned int k);
    /// The wall flags, contact nodes and prescribed nodes of stage k on the current partition.
    void   stage_nodes(const unsigned int k);
    double point_force_scale = 1; ///< multiplies the point forces (unstaged static ramp)
    /// After a repartition: what depends on the partition and lives across
    /// steps (the space's DoFs, the wall flags and prescribed nodes of the
    /// stage, the nodal vectors); the active set, the sparsity, the tangent and
    /// the constraints are rebuilt by every step's prepare_step().
    void grid_changed() override;
    /// Active set, constraints and matrix layout of the points' current cells.
    void prepare_step();
    /// Static steps: start_imbalance (and its norm) from the converged state
    /// at the previous load level on this step's grid; assemble() subtracts it
    /// from here on with 'carry start imbalance'. Collective.
    void measure_start_imbalance();
    /// What the phases of one step (advance_by) share.
    struct StepState
    {
      double                 h = 0;
      dealii::Tensor<1, dim> g;              ///< the body force at t + h (apply_loads_at)
      double                 f_ext      = 0; ///< the load scale of Newton's residual test
      double                 load_level = 1; ///< the static load level of the step (step_load_level)
      /// sum of |f_ext| over the DoFs (the magnitude of the load the nodes carry)
      double       f_ext_sum = 0;
      NewtonResult result; ///< the last Newton solve, its iterations those of all passes
      /// Newton solves (contact passes) of the step, nodes released and put in contact over them
      unsigned int       passes = 0, released = 0, added = 0;
      unsigned int       linear_iterations     = 0;
      double             worst_linear_residual = 0;
      bool               any_contact           = false; ///< contact nodes on some rank
      std::ostringstream pass_log;                      ///< the passes that changed the active set
    };
    /// The step's start: Newmark's step, the footing's time, prepare_step(), the
    /// body force at t + h, the damping stiffness ('rayleigh beta'), the external
    /// force scale and the force plates' targets at t + h.
    StepState begin_step(const double h);
    /// A failed step: the cut-back (the loop halves h), or RunStopped when the
    /// retry would replay the same problem (cut_back_replays).
    StepOutcome cut_back(const StepState &s);
    /// The first iterate: du = 0, the lifted predictor of the prescribed DoFs
    /// (collective), mixed u-p: the pressure predictor. false: the predictor
    /// failed (the step is cut back).
    bool predict(const StepState &s);
    /// Newton, then (contact walls on the nodes) the active set from the
    /// converged state's reactions and penetrations; a change re-solves from
    /// there. false: the contact reactions failed (the step is cut back).
    bool solve_newton(StepState &s);
    /// The step's StepReport (last) and the run's totals.
    void report_newton(const StepState &s);
    /// A converged step: the reactions of the prescribed nodes and plates, the
    /// shift of the velocity regions, the plates' displacements. false: the
    /// reactions failed (the step is cut back).
    bool apply_reactions(const StepState &s);
    /// The converged increment to the points: the contact state of the points,
    /// the convective phase (CommitUpdatedLagrangian), relocation.
    void convective_phase(const StepState &s);
    /// The step's log line.
    void log_step(const StepState &s);
    /// The wall constraints (fixed/roller walls, prescribed DoFs with `values`,
    /// and the contact nodes now in contact) merged with the inactive pins.
    dealii::AffineConstraints<double> step_constraints(const std::vector<double> *values          = nullptr,
                                                       const bool                 with_contact    = true,
                                                       const bool                 with_prescribed = true,
                                                       const bool                 hold_plates     = false,
                                                       const bool                 hold_negligible = true) const;
    /// Contact walls: the nodes and their state (1 = in contact and, on a
    /// Coulomb wall, sticking; 2 = in contact and slipping (Coulomb); 0 = free)
    /// at the normal DoF of each node, decided by the owner, ghosts updated.
    std::vector<loads::ContactNode> contact_nodes;
    Vector                          contact_state;
    /// Coulomb walls on the nodes: at the tangential DoFs of a slipping node the
    /// force the wall exerts on it, mu |normal reaction| against its slip (an
    /// external force of the step, fixed within a Newton solve, updated between
    /// the active-set passes); zero elsewhere
    Vector contact_friction;
    /// true: 'contact friction' is a Coulomb coefficient mu > 0 (nodes)
    bool
    coulomb_nodes() const
    {
      return !prm.contact_no_slip && prm.contact_mu > 0 && !prm.contact_on_points;
    }
    /// Per contact node: stick/slip changes in the current step (after four the
    /// node keeps its state for the rest of the step: no cycling)
    std::vector<unsigned char> friction_flips;
    /// friction changes of the last update_contact: stick/slip switches and
    /// slip forces not yet converged (global); the active-set passes go on while > 0
    unsigned int       friction_changes    = 0;
    unsigned long long total_slip_switches = 0, total_slip_node_steps = 0;
    /// a restart's contact state (rows: normal DoF, state, dim friction components)
    std::vector<double> restored_contact;
    /// (Re)sets the contact state: all nodes in contact, no friction force, or
    /// the restored state after a restart
    void reset_contact_state();
    /// Per contact node: times it changed state in the current step (a node that
    /// changed twice is held in contact for the rest of the step: no cycling).
    std::vector<unsigned char> contact_changes;
    /// Per contact node (at its normal DoF, ghosts updated): the gap between the
    /// wall and the material next to it at the start of the step, the smallest
    /// over the points of the node's cells of (distance of the point to the
    /// wall) - (half its size, V_p^(1/dim) / 2). A node can be in contact only
    /// while its gap is at most half a point size (the material is at the wall).
    Vector           contact_gap;
    std::vector<int> node_contact; ///< by grid local node: index into contact_nodes or -1
    void             measure_contact_gaps();
    /// 'contact gap' x the cell size normal to the wall
    double
    contact_gap_tolerance(const loads::ContactNode &c) const
    {
      return prm.contact_gap * (prm.grid_upper[c.axis] - prm.grid_lower[c.axis]) / prm.grid_cells[c.axis];
    }
    unsigned long long gap_releases = 0; ///< nodes released because the material left the wall (all steps)
    /// After a converged Newton solve: the wall reactions (residual at the
    /// contact DoFs, internal + inertia - external, assembled without the
    /// contact constraints) release the nodes pulled by the wall and the free
    /// nodes that penetrate it are put in contact. Returns the global number
    /// of nodes released and added. Collective.
    std::pair<unsigned int, unsigned int> update_contact(const dealii::Tensor<1, dim> &g, const double force_scale);
    unsigned long long                    total_contact_released = 0, total_contact_added = 0, total_contact_passes = 0;
    /// 'contact method = points': the penalty walls on the points (null otherwise)
    std::unique_ptr<PointContact<dim>> point_contact;
    unsigned long long                 total_point_contacts = 0, total_point_releases = 0, total_point_slip_steps = 0;
    double                             worst_penetration_ratio = 0;
    /// Lumped nodal mass and the mass-weighted projections of v_p and a_p
    /// (Eqs. 2.6-2.9) onto the active DoFs.
    void project_to_grid();
    /// 'mass matrix = consistent': r += M (a + alpha_R v) and tangent += coef M at
    /// the iterate du, with M_ij = sum_p m_p N_i N_j on the free DoFs.
    void add_consistent_inertia(const bool with_tangent);
    /// negligible_dofs from the step's lumped masses (prm.negligible_mass)
    void find_negligible_nodes();
    /// At a converged step: the force the held negligible-mass DoFs carry (the
    /// residual assembled without constraints, summed |r| over their
    /// displacement components) as a share of all the forces on the nodes
    /// (summed |f_ext| plus the reactions), into `last`; RunStopped above
    /// 'negligible mass load limit'. Collective.
    void measure_held_load(const StepState &s);
    /// Residual (and tangent) at the iterate du (ghosts up to date); returns |r|.
    double assemble(const bool with_tangent, const dealii::Tensor<1, dim> &g);
    /// Mixed u-p: the nodal pressure predictor of Eq. 5.20 into the pressure
    /// components of du (ghosts updated).
    void predict_pressure();
    /// f(std::integral_constant<unsigned int, nc>) with the space's components.
    template <class F>
    void
    with_components(F &&f) const
    {
      if (prm.mixed_up)
        f(std::integral_constant<unsigned int, dim + 1>());
      else
        f(std::integral_constant<unsigned int, dim>());
    }
    /// f(K()) with K the shape kernel of 'numerics/shape function'
    template <class F>
    void
    with_kernel(F &&f) const
    {
      shape::with_kernel<dim>(prm.bspline(), std::forward<F>(f));
    }
    /// 'damping/stiffness damping' > 0: damping_stiffness = the force tangent at du = 0 (the step's start)
    void assemble_damping_stiffness(const dealii::Tensor<1, dim> &g);
    /// Newmark a^{n+1} at the owned DoFs from du (dynamic only), ghosts updated.
    void nodal_acceleration(Vector &a) const;
    /// The newest valid checkpoint into the state (false: none). Collective.
    bool restore_checkpoint();
    /// axisymmetric, a fresh start: the seeded points' volume, mass and traction
    /// forces become those of their rings (docs/implicit.md, "Axisymmetry")
    void ring_measure();

    unsigned int acceleration_offset = 0;
    unsigned int pressure_offset     = dealii::numbers::invalid_unsigned_int; ///< mixed u-p: p_p
    /// axisymmetric: the point's radius r_n at the start of the step (set by prepare_step)
    unsigned int                             radius_offset = dealii::numbers::invalid_unsigned_int;
    std::vector<const materials::Material *> split_models;    ///< mixed u-p, per material id
    dealii::AffineConstraints<double>        constraints;     ///< Dirichlet + inactive, homogeneous
    std::vector<unsigned char>               boundary_flags;  ///< by grid local DoF (fixed/roller walls)
    std::vector<loads::PrescribedNodeDof>    prescribed_dofs; ///< of 'loads/velocity k' (owned + ghost)
    std::vector<unsigned char>               idle_conditions; ///< per condition: reported as acting on nothing
    /// per condition of the stage: the displacement it has prescribed so far
    /// (the shift of its region with 'velocity regions follow')
    std::vector<dealii::Tensor<1, dim>> region_shift;
    /// DoFs (relevant, every component) of nodes of negligible mass, held this step
    std::vector<dealii::types::global_dof_index> negligible_dofs;
    /// some stage has 'velocity k' conditions (series columns prescribed_force_*)
    bool
    any_velocity_condition() const
    {
      for (const auto &st : prm.stages)
        if (!st.velocities.empty())
          return true;
      return false;
    }
    /// the displacement condition k of the stage prescribes over [time, time + h]
    dealii::Tensor<1, dim> condition_increment(const unsigned int k, const double h) const;
    /// the reaction of the prescribed nodes at the converged iterate (StepReport)
    void prescribed_reaction(const dealii::Tensor<1, dim> &g);
    /// The residual at the iterate du assembled under `other` in place of the
    /// step's constraints (the reactions of what the step holds and `other`
    /// does not); constraints and residual unchanged on return. Collective.
    Vector residual_under(dealii::AffineConstraints<double> &other, const dealii::Tensor<1, dim> &g);

    // ---- rigid plates ('boundary conditions/rigid plate k'; docs/implicit.md "Rigid plate")
    // A displacement-controlled plate and the held tangential components of a
    // rough one are prescribed DoFs (prescribed_dofs, condition index
    // n_velocities() + plate index): the lifting, the increments and the
    // reaction of 'loads/velocity k'. The axis component of a force-controlled
    // plate is one unknown per plate: its nodes' DoFs are free in the assembly
    // (the tangent and residual keep their rows) and solve_with_plates()
    // condenses them exactly by superposition.
    unsigned int
    n_velocities() const
    {
      return prm.stages[current_stage].velocities.size();
    }
    bool
    force_plate(const unsigned int k) const
    {
      return prm.rigid_plates[k].control == loads::RigidPlate<dim>::Control::force;
    }
    bool
    any_force_plate() const
    {
      for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
        if (force_plate(k))
          return true;
      return false;
    }
    /// some plate has prescribed DoFs (displacement control or rough): reactions
    bool
    any_plate_reaction() const
    {
      for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
        if (!force_plate(k) || prm.rigid_plates[k].rough)
          return true;
      return false;
    }
    /// The plates' prescribed DoFs appended to prescribed_dofs (a component a
    /// fixed/roller wall holds stays the wall's).
    void append_plate_dofs();
    /// Setup: every plate holds a grid node, shares none with another plate
    /// and has one whose axis component no wall of any stage holds
    /// (InputError naming the plate); the log line per plate.
    void check_plates();
    /// After the step's constraints: the owned axis DoFs of each force plate
    /// that are free this step, and all of them (every rank) for the matrix.
    void find_plate_dofs();
    /// The step's Newton solve with force plates: with the tangent K and the
    /// residual r assembled with the plate DoFs free, e_k the indicator of
    /// plate k's DoFs, K_c = K with their rows and columns zeroed (diagonal
    /// kept): z_0 = K_c^-1 (-r), z_k = K_c^-1 (-K e_k), and delta = z_0 + sum
    /// c_k (z_k + e_k) with c from the linearised force balance of each plate,
    /// sum_{i in P_k} (r + K delta)_i = F_k. Leaves K_c in the tangent.
    LinearSolveInfo solve_with_plates();
    /// plate displacement along its axis (the plates' state, checkpointed)
    std::vector<double> plate_displacement;
    /// per plate: its step increment along the axis so far (force control: the
    /// sum of the accepted alpha c_k), and c_k of the last solve
    std::vector<double> plate_step, plate_c;
    /// per plate: F_k(t + h) (force control) and sum of r over its DoFs at the last assembly
    std::vector<double> plate_target, plate_sum;
    /// per plate: the converged reaction along the axis (displacement control)
    /// and the tangential one (rough), per component
    std::vector<dealii::Tensor<1, dim>>   plate_reaction;
    std::vector<loads::PrescribedNodeDof> plate_nodes; ///< rigid_plate_node_dofs (owned + ghost)
    /// per force plate: its owned free axis DoFs this step
    std::vector<std::vector<dealii::types::global_dof_index>> plate_owned;
    std::vector<dealii::types::global_dof_index>              plate_all;   ///< every rank's, sorted
    std::vector<unsigned char>                                idle_plates; ///< per plate: reported as acting on nothing
    bool   plates_held          = false; ///< the predictor holds the force plates' DoFs (their increment 0)
    double seconds_plates       = 0;     ///< the plates' extra linear algebra (products, zeroing, combination)
    double seconds_plates_solve = 0;     ///< the plates' Newton solves (all right-hand sides)
    /// The displacement of a prescribed DoF over the step [t, t + h].
    double prescribed_increment(const loads::PrescribedNodeDof &p, const double h) const;
    /// du before Newton: one linear solve with the prescribed increments lifted
    /// into the right-hand side (throws NewtonFailure if it fails).
    void   predict_prescribed(const double h, const dealii::Tensor<1, dim> &g);
    double lifted_residual = 0; ///< |r| of the step's lifted system (0 without prescribed DoFs)
    /// delta from tangent delta = -residual (the step's linear solve, timed and
    /// counted); a failed or singular solve throws NewtonFailure.
    LinearSolveInfo solve_for_delta();
    /// delta from tangent delta = -r
    LinearSolveInfo solve_for_delta(const Vector &r);
    /// each r[k] replaced by x solving tangent x = -r[k] (direct: one factorisation)
    LinearSolveInfo                        solve_several(std::vector<Vector> &r);
    dealii::TrilinosWrappers::SparseMatrix tangent;
    /// 'damping/stiffness damping' > 0: the stiffness K_n of the step's start (du = 0), whose beta K_n v^{n+1}
    /// is the damping force of the step (assemble_damping_stiffness)
    dealii::TrilinosWrappers::SparseMatrix damping_stiffness;
    bool   assembling_damping = false; ///< assemble() stops after the points' force (K_n for the damping)
    Vector du, delta, residual, mass, v_n, a_n, a_new;
    /// F-bar: the mean det dF of each active cell at the current du (transfer::CellMeanJacobian)
    std::vector<double> cell_jbar;
    /// the ghost penalty's faces of the step (prm.ghost_penalty > 0)
    GhostPenalty<dim> ghost;
    /// gamma times the largest constrained modulus of the materials
    double ghost_stiffness = 0;
    /// the residual of the converged state on this step's grid at the
    /// previous load level, |.| / |f_ext| of the step (series start_imbalance)
    Vector start_imbalance;
    double start_imbalance_norm = 0, start_imbalance_share = 0;
    /// whether assemble() subtracts start_imbalance (prm.carry_imbalance, once measured)
    bool carrying_imbalance = false;
    /// Owned DoFs the last converged step held by a condition of the step
    /// (prescribed, plate, contact, negligible mass; not the walls, not the
    /// inactive pins): their start imbalance is that hold's reaction, not the
    /// grid change, and is not carried. Empty after a grid change or a restart.
    std::vector<dealii::types::global_dof_index> held_last_step;
    /// held_last_step from the step's final constraints. Collective.
    void record_held_dofs();
    void compute_cell_jbar();
    /// consistent mass: a^{n+1} + alpha_R v^{n+1} at the free DoFs (0 at constrained
    /// ones), ghosts updated, the field the inertia integrand reads
    Vector                                       inertia_field;
    std::vector<std::pair<double, std::string>> &pvd_records; ///< the Simulation's, of the points
    PointProbes<dim>                             probes;      ///< output/probes (series.csv, results file)
    // totals for the summary
    unsigned long long total_iterations = 0, total_linear_iterations = 0;
    double             seconds_assembly = 0, seconds_solve = 0, seconds_commit = 0;
    double             cpu_seconds_assembly = 0; ///< the assemblies' CPU time (thread_cpu_seconds)
    unsigned int       n_assemblies = 0, n_solves = 0;
  };
} // namespace talus::implicit_mpm
