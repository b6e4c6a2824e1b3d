// Modified Cam-Clay (Roscoe & Burland 1968; seed 000 §7.1.1) in rate form.
//
// Geotechnical invariants inside the model (compression positive):
//   p = -tr(sigma)/3,  q = sqrt(3/2 s:s),  eps_v = -tr(eps).
// Yield surface and associated flow:  f = q^2/M^2 + p (p - p_c) <= 0.
// Elasticity: p = p_n exp(d eps_v^e / kappa*) (kappa* = kappa/v, v the specific
// volume at the start of the step) and a shear modulus from a constant Poisson's
// ratio, G = 3 K (1-2nu) / (2(1+nu)) with K = p_n/kappa* at the start of the step.
// Hardening: p_c = p_c,n exp(d eps_v^p / (lambda* - kappa*)).
// Integration: fully implicit (backward Euler) return; the unknowns are the plastic
// volumetric strain increment and the plastic multiplier, solved by a 2x2 Newton
// iteration with analytic Jacobian and line search; q follows in closed form
// (radial return in the deviatoric plane). A step that does not converge is
// split into sub-steps. Objective (Jaumann) rotation of the stress first.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class ModifiedCamClay : public Material
  {
  public:
    ModifiedCamClay(const double M, const double lambda, const double kappa, const double poisson,
                    const double initial_void_ratio, const double ocr, const double min_pressure = 1e3,
                    const std::string &where = "modified cam clay");
    ModifiedCamClay(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "modified cam clay";
    }
    /// Pressure-dependent stiffness: K + 4G/3 evaluated at reference_pressure with
    /// v = 1 + e0 (an upper estimate for the critical time step while p' stays below it).
    double constrained_modulus() const override;
    unsigned int
    n_history() const override
    {
      return 4;
    }
    std::vector<std::string> history_names() const override;
    void                     initialize_history(const Stress &sigma, ArrayView<double> history) const override;
    void                     update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                                           ArrayView<double> history) const override;

    enum : unsigned int
    {
      h_preconsolidation     = 0, ///< p_c [Pa], compression positive
      h_specific_volume      = 1, ///< v = 1 + e [-]
      h_plastic_vol_strain   = 2, ///< accumulated tr(eps^p), dilation positive [-]
      h_plastic_shear_strain = 3  ///< accumulated plastic deviatoric strain eps_q^p [-]
    };

    double
    slope_csl() const
    {
      return M;
    }

    /// Reference pressure for constrained_modulus() [Pa]; drivers can set it to the
    /// largest expected mean effective stress.
    double reference_pressure = 1e6;

  private:
    void setup(const std::string &where);
    /// One implicit step; false if the local Newton iteration did not converge.
    bool integrate(const Strain &d_eps, Stress &sigma, double *h) const;

    double M, lam, kap, nu, e0, ocr, p_min;
  };
} // namespace talus::materials
