#include <talus/base/errors.h>
#include <talus/materials/finite_strain_tools.h>
#include <talus/materials/material.h>
#include <talus/materials/linear_elastic.h>
#include <talus/materials/neo_hookean.h>
#include <talus/materials/nor_sand.h>
#include <talus/materials/hencky_mohr_coulomb.h>
#include <talus/materials/j2_plasticity.h>
#include <talus/materials/mohr_coulomb.h>
#include <talus/materials/tresca.h>
#include <talus/materials/newtonian.h>
#include <talus/materials/bingham.h>
#include <talus/materials/frictional_fluid.h>
#include <talus/materials/modified_cam_clay.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <stdexcept>
#include <map>

namespace talus::materials
{
  void
  Material::finite_strain_update(const dealii::Tensor<2, 3> &, ArrayView<const double>, ArrayView<double>, Stress &,
                                 dealii::Tensor<4, 3> *) const
  {
    throw InputError("material '" + name + "': model '" + model_name() +
                     "' has no finite-strain form; choose one of the finite-strain models");
  }

  namespace
  {
    [[noreturn]] void
    no_split(const Material &m)
    {
      throw std::logic_error("model '" + m.model_name() + "' has no volumetric/deviatoric split");
    }
  } // namespace

  double
  Material::split_pressure(const double) const
  {
    no_split(*this);
  }

  double
  Material::split_dpressure_dJ(const double) const
  {
    no_split(*this);
  }

  double
  Material::split_bulk_modulus() const
  {
    no_split(*this);
  }

  double
  Material::split_shear_modulus() const
  {
    no_split(*this);
  }

