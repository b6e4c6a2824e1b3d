// talus — 'material k/pore liquid': the pore liquid of a material, one section
// for every family (issue 37: one vocabulary; docs/boundary-conditions.md,
// "Pore liquid"). Declared and read here; each family checks and honours what
// it can and refuses the rest (exit 2, the entry and the reason):
//   talus-explicit       drained | undrained (1-phase effective stress) |
//                        coupled (2-phase single point), seed 000 §3.4, §4.5
//   talus-semi-implicit  porosity and hydraulic conductivity of the soil (the
//                        body's 'phase' decides what is seeded; undrained refused)
//   talus-implicit       drained only (a 1-phase solid family)
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace talus::materials
{
  enum class Drainage
  {
    drained,   ///< 1-phase, no pore pressure (dry, or drained with zero excess pressure)
    undrained, ///< 1-phase effective-stress analysis, Eq. 4.52 (pore pressure from the volumetric strain)
    coupled    ///< 2-phase (talus-explicit: single material point, §3.4, §4.5)
  };

  /// "drained", "undrained", "coupled"
  std::string drainage_name(Drainage d);

  /// The entries of one material's 'pore liquid' (defaults as declared).
  struct PoreLiquid
  {
    Drainage drainage               = Drainage::drained;
    double   porosity               = 0.3;   ///< n_0 [-]
    double   density                = 1000;  ///< 'liquid density' rho_L [kg/m^3]
    double   bulk_modulus           = 2.2e9; ///< 'liquid bulk modulus' K_L [Pa]
    double   viscosity              = 1e-3;  ///< 'liquid viscosity' mu_d [Pa s]
    double   intrinsic_permeability = 1e-10; ///< kappa [m^2]
    double   conductivity           = 0;     ///< the entry 'hydraulic conductivity' [m/s]; 0: from kappa
    double   gravity                = 9.81;  ///< 'permeability gravity', g of Eq. 3.25 [m/s^2]

    /// The hydraulic conductivity (Darcy permeability) k [m/s]: the entry
    /// 'hydraulic conductivity' when > 0, else kappa rho_L g / mu_d (Eq. 3.25).
    double
    hydraulic_conductivity() const
    {
      return conductivity > 0 ? conductivity : intrinsic_permeability * density * gravity / viscosity;
    }
  };

  /// Declares the subsection 'pore liquid' inside the current 'material k'.
  void declare_pore_liquid(dealii::ParameterHandler &prm);

  /// Reads the subsection 'pore liquid' of the current 'material k' (no checks).
  PoreLiquid read_pore_liquid(dealii::ParameterHandler &prm);

  /// InputError naming `where`/porosity unless 0 < n < 1 (`where`: "material k/pore liquid").
  void check_porosity(const PoreLiquid &p, const std::string &where);

  /// The entries of a seeping liquid: liquid density, liquid viscosity and
  /// permeability gravity > 0, and a hydraulic conductivity > 0 (the entry, or
  /// from a positive intrinsic permeability); InputError naming the entry.
  void check_seepage(const PoreLiquid &p, const std::string &where);
} // namespace talus::materials
