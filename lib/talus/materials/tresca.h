// Tresca elastic-perfectly plastic model in rate form (seed 000 §7.1.2.1):
// isotropic linear elasticity, associated flow, hexagonal prism
//   F = (sigma_1 - sigma_3) - 2 s_u <= 0     (sigma_1 >= sigma_2 >= sigma_3),
// the undrained (total stress) model of clay with undrained shear strength s_u.
// Backward-Euler return in principal stress space with exact face and edge
// returns (principal_return.h). Tension positive; the criterion is sign-free.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class Tresca : public Material
  {
  public:
    Tresca(const double young, const double poisson, const double undrained_shear_strength,
           const std::string &where = "tresca");
    Tresca(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "tresca";
    }
    double
    constrained_modulus() const override
    {
      return K + 4.0 * G / 3.0;
    }
    unsigned int
    n_history() const override
    {
      return 2;
    }
    std::vector<std::string> history_names() const override;
    void                     update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                                           ArrayView<double> history) const override;
    void                     update_stresses(RateUpdate *points, const unsigned int n, const double dt) const override;
    double                   elastic_energy_density(const Stress &sigma) const override;

    enum : unsigned int
    {
      h_plastic_shear_strain = 0, ///< accumulated sqrt(2/3 de^p:de^p) [-]
      h_yield_state          = 1  ///< last step: 0 elastic, 1 face, 2 edge
    };

  private:
    void   setup(const std::string &where);
    double E, nu, su;
    double G, K, lambda;
  };
} // namespace talus::materials
