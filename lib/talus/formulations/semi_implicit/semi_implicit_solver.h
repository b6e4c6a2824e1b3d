// talus — the Solver of the semi-implicit two-phase double-point family (seed
// 002 §4.5): its state between steps, the phases of one step and the files it
// writes, over the shared core: two MaterialPointSets, the kernels' point
// stencils (transfer/stencil_ops.h), a scalar NodalSpace + ActiveSet for the
// pressure increment, CG + ML AMG (solvers/linear_solver.h), the one TimeLoop.
// The definitions, by concern: semi_implicit_setup.cc (grid, layouts, seeding,
// checkpoints, the tool's run), semi_implicit_step.cc (the fractional step),
// semi_implicit_output.cc (diagnostics, series, files, summary); each is
// instantiated there for dim 2 and 3. The .prm: semi_implicit_parameters.cc.
//
// Signs: tension positive for the effective stress and the pore pressure (the
// paper's §2), so the hydrostatic pore pressure is negative.
#pragma once

#include <talus/base/tool.h>
#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/probes.h>
#include <talus/formulations/common/simulation.h>
#include <talus/formulations/semi_implicit/boundary_loads.h>
#include <talus/transfer/fbar.h>
#include <talus/transfer/pressure_relaxation.h>
#include <talus/formulations/semi_implicit/semi_implicit.h>
#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/particles/material_point_set.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/solvers/linear_solver.h>
#include <talus/transfer/active_set.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <algorithm>
#include <initializer_list>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace talus::materials
{
  class Material;
}

namespace talus::semi_implicit
{
  /// Property offsets of the extras of both sets.
  struct Fields
  {
    unsigned int porosity = 0, initial_porosity = 0, initial_volume = 0, conductivity = 0, pressure = 0;
    unsigned int pressure_gradient   = 0;
    unsigned int surface_offset      = 0; // dim values: from the point to its share of the loaded face
    unsigned int poisson_coefficient = 0, poisson_flux = 0;                 // poisson_flux: dim values, phi v*
    unsigned int smoothed_volume_increment = 0, patch_elastic_jacobian = 0; // F-bar: dJbar, Jebar
    unsigned int smoothed_jacobian = 0;                                     // Nor-Sand (96)-(97): Jbar^{t+1}
    unsigned int plate_flux        = 0; // rigid plates with force control: dim values, phi v* of a unit plate velocity
    /// point sets = one set: the pore water a soil point carries (soil layout;
    /// pressure and pressure_gradient above are the soil's too then)
    unsigned int water_velocity = 0, water_mass = 0; // water_velocity: dim values
  };

  template <int dim>
  class Solver : public Simulation<dim>
  {
  public:
    using L = PropertyLayout<dim>;
    TALUS_SIMULATION_MEMBERS;

    Solver(const Parameters<dim> &p, MPI_Comm comm)
        : Simulation<dim>(p, p, comm, {"soil", "water"})
        , prm(p)
        , soil(*this->point_sets[0])
        , water(*this->point_sets[1])
        , bloads(p, grid, comm)
        , pspace(grid, 1)
        , active(pspace)
    {
    }

    void setup();
    std::string
    tool_name() const override
    {
      return "talus-semi-implicit";
    }
    void describe(std::ostream &out) const override;
    double
    begin_stage(const unsigned int, const bool, const bool) override
    {
      return prm.end_time;
    }
    /// One step (step<K>) with the run's shape functions.
    StepOutcome              advance_by(const double h) override;
    void                     check_stability() const override;
    std::vector<std::string> series_columns() const override;
    std::vector<double>      series_values(const bool after_step) override;
    void                     write_vtu(const unsigned int counter) override;
    void                     rewrite_records() override;
    std::string              write_checkpoint() override;
    void                     finish(const std::string &series_csv) override;
    void                     summary(const LoopTimings &timings) override;

