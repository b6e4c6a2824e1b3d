// Compressible Neo-Hookean hyperelasticity (seed 001 §3.1), finite-strain form,
// with the volumetric/deviatoric split used by the mixed u-p formulation.
//
//  * "coupled" energy (seed 001 Eq. 3.17):
//        Psi = lambda/2 (ln J)^2 - mu ln J + mu/2 (tr C - 3)
//        tau = lambda ln J I + mu (b - I)                              (Eq. 3.25)
//  * "split" energy (seed 001 Eq. 3.43) with the stated volumetric function
//        Psi = K U(J) + mu/2 (tr(J^-2/3 C) - 3),
//        U(J) = 1/2 [ (J^2 - 1)/2 - ln J ],  U'(J) = (J - 1/J)/2,  U''(J) = (1 + J^-2)/2
//        tau = J p I + mu dev(bbar),  p = K U'(J),  bbar = J^-2/3 b   (Eq. 3.44)
//    U is convex, U(1) = U'(1) = 0, U''(1) = 1 and U -> inf for J -> 0 and J -> inf.
// History: the left Cauchy-Green tensor b = F F^T (6 values). Tension positive.
#pragma once

#include <talus/materials/material.h>

namespace talus::materials
{
  class NeoHookean : public Material
  {
  public:
    enum class Energy
    {
      coupled,
      split
    };

    NeoHookean(const double young, const double poisson, const Energy energy = Energy::coupled);
    NeoHookean(dealii::ParameterHandler &prm, const std::string &where);

    static void declare_parameters(dealii::ParameterHandler &prm);

    std::string
    model_name() const override
    {
      return "neo hookean";
    }
    double
    constrained_modulus() const override
    {
      return lambda + 2 * mu;
    }

    unsigned int
    n_history() const override
    {
      return 6;
    }
    std::vector<std::string> history_names() const override;
    /// Sets b such that the Cauchy stress tau(b) / J(b) is sigma (the given
    /// stress is that of the initial state); sigma = 0 gives b = I.
    void initialize_history(const Stress &sigma, ArrayView<double> history) const override;

    /// Rate form: dF = I + d_eps + d_omega, then the finite-strain update; the
    /// returned Cauchy stress is tau / J with J = sqrt(det b).
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

    double elastic_energy_density(const Stress &sigma) const override;

    /// Kirchhoff stress for a given b (energy as configured).
    Stress kirchhoff_stress(const Stress &b) const;

    // ---- Volumetric / deviatoric split for the mixed u-p driver (seed 001 §3.1,
    // Eqs. 3.43-3.52), always with the U(J) stated above.
    /// K U(J) [Pa]
    double volumetric_energy(const double J) const;
    /// Pressure (mean Cauchy stress, tension positive) p = K U'(J) [Pa]
    double pressure(const double J) const;
    /// dp/dJ = K U''(J) [Pa]
    double dpressure_dJ(const double J) const;
    /// Kirchhoff pressure J p = J K U'(J) [Pa]
    double
    kirchhoff_pressure(const double J) const
    {
      return J * pressure(J);
    }
    /// Deviatoric Kirchhoff stress mu dev(J^-2/3 b).
    Stress deviatoric_kirchhoff_stress(const Stress &b) const;
    /// Spatial tangent of the deviatoric part (Eq. 3.52):
    ///   c_dev = 2/3 mu tr(bbar) I_dev - 2/3 (tau_dev (x) I + I (x) tau_dev)
    dealii::Tensor<4, 3> deviatoric_spatial_tangent(const Stress &b) const;
    /// Spatial tangent of the volumetric part at fixed pressure p (Eq. 3.51):
    ///   c_vol = J p (I (x) I - 2 I_sym)
    /// (the full displacement-form tangent adds J^2 dp/dJ I (x) I).
    static dealii::Tensor<4, 3> volumetric_spatial_tangent(const double J, const double p);
    /// The split of the mixed u-p driver (Material::split_update): with the
    /// split energy, p(J) = K U'(J) above.
    bool
    has_volumetric_split() const override
    {
      return energy_form == Energy::split;
    }
    double
    split_pressure(const double J) const override
    {
      return pressure(J);
    }
    double
    split_dpressure_dJ(const double J) const override
    {
      return dpressure_dJ(J);
    }
    double
    split_bulk_modulus() const override
    {
      return bulk_modulus();
    }
    double
    split_shear_modulus() const override
    {
      return mu;
    }
    /// tau_dev = mu dev(J^-2/3 b) and its tangent (Eq. 3.52) computed directly,
    /// not as tau - J p I: at nu = 0.499999 (K/G = 5e5) the difference would
    /// lose 6 digits (the u-p tangent test at that nu sees it: 2e-7 vs 9e-11)
    void split_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                      ArrayView<double> history_new, Stress &tau_dev, double &J,
                      dealii::Tensor<4, 3> *dtau_dev_ddF) const override;

    double
    shear_modulus() const
    {
      return mu;
    }
    double
    lame_lambda() const
    {
      return lambda;
    }
    double
    bulk_modulus() const
    {
      return lambda + 2.0 * mu / 3.0;
    }
    Energy
    energy() const
    {
      return energy_form;
    }

  private:
    double E, nu, lambda, mu;
    Energy energy_form;
  };
} // namespace talus::materials
