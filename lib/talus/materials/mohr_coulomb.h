// Mohr-Coulomb elastic-perfectly plastic model in rate form (seed 000 §7.1.2.2):
// isotropic linear elasticity, Mohr-Coulomb yield surface (friction angle phi,
// cohesion c), non-associated Mohr-Coulomb plastic potential with dilatancy angle
// psi, optional Rankine tension cut-off. Backward-Euler return in principal stress
// space with exact treatment of faces, edges and apexes (principal_return.h).
//
// Tension positive in the code: with sigma_1 >= sigma_2 >= sigma_3,
//   F = (sigma_1 - sigma_3) + (sigma_1 + sigma_3) sin(phi) - 2 c cos(phi) <= 0,
//   P = (sigma_1 - sigma_3) + (sigma_1 + sigma_3) sin(psi),
//   tension cut-off: sigma_1 <= T (associated), T <= c cot(phi).
// In geotechnical (compression positive) terms the failure condition of a
// triaxial compression test reads s1' = s3' (1+sin phi)/(1-sin phi) + 2c cos phi/(1-sin phi).
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class MohrCoulomb : public Material
  {
  public:
    /// Angles in degrees; tensile_strength < 0 means "no tension cut-off".
    MohrCoulomb(const double young, const double poisson, const double cohesion, const double friction_angle_deg,
                const double dilatancy_angle_deg, const double tensile_strength = -1.0,
                const std::string &where = "mohr coulomb");
    MohrCoulomb(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "mohr coulomb";
    }
    double
    constrained_modulus() const override
    {
      return K + 4.0 * G / 3.0;
    }
    unsigned int
    n_history() const override
    {
      return 3;
    }
    std::vector<std::string> history_names() const override;
    void                     update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                                           ArrayView<double> history) const override;
    void                     update_stresses(RateUpdate *points, const unsigned int n, const double dt) const override;
    double                   elastic_energy_density(const Stress &sigma) const override;

    double
    shear_modulus() const
    {
      return G;
    }
    double
    bulk_modulus() const
    {
      return K;
    }
    /// Active tension limit T [Pa] (tension positive); +inf when there is none.
    double
    tension_limit() const
    {
      return T;
    }

    /// History slots.
    enum : unsigned int
    {
      h_plastic_shear_strain = 0, ///< accumulated sqrt(2/3 de^p:de^p) [-]
      h_plastic_vol_strain   = 1, ///< accumulated tr(eps^p), dilation positive [-]
      h_yield_state          = 2  ///< last step: 0 elastic, 1 face, 2 edge, 3 corner/apex
    };

  private:
    void setup(const std::string &where);

    double E, nu, c, phi, psi, T_in;
    double G, K, lambda, T;
    bool   has_apex; ///< the MC cone closes at a finite apex (phi > 0)
  };
} // namespace talus::materials
