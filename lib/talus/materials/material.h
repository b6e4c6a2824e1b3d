// talus — constitutive model interface shared by the explicit, implicit and
// semi-implicit drivers. Light on deal.II: tensors only.
//
// Conventions
//  * Stresses are Cauchy stresses, tension positive, always 3x3 (plane strain in 2D
//    keeps sigma_zz).
//  * The rate form (explicit driver, seed 000 §7.1) receives the small strain
//    increment d_eps = sym(grad du) and the spin increment d_omega = skew(grad du)
//    of one step. The objective (Jaumann) correction of the stress is applied by
//    the model through apply_jaumann_rotation(), so models with tensorial history
//    can rotate it as well.
//  * History variables are plain doubles stored per material point; a model
//    declares how many it needs and their names (for output).
#pragma once

#include <deal.II/base/array_view.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <memory>
#include <string>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

namespace talus::materials
{
  using dealii::ArrayView;
  using Stress = dealii::SymmetricTensor<2, 3>;
  using Strain = dealii::SymmetricTensor<2, 3>;
  using Spin   = dealii::Tensor<2, 3>;

  /// Jaumann-rate rotation of the stress over one step by the exactly orthogonal
  /// Cayley (Hughes-Winget) rotation of the spin increment d_omega = skew(grad du).
  inline Stress apply_jaumann_rotation(const Stress &sigma, const Spin &d_omega);

  /// One point of a batched rate-form update (Material::update_stresses): the
  /// increments of the step and the stress and history, updated in place.
  struct RateUpdate
  {
    Strain  d_eps;
    Spin    d_omega;
    Stress  sigma;
    double *history;
  };

  class Material
  {
  public:
    virtual ~Material() = default;

    /// Registry name of the model, e.g. "linear elastic".
    virtual std::string model_name() const = 0;

    /// Mass density of the material [kg/m^3].
    double
    density() const
    {
      return rho;
    }
    void
    set_density(const double r)
    {
      rho = r;
    }

    /// Constrained (P-wave) modulus E_c [Pa] used by the critical time step
    /// (seed 000 Eq. 4.120). For liquids: the bulk modulus.
    virtual double constrained_modulus() const = 0;

    /// Largest dynamic viscosity [Pa s] the model can produce (liquids; 0 for
    /// solids). Drivers use it for the viscous time-step limit dt <= rho h^2 / (2 mu).
    virtual double
    dynamic_viscosity() const
    {
      return 0.0;
    }

    /// Number and names of the history variables stored per material point.
    virtual unsigned int
    n_history() const
    {
      return 0;
    }
    virtual std::vector<std::string>
    history_names() const
    {
      return {};
    }
    /// Initialise the history for a point with the given initial stress.
    virtual void
    initialize_history(const Stress & /*sigma*/, ArrayView<double> /*history*/) const
    {
    }

    /// Rate-form stress update (explicit driver): updates sigma (Jaumann rotated
    /// then integrated over the strain increment) and history in place.
    virtual void update_stress(const Strain &d_eps, const Spin &d_omega, const double dt, Stress &sigma,
                               ArrayView<double> history) const = 0;

    /// The same for n points of one cell (the explicit update pass calls it once
    /// per cell and model instead of once per point). Default: update_stress()
    /// per point; a model overrides it with update_stresses_with() below, which
    /// calls its own update_stress() non-virtually (inlined in the model's file).
    virtual void
    update_stresses(RateUpdate *points, const unsigned int n, const double dt) const
    {
      const unsigned int nh = n_history();
      for (unsigned int k = 0; k < n; ++k)
        update_stress(points[k].d_eps, points[k].d_omega, dt, points[k].sigma,
                      ArrayView<double>(points[k].history, nh));
    }

    /// ---- Finite-strain form (implicit updated-Lagrangian and semi-implicit
    /// drivers, seed 001 ch. 3, seed 002 §4.3). Models without it return false.
    virtual bool
    has_finite_strain_form() const
    {
      return false;
    }

    /// Given the incremental deformation gradient of the step dF = F_{n+1} F_n^{-1}
    /// and the history at the start of the step (converged state), compute the
    /// Kirchhoff stress tau_{n+1}, the updated history, and (if dtau_ddF is not
    /// null) the consistent tangent d tau_{n+1} / d dF (a full 4th-order tensor,
    /// dtau_ij / d dF_kl). Models that need the total F keep it in their history.
    /// Must not modify history_old; history_new may alias nothing else.
    virtual void finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                                      ArrayView<double> history_new, Stress &tau, dealii::Tensor<4, 3> *dtau_ddF) const;

