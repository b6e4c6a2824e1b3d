// talus — explicit MPM: pore liquid of a material (drained | undrained effective
// stress | coupled 2-phase, seed 000 §3.4, §4.3.8, §4.5), the 2-phase single-point
// time step (§4.5.6-4.5.7) with the shared loads of lib/talus/loads (their 2-phase
// meaning: load_control.h), the critical time steps of every phase (§4.6, Eqs.
// 4.120-4.129) and the liquid free-surface detection (§6.8).
//
// The 1-phase solver (explicit_solver.cc) keeps its fused hot loop; a scene with a
// coupled material or a body 'traction face' switches Solver::step() to
// TwoPhase::step(), a separate set of unfused passes. An undrained material is a
// 1-phase material (a wrapper adding the pore pressure of Eq. 4.52) and costs the
// hot loop nothing.
#pragma once

#include <talus/formulations/common/diagnostics.h>
#include <talus/formulations/explicit/forward.h>
#include <talus/materials/material.h>
#include <talus/materials/pore_liquid.h>
#include <talus/particles/material_points.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/tensor.h>

#include <memory>
#include <string>
#include <vector>

namespace talus::explicit_mpm
{
  // the shared 'material k/pore liquid' (materials/pore_liquid.h)
  using materials::Drainage;
  using materials::PoreLiquid;

  /// "body k/traction face", "body k/traction": an alias of a constant global
  /// loads/traction on that face of a box body (added by loads::parse_parameters);
  /// kept here for the checks and the selection of the separate step.
  template <int dim>
  struct BodyTraction
  {
    int                    face = -1; ///< -1 none; 2 axis + (0 lower, 1 upper)
    dealii::Tensor<1, dim> traction;  ///< [Pa]
  };

  template <int dim>
  struct LiquidParameters
  {
    std::vector<PoreLiquid>        pore_liquid;             ///< per material
    std::vector<BodyTraction<dim>> tractions;               ///< per body
    double                         free_surface_factor = 0; ///< F_FreeSurf of Eq. 6.40; 0: off
    double                         local_damping = 0; ///< 'two phase/local damping' (alias of damping/local damping)
    /// 'two phase/pressure relaxation' C: with quadratic B-splines each step blends
    /// the point pore pressures towards their node map-remap with the share
    /// min(1, C c_v dt / h^2) (transfer/pressure_relaxation.h); 0 = off. Linear
    /// shape functions ignore it.
    double pressure_relaxation = 1.0;
    bool   any_coupled() const;
    bool   any_traction() const;
  };

  /// .prm declarations: inside a "body k" subsection, and the top-level
  /// "liquid" subsection ('material k/pore liquid': materials::declare_pore_liquid).
  void declare_body_traction(dealii::ParameterHandler &prm, const unsigned int dim);
  void declare_liquid_output(dealii::ParameterHandler &prm);

  /// Read "pore liquid" of the current material subsection and check what
  /// talus-explicit needs of it; a given hydraulic conductivity becomes kappa =
  /// k mu_d / (rho_L g). For undrained materials `material` is replaced by the
  /// effective-stress wrapper.
  PoreLiquid parse_pore_liquid(dealii::ParameterHandler &prm, const std::string &where,
                               std::shared_ptr<const materials::Material> &material);
  template <int dim>
  BodyTraction<dim> parse_body_traction(dealii::ParameterHandler &prm, const std::string &where);
  /// "liquid/free surface factor" and "two phase/local damping"
  template <int dim>
  void parse_liquid_output(dealii::ParameterHandler &prm, LiquidParameters<dim> &p);

  /// Critical time step of one material (seed 000 §4.6).
  struct CriticalStep
  {
    std::string material, model, phase;    ///< phase: solid | liquid | undrained | coupled
    std::string formula;                   ///< the equation used
    double      wave_speed = 0;            ///< c (c_1 of Eq. 4.125 for coupled) [m/s]
    double      dt         = 0;            ///< the step used [s]
    double      dt_wave = 0, dt_other = 0; ///< L/c; viscous (liquids) or Eq. 4.124 (coupled)
    double      dt_4_122 = 0;              ///< coupled: min(4.123, 4.124)
  };