  void
  Material::split_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                         ArrayView<double> history_new, Stress &tau_dev, double &J,
                         dealii::Tensor<4, 3> *dtau_dev_ddF) const
  {
    if (!has_volumetric_split())
      no_split(*this);
    Stress tau;
    finite_strain_update(dF, history_old, history_new, tau, dtau_dev_ddF);
    J              = kirchhoff_jacobian(ArrayView<const double>(history_new.data(), history_new.size()));
    const double p = split_pressure(J);
    tau_dev        = tau - J * p * dealii::unit_symmetric_tensor<3>();
    if (!dtau_dev_ddF)
      return;
    // d (J p(J)) / d dF_kl = (p + J p') dJ / d dF_kl, dJ / d dF_kl = J dF^-1_lk
    const double               dJp  = (p + J * split_dpressure_dJ(J)) * J;
    const dealii::Tensor<2, 3> Finv = invert(dF);
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int k = 0; k < 3; ++k)
        for (unsigned int l = 0; l < 3; ++l)
          (*dtau_dev_ddF)[i][i][k][l] -= dJp * Finv[l][k];
  }

  Stress
  Material::finite_strain_step(const dealii::Tensor<2, 3> &dF, ArrayView<double> history) const
  {
    constexpr unsigned int max_history = 64;
    AssertThrow(history.size() <= max_history, dealii::ExcMessage("history too long for a finite-strain step"));
    double old[max_history];
    std::copy(history.begin(), history.end(), old);
    Stress tau;
    finite_strain_update(dF, ArrayView<const double>(old, history.size()), history, tau, nullptr);
    return tau;
  }

  Stress
  Material::finite_strain_rate_update(const Strain &d_eps, const Spin &d_omega, ArrayView<double> history) const
  {
    return finite_strain_step(fs::incremental_deformation_gradient(d_eps, d_omega), history);
  }

  void
  check_isotropic_elasticity(const double E, const double nu, const std::string &where)
  {
    require(E > 0, where + "/young modulus", "must be > 0 (got " + std::to_string(E) + ")");
    require(nu > -1.0 && nu < 0.5, where + "/poisson ratio",
            "must satisfy -1 < nu < 0.5 (got " + std::to_string(nu) + ")");
  }

  double
  checked_increment_jacobian(const dealii::Tensor<2, 3> &dF, const Material &m)
  {
    const double detf = determinant(dF);
    if (!(detf > 0))
      throw InstabilityError("material '" + m.name + "' (" + m.model_name() + "): det dF = " + std::to_string(detf) +
                             " <= 0");
    return detf;
  }

  double
  isotropic_elastic_energy_density(const double E, const double nu, const Stress &s)
  {
    // W = 1/2 sigma : C^-1 : sigma = (1/(2E)) [ (1+nu) s:s - nu tr(s)^2 ]
    return (1.0 / (2 * E)) * ((1 + nu) * scalar_product(s, s) - nu * trace(s) * trace(s));
  }

  double
  Material::elastic_energy_density(const Stress &) const
  {
    return 0.0;
  }

  namespace
  {
    struct ModelEntry
    {
      std::function<void(dealii::ParameterHandler &)>                                           declare;
      std::function<std::unique_ptr<Material>(dealii::ParameterHandler &, const std::string &)> create;
    };

    const std::map<std::string, ModelEntry> &
    registry()
    {
      static const std::map<std::string, ModelEntry> r = {
        {"nor sand",
         {&NorSand::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new NorSand(prm, where));
          }}},
        {"hencky mohr coulomb",
         {&HenckyMohrCoulomb::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new HenckyMohrCoulomb(prm, where));
          }}},
        {"j2 plasticity",
         {&J2Plasticity::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new J2Plasticity(prm, where));
          }}},
        {"neo hookean",
         {&NeoHookean::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new NeoHookean(prm, where));
          }}},
        {"linear elastic",
         {&LinearElastic::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new LinearElastic(prm, where));
          }}},
        {"mohr coulomb",
         {&MohrCoulomb::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new MohrCoulomb(prm, where));
          }}},
        {"tresca",
         {&Tresca::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new Tresca(prm, where));
          }}},
        {"newtonian",
         {&Newtonian::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new Newtonian(prm, where));
          }}},
        {"bingham",
         {&Bingham::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new Bingham(prm, where));
          }}},
        {"frictional fluid",
         {&FrictionalFluid::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new FrictionalFluid(prm, where));
          }}},
        {"modified cam clay",
         {&ModifiedCamClay::declare_parameters,
          [](dealii::ParameterHandler &prm, const std::string &where) {
            return std::unique_ptr<Material>(new ModifiedCamClay(prm, where));
          }}},
      };
      return r;
    }

    std::string
    model_list()
    {
      std::string s;
      for (const auto &[k, v] : registry())
        s += (s.empty() ? "" : "|") + k;
      return s;
    }
  } // namespace

  std::vector<std::string>
  registered_models()
  {
    std::vector<std::string> names;
    for (const auto &[k, v] : registry())
      names.push_back(k);
    return names;
  }

  void
  declare_material_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("model", "linear elastic", dealii::Patterns::Selection(model_list()),
                      "Constitutive model of this material.");
    prm.declare_entry("density", "2000", dealii::Patterns::Double(0.0), "Mass density [kg/m^3], > 0.");
    for (const auto &[k, v] : registry())
      {
        prm.enter_subsection(k);
        v.declare(prm);
        prm.leave_subsection();
      }
  }

  std::unique_ptr<Material>
  create_material(dealii::ParameterHandler &prm, const std::string &where, const unsigned int id)
  {
    const std::string model = prm.get("model");
    const auto        it    = registry().find(model);
    require(it != registry().end(), where, "unknown model '" + model + "'; allowed: " + model_list());
    const double rho = prm.get_double("density");
    require(rho > 0, where + "/density", "must be > 0 (got " + std::to_string(rho) + ")");
    prm.enter_subsection(model);
    auto m = it->second.create(prm, where + "/" + model);
    prm.leave_subsection();
    m->name = where;
    m->id   = id;
    m->set_density(rho);
    return m;
  }
} // namespace talus::materials
