// Nor-Sand (Jefferies 1993) in the finite-strain hyperelastic-plastic form of
// Borja & Andrade (2006), with the large-deformation modifications of seed 002
// App. B: dilatancy cut-off (Eq. 92), gas-like cut-off (Eq. 93) and the
// initialisation of App. B.4 (Eq. 113).
//
// Tension positive; p = tr(tau)/3 < 0 in compression, q = sqrt(3/2) ||dev tau||.
//  Elastic (log strains eps_e = 1/2 ln b_e, eps_v = tr eps_e, e = dev eps_e):
//    p = p_ref exp(-(eps_v - eps_v,ref)/kappa),  dev tau = 2 G e
//    (the coupling term alpha_0 of Borja & Andrade is not used: G constant, Table 6)
//  Yield / potential (N, Nbar in (0,1)):
//    F = q + eta(p, p_i) p,   eta = M/N [1 - (1-N)(p/p_i)^(N/(1-N))]
//    Q = q + etabar(p, p_i) p  with Nbar,  dQ/dp = M/Nbar [1 - (p/p_i)^(Nbar/(1-Nbar))]
//  Hardening:  dp_i = h (p_i* - p_i) d eps_s^p,
//    p_i* = p (1 - N alpha psi_i / M)^((N-1)/N),  psi_i = v - v_c0 + lambda ln(-p_i / p_unit)
//    (alpha < 0: D* = alpha psi_i, dilation positive), v = v_0 J.
//  Return mapping: implicit (backward Euler) in the invariants of the trial
//  elastic log strain, unknowns (eps_v, dlambda, p_i), 3x3 Newton; deviatoric
//  direction fixed (circular cone, M independent of the Lode angle); consistent
//  principal moduli by implicit differentiation, spatial tangent as Eq. 3.145.
//  Tip of the yield surface (q = 0 reached, isotropic compression beyond the tip):
//  q = 0, p on the tip, hardening driven by eps_s^tr; tangent by central
//  differences in principal space (rare branch).
// History: b_e (6), J, v, p_i, Ebar_d^p, psi_i at cut-off start, p_ref, eps_v,ref.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class NorSand : public Material
  {
  public:
    struct Parameters
    {
      double G          = 40e6;  ///< shear modulus [Pa]
      double kappa      = 0.002; ///< elastic compressibility (swelling index) [-]
      double lambda     = 0.02;  ///< slope of the CSL in v - ln p [-]
      double v_c0       = 1.892; ///< CSL specific volume at p = p_unit [-]
      double M          = 1.0;   ///< critical state stress ratio [-]
      double N          = 0.1;   ///< yield function constant [-]
      double N_bar      = 0.1;   ///< plastic potential constant [-]
      double h          = 100;   ///< hardening coefficient [-]
      double alpha      = -2.0;  ///< multiplier of the maximum plastic dilatancy [-]
      double v0         = 2.0;   ///< initial specific volume [-]
      double p0         = 2e3;   ///< initial reference pressure (compression +) [Pa]
      double eps_v0     = 0.0;   ///< elastic volumetric strain at p0 [-]
      double ocr        = 1.0;   ///< overconsolidation ratio [-]
      double p_unit     = 1.0;   ///< pressure unit of the CSL logarithm [Pa]
      double cut_start  = 1.0;   ///< dilatancy cut-off start, Ebar_d^p [-]
      double cut_end    = 1.5;   ///< dilatancy cut-off end, Ebar_d^p [-]
      double gas_factor = 1.6;   ///< gas-like cut-off v_crit = gas_factor v0 [-]
    };

    explicit NorSand(const Parameters &p);
    NorSand(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "nor sand";
    }
    /// K + 4/3 G at the reference pressure, K = p0 / kappa.
    double constrained_modulus() const override;

    unsigned int
    n_history() const override
    {
      return 13;
    }
    /// history slot of the specific volume v (= v0 J unless a caller sets it)
    static constexpr unsigned int specific_volume_slot = 7;
    std::vector<std::string>      history_names() const override;
    /// sigma = 0: isotropic state at p0 (reference), eps_v,ref; p_i from Eq. 113
    /// with the OCR. sigma != 0: reference pressure p_ref = tr(sigma)/3, deviatoric
    /// elastic strain dev(sigma)/(2G), p_i = OCR x the image pressure of the yield
    /// surface through sigma (Eq. 113 for q = 0).
    void initialize_history(const Stress &sigma, ArrayView<double> history) const override;
    /// App. B.4: after elastic gravity loading, take the current p and eps_v as the
    /// reference, p_i from the OCR (Eq. 113) and v0 <- J v0 (kept in the history).
    /// Returns true.
    bool reinitialize_reference(ArrayView<double> history) const override;
    /// The App. B.4 stage's model: this one without plasticity.
    std::shared_ptr<const Material> initialisation_model() const override;
    bool
    has_specific_volume() const override
    {
      return true;
    }
    /// history[specific_volume_slot] = v0 J / det_increment
    void
    set_specific_volume(const double J, const double det_increment, ArrayView<double> history) const override
    {
      history[specific_volume_slot] = P.v0 * J / det_increment;
    }
    /// Elastic only (App. B.4 gravity phase) when false.
    void
    set_plasticity(const bool on)
    {
      plastic = on;
    }

    void update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                       ArrayView<double> history) const override;

    bool
    has_finite_strain_form() const override
    {
      return true;
    }

    double kirchhoff_jacobian(ArrayView<const double> history) const override;
    /// J^e = sqrt(det b_e) of the history's elastic left Cauchy-Green tensor
    /// (the modified F-bar of the semi-implicit family, seed 002 Eq. 82).
    double elastic_jacobian(ArrayView<const double> history) const override;
    bool
    keeps_elastic_b() const override
    {
      return true;
    }
    void finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                              ArrayView<double> history_new, Stress &tau,
                              dealii::Tensor<4, 3> *dtau_ddF) const override;

    const Parameters &
    parameters() const
    {
      return P;
    }
    /// Image pressure on the yield surface through (p, q) (p < 0).
    double image_pressure_through(const double p, const double q) const;

    struct State
    {
      double pi, Ed, psi_start, p_ref, ev_ref, v;
    };
    /// Principal map: sorted trial log strains -> principal tau, d tau/d eps_tr
    /// (if D != nullptr), updated state; returns 0 elastic, 1 plastic, 2 tip.
    int principal_update(const double eps[3], const State &s0, double tau[3], double (*D)[3], State &s1) const;

  private:
    void       check(const std::string &where) const;
    Parameters P;
    bool       plastic = true;
  };
} // namespace talus::materials