  /// Per material, for the smallest cell edge L_min.
  std::vector<CriticalStep>
  critical_time_steps(const std::vector<std::shared_ptr<const materials::Material>> &materials,
                      const std::vector<PoreLiquid> &pore_liquid, const double L_min);

  /// 2-phase single-point formulation: properties, time step, energies.
  template <int dim>
  class TwoPhase
  {
  public:
    explicit TwoPhase(Solver<dim> &s);
    /// porosity, pore pressure, liquid velocity (coupled)
    void extend_layout(PropertyLayout<dim> &layout);
    /// After a repartition of the grid (load balancing): the liquid's nodal
    /// vectors on the new partition (the step rebuilds their values each step).
    void grid_changed();
    /// after seeding: solid masses (1-n) rho_S V, porosity, liquid velocity
    void initialize_particles();
    /// One step of §4.5.7, with the hooks of the loads (Solver::control) at
    /// the places of the 1-phase step (load_control.h). Collective.
    void step(const double dt);
    /// step() with the shape kernel K of the run (numerics/shape function).
    template <class K>
    void step_with(const double dt);
    /// What the points' pore liquid adds to the point sums (Solver::point_sums):
    /// its mass n rho_L V and velocity, and with `strain` the energy of the pore
    /// pressure V n p^2 / (2 K_L), for the points of coupled materials.
    void add_sum_options(diagnostics::SumOptions<dim> &o, bool strain) const;
    /// Liquid mass n rho_L V of a point (0 unless it is of a coupled material).
    double liquid_mass(const double *P) const;

    unsigned int porosity = 0, pore_pressure = 0, liquid_velocity = 0;
    bool         coupled = false;

  private:
    friend class loads::LoadControl<dim>;
    // the phases of step_with() (§4.5.7), in their order; the loads' hooks
    // are called between them by step_with()
    template <class K>
    void particles_to_nodes();
    void nodal_accelerations();
    template <class K>
    void g2p_velocity_p2g_momentum(const double dt);
    void nodal_velocities();
    template <class K>
    void g2p_update(const double dt);
    // pieces of the phases
    void update_ghosts(Vector &solid, Vector &liquid);
    /// the shares of the relaxed pore pressure of the step h, per material
    void relaxation_fractions(const double h);
    /// the node map of the pore pressure p_I = sum N mL p / sum N mL (the sums of
    /// particles_to_nodes), on the scalar slot of each node, with its ghosts
    void   pressure_map();
    double pore_liquid_update(double *P, const PoreLiquid &pl, const double dvS, const double div_uL,
                              diagnostics::PointSums<dim> &sums, bool &bad) const;

    Solver<dim> &s;
    // lumped nodal quantities: liquid mass without / with porosity, drag,
    // liquid force and momentum (solid: the solver's nodal_mass, nodal_a, nodal_p)
    Vector m_liquid, m_liquid_n, drag, f_liquid, p_liquid, a_liquid;
    /// the pore-pressure relaxation (quadratic B-splines, pressure_relaxation > 0):
    /// on, the node map of the pore pressure, the share per material in this step
    bool                relax = false;
    Vector              p_node;
    std::vector<double> relax_share;
  };

  /// Liquid free-surface detection (§6.8): nodal density of the non-empty
  /// cells (Eq. 6.38), interpolated to the points (6.39), flagged when below
  /// F rho_0 (6.40). Computed only when an output needs it.
  template <int dim>
  class FreeSurface
  {
  public:
    FreeSurface(Solver<dim> &s, const double factor);
    void extend_layout(PropertyLayout<dim> &layout);
    /// After a repartition of the grid: the nodal vectors on the new partition.
    void grid_changed();
    /// Flags the points (property "free_surface") and sums the count and the
    /// extent of the particles (collective). Returns {count, extent (min, max per axis)}.
    void                update();
    unsigned long long  count = 0;
    std::vector<double> extent; ///< x_min, x_max, y_min, y_max (, z_min, z_max)
    unsigned int        flag = 0;

  private:
    /// the nodal density (Eq. 6.38) and its value at the points (6.39) with the
    /// shape kernel K of the run
    template <class K>
    void update_with();

    Solver<dim> &s;
    double       factor;
    Vector       mass, volume;
  };
} // namespace talus::explicit_mpm
