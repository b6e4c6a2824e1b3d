// Finite-strain Mohr-Coulomb plasticity with Hencky (logarithmic) elasticity
// (seed 001 §3.3): return to plane / line (edge) / apex in principal Kirchhoff
// stress space, consistent tangent Eq. 3.145.
//
//  Psi = lambda/2 (tr eps_e)^2 + mu eps_e : eps_e,  eps_e = 1/2 ln b_e   (Eq. 3.99)
//  principal: tau_A = a eps_A, a = lambda 1 1^T + 2 mu I                  (Eq. 3.103)
//  sorted tau_1 >= tau_2 >= tau_3 (tension positive):
//    f = k tau_1 - tau_3 - 2 c sqrt(k),  g = m tau_1 - tau_3,
//    k = (1 + sin phi)/(1 - sin phi),  m = (1 + sin psi)/(1 - sin psi)
//  Trial state from b_tr = dF b_e,n dF^T; perfectly plastic; the return is exact
//  (linear in the trial log strains within each region).
// Repeated principal stretches: the spin part of the tangent uses
// (tau_A - tau_B)/(x_A - x_B) and, for |x_A - x_B| <= 1e-8 max x, its analytic
// limit (continuous at coincidence), see fs::isotropic_derivative.
// History: b_e (6), J (total volume ratio), accumulated plastic strain, return
// region (0 elastic, 1 plane, 2 edge tau_1 = tau_2, 3 edge tau_2 = tau_3, 4 apex).
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class HenckyMohrCoulomb : public Material
  {
  public:
    HenckyMohrCoulomb(const double young, const double poisson, const double cohesion, const double friction_angle_deg,
                      const double dilatancy_angle_deg);
    HenckyMohrCoulomb(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "hencky mohr coulomb";
    }
    double
    constrained_modulus() const override
    {
      return lambda + 2 * mu;
    }

    unsigned int
    n_history() const override
    {
      return 9;
    }
    std::vector<std::string> history_names() const override;
    /// Elastic pre-strain with tau = sigma; throws InputError if sigma violates f <= 0.
    void initialize_history(const Stress &sigma, ArrayView<double> history) const override;

    /// Rate form: dF = I + d_eps + d_omega, finite-strain update, sigma = tau / J.
    void update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                       ArrayView<double> history) const override;

    bool
    has_finite_strain_form() const override
    {
      return true;
    }

    double kirchhoff_jacobian(ArrayView<const double> history) const override;
    /// J^e = sqrt(det b_e) of the history's elastic left Cauchy-Green tensor
    /// (the modified F-bar of the semi-implicit family, seed 002 Eq. 82).
    double elastic_jacobian(ArrayView<const double> history) const override;
    bool
    keeps_elastic_b() const override
    {
      return true;
    }
    void finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                              ArrayView<double> history_new, Stress &tau,
                              dealii::Tensor<4, 3> *dtau_ddF) const override;

    double elastic_energy_density(const Stress &sigma) const override;

    /// Return mapping in principal space (sorted descending trial log strains):
    /// principal tau, d tau_A / d eps_tr_B and the region (0..4 as above).
    int principal_return(const double eps_tr[3], double tau[3], double D[3][3]) const;

    double yield_function(const double tau_sorted[3]) const;
    double
    shear_modulus() const
    {
      return mu;
    }
    double
    lame_lambda() const
    {
      return lambda;
    }

  private:
    void   setup(const std::string &where);
    double E, nu, c, phi, psi, lambda, mu, k, m, sqk, tau_apex;
  };
} // namespace talus::materials
