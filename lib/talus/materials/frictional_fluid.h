// Frictional fluid (seed 000 §7.2.3): the Bingham model of bingham.h with a
// pressure-dependent (Drucker-Prager type) yield stress
//     tau_y = max(p, 0) sin(phi),
// p the liquid pressure (compression positive). Solid-like (elastic E, nu) below
// it, viscous with mu_eff = min(mu + tau_y / gamma_dot, mu_max) above it.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class FrictionalFluid : public Material
  {
  public:
    FrictionalFluid(const double young, const double poisson, const double bulk_modulus,
                    const double friction_angle_deg, const double viscosity, const double max_viscosity,
                    const double cavitation_pressure, const std::string &where = "frictional fluid");
    FrictionalFluid(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    /// Eq. 7.33 (default) or the density form after cavitation ("cavitation
    /// recovery", see liquid_common.h)
    bool incremental_cavitation = true;

    std::string
    model_name() const override
    {
      return "frictional fluid";
    }
    double
    constrained_modulus() const override
    {
      return K + 4.0 * G / 3.0;
    }
    double
    dynamic_viscosity() const override
    {
      return mu_max;
    }
    unsigned int
    n_history() const override
    {
      return 2;
    }
    std::vector<std::string>
    history_names() const override
    {
      return {"volumetric strain", "effective viscosity"};
    }
    void initialize_history(const Stress &sigma, ArrayView<double> history) const override;
    void update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                       ArrayView<double> history) const override;

    enum : unsigned int
    {
      h_volumetric_strain   = 0,
      h_effective_viscosity = 1
    };

  private:
    void   setup(const std::string &where);
    double E, nu, K, phi, mu, mu_max, p_cav;
    double G, sin_phi;
  };
} // namespace talus::materials
