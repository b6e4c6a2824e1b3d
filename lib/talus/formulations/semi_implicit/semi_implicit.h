// talus — the semi-implicit two-phase double-point MPM (seed 002: Xie, Navas &
// López-Querol 2025, §3-4): soil and water are two MaterialPointSets on one
// grid; one step is the incremental fractional step of the paper's §4.5 (P2N
// of both phases, water predictor with implicit Darcy drag, mixture predictor,
// one pressure-increment Poisson solve, correction, FLIP update of both sets,
// MUSL remap, ΔF / J / volume / porosity). The time step is limited by the
// soil skeleton's wave speed only. Decisions the paper leaves open:
// docs/semi-implicit.md.
#pragma once

#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/loads/drainage.h>
#include <talus/loads/settings.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <string>
#include <vector>

namespace talus::semi_implicit
{
  /// What a body seeds (body k/phase).
  enum class Phase
  {
    saturated, ///< soil and water points over the same region
    soil,      ///< soil points only (dry skeleton)
    water      ///< water points only (free water)
  };

  /// The soil's pore data of one material, from 'material k/pore liquid'
  /// (materials/pore_liquid.h).
  struct SoilData
  {
    double porosity     = 0.3; ///< n_0 [-] ('porosity')
    double conductivity = 0;   ///< hydraulic conductivity k_0 [m/s] (PoreLiquid::hydraulic_conductivity())
  };

  /// Volumetric-locking stabilisation of the soil (seed 002 §4.4.2):
  /// 'numerics/volumetric stabilisation', the shared scene's (transfer/fbar.h).
  using VolumetricStabilisation = transfer::VolumetricStabilisation;

  template <int dim>
  struct Parameters : SceneParameters<dim>, RunParameters<dim>
  {
    std::vector<Phase>    phase_of_body;
    std::vector<SoilData> soil_of_material;
    /// per body: the material ids of its points (a file body: those of its rows)
    std::vector<std::vector<unsigned int>> materials_of_body;
    /// the shared loads (issue 37; boundary_loads.h): 'loads/traction k',
    /// 'loads/velocity k' and 'boundary conditions/drainage k' (after the
    /// drained boundaries of the alias 'semi implicit/drained boundaries')
    std::vector<loads::Traction<dim>>           tractions;
    std::vector<loads::PrescribedVelocity<dim>> velocities;
    std::vector<loads::Drainage<dim>>           drainage;
    /// 'semi implicit/traction acts at': the body surface (true) or the load points
    bool traction_at_surface = true;
    // time step: fixed, or courant x the soil skeleton's critical step
    double time_step = 0, courant = 0.5;
    // 'semi implicit' subsection
    double water_density         = 1000;  ///< rho_w [kg/m^3]
    double unit_weight_gravity   = 9.81;  ///< g of the drag (Eq. 15), kept when the body force is 0
    double free_surface_fraction = 0.5;   ///< a cell is wet when its water volume / cell volume >= this
    double pressure_tolerance    = 1e-10; ///< CG relative residual of the Poisson solve
    /// the ML hierarchy of the Poisson solve is rebuilt at every step that is a
    /// multiple of this (and when the pressure DoF set changes, at checkpoints);
    /// 1: every step
    unsigned int pressure_rebuild_interval = 100;
    bool         kozeny_carman             = false; ///< k = C1 n^3 / (1 - n)^2 (Alg. 8(g))
    bool         pressure_smoothing        = true;  ///< Eq. 77 map-remap of the pore pressure every step
    bool         linear_smoothing          = true;  ///< the map carries each point's value by its gradient
    /// share of the smoothed value in a water point's pore pressure per step (1: Eq. 77,
    /// the point's value replaced; below 1 the point keeps 1 - this of its own value)
    double smoothing_fraction = 1.0;
    /// 'pressure smoothing fraction = automatic': per material and step
    /// min(1, c_v dt / h_min^2) (smoothing_fractions_of_materials)
    bool   automatic_smoothing_fraction = false;
    double flip_fraction                = 1.0; ///< 1: pure FLIP (the paper); the rest PIC
    double patch_size                   = 1.5; ///< side of the modified F-bar patches in cells (Eq. 83)
    /// single: the water is carried on the soil points (its points move with the
    /// soil's velocity, so they stay on them); double: its own points
    bool single_point = false;
    /// one set (with single_point): one point set, each point carrying the soil
    /// and its pore water; every point pass walks it once for both phases
    bool one_set = false;
    /// Nor-Sand specific volume v = v0 Jbar with Jbar the node-smoothed total J
    /// of the soil points (seed 002 Eqs. 96-97), else v = v0 J (Eq. 95)
    bool smoothed_specific_volume = true;
    /// rigid skeleton: v_s = 0 at every node, the soil's terms dropped from the
    /// pressure equation (seepage through a fixed soil)
    bool rigid_skeleton = false;
    /// seed 002 App. B.4: for t < initialisation time gravity ramps from 0, the
    /// soil models are elastic, the water rides on the soil and every soil point
    /// has the conductivity below; at its end the Nor-Sand references are reset
    double initialisation_time         = 0;
    double initialisation_conductivity = 1;
  };

  void declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file);
  template <int dim>
  Parameters<dim> parse_parameters(dealii::ParameterHandler &prm);
  /// --check: parse and validate without grid or points.
  void check_parameters(dealii::ParameterHandler &prm, const std::string &prm_file);
  int  run(dealii::ParameterHandler &prm, const std::string &prm_file);

  /// The critical step of the soil skeleton: min over soil materials of
  /// h / sqrt(E_c / ((1 - n) rho_s)) (the skeleton alone, the fastest wave).
  template <int dim>
  double soil_critical_time_step(const Parameters<dim> &p, double h_min);

  /// Per material: the share of the smoothed pore pressure in a step dt
  /// ('pressure smoothing fraction'): the number given, or (automatic)
  /// min(1, c_v dt / h_min^2) with the consolidation coefficient
  /// c_v = k E_c / (rho_w g) of the material's skeleton (k: `conductivity`, the
  /// initialisation's during the App. B.4 stage); 1 for a material no body seeds
  /// as soil (free water: nothing consolidates).
  template <int dim>
  std::vector<double> smoothing_fractions_of_materials(const Parameters<dim> &p, double dt, double h_min,
                                                       bool initial_stage);

  /// x with 4 significant digits (the numbers in messages).
  std::string number_text(const double x);
} // namespace talus::semi_implicit