  private:
    /// What the phases of one step share: its size and gravity, whether it is
    /// in the App. B.4 stage, the nodal mass cut-offs, the plates' velocities.
    struct StepState
    {
      double                 h             = 0;
      bool                   initial_stage = false; ///< elastic models, the water on the soil
      dealii::Tensor<1, dim> g;                     ///< gravity, ramped during the initialisation
      /// nodal soil / water masses at or below these count as empty (A3)
      double ms_cut = 0, mw_cut = 0;
      /// mark_free_surface ran (sealed_surface, before the predictors)
      bool surface_marked = false;
      /// per rigid plate: its velocity over the step (force control: found by
      /// plate_balance at the end of the step, 0 until then)
      std::vector<double> plate_v;
    };
    /// One fractional step (seed 002 §4.5), the phases below in order. Collective.
    template <class K>
    void step(const double h);
    /// The step's shared values and the displacement-controlled plates'
    /// velocities; the nodal sums zeroed, the phase timer started.
    StepState begin_step(const double h);
    /// (1)-(2), (3a)/(4a): P2N of both sets, the nodal pore pressure p^t and its
    /// forces on both phases.
    template <class K>
    void particles_to_nodes(StepState &this_step);
    /// soil mass, momentum, porosity, drag and force
    template <class K>
    void soil_to_nodes(StepState &this_step);
    /// their exchange; nodal n and v_s^t; ms_cut
    void soil_nodal_fields(StepState &this_step);
    /// the water points' porosity and volume; water mass, velocity, mapped
    /// pore pressure, drag Q; cell water volumes; v_w^t; mw_cut
    template <class K>
    void water_to_nodes(StepState &this_step);
    /// the smoothed pore pressure of the water points; Gpw, Gps
    template <class K>
    void pore_pressure_forces();
    /// The nodes of a sealed surface (BoundaryLoads::sealed_surface) and their
    /// surface vectors beta_J = sum_s V grad N_J (its held components 0):
    /// the lumped surface term -beta_J p_J of the pore pressure on the soil in
    /// the predictor (p^t), the correction and the Poisson rows (the
    /// increment); docs/semi-implicit.md 'A sealed surface'
    template <class K>
    void sealed_surface(StepState &this_step);
    /// A_rc += v in a Poisson row beyond the assembled cells: a Dirichlet row is
    /// skipped, a Dirichlet column moves its value to the right-hand side
    void
    add_poisson_entry(const dealii::AffineConstraints<double> &constraints, const dealii::types::global_dof_index r,
                      const dealii::types::global_dof_index c, const double v)
    {
      if (constraints.is_constrained(r))
        return;
      if (constraints.is_constrained(c))
        rhs(r) -= v * constraints.get_inhomogeneity(c);
      else
        A.add(r, c, v);
    }
    /// The sealed surface's terms of the Poisson system (before its
    /// compress): the matrix entries of the surface force's increment and the
    /// surface's flux beta_J . v_s*_J on the right-hand side
    template <class K>
    void add_sealed_surface_terms(const dealii::AffineConstraints<double> &constraints);
    /// The surface vectors of the impermeable rigid plates: beta_plate at a
    /// plate's axis DoF = sum_s V grad N_J (the surface integral of N_J n):
    /// the pore pressure's push on the plate (+beta p^{t+1} in the plate's
    /// residual) and the flux of the moving impermeable surface beta . V in
    /// the continuity rows (docs/semi-implicit.md 'An impermeable plate')
    template <class K>
    void plate_surface(const StepState &this_step);
    /// The outflow terms of the plate's solved nodes at a draining face (the
    /// plate-first rule keeps their rows; their support reaches the face the
    /// water leaves by): the matrix entries of the surface force's increment
    /// and the outflow beta_out_J . q*_J on the right-hand side
    /// (docs/semi-implicit.md 'The plate's corner on a draining face')
    template <class K>
    void add_plate_outflow_terms(const dealii::AffineConstraints<double> &constraints);
    /// the outflow beta_out_J . ((1 - n) vs_J + n vw_J) on the right-hand side
    void add_plate_outflow_flux(const dealii::AffineConstraints<double> &constraints, const Vector &vs,
                                const Vector &vw, Vector &f) const;
    /// the plate surface's flux beta_plate_J . v_J on the right-hand side of
    /// the Poisson rows (v: v_s* of the step or a plate's unit velocity)
    void add_plate_surface_flux(const dealii::AffineConstraints<double> &constraints, const Vector &v, Vector &f) const;
    /// (3)-(4): the water and the mixture predictor, the drag implicit in both:
    /// v_s*, v_w* per node (a 2 x 2 system), the plates' unit responses
    void water_and_mixture_predictors(const StepState &this_step);
    /// (5): the pressure-increment Poisson equation, assembled and solved:
    /// dp_node (0 in a dry scene), and per force plate its unit response
    template <class K>
    void pressure_poisson(const StepState &this_step);
    /// the points' Poisson coefficient h phi / rho and flux phi v*
    template <class K>
    void point_poisson_terms(const StepState &this_step);
    /// Rebuild the pressure DoF set when needed (collective); returns whether it did.
    template <class K>
    bool update_pressure_pattern();
    /// wet, dry and near_wet: the free water surface's nodes
    void mark_free_surface();
    /// p^{t+1} = 0 on drained faces and the free surface, dp = 0 without water;
    /// dirichlet_homogeneous: the same lines with zero values (a plate's unit response)
    void pressure_dirichlet_values(const StepState &this_step, dealii::AffineConstraints<double> &dirichlet,
                                   dealii::AffineConstraints<double> &dirichlet_homogeneous);
    /// The matrix (a new one for a new pattern) and right-hand side of the step.
    template <class K>
    void assemble_pressure_system(const dealii::AffineConstraints<double> &constraints, const bool new_pattern);
    /// CG + AMG on the assembled system; dp_node.
    void solve_pressure(const dealii::AffineConstraints<double> &constraints);
    /// Per force plate: the pressure increment of a unit plate velocity (r.dp).
    template <class K>
    void plate_unit_pressures(const dealii::AffineConstraints<double> &dirichlet,
                              const dealii::AffineConstraints<double> &dirichlet_homogeneous);
    /// (6): the pressure increment's forces and v^{t+1} of both phases.
    template <class K>
    void correction(const StepState &this_step);
    /// v^{t+1} of local DoF i from v* and the pressure increment's weak
    /// gradients; a plate's axis DoF moves with Vp[k]
    /// (dpv: the pressure increment of this response, for the surface terms)
    void correct_velocities(const StepState &this_step, const unsigned int i, const double vss, const double vws,
                            const double gsi, const double gwi, const double *dpv, const double *Vp, double &vs,
                            double &vw) const;
    /// The rigid plates' momentum balance: the force plates' velocities (and
    /// the step's fields with them), every plate's force, reaction, position.
    void plate_balance(StepState &this_step);
    /// The plates' residuals R0 (column 0) and R1 (a column per force plate),
    /// summed over the ranks
    std::vector<double> plate_residuals(const StepState &this_step);
    /// Solve R0 + R1 V = F(t + h) for the force plates' V; add V x their unit
    /// responses to the step's fields.
    void solve_force_plates(StepState &this_step, const std::vector<double> &R);
    /// The reactions of the velocity conditions (BoundaryLoads::reactions):
    /// the mixture's momentum residual of their DoFs, as the plates' R and T.
    /// Collective.
    void velocity_reactions(const StepState &this_step);
    /// (7)-(8a): FLIP velocities and pore pressure of the points, the MUSL
    /// scatter of the soil's momentum (Ps)
    template <class K>
    void nodes_to_particles();
    /// (8a): the remapped soil velocity vs_t from Ps
    void remap_soil_velocity(const StepState &this_step);
    /// How far the plates' nodes moved apart and slipped (node_spread, node_slip).
    void plate_node_spread(const StepState &this_step);
    /// (7a), (8b-g): the soil's ΔF, volume, J, porosity, conductivity and
    /// stress, both sets moved and relocated.
    template <class K>
    void update_and_move_points(const StepState &this_step);
    // point sets = one set (semi_implicit_one_set.cc): the point passes of
    // both phases in one walk over the soil set, whose points carry the water;
    // the phases above call them in place of their two walks (the water set
    // is empty)
    /// the scene has pore water (water points, or one-set points carrying water)
    bool
    has_water() const
    {
      if (prm.one_set)
        return std::find(prm.phase_of_body.begin(), prm.phase_of_body.end(), Phase::saturated) !=
               prm.phase_of_body.end();
      return water.handler.n_global_particles() > 0;
    }
    /// the water volume a one-set point stands for, V_w = m_w / (rho_w n)
    /// (Eq. 36 with the point's own porosity; 0 for a dry point)
    double
    water_volume(const double *P) const
    {
      return P[fs.water_mass] / (prm.water_density * P[fs.porosity]);
    }
    /// The nodal sums a soil point adds in P2N (steps (1)-(2)).
    struct SoilSums
    {
      double *ms, *ps, *mn, *mk, *fs; ///< into Ms, Ps, Mn, Mk, Fs (local entries)
    };
    /// A soil point's P2N, shared by the two-set and the one-set walks: mass
    /// (44), momentum (45), porosity (46), the drag coefficient integrated over
    /// the soil points (in place of (47) and (58)), gravity and the
    /// effective-stress force (54)-(55). A loaded point's traction is the caller's.
    template <class Stencil>
    void
    scatter_soil_point(const double *P, const Stencil &s, const SoilSums &to, const bool initial_stage,
                       const dealii::Tensor<1, dim> &g) const
    {
      const double m = P[L::mass];
      s.scatter(to.ms, m);
      s.scatter_vector(to.ps, m, P + L::velocity);
      s.scatter(to.mn, m * P[fs.porosity]);
      const double k = initial_stage ? prm.initialisation_conductivity : P[fs.conductivity];
      s.scatter(to.mk,
                P[fs.porosity] * P[fs.porosity] * prm.water_density * prm.unit_weight_gravity * P[L::volume] / k);
      double gm[dim];
      for (unsigned int d = 0; d < dim; ++d)
        gm[d] = g[d];
      s.scatter_vector(to.fs, m, gm);
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      s.scatter_divergence(to.fs, t);
    }
    /// (7a)-(7b) the FLIP update of a point velocity v (dim values) from the
    /// nodal velocities at t + 1 and t, 1 - flip of PIC blended in.
    template <class Stencil>
    void
    flip_update(const Stencil &s, const double *v_new, const double *v_old, double *v) const
    {
      const double flip = prm.flip_fraction;
      double       a[dim], b[dim];
      s.vector_value(v_new, a);
      s.vector_value(v_old, b);
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = flip * (v[d] + a[d] - b[d]) + (1 - flip) * a[d];
    }
    /// (77) a water point's pore pressure from the nodal p^t: replaced (the paper),
    /// or blended by the step's `pressure smoothing fraction` of its material
    /// (`P`: the point's properties)
    template <class Stencil>
    void
    smooth_pressure(const Stencil &s, const double *p_node, const double *P, double &p) const
    {
      const double beta = smoothing_fraction_of_material[static_cast<unsigned int>(P[L::material])];
      p                 = transfer::blend_pressure(p, s.value(p_node), beta);
    }
    /// (7c) a water point's pore pressure p += dp (as an increment: p_I^t + dp_I
    /// interpolated differs by the remap) and its gradient grad p^t + grad dp;
    /// `f`: the offsets of the point's layout.
    template <class Stencil>
    void
    pressure_update(const Stencil &s, const double *p_t, const double *dp, const Fields &f, double *P) const
    {
      P[f.pressure] += s.value(dp);
      double gp[dim], gdp[dim];
      s.gradient(p_t, gp);
      s.gradient(dp, gdp);
      for (unsigned int d = 0; d < dim; ++d)
        P[f.pressure_gradient + d] = gp[d] + gdp[d];
    }
    /// P2N of both phases (soil_to_nodes' sums and water_to_nodes')
    template <class K>
    void one_set_to_nodes(const StepState &this_step);
    /// the smoothed pore pressure of the points; Gps and Gpw
    template <class K>
    void one_set_pressure_forces();
    /// sum_s V N grad phi into fs, sum_w V_w N grad phi into fw
    template <class K>
    void one_set_weak_gradients(const double *phi, double *fs_out, double *fw_out);
    /// the Poisson coefficient and flux of both phases, summed per point
    template <class K>
    void one_set_poisson_terms(const StepState &this_step);
    /// a force plate's unit response: the water's flux (ew) added to the soil's
    template <class K>
    void one_set_plate_flux(const double *ew);
    /// FLIP of both phases, the pore pressure, the MUSL scatter of the soil (into Ps)
    template <class K>
    void one_set_to_particles();
    /// The soil update of update_and_move_points (a transfer::UpdateAndMove op).
    template <class K>
    struct SoilUpdate;
    /// The newest valid checkpoint into the state (false: none). Collective.
    bool restore_checkpoint();
    /// The node-smoothed volume measures of the soil points, one map and
    /// remap: F-bar's increment dJbar (80) and, for the modified F-bar, the
    /// patch mean Jebar (83); Nor-Sand's total Jbar^{t+1} (97)
    template <class K>
    void volume_averages(const double h, const double ms_cut);
    /// whether the soil points need Jbar (a nor sand material, smoothing on)
    bool smooth_jacobian = false;
    void seed();
    void geostatic_state();
    /// compress(add) then update ghosts, for every vector given
    void exchange(std::initializer_list<Vector *> vs) const;
    /// local (owned + ghost) size of a grid vector
    unsigned int
    n_local() const
    {
      return grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    }