    /// One step of finite_strain_update() with the history updated in place
    /// (from a copy of the old one; no tangent). Returns the Kirchhoff stress;
    /// the caller divides by its J. Used by the rate form below and by the
    /// semi-implicit driver, which passes its (stabilised) increment dF itself.
    Stress finite_strain_step(const dealii::Tensor<2, 3> &dF, ArrayView<double> history) const;

    /// det F of the total deformation that the Kirchhoff stress of
    /// finite_strain_update() refers to, read from the history: sigma = tau / J.
    /// (Initial stresses make it differ from the driver's volume ratio.)
    virtual double
    kirchhoff_jacobian(ArrayView<const double> /*history*/) const
    {
      return 1.0;
    }

    /// ---- State queries of the semi-implicit driver (seed 002). The defaults
    /// describe a model without b_e, specific volume or initialisation stage.
    /// Whether the history keeps the elastic left Cauchy-Green tensor b_e (the
    /// modified F-bar scales it, Eqs. 81-83).
    virtual bool
    keeps_elastic_b() const
    {
      return false;
    }
    /// J^e = sqrt(det b_e) of the history's b_e (Eq. 82); 0 without b_e.
    virtual double
    elastic_jacobian(ArrayView<const double> /*history*/) const
    {
      return 0.0;
    }
    /// Whether the history keeps a specific volume v that each step multiplies
    /// by det of its increment (v = v0 J; Nor-Sand).
    virtual bool
    has_specific_volume() const
    {
      return false;
    }
    /// Set that specific volume to v0 J / det_increment, so that the next step,
    /// with an increment of determinant det_increment, ends at v0 J (seed 002
    /// Eq. 96 with a J of the driver's). Nothing for a model without it.
    virtual void
    set_specific_volume(const double /*J*/, const double /*det_increment*/, ArrayView<double> /*history*/) const
    {
    }
    /// The model of the elastic initialisation stage (seed 002 App. B.4): an
    /// elastic copy, or null when the model serves as it is.
    virtual std::shared_ptr<const Material>
    initialisation_model() const
    {
      return nullptr;
    }
    /// End of that stage: the current state becomes the model's reference
    /// (Nor-Sand, Eqs. 111-114). False (history untouched) for a model without.
    virtual bool
    reinitialize_reference(ArrayView<double> /*history*/) const
    {
      return false;
    }

