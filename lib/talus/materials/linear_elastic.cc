#include <talus/base/errors.h>
#include <talus/materials/linear_elastic.h>

#include <deal.II/base/parameter_handler.h>

namespace talus::materials
{
  LinearElastic::LinearElastic(const double young, const double poisson)
    : E(young)
    , nu(poisson)
  {
    check_isotropic_elasticity(E, nu, "linear elastic");
    two_G       = E / (1 + nu);
    lame_lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  }

  LinearElastic::LinearElastic(dealii::ParameterHandler &prm, const std::string &where)
    : E(prm.get_double("young modulus"))
    , nu(prm.get_double("poisson ratio"))
  {
    check_isotropic_elasticity(E, nu, where);
    two_G       = E / (1 + nu);
    lame_lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  }

  void
  LinearElastic::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e7", dealii::Patterns::Double(), "Young's modulus E [Pa], > 0.");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(), "Poisson's ratio nu [-], -1 < nu < 0.5.");
  }

  double
  LinearElastic::constrained_modulus() const
  {
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  }

  namespace
  {
    // the update of one point, inlined into both the per-point and the per-cell call
    inline DEAL_II_ALWAYS_INLINE void
    elastic_update(const double two_G, const double lame_lambda, const Strain &d_eps, const Spin &d_omega,
                   Stress &sigma)
    {
      const double G      = 0.5 * two_G;
      const double lambda = lame_lambda;
      sigma               = apply_jaumann_rotation(sigma, d_omega);
      const double tr     = trace(d_eps);
      sigma += 2 * G * d_eps;
      for (unsigned int i = 0; i < 3; ++i)
        sigma[i][i] += lambda * tr;
    }
  } // namespace

  void
  LinearElastic::update_stress(const Strain &d_eps,
                               const Spin &  d_omega,
                               const double,
                               Stress &sigma,
                               ArrayView<double>) const
  {
    elastic_update(two_G, lame_lambda, d_eps, d_omega, sigma);
  }

  void
  LinearElastic::update_stresses(RateUpdate *points, const unsigned int n, const double dt) const
  {
    (void)dt;
    for (unsigned int k = 0; k < n; ++k)
      elastic_update(two_G, lame_lambda, points[k].d_eps, points[k].d_omega, points[k].sigma);
  }

  double
  LinearElastic::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }
} // namespace talus::materials
