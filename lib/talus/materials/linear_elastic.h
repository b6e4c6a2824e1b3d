// Linear isotropic elasticity in rate form (seed 000 §7.1.1.1), Jaumann rate.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class LinearElastic : public Material
  {
  public:
    LinearElastic(const double young, const double poisson);
    LinearElastic(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "linear elastic";
    }
    double constrained_modulus() const override;
    void   update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                         ArrayView<double> history) const override;
    void   update_stresses(RateUpdate *points, const unsigned int n, const double dt) const override;
    double elastic_energy_density(const Stress &sigma) const override;

    double
    young_modulus() const
    {
      return E;
    }
    double
    poisson_ratio() const
    {
      return nu;
    }
    double
    shear_modulus() const
    {
      return E / (2 * (1 + nu));
    }
    double
    bulk_modulus() const
    {
      return E / (3 * (1 - 2 * nu));
    }

  private:
    double E, nu;
    double two_G = 0, lame_lambda = 0; // precomputed: the update runs per point and step
  };
} // namespace talus::materials
