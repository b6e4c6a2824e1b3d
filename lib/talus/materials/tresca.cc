#include <talus/base/errors.h>
#include <talus/materials/principal_return.h>
#include <talus/materials/tresca.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace talus::materials
{
  using namespace internal;

  Tresca::Tresca(const double E_, const double nu_, const double su_, const std::string &where)
      : E(E_)
      , nu(nu_)
      , su(su_)
  {
    setup(where);
  }

  Tresca::Tresca(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , su(prm.get_double("undrained shear strength"))
  {
    setup(where);
  }

  void
  Tresca::setup(const std::string &where)
  {
    check_isotropic_elasticity(E, nu, where);
    require(su > 0, where + "/undrained shear strength", "must be > 0 (got " + std::to_string(su) + ")");
    G      = E / (2 * (1 + nu));
    K      = E / (3 * (1 - 2 * nu));
    lambda = K - 2.0 * G / 3.0;
  }

  void
  Tresca::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e7", dealii::Patterns::Double(),
                      "Young's modulus E [Pa], > 0 (undrained: E_u).");
    prm.declare_entry("poisson ratio", "0.495", dealii::Patterns::Double(),
                      "Poisson's ratio nu [-], -1 < nu < 0.5 (undrained: close to 0.5).");
    prm.declare_entry("undrained shear strength", "20e3", dealii::Patterns::Double(),
                      "Undrained shear strength s_u = tau_f [Pa], > 0; failure at q = sigma_1 - sigma_3 = 2 s_u.");
  }

  std::vector<std::string>
  Tresca::history_names() const
  {
    return {"plastic shear strain", "yield state"};
  }

  void
  Tresca::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                        ArrayView<double> history) const
  {
    sigma           = apply_jaumann_rotation(sigma, d_omega);
    const double tr = trace(d_eps);
    sigma += 2 * G * d_eps;
    for (unsigned int i = 0; i < 3; ++i)
      sigma[i][i] += lambda * tr;

    const Vec3   pv  = principal_values(sigma);
    const double tol = 1e-12 * std::max({std::abs(pv[0]), std::abs(pv[2]), su});
    if (pv[0] - pv[2] - 2 * su <= tol)
      {
        if (history.size() > 0)
          history[h_yield_state] = 0;
        return;
      }
    const Spectral sd    = spectral_decomposition(sigma);
    auto           plane = [&](const unsigned int i, const unsigned int j) {
      PlanarSurface s{{{0, 0, 0}}, 2 * su, {{0, 0, 0}}};
      s.a[i] = s.b[i] = 1;
      s.a[j] = s.b[j] = -1;
      return s;
    };
    const PlanarSurface         cand[3] = {plane(0, 2), plane(1, 2), plane(0, 1)};
    const PlanarSurface         chk[6] = {plane(0, 2), plane(1, 2), plane(0, 1), plane(2, 0), plane(2, 1), plane(1, 0)};
    const PrincipalReturnResult r      = return_to_planar_surfaces(sd.values, lambda, G, cand, 3, chk, 6, tol);
    if (!r.converged)
      throw InstabilityError("tresca: return mapping found no admissible stress");
    if (r.n_active == 0)
      {
        if (history.size() > 0)
          history[h_yield_state] = 0;
        return;
      }
    sigma = compose(r.sigma, sd);
    if (history.size() > 0)
      {
        const double ev = r.dep[0] + r.dep[1] + r.dep[2];
        double       q  = 0;
        for (unsigned int i = 0; i < 3; ++i)
          q += (r.dep[i] - ev / 3) * (r.dep[i] - ev / 3);
        history[h_plastic_shear_strain] += std::sqrt(2.0 / 3.0 * q);
        history[h_yield_state] = r.n_active;
      }
  }

  double
  Tresca::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }
  void
  Tresca::update_stresses(RateUpdate *points, const unsigned int n, const double dt) const
  {
    update_stresses_with(*this, points, n, dt);
  }
} // namespace talus::materials