    /// ---- Volumetric/deviatoric split (the mixed u-p driver, seed 001 ch. 5).
    /// A model has it when tau = J p(J) I + tau_dev with p a function of
    /// J = kirchhoff_jacobian(history) alone, J_{n+1} = J_n det dF (isochoric
    /// plastic flow) and a deviatoric response that does not depend on the
    /// pressure (no pressure-dependent yield): then the nodal pressure of u-p can
    /// replace p(J). Neo-Hookean (split energy) and J2 have it; Mohr-Coulomb
    /// (phi > 0) and Nor-Sand do not.
    virtual bool
    has_volumetric_split() const
    {
      return false;
    }
    /// p(J): the mean Cauchy stress of the volumetric part [Pa] (tension positive)
    virtual double split_pressure(const double J) const;
    /// dp/dJ [Pa]
    virtual double split_dpressure_dJ(const double J) const;
    /// the bulk modulus K = J dp/dJ at J = 1 (the u-p pressure rows are scaled by 1/K)
    virtual double split_bulk_modulus() const;
    /// the elastic shear modulus G (the u-p stabilisation weight alpha V / G)
    virtual double split_shear_modulus() const;
    /// One step of a model with the split, from finite_strain_update(): J, the
    /// deviatoric part tau_dev = tau - J p(J) I and (if asked) its derivative
    /// d tau_dev / d dF = d tau / d dF - I (x) (p + J p') J dF^-T. One place for
    /// every model: the models provide p(J) only. The subtraction loses about
    /// log10(K/G) digits of tau_dev; a model used near incompressibility may
    /// override it with its deviatoric part computed directly (Neo-Hookean).
    virtual void split_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                              ArrayView<double> history_new, Stress &tau_dev, double &J,
                              dealii::Tensor<4, 3> *dtau_dev_ddF) const;

    /// Strain energy density increment is computed by the driver from stresses;
    /// this returns the elastic strain energy density of a stress state (for energy
    /// diagnostics), W = 1/2 sigma : C^-1 : sigma. Zero when not meaningful.
    virtual double elastic_energy_density(const Stress &sigma) const;

    std::string  name; ///< user-facing name (".prm" subsection), for messages
    unsigned int id = 0;

  protected:
    /// Rate form of a finite-strain model (explicit driver): dF = I + d_eps +
    /// d_omega, finite_strain_update() from a copy of the history (updated in
    /// place). Returns the Kirchhoff stress; the caller divides by its J.
    Stress finite_strain_rate_update(const Strain &d_eps, const Spin &d_omega, ArrayView<double> history) const;

    double rho = 0.0;
  };

  /// Material::update_stresses of a model Model: its update_stress() called
  /// qualified (no virtual dispatch), so it is inlined into the loop.
  template <class Model>
  inline void
  update_stresses_with(const Model &m, RateUpdate *points, const unsigned int n, const double dt)
  {
    const unsigned int nh = m.n_history();
    for (unsigned int k = 0; k < n; ++k)
      m.Model::update_stress(points[k].d_eps, points[k].d_omega, dt, points[k].sigma,
                             ArrayView<double>(points[k].history, nh));
  }

  inline Stress
  apply_jaumann_rotation(const Stress &sigma, const Spin &w)
  {
    // Objective integration of the Jaumann rate over one step: sigma <- Q sigma Q^T
    // with the Cayley (Hughes-Winget) rotation Q = (I - W/2)^-1 (I + W/2). In closed
    // form, with A = W/2 and a its axial vector: Q = I + 2/(1+|a|^2) (A + A^2).
    // Q is exactly orthogonal, so stress invariants are preserved to round-off,
    // and Q sigma Q^T = sigma + W sigma - sigma W + O(|W|^2).
    // Written out with plain doubles on the raw entries of sigma (deal.II order
    // 00, 11, 22, 01, 02, 12), inline: it runs once per material point and step.
    const double a0 = 0.5 * w[2][1], a1 = 0.5 * w[0][2], a2 = 0.5 * w[1][0];
    const double aa = a0 * a0 + a1 * a1 + a2 * a2;
    if (aa == 0.0)
      return sigma;
    const double c = 2.0 / (1.0 + aa);
    // A = [[0,-a2,a1],[a2,0,-a0],[-a1,a0,0]], A^2 = a a^T - |a|^2 I
    double Q[3][3];
    Q[0][0]          = 1.0 + c * (a0 * a0 - aa);
    Q[1][1]          = 1.0 + c * (a1 * a1 - aa);
    Q[2][2]          = 1.0 + c * (a2 * a2 - aa);
    Q[0][1]          = c * (-a2 + a0 * a1);
    Q[1][0]          = c * (a2 + a0 * a1);
    Q[0][2]          = c * (a1 + a0 * a2);
    Q[2][0]          = c * (-a1 + a0 * a2);
    Q[1][2]          = c * (-a0 + a1 * a2);
    Q[2][1]          = c * (a0 + a1 * a2);
    const double s00 = sigma.access_raw_entry(0), s11 = sigma.access_raw_entry(1), s22 = sigma.access_raw_entry(2),
                 s01 = sigma.access_raw_entry(3), s02 = sigma.access_raw_entry(4), s12 = sigma.access_raw_entry(5);
    const double S[3][3] = {{s00, s01, s02}, {s01, s11, s12}, {s02, s12, s22}};
    double       QS[3][3];
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        QS[i][j] = Q[i][0] * S[0][j] + Q[i][1] * S[1][j] + Q[i][2] * S[2][j];
    Stress                 r;
    constexpr unsigned int raw[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = i; j < 3; ++j)
        r.access_raw_entry(raw[i][j]) = QS[i][0] * Q[j][0] + QS[i][1] * Q[j][1] + QS[i][2] * Q[j][2];
    return r;
  }

  /// Elastic strain energy density 1/2 s : C^-1 : s of isotropic linear
  /// elasticity with Young's modulus E and Poisson's ratio nu.
  double isotropic_elastic_energy_density(const double E, const double nu, const Stress &s);

  /// Validate isotropic elastic constants: E > 0 and -1 < nu < 0.5; throws
  /// InputError naming `where`/young modulus or `where`/poisson ratio.
  void check_isotropic_elasticity(const double E, const double nu, const std::string &where);

  /// det(dF) of an incremental deformation gradient, or InstabilityError naming
  /// the material and model when it is not positive (inverted point).
  double checked_increment_jacobian(const dealii::Tensor<2, 3> &dF, const Material &m);

  /// Declare the subsection of one material: "model", "density" and every
  /// model's own subsection.
  void declare_material_parameters(dealii::ParameterHandler &prm);

  /// Build the material described by the current subsection of prm. `where`
  /// names the subsection for error messages. Throws talus::InputError.
  std::unique_ptr<Material> create_material(dealii::ParameterHandler &prm, const std::string &where,
                                            const unsigned int id);

  /// Names of all registered models (for error messages and --help).
  std::vector<std::string> registered_models();
} // namespace talus::materials
