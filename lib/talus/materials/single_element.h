// talus — single-element (material point) driver: runs one material along a
// homogeneous strain or mixed stress/strain path (seed 002 App. B.2). Used by
// tools/talus-element and by the material unit tests.
//
// Axis x (0) is the axial direction of the triaxial and oedometer paths; y, z are
// lateral. Simple shear shears x along y (grad u = gamma e_x (x) e_y).
// Inside the driver everything is tension positive; the records also carry the
// geotechnical (compression positive) invariants.
#pragma once

#include <talus/materials/material.h>

#include <functional>
#include <string>
#include <vector>

namespace talus::materials
{
  enum class ElementPath
  {
    oedometer,
    isotropic_compression,
    drained_triaxial_compression,
    drained_triaxial_extension,
    undrained_triaxial_compression,
    undrained_triaxial_extension,
    simple_shear
  };

  /// "oedometer|isotropic compression|drained triaxial compression|..."
  std::string element_path_names();
  ElementPath element_path_from_name(const std::string &name);

  struct ElementTestSettings
  {
    ElementPath path          = ElementPath::drained_triaxial_compression;
    bool        finite_strain = false; ///< use finite_strain_update (dF) instead of update_stress
    /// Magnitude (> 0) of the controlled strain at the end of the path: axial strain
    /// (triaxial, oedometer), volumetric strain (isotropic), engineering shear strain
    /// gamma (simple shear). Logarithmic strain in the finite-strain form.
    double       target_strain         = 0.1;
    unsigned int n_increments          = 1000;
    double       time_increment        = 1e-3;  ///< dt per increment [s]
    double       initial_pressure      = 100e3; ///< initial mean effective stress p0' [Pa], compression positive
    double       k0                    = 1.0;   ///< initial lateral / axial effective stress ratio
    double       newton_tolerance      = 1e-11; ///< relative, on the lateral stresses (drained paths)
    unsigned int max_newton_iterations = 50;
  };

  struct ElementRecord
  {
    unsigned int        step = 0;
    double              time = 0;
    Strain              eps;       ///< total strain (small) or logarithmic strain (finite), tension positive
    double              gamma = 0; ///< engineering shear strain of the simple-shear path
    Stress              sigma;     ///< Cauchy stress, tension positive
    std::vector<double> history;
    unsigned int        newton_iterations = 0;

    // geotechnical invariants (compression positive)
    double
    p() const
    {
      return -trace(sigma) / 3.0;
    }
    double q() const; ///< sqrt(3 J2) >= 0
    double
    eps_axial() const
    {
      return -eps[0][0];
    }
    double
    eps_vol() const
    {
      return -trace(eps);
    }
  };

  /// Run the path; `out` is called for the initial state (step 0) and after every
  /// increment. Throws talus::InputError for settings that do not make sense and
  /// InstabilityError when the mixed-control Newton loop does not converge.
  void run_element_test(const Material &material, const ElementTestSettings &settings,
                        const std::function<void(const ElementRecord &)> &out);
} // namespace talus::materials
