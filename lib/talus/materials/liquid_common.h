// talus — pieces shared by the liquid models (Newtonian, Bingham, frictional
// fluid), seed 000 §7.2. Internal to talus_materials.
//
// Pressure (compression positive) of a weakly compressible liquid with a
// cavitation threshold p_c (seed 000 Eqs. 7.30-7.33): the pressure is a state
// function of the accumulated volumetric strain eps_v (tension positive),
//     p = max(p_c, -K eps_v),
// so a liquid stretched beyond cavitation keeps p = p_c until the cavitated
// volume has been recompressed (the density-based form of Eq. 7.32), rather than
// restarting from p_c at the first compressive increment.
#pragma once

#include <talus/base/errors.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/symmetric_tensor.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace talus::materials::internal
{
  inline double
  liquid_pressure(const double K, const double eps_v, const double p_cav)
  {
    return std::max(p_cav, -K * eps_v);
  }

  /// Add the volumetric strain increment and return the pressure. With
  /// `incremental` (seed 000 Eq. 7.33, dp = -K d eps_v with p >= p_cav) the stored
  /// strain is clamped at the cavitation strain -p_cav / K, so a cavitated liquid
  /// builds pressure again at its first compression; otherwise (the density form
  /// of Eqs. 7.30-7.32) it stays at p_cav until the cavitated volume is closed.
  /// In an MPM flow the integrated point volumes drift (a spreading layer gains
  /// volume), and the density form then keeps most points of a dam break cavitated
  /// (measured: 1273 of 1600 at T = 1.19 vs 319 with the incremental form).
  inline double
  update_liquid_pressure(const double K, double &eps_v, const double d_eps_v, const double p_cav,
                         const bool incremental)
  {
    eps_v += d_eps_v;
    if (incremental && -K * eps_v < p_cav)
      eps_v = -p_cav / K;
    return liquid_pressure(K, eps_v, p_cav);
  }

  /// Engineering shear rate gamma_dot = sqrt(2 D':D') of the deviatoric rate D'
  /// (simple shear with rate g gives gamma_dot = g), and the equivalent shear
  /// stress tau = sqrt(s:s / 2) (simple shear stress tau gives tau).
  inline double
  shear_rate(const dealii::SymmetricTensor<2, 3> &Ddev)
  {
    return std::sqrt(2.0 * scalar_product(Ddev, Ddev));
  }
  inline double
  equivalent_shear_stress(const dealii::SymmetricTensor<2, 3> &s)
  {
    return std::sqrt(0.5 * scalar_product(s, s));
  }

  /// Deviatoric stress of the visco-plastic liquids (Bingham, frictional fluid;
  /// seed 000 §7.2.2-7.2.3). Solid-like (linear elastic, shear modulus G) while
  /// the elastic trial stays at or below the yield stress tau_y; otherwise viscous
  /// with the effective viscosity mu_eff = min(mu + tau_y / gamma_dot, mu_max), so
  /// that in steady simple shear tau = tau_y + mu gamma_dot (until the cap). A
  /// cavitated liquid carries no deviatoric stress. mu_eff is 0 when solid-like.
  inline dealii::SymmetricTensor<2, 3>
  viscoplastic_deviator(const dealii::SymmetricTensor<2, 3> &s_old, const dealii::SymmetricTensor<2, 3> &d_eps,
                        const double dt, const double G, const double tau_y, const double mu, const double mu_max,
                        const bool cavitated, double &mu_eff)
  {
    mu_eff = 0.0;
    if (cavitated)
      return dealii::SymmetricTensor<2, 3>();
    const dealii::SymmetricTensor<2, 3> de    = deviator(d_eps);
    const dealii::SymmetricTensor<2, 3> trial = s_old + 2.0 * G * de;
    if (equivalent_shear_stress(trial) <= tau_y || !(dt > 0))
      return trial;
    const dealii::SymmetricTensor<2, 3> Ddev = de / dt;
    const double                        gd   = shear_rate(Ddev);
    mu_eff                                   = (gd > 0) ? std::min(mu + tau_y / gd, mu_max) : mu_max;
    return 2.0 * mu_eff * Ddev;
  }

  inline void
  declare_liquid_pressure_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("bulk modulus", "2.2e9", dealii::Patterns::Double(),
                      "Bulk modulus of the liquid K_L [Pa], > 0 (dp = -K_L tr(d eps), p compression positive).");
    prm.declare_entry("cavitation threshold", "0", dealii::Patterns::Double(),
                      "Cavitation pressure p_cav [Pa], <= 0 (compression positive): the pressure never "
                      "drops below it; while cavitated the deviatoric stress is zero.");
    prm.declare_entry("cavitation recovery", "incremental", dealii::Patterns::Selection("incremental|volumetric"),
                      "After cavitation: 'incremental' (seed 000 Eq. 7.33: dp = -K_L tr(d eps), p >= p_cav; the "
                      "pressure rises at the first compression) or 'volumetric' (p = max(p_cav, -K_L eps_v) of "
                      "the accumulated volumetric strain: stays at p_cav until the cavitated volume is "
                      "recompressed).");
  }

  inline void
  check_liquid_pressure_parameters(const double K, const double p_cav, const std::string &where)
  {
    require(K > 0, where + "/bulk modulus", "must be > 0 (got " + std::to_string(K) + ")");
    require(p_cav <= 0, where + "/cavitation threshold",
            "must be <= 0 (compression positive; got " + std::to_string(p_cav) + ")");
  }
} // namespace talus::materials::internal
