#include <talus/materials/bingham.h>
#include <talus/materials/liquid_common.h>

namespace talus::materials
{
  using namespace internal;

  Bingham::Bingham(const double E_, const double nu_, const double K_, const double tau_y_, const double mu_,
                   const double mu_max_, const double p_cav_, const std::string &where)
      : E(E_)
      , nu(nu_)
      , K(K_)
      , tau_y(tau_y_)
      , mu(mu_)
      , mu_max(mu_max_)
      , p_cav(p_cav_)
  {
    setup(where);
  }

  Bingham::Bingham(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , K(prm.get_double("bulk modulus"))
      , tau_y(prm.get_double("yield stress"))
      , mu(prm.get_double("dynamic viscosity"))
      , mu_max(prm.get_double("maximum viscosity"))
      , p_cav(prm.get_double("cavitation threshold"))
  {
    incremental_cavitation = prm.get("cavitation recovery") == "incremental";
    setup(where);
  }

  void
  Bingham::setup(const std::string &where)
  {
    check_isotropic_elasticity(E, nu, where);
    check_liquid_pressure_parameters(K, p_cav, where);
    require(tau_y >= 0, where + "/yield stress", "must be >= 0 (got " + std::to_string(tau_y) + ")");
    require(mu >= 0, where + "/dynamic viscosity", "must be >= 0 (got " + std::to_string(mu) + ")");
    require(mu_max > 0 && mu_max >= mu, where + "/maximum viscosity",
            "must be > 0 and >= the dynamic viscosity (got " + std::to_string(mu_max) + ")");
    G = E / (2 * (1 + nu));
  }

  void
  Bingham::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e6", dealii::Patterns::Double(),
                      "Young's modulus E [Pa], > 0, of the solid-like (unyielded) state; gives G = E/(2(1+nu)).");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(), "Poisson's ratio nu [-], -1 < nu < 0.5.");
    declare_liquid_pressure_parameters(prm);
    prm.declare_entry("yield stress", "100", dealii::Patterns::Double(),
                      "Bingham yield stress tau_y [Pa], >= 0 (equivalent shear stress sqrt(s:s/2)).");
    prm.declare_entry("dynamic viscosity", "1", dealii::Patterns::Double(),
                      "Plastic (Bingham) viscosity mu [Pa s], >= 0.");
    prm.declare_entry("maximum viscosity", "1e4", dealii::Patterns::Double(),
                      "Cap mu_max [Pa s] on the effective viscosity mu + tau_y/gamma_dot (low shear rates), >= mu.");
  }

  void
  Bingham::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    h[h_volumetric_strain]   = trace(sigma) / (3.0 * K);
    h[h_effective_viscosity] = 0;
  }

  void
  Bingham::update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                         ArrayView<double> h) const
  {
    const Stress s_old = deviator(apply_jaumann_rotation(sigma, d_omega));
    const double p     = update_liquid_pressure(K, h[h_volumetric_strain], trace(d_eps), p_cav, incremental_cavitation);
    double       mu_eff;
    sigma                    = viscoplastic_deviator(s_old, d_eps, dt, G, tau_y, mu, mu_max, !(p > p_cav), mu_eff);
    h[h_effective_viscosity] = mu_eff;
    for (unsigned int i = 0; i < 3; ++i)
      sigma[i][i] -= p;
  }
} // namespace talus::materials
