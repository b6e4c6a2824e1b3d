// Weakly compressible Newtonian liquid with a cavitation threshold (seed 000
// §7.2.1): sigma = -p I + 2 mu D', with D' the deviatoric rate of deformation
// (d_eps/dt) and p = max(p_cav, -K_L eps_v) (see liquid_common.h). The deviatoric
// stress vanishes while the liquid is cavitated (p = p_cav). The stress carries no
// memory of its deviatoric part, so the Jaumann rotation has nothing to rotate.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class Newtonian : public Material
  {
  public:
    Newtonian(const double bulk_modulus, const double viscosity, const double cavitation_pressure,
              const std::string &where = "newtonian");
    Newtonian(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    /// Eq. 7.33 (default) or the density form after cavitation ("cavitation
    /// recovery", see liquid_common.h)
    bool incremental_cavitation = true;

    std::string
    model_name() const override
    {
      return "newtonian";
    }
    double
    constrained_modulus() const override
    {
      return K;
    }
    double
    dynamic_viscosity() const override
    {
      return mu;
    }
    unsigned int
    n_history() const override
    {
      return 1;
    }
    std::vector<std::string>
    history_names() const override
    {
      return {"volumetric strain"};
    }
    void initialize_history(const Stress &sigma, ArrayView<double> history) const override;
    void update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                       ArrayView<double> history) const override;

    enum : unsigned int
    {
      h_volumetric_strain = 0 ///< accumulated tr(d eps) [-], tension positive
    };

  private:
    void   setup(const std::string &where);
    double K, mu, p_cav;
  };
} // namespace talus::materials
