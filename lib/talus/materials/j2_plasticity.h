// Finite-strain J2 hyperelastoplasticity with linear isotropic hardening
// (seed 001 §3.2; Simo's multiplicative radial return in b_e form).
//
//  Psi = K U(J) + mu/2 (tr bbar_e - 3),  U(J) = 1/2 [ (J^2 - 1)/2 - ln J ]
//  tau = J p I + s,   J p = K (J^2 - 1)/2,   s = mu dev(bbar_e)
//  f   = ||s|| - sqrt(2/3) (sigma_Y + H alpha) <= 0
//  trial:  bbar_tr = fbar bbar_n fbar^T,  fbar = det(dF)^-1/3 dF
//  return: mubar = mu tr(bbar_tr)/3, dgamma = f_tr / (2 mubar (1 + H/(3 mubar))),
//          s = s_tr - 2 mubar dgamma n,  alpha += sqrt(2/3) dgamma,
//          bbar_e = s/mu + tr(bbar_tr)/3 I                      (seed 001 Algorithm 3)
//  tangent: Eq. 3.93 (spatial, Lie form), converted to d tau / d dF.
// Plastic flow is isochoric, so the elastic and the total Jacobian coincide; J is
// kept in the history. History: bbar_e (6), J, alpha.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class J2Plasticity : public Material
  {
  public:
    J2Plasticity(const double young, const double poisson, const double yield_stress, const double hardening_modulus);
    J2Plasticity(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "j2 plasticity";
    }
    double
    constrained_modulus() const override
    {
      return K + 4.0 * mu / 3.0;
    }

    unsigned int
    n_history() const override
    {
      return 8;
    }
    std::vector<std::string> history_names() const override;
    /// Elastic pre-strain such that tau = sigma (must lie inside the yield surface).
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
    void   finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                                ArrayView<double> history_new, Stress &tau,
                                dealii::Tensor<4, 3> *dtau_ddF) const override;

    double elastic_energy_density(const Stress &sigma) const override;

    /// The split of the mixed u-p driver: J p = K (J^2 - 1)/2, i.e. p(J) = K U'(J)
    /// with the U of the split Neo-Hookean; the yield function depends on s
    /// only and the flow is isochoric (J is the elastic and the total one).
    bool
    has_volumetric_split() const override
    {
      return true;
    }
    double
    split_pressure(const double J) const override
    {
      return 0.5 * K * (J - 1.0 / J);
    }
    double
    split_dpressure_dJ(const double J) const override
    {
      return 0.5 * K * (1.0 + 1.0 / (J * J));
    }
    double
    split_bulk_modulus() const override
    {
      return K;
    }
    double
    split_shear_modulus() const override
    {
      return mu;
    }

    double
    shear_modulus() const
    {
      return mu;
    }
    double
    bulk_modulus() const
    {
      return K;
    }
    double
    yield_stress() const
    {
      return sigma_y;
    }
    double
    hardening_modulus() const
    {
      return H;
    }

  private:
    double E, nu, sigma_y, H, mu, K;
  };
} // namespace talus::materials