    const Parameters<dim> &prm;
    MaterialPointSet<dim> &soil, &water; ///< the Simulation's two point sets
    /// issue 37: the shared tractions, prescribed velocities and drainage
    /// conditions (boundary_loads.h); its hooks are called from the phases
    BoundaryLoads<dim> bloads;
    /// output/probes: the soil points tracked (displacement, velocity,
    /// effective stress) and the water points nearest to the same places at
    /// t = 0 (their pore pressure); no water points: none of the latter
    PointProbes<dim> probes, water_probes;
    /// probes at t = 0 (a fresh start)
    void select_probes();
    /// Everything of the grid's partition that lives across steps: the
    /// pressure space, the per-DoF node maps and wall/drained flags, the nodal
    /// vectors, the sets' cell lists; the next step rebuilds the active set and
    /// the pressure matrix. Called by the load balancer after a repartition.
    void grid_changed() override;
    /// the next step rebuilds the pressure DoF set (after a repartition and
    /// after a checkpoint write)
    bool                                   partition_changed = true;
    Fields                                 fs, fw; ///< offsets in the soil and the water layout
    NodalSpace<dim>                        pspace; ///< the scalar pressure space
    ActiveSet<dim>                         active;
    dealii::TrilinosWrappers::SparseMatrix A;
    /// CG + ML AMG with the hierarchy kept between steps (solvers/linear_solver.h);
    /// invalidated when A is reinit and at every checkpoint write
    ReusedAMGSolver pressure_solver;
    /// steps of this run (not of a checkpoint's past: a restart rebuilds once
    /// more) that built a new pressure DoF set, sparsity and matrix
    unsigned long long n_pattern_changes = 0;
    /// of which: the cells were the same, but a point's stencil left the kept pattern
    unsigned long long n_pattern_window_changes = 0;
    Vector             rhs, dp_solution;

