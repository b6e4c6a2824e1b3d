// talus — explicit dynamic 1-phase solid MPM (seed 000 §3.2, §4.3, algorithm of
// §4.3.7): lumped mass, momentum-based nodal velocities (modified Lagrangian
// update), Jaumann-rate stress update, volume update, relocation.
#pragma once

#include <talus/formulations/common/diagnostics.h>
#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/probes.h>
#include <talus/formulations/common/simulation.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/formulations/explicit/fem.h>
#include <talus/formulations/explicit/forward.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/formulations/explicit/explicit_two_phase.h>
#include <talus/grid/background_grid.h>
#include <talus/io/grid_mesh.h>
#include <talus/loads/settings.h>
#include <talus/materials/material.h>
#include <talus/particles/material_point_set.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/particles/particle_handler.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace talus::explicit_mpm
{
  /// The .prm of talus-explicit: the shared scene and run sections
  /// (formulations/common/scene_parameters.h) and the explicit family's own.
  template <int dim>
  struct Parameters : SceneParameters<dim>, RunParameters<dim>
  {
    // time step
    double courant         = 0.5;
    double time_step       = 0.0; ///< 0: courant x critical
    bool   force_time_step = false;
    // stability
    double energy_growth_limit = 10.0;
    // loads, friction, damping, convergence, mass scaling, K0, stages
    loads::Settings<dim> loads;
    // MPM-MIXED, strain smoothing, contact (seed 000 chapter 6; numerics.h)
    NumericsOptions numerics;
    // pore liquid per material, tractions per body, free-surface detection
    // (explicit_two_phase.h)
    LiquidParameters<dim> liquid;
  };

  /// Declare the complete .prm of talus-explicit. `prm_file` (may be empty)
  /// provides the dimension and the numbers of materials and bodies.
  void declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file);
  /// The same with another default of 'numerics/integration' (talus-fem: "fem").
  void declare_parameters_with_integration(dealii::ParameterHandler &prm, const std::string &prm_file,
                                           const std::string &default_integration);

  /// Read the parsed parameters (validating them; InputError names the entry).
  template <int dim>
  Parameters<dim> parse_parameters(dealii::ParameterHandler &prm);

  /// Run the tool: dispatch on the dimension. Returns the exit code.
  int run(dealii::ParameterHandler &prm, const std::string &prm_file);

  struct Timings
  {
    double p2g = 0, grid = 0, g2p = 0, relocation = 0, output = 0, total = 0;
  };

  struct Energies
  {
    double kinetic = 0, strain = 0, gravity_potential = 0, external_work = 0;
    double
    total() const
    {
      return kinetic + strain + gravity_potential - external_work;
    }
  };

  /// The explicit formulation: its step, diagnostics and files; the time loop
  /// (formulations/common/time_loop.h) drives it. The run state (time, dt,
  /// step_number, stage, output counters) is the RunState base.
  template <int dim>
  class Solver : public Simulation<dim>
  {
  public:
    TALUS_SIMULATION_MEMBERS;

    Solver(const Parameters<dim> &prm, MPI_Comm comm);
    ~Solver();

    /// Grid, DoFs, boundary conditions, particles, time step. Collective.
    void setup();
    /// One explicit step of size dt (§4.3.7). Collective.
    void step(const double dt);
    /// n steps of the current time step with the stability check after each
    /// (throws InstabilityError), no output. For probes and tests.
    void advance(const unsigned int n_steps);

    /// Critical time step of §4.6 over all materials and the smallest cell
    /// (the smallest of critical_time_steps()).
    double critical_time_step() const;
    /// Per material: phase, formula and step (seed 000 §4.6.1-4.6.3).
    std::vector<CriticalStep> critical_time_steps() const;
    double
    time_step() const
    {
      return dt;
    }

    /// Global sums over particles (collective; formulations/common/diagnostics.h).
    Energies               energies() const;
    dealii::Tensor<1, dim> total_momentum() const;
    double                 total_mass() const; ///< of the solid (2-phase: without the pore liquid)
    /// The point sums of the current state, both phases of 2-phase points,
    /// reduced over the ranks; `strain`: with the strain energy. Collective.
    diagnostics::PointSums<dim> point_sums(bool strain) const;
    unsigned long long
    n_particles() const
    {
      return points.handler.n_global_particles();
    }

    /// For tests: after step(), the mass/force accumulated by the fused update
    /// pass and the relocation must equal a fresh P2G of the new state, and the
    /// incrementally kept (cell, count) list must equal one read from storage.
    /// Returns the largest relative difference of mass and force (entries of
    /// the active DoFs and ghosts) and whether the cell lists agree.
    std::pair<double, bool> check_incremental_state();

    /// P2G of the points' momentum m v into v (zeroed first; compressed).
    /// Collective. Used by the loads (nodal velocity before the step). With
    /// velocity transfer = apic: m (v + C_p (x_i - x_p)) (formulations/explicit/affine_ops.h).
    void scatter_point_momentum(Vector &v);
    /// Offset of the APIC affine matrix C_p (dim x dim, row-major) in the point
    /// properties; 0 when velocity transfer = flip (no such block).
    unsigned int affine_offset = 0;

    /// Nodal lumped mass and momentum after a P2G of the current particle state
    /// (for tests): returns global sums sum_i m_i and sum_i p_i.
    std::pair<double, dealii::Tensor<1, dim>> grid_mass_and_momentum();

    const Parameters<dim> &prm;
    /// The material points (the Simulation's one set: its layout, cell list and relocation).
    MaterialPointSet<dim>     &points;
    std::vector<unsigned char> constrained;
    /// Nodal lumped mass; nodal_a holds the force until nodal_acceleration()
    /// divides it, then the acceleration; nodal_p the momentum until
    /// nodal_velocity(), then the velocity.
    Vector nodal_mass, nodal_a, nodal_p;
    /// Locally owned DoFs (local indices) of the active cells plus those other
    /// ranks contribute to: the only nodes the grid update visits.
    std::vector<unsigned int> active_dofs;
    Timings                   timings;
    Energies                  initial_energies;

    /// Write the complete state to <checkpoint dir>/checkpoint-<step>.h5
    /// (written as .part, renamed when complete; older ones beyond `keep`
    /// removed). Collective. Returns the file name.
    std::string write_checkpoint() override;

    // ---- the Formulation interface (the time loop's view)
    std::string
    tool_name() const override
    {
      return "talus-explicit";
    }
    void                     describe(std::ostream &out) const override;
    unsigned int             n_stages() const override;
    double                   begin_stage(const unsigned int k, const bool first, const bool resumed) override;
    bool                     stage_converged(std::string &message) override;
    void                     before_step(const double h, const bool diagnostics_due) override;
    StepOutcome              advance_by(const double h) override;
    void                     check_stability() const override;
    void                     prepare_output() override;
    std::vector<std::string> series_columns() const override;
    std::vector<double>      series_values(const bool after_step) override;
    void                     write_vtu(const unsigned int counter) override;
    void                     rewrite_records() override;
    void                     finish(const std::string &series_csv) override;
    void                     summary(const LoopTimings &loop_timings) override;

    /// Checkpoint files in the directory, newest first (rank 0 lists, all get it).
    std::vector<std::string> list_checkpoints() const;
    /// Strain energy is summed in the update pass only when a series row or a
    /// stability check needs it (set by the time loop).
    bool   need_strain_energy = true;
    double energy_scale       = 0;
    /// total mass of the points at setup (for the floor of the stability check)
    double total_mass_setup = 0;
    /// Gravity of the running stage (prm.gravity without stages).
    dealii::Tensor<1, dim> gravity;
    /// Mass scaling factor beta of the running stage (seed 000 §6.5): nodal
    /// accelerations f / (beta m); critical_time_step() includes sqrt(beta).
    double mass_scaling = 1.0;
    /// Loads/friction/damping/convergence/K0/stages; null when none is used.
    std::unique_ptr<loads::LoadControl<dim>> control;

    /// chapter-6 numerics, null when switched off (numerics.h)
    std::unique_ptr<Contact<dim>>         contact;
    std::unique_ptr<StrainSmoothing<dim>> smoothing;
    /// 2-phase / traction step (separate passes; null: the fused 1-phase step)
    std::unique_ptr<TwoPhase<dim>> two_phase;
    /// free-surface detection at output times (null: off)
    std::unique_ptr<FreeSurface<dim>> free_surface;
    /// FEM / UL-FEM on the same grid (numerics/integration = fem | ul-fem;
    /// null for MPM): Gauss-point seeding and its own update pass (fem.h)
    std::unique_ptr<FemIntegration<dim>> fem;

    /// Write the results file (output/results file, HDF5): series, probes,
    /// final particle fields and fields mapped to the grid nodes. Collective.
    void write_results(const std::string &series_csv) const;
    /// Zero a nodal vector where it can be non-zero: the active DoFs and the ghosts
    /// (empty regions of the grid cost nothing).
    void zero_on_active(Vector &v) const;

  private:
    friend class loads::LoadControl<dim>;
    /// Read the newest valid checkpoint into the (empty) particle handler and
    /// the solver state; returns false if there is none. Collective.
    bool        restore_checkpoint();
    std::string checkpoint_directory() const;
    friend class TwoPhase<dim>;
    friend class FreeSurface<dim>;
    friend class FemIntegration<dim>;
    /// Cell list of the points from storage, and the active DoFs.
    void collect_active_cells();
    void collect_active_dofs();

    /// After the partition changed: boundary flags, nodal vectors, cell lists,
    /// active DoFs and the features' grid data.
    void                       grid_changed() override;
    std::vector<unsigned char> dof_marker;
    /// Call f(kernel) with the shape kernel of the run (numerics/shape
    /// function): the walks of the step are templates on it.
    template <class F>
    void with_kernel(F &&f);
    // the walks of the step (transfer/ ops)
    void p2g_mass_and_force();
    void nodal_acceleration();
    void g2p_velocity_p2g_momentum(const double dt);
    void nodal_velocity();
    void g2p_update(const double dt);
    /// The update pass (FLIP, or with `apic` the APIC G2P of v_p, C_p fused in)
    template <class Kernel, bool apic = false>
    void g2p_update_with(Kernel, const double dt);
    /// The 1-phase step with velocity transfer = apic (after the nodal
    /// acceleration): affine P2G of p^t, v^L = p^t / m + h a, then the update
    /// pass with the APIC G2P (g2p_update_with<K, true>).
    void apic_nodal_velocity(const double dt);
    /// APIC with body velocity conditions (after apic_nodal_velocity): the
    /// APIC G2P of v_p and C_p from v^L, the conditioned points set to their
    /// prescribed velocity (C_p rows 0), the affine P2G of all points and
    /// v = p / m; the update pass then moves the points with that v (MUSL, as
    /// the FLIP step does) and keeps their v_p, C_p.
    void apic_body_velocities();
    /// numerics/volumetric stabilisation = f-bar, after the nodal velocity: each
    /// point's dJ = det(I + h grad v) mapped to the nodes weighted by mass and
    /// back (seed 002 Eqs. 79-80; transfer/fbar.h) into its property fbar_offset.
    template <class Kernel>
    void volume_averages_with(Kernel, const double dt);
    /// F-bar: offset of the point's smoothed dJbar (0: off) and the nodal sum m dJ
    unsigned int fbar_offset = 0;
    Vector       nodal_dj;
    /// Relocation; moved points add their mass and force to the next step's sums.
    void relocate();
    void write_final_particles() const;

    bool p2g_ready = false; ///< nodal mass/force of the current state accumulated
    // local point sums (energies, momentum) and validity from the last update pass
    diagnostics::PointSums<dim> local_sums;
    bool                        local_bad     = false;
    double                      external_work = 0;
    /// the PVD records of the points (the Simulation's) and of the grid
    std::vector<std::pair<double, std::string>> &pvd_records;
    std::vector<std::pair<double, std::string>>  grid_pvd_records;
    PointProbes<dim>                             probes; // output/probes
  };
} // namespace talus::explicit_mpm
