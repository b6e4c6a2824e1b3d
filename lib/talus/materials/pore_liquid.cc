#include <talus/base/errors.h>
#include <talus/materials/pore_liquid.h>

#include <sstream>

namespace talus::materials
{
  std::string
  drainage_name(const Drainage d)
  {
    return d == Drainage::coupled ? "coupled" : d == Drainage::undrained ? "undrained" : "drained";
  }

  void
  declare_pore_liquid(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Selection;
    prm.enter_subsection("pore liquid");
    prm.declare_entry("drainage", "drained", Selection("drained|undrained|coupled"),
                      "Pore liquid of this material (seed 000 §4.3.8, §4.5). talus-explicit: 'drained' (1-phase, "
                      "no pore pressure; 'density' is the bulk density), 'undrained' (1-phase effective-stress "
                      "analysis: excess pore pressure dp = -(K_L/n) tr(d eps), total stress = effective - p I; "
                      "'density' is the saturated bulk density), 'coupled' (2-phase single point, §4.5: "
                      "'density' is the density of the solid grains rho_S). talus-semi-implicit: the body's "
                      "'phase' decides (drained and coupled read alike; 'density' is the grain density), "
                      "undrained refused. talus-implicit: drained only.");
    prm.declare_entry("porosity", "0.3", Double(0),
                      "Initial porosity n_0, 0 < n_0 < 1 (talus-explicit: undrained, coupled; "
                      "talus-semi-implicit: the soil's n_0).");
    prm.declare_entry("liquid density", "1000", Double(0),
                      "Density of the pore liquid rho_L [kg/m^3] (talus-explicit: coupled). talus-semi-implicit has "
                      "one water, of 'semi implicit/water density': it refuses another value here.");
    prm.declare_entry("liquid bulk modulus", "2.2e9", Double(0),
                      "Bulk modulus of the pore liquid K_L [Pa] (talus-explicit: undrained, coupled). "
                      "talus-semi-implicit's water is incompressible: it refuses a value other than the default.");
    prm.declare_entry("liquid viscosity", "1e-3", Double(0),
                      "Dynamic viscosity of the pore liquid mu_d [Pa s] (coupled; the conversion of the "
                      "intrinsic permeability).");
    prm.declare_entry("intrinsic permeability", "1e-10", Double(0),
                      "Intrinsic permeability kappa [m^2]; the hydraulic conductivity is k = kappa rho_L g / mu_d "
                      "(Eq. 3.25; the defaults give 9.81e-4 m/s) unless 'hydraulic conductivity' is given.");
    prm.declare_entry("hydraulic conductivity", "0", Double(0),
                      "The hydraulic conductivity (Darcy permeability) k [m/s]; when > 0 it is used and "
                      "'intrinsic permeability' is not (talus-explicit: kappa = k mu_d / (rho_L g)); 0: "
                      "k = kappa rho_L g / mu_d.");
    prm.declare_entry("permeability gravity", "9.81", Double(0),
                      "g of Eq. 3.25 [m/s^2], independent of the gravity vector (a consolidation test "
                      "without body force still has k = kappa rho_L g / mu_d).");
    prm.leave_subsection();
  }

  PoreLiquid
  read_pore_liquid(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("pore liquid");
    PoreLiquid        p;
    const std::string d = prm.get("drainage");
    p.drainage     = d == "coupled" ? Drainage::coupled : d == "undrained" ? Drainage::undrained : Drainage::drained;
    p.porosity     = prm.get_double("porosity");
    p.density      = prm.get_double("liquid density");
    p.bulk_modulus = prm.get_double("liquid bulk modulus");
    p.viscosity    = prm.get_double("liquid viscosity");
    p.intrinsic_permeability = prm.get_double("intrinsic permeability");
    p.conductivity           = prm.get_double("hydraulic conductivity");
    p.gravity                = prm.get_double("permeability gravity");
    prm.leave_subsection();
    return p;
  }

  void
  check_porosity(const PoreLiquid &p, const std::string &where)
  {
    std::ostringstream n;
    n << p.porosity;
    require(p.porosity > 0 && p.porosity < 1, where + "/porosity", "is " + n.str() + "; must satisfy 0 < n < 1");
  }

  void
  check_seepage(const PoreLiquid &p, const std::string &where)
  {
    require(p.density > 0, where + "/liquid density", "must be > 0");
    require(p.viscosity > 0, where + "/liquid viscosity", "must be > 0");
    require(p.gravity > 0, where + "/permeability gravity", "must be > 0");
    if (p.conductivity <= 0)
      require(p.intrinsic_permeability > 0, where + "/intrinsic permeability",
              "must be > 0 (or give 'hydraulic conductivity' > 0)");
  }
} // namespace talus::materials