    // per grid local DoF: the node's component-0 DoF, component, prescribed zero
    std::vector<unsigned int>  node_of;
    std::vector<unsigned char> component, constrained;
    std::vector<unsigned char> water_constrained, drained; // per DoF; per node (component-0 DoF): on a drained face
    std::vector<dealii::Point<dim>> node_x;                // position of the node of a local DoF
    // nodal fields (grid vectors; scalars at the component-0 DoF)
    Vector Ms, Ps, Mn, Mk,
      Fs; // soil mass, momentum, sum m n, sum N n^2 rho_w g V / k (drag), force (internal + gravity)
    Vector Ww, Pw0, Ww0, Mwp, Mw; // sum N rho_w V, sum N rho_w V0 v, sum N rho_w V0, sum N m p, sum N m
    Vector Gpw, Gps; // sum V N grad p^t over the water / the soil points (times n_I, 1 - n_I: the pore pressure forces)
    Vector Mwg;      // sum N m grad p (linear pressure map)
    Vector n_node, Q_node, Mw_node; // nodal porosity n_I, drag Q_I, water mass M_wI
    Vector vs_t, vw_t, vs_star, vw_star, vs_new, vw_new;
    Vector p_node, dp_node, gs, gw, wet, dry, near_wet;
    Vector beta;                                   // per DoF: the sealed surface's sum_s V grad N (0 elsewhere)
    std::vector<unsigned char> sealed;             // per node (component-0 DoF): a node of a sealed surface this step
    bool                       any_sealed = false; // some rank has a sealed node this step
    Vector                     beta_plate; // per DoF: an impermeable plate's axis DoF: sum_s V grad N (0 elsewhere)
    bool                       any_plate_sealed = false; // the scene has an impermeable rigid plate
    /// per DoF: at a node an impermeable plate holds (its row solved), the
    /// components the plate, walls and prescribed velocities leave free:
    /// sum_s V grad N_J, the surface integral of N_J n over the faces other
    /// than the plate's, i.e. the node's share of a draining face (0 inside)
    Vector              beta_out;
    bool                any_plate_outflow = false; // some DoF has beta_out != 0 this step
    double              outflow_ms_cut    = 0;     // the step's soil mass cut-off (A3)
    std::vector<double> outflow_bb;                // per node (component-0 DoF): |beta_out|^2
    double              sealed_h = 0;              // the step's size (the Poisson terms of the seal)
    std::vector<double> cell_water_volume;
    Vector              Mdj; // F-bar: sum N m dJ of the soil points
    Vector              Mjt; // Nor-Sand: sum N m J^{t+1} of the soil points
    // modified F-bar patches: a fixed square tiling from the grid's lower corner
    transfer::PatchTiling<dim> patches;
    std::vector<double>        patch_mass, patch_mass_Je;


