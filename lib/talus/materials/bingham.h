// Bingham visco-plastic liquid (seed 000 §7.2.2): linear elastic in shear (E, nu)
// while the equivalent shear stress sqrt(s:s/2) stays below the yield stress
// tau_y; beyond it viscous with the capped effective viscosity
//     mu_eff = min(mu + tau_y / gamma_dot, mu_max),  gamma_dot = sqrt(2 D':D'),
// so that in steady simple shear tau = tau_y + mu gamma_dot. The pressure follows
// the weakly compressible liquid with cavitation (liquid_common.h). The elastic
// deviatoric stress is carried in sigma and Jaumann-rotated.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class Bingham : public Material
  {
  public:
    Bingham(const double young, const double poisson, const double bulk_modulus, const double yield_stress,
            const double viscosity, const double max_viscosity, const double cavitation_pressure,
            const std::string &where = "bingham");
    Bingham(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    /// Eq. 7.33 (default) or the density form after cavitation ("cavitation
    /// recovery", see liquid_common.h)
    bool incremental_cavitation = true;

    std::string
    model_name() const override
    {
      return "bingham";
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
      h_volumetric_strain   = 0, ///< accumulated tr(d eps) [-], tension positive
      h_effective_viscosity = 1  ///< mu_eff of the last step [Pa s]; 0 when solid-like
    };

  private:
    void   setup(const std::string &where);
    double E, nu, K, tau_y, mu, mu_max, p_cav;
    double G;
  };
} // namespace talus::materials
