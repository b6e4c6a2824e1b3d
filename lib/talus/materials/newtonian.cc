#include <talus/materials/liquid_common.h>
#include <talus/materials/newtonian.h>

namespace talus::materials
{
  using namespace internal;

  Newtonian::Newtonian(const double K_, const double mu_, const double p_cav_, const std::string &where)
      : K(K_)
      , mu(mu_)
      , p_cav(p_cav_)
  {
    setup(where);
  }

  Newtonian::Newtonian(dealii::ParameterHandler &prm, const std::string &where)
      : K(prm.get_double("bulk modulus"))
      , mu(prm.get_double("dynamic viscosity"))
      , p_cav(prm.get_double("cavitation threshold"))
  {
    incremental_cavitation = prm.get("cavitation recovery") == "incremental";
    setup(where);
  }

  void
  Newtonian::setup(const std::string &where)
  {
    check_liquid_pressure_parameters(K, p_cav, where);
    require(mu >= 0, where + "/dynamic viscosity", "must be >= 0 (got " + std::to_string(mu) + ")");
  }

  void
  Newtonian::declare_parameters(dealii::ParameterHandler &prm)
  {
    declare_liquid_pressure_parameters(prm);
    prm.declare_entry("dynamic viscosity", "1e-3", dealii::Patterns::Double(),
                      "Dynamic viscosity mu [Pa s], >= 0 (water: 1e-3).");
  }

  void
  Newtonian::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    h[h_volumetric_strain] = trace(sigma) / (3.0 * K); // p0 = -K eps_v0
  }

  void
  Newtonian::update_stress(const Strain &d_eps, const Spin &, const double dt, Stress &sigma, ArrayView<double> h) const
  {
    const double p = update_liquid_pressure(K, h[h_volumetric_strain], trace(d_eps), p_cav, incremental_cavitation);
    if (dt > 0 && p > p_cav)
      sigma = (2.0 * mu / dt) * deviator(d_eps);
    else
      sigma = Stress();
    for (unsigned int i = 0; i < 3; ++i)
      sigma[i][i] -= p;
  }
} // namespace talus::materials