    // rigid plates (issue 37; docs/semi-implicit.md 'Rigid plate'): per local
    // grid DoF the plate whose axis component it is (none: not a plate DoF or
    // held by a wall, which keeps it), and the plate of a rough plate's
    // tangential DoF (held at zero like a wall; its reaction is summed)
    static constexpr unsigned int no_plate = static_cast<unsigned int>(-1);
    std::vector<unsigned int>     plate_of, plate_tangential_of;
    /// per node (component-0 DoF): a node of an impermeable plate, which covers
    /// the surface there: no free-surface p = 0 at it (the pressure is solved)
    std::vector<unsigned char> plate_sealed;
    /// per node (component-0 DoF): the plate that holds it, or no_plate
    std::vector<unsigned int> plate_node_of;
    /// per plate: the state between steps (checkpointed) and the last step's answer
    struct PlateState
    {
      double displacement = 0; ///< along the axis [m] (the unknown of force control)
      double velocity     = 0; ///< of the last step [m/s]
      double force        = 0; ///< the force the plate exerted on the material along its axis [N]
      double tangential   = 0; ///< |tangential reaction| of a rough plate [N]
      /// sum over the steps of h x (the largest difference between the velocity
      /// a plate node moves the soil with and the plate's: the axis component,
      /// and a rough plate's tangential ones against 0), in v^{t+1} and in the
      /// remapped velocity: a bound on how far the plate's nodes moved apart [m]
      double node_spread = 0;
      /// sum over the steps of h x the largest tangential velocity of a plate
      /// node in v^{t+1} (components no wall holds): 0 for a rough plate [m]
      double node_slip = 0;
    };
    std::vector<PlateState>   plate_state;
    std::vector<unsigned int> force_plates; ///< indices of the force-controlled plates
    /// per plate: grid nodes (global count) and axis DoFs it moves (not held by a wall)
    std::vector<unsigned long long> plate_nodes, plate_axis_dofs;
    /// per force plate k: the step's response to a unit plate velocity (its
    /// predictor velocities of soil and water, nodal pressure increment, the
    /// weak gradients of that increment, corrected velocities)
    struct PlateResponse
    {
      Vector es, ew, dp, gs, gw, vs, vw;
    };
    std::vector<PlateResponse> plate_response;
    /// Check the plates against the grid (collective; InputError naming the plate).
    void check_plates();
    // App. B.4 initialisation: the models of the elastic stage (nor sand
    // without plasticity, the others as they are), per material
    std::vector<std::shared_ptr<const materials::Material>> initialisation_models;
    bool
    initialising(const double t) const
    {
      return t < prm.initialisation_time - 1e-9 * dt;
    } // as the loop's end test
    /// End of the App. B.4 stage: every nor sand point's references from its
    /// current state (Eqs. 111-114). Logs one line.
    void end_initialisation();

