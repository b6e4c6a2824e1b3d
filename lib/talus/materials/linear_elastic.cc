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
    /// sigma <- Q sigma Q^T + 2 G d_eps + lambda tr(d_eps) I, written to sigma once: writing
    /// the rotated stress entry by entry and reading it back in pairs (as sigma = rotate;
    /// sigma += ...) stalls each pair load on two 8-byte stores (no store-to-load
    /// forwarding), about a fifth of the explicit bench's stress update (docs/scaling.md).
    /// Always inlined: the batch loop of update_stresses() called it out of line
    /// (docs/scaling.md, issue 41).
    [[gnu::always_inline]] inline void
    elastic_rate_update(const double two_G, const double lame_lambda, const Strain &d_eps, const Spin &d_omega,
                        Stress &sigma)
    {
      const double tr      = trace(d_eps);
      const Stress rotated = apply_jaumann_rotation(sigma, d_omega);
      double       out[6];
      for (unsigned int k = 0; k < 6; ++k)
        out[k] = rotated.access_raw_entry(k) + two_G * d_eps.access_raw_entry(k);
      for (unsigned int k = 0; k < 3; ++k)
        out[k] += lame_lambda * tr;
      for (unsigned int k = 0; k < 6; ++k)
        sigma.access_raw_entry(k) = out[k];
    }
  } // namespace

  void
  LinearElastic::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                               ArrayView<double>) const
  {
    elastic_rate_update(two_G, lame_lambda, d_eps, d_omega, sigma);
  }

  void
  LinearElastic::update_stresses(RateUpdate *points, const unsigned int n, const double) const
  {
    for (unsigned int k = 0; k < n; ++k)
      elastic_rate_update(two_G, lame_lambda, points[k].d_eps, points[k].d_omega, points[k].sigma);
  }

  double
  LinearElastic::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }
} // namespace talus::materials