    // diagnostics
    LinearSolveInfo    last_solve;
    unsigned long long solver_iterations = 0, n_solves = 0;
    double             seconds_solve    = 0; ///< CG + AMG set-ups
    double             dt_soil_critical = 0;
    /// per material: the share of the smoothed pore pressure in this step (begin_step)
    std::vector<double> smoothing_fraction_of_material;
    // wall-clock phases of the step (a few clock reads per step; the solve is
    // seconds_solve): P2N, nodal updates, Poisson set-up and assembly, N2P
    // (FLIP + MUSL remap), soil update and stress (with F-bar), water move
    // and the relocation of both sets
    struct PhaseTimes
    {
      double p2n = 0, grid = 0, poisson = 0, n2p = 0, stress = 0, relocation = 0;
    } phase;
    template <class K>
    double shape_walk_seconds(); // one stencil walk over both sets (summary)
    /// Each set's point stencils, kept between the walks of a step (the
    /// positions change only at the move): transfer::StencilCache checks every
    /// entry against its point at each use; cleared when the grid changes.
    struct StencilCaches
    {
      transfer::StencilCache<dim, shape::BSpline2Box<dim>> bspline;
      transfer::StencilCache<dim, shape::Q1Box<dim>>       linear;
      void
      clear()
      {
        bspline.clear();
        linear.clear();
      }
    } soil_stencils, water_stencils;
    template <class K>
    transfer::StencilCache<dim, K> &
    stencils(const MaterialPointSet<dim> &set)
    {
      StencilCaches &c = &set == &soil ? soil_stencils : water_stencils;
      if constexpr (std::is_same_v<K, shape::BSpline2Box<dim>>)
        return c.bspline;
      else
        return c.linear;
    }
    /// phase timers: add_lap(x) adds the time since the last lap to x
    Clock::time_point lap;
    void
    add_lap(double &x)
    {
      const auto now = Clock::now();
      x += std::chrono::duration<double>(now - lap).count();
      lap = now;
    }
  };
} // namespace talus::semi_implicit
