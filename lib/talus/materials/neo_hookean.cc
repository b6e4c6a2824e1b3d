#include <talus/base/errors.h>
#include <talus/materials/finite_strain_tools.h>
#include <talus/materials/neo_hookean.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace talus::materials
{
  namespace
  {
    NeoHookean::Energy
    parse_energy(const std::string &s, const std::string &where)
    {
      if (s == "coupled")
        return NeoHookean::Energy::coupled;
      if (s == "split")
        return NeoHookean::Energy::split;
      throw InputError(where + "/volumetric energy: unknown value '" + s + "'; allowed: coupled|split");
    }

    /// Solve det(D + c I) = 1 for c (D symmetric, traceless), Newton from c = 1.
    double
    unimodular_shift(const Stress &D)
    {
      double c = 1.0;
      for (int it = 0; it < 50; ++it)
        {
          Stress m = D;
          for (unsigned int i = 0; i < 3; ++i)
            m[i][i] += c;
          const double d  = determinant(m);
          const double dd = d * trace(invert(m));
          const double dc = (d - 1.0) / dd;
          c -= dc;
          if (std::abs(dc) < 1e-15 * std::abs(c))
            break;
        }
      return c;
    }
  } // namespace

  NeoHookean::NeoHookean(const double young, const double poisson, const Energy energy)
      : E(young)
      , nu(poisson)
      , energy_form(energy)
  {
    check_isotropic_elasticity(E, nu, "neo hookean");
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu     = E / (2 * (1 + nu));
  }

  NeoHookean::NeoHookean(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , energy_form(parse_energy(prm.get("volumetric energy"), where))
  {
    check_isotropic_elasticity(E, nu, where);
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu     = E / (2 * (1 + nu));
  }

  void
  NeoHookean::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e7", dealii::Patterns::Double(), "Small-strain Young's modulus E [Pa], > 0.");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(),
                      "Small-strain Poisson's ratio nu [-], -1 < nu < 0.5.");
    prm.declare_entry("volumetric energy", "coupled", dealii::Patterns::Selection("coupled|split"),
                      "coupled: Psi = lambda/2 (ln J)^2 - mu ln J + mu/2 (tr C - 3) (seed 001 Eq. 3.17); "
                      "split: Psi = K U(J) + mu/2 (tr Cbar - 3), U(J) = ((J^2-1)/2 - ln J)/2 "
                      "(seed 001 Eq. 3.43, for the mixed u-p formulation).");
  }

  std::vector<std::string>
  NeoHookean::history_names() const
  {
    return {"b_xx", "b_yy", "b_zz", "b_xy", "b_yz", "b_xz"};
  }

  void
  NeoHookean::initialize_history(const Stress &sigma_cauchy, ArrayView<double> h) const
  {
    // The elastic b whose Cauchy stress tau(b) / J(b) is the given one: b of
    // the Kirchhoff stress tau = J sigma, a fixed point in J = sqrt(det b)
    // (|J - 1| is the elastic volume strain: a few passes reach round-off).
    // Taking sigma itself as tau would leave the first update's stress off by
    // the factor 1 / J (a K0 column then moved by 1e-3 of its settlement).
    const auto b_of_kirchhoff = [this](const Stress &sigma) {
      Stress b;
      if (energy_form == Energy::coupled)
        {
          // tau = lambda s I + mu (b - I), s = ln J = 1/2 ln det b: scalar Newton in s.
          double s = 0.0;
          for (int it = 0; it < 60; ++it)
            {
              b = dealii::unit_symmetric_tensor<3>() + (sigma - lambda * s * dealii::unit_symmetric_tensor<3>()) / mu;
              const double det = determinant(b);
              require(det > 0, name.empty() ? "neo hookean" : name,
                      "initial stress not reachable by the Neo-Hookean law");
              const double g  = s - 0.5 * std::log(det);
              const double dg = 1.0 + 0.5 * lambda / mu * trace(invert(b));
              s -= g / dg;
              if (std::abs(g) < 1e-15)
                break;
            }
          b = dealii::unit_symmetric_tensor<3>() + (sigma - lambda * s * dealii::unit_symmetric_tensor<3>()) / mu;
        }
      else
        {
          const double K  = bulk_modulus();
          const double sm = trace(sigma) / 3.0; // = J p = K (J^2 - 1)/2
          require(1.0 + 2.0 * sm / K > 0, name.empty() ? "neo hookean" : name,
                  "initial mean stress not reachable by the Neo-Hookean law");
          const double J    = std::sqrt(1.0 + 2.0 * sm / K);
          const Stress D    = deviator(sigma) / mu;
          const double c    = unimodular_shift(D);
          const Stress bbar = D + c * dealii::unit_symmetric_tensor<3>();
          b                 = std::pow(J, 2.0 / 3.0) * bbar;
        }
      return b;
    };
    double J = 1.0;
    Stress b = b_of_kirchhoff(sigma_cauchy);
    for (int pass = 0; pass < 30; ++pass)
      {
        const double J_b = std::sqrt(determinant(b));
        if (std::abs(J_b - J) <= 1e-15 * J_b)
          break;
        J = J_b;
        b = b_of_kirchhoff(J * sigma_cauchy);
      }
    fs::store_sym(b, h, 0);
  }

  Stress
  NeoHookean::kirchhoff_stress(const Stress &b) const
  {
    const double J = std::sqrt(determinant(b));
    if (energy_form == Energy::coupled)
      return lambda * std::log(J) * dealii::unit_symmetric_tensor<3>() + mu * (b - dealii::unit_symmetric_tensor<3>());
    return kirchhoff_pressure(J) * dealii::unit_symmetric_tensor<3>() + deviatoric_kirchhoff_stress(b);
  }

  double
  NeoHookean::volumetric_energy(const double J) const
  {
    return bulk_modulus() * 0.5 * (0.5 * (J * J - 1.0) - std::log(J));
  }

  double
  NeoHookean::pressure(const double J) const
  {
    return bulk_modulus() * 0.5 * (J - 1.0 / J);
  }

  double
  NeoHookean::dpressure_dJ(const double J) const
  {
    return bulk_modulus() * 0.5 * (1.0 + 1.0 / (J * J));
  }

  Stress
  NeoHookean::deviatoric_kirchhoff_stress(const Stress &b) const
  {
    const double J = std::sqrt(determinant(b));
    return mu * std::pow(J, -2.0 / 3.0) * deviator(b);
  }

  dealii::Tensor<4, 3>
  NeoHookean::deviatoric_spatial_tangent(const Stress &b) const
  {
    const double         J    = std::sqrt(determinant(b));
    const double         trbb = std::pow(J, -2.0 / 3.0) * trace(b);
    const Stress         tdev = deviatoric_kirchhoff_stress(b);
    const double         a    = 2.0 / 3.0 * mu * trbb;
    dealii::Tensor<4, 3> c;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              const double dij = (i == j), dkl = (k == l);
              const double Is = 0.5 * ((i == k) * (j == l) + (i == l) * (j == k));
              c[i][j][k][l]   = a * (Is - dij * dkl / 3.0) - 2.0 / 3.0 * (tdev[i][j] * dkl + dij * tdev[k][l]);
            }
    return c;
  }

  dealii::Tensor<4, 3>
  NeoHookean::volumetric_spatial_tangent(const double J, const double p)
  {
    dealii::Tensor<4, 3> c;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              const double Is = 0.5 * ((i == k) * (j == l) + (i == l) * (j == k));
              c[i][j][k][l]   = J * p * (double((i == j) * (k == l)) - 2.0 * Is);
            }
    return c;
  }

  void
  NeoHookean::split_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                           ArrayView<double> history_new, Stress &tau_dev, double &J,
                           dealii::Tensor<4, 3> *dtau_dev_ddF) const
  {
    checked_increment_jacobian(dF, *this);
    const Stress b_n = fs::load_sym(history_old, 0);
    const Stress b   = symmetrize(dF * dealii::Tensor<2, 3>(b_n) * transpose(dF));
    fs::store_sym(b, history_new, 0);
    J       = std::sqrt(determinant(b));
    tau_dev = deviatoric_kirchhoff_stress(b);
    if (dtau_dev_ddF)
      *dtau_dev_ddF = fs::lie_tangent_to_dF(deviatoric_spatial_tangent(b), tau_dev, dF);
  }

  void
  NeoHookean::finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> history_old,
                                   ArrayView<double> history_new, Stress &tau, dealii::Tensor<4, 3> *dtau_ddF) const
  {
    checked_increment_jacobian(dF, *this); // throws for det dF <= 0 (an inverted point)
    const Stress b_n = fs::load_sym(history_old, 0);
    const Stress b   = symmetrize(dF * dealii::Tensor<2, 3>(b_n) * transpose(dF));
    fs::store_sym(b, history_new, 0);
    tau = kirchhoff_stress(b);
    if (!dtau_ddF)
      return;
    // A = d tau / d b (symmetric in k,l), then the chain rule through b = dF b_n dF^T.
    const double         J    = std::sqrt(determinant(b));
    const Stress         binv = invert(b);
    dealii::Tensor<4, 3> A;
    if (energy_form == Energy::coupled)
      {
        // tau = lambda ln J I + mu (b - I):  A = lambda/2 I (x) b^-1 + mu I_sym
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int l = 0; l < 3; ++l)
                A[i][j][k][l] =
                  0.5 * lambda * (i == j) * binv[k][l] + mu * 0.5 * ((i == k) * (j == l) + (i == l) * (j == k));
      }
    else
      {
        // tau = K (J^2-1)/2 I + mu J^-2/3 dev b:
        // A = K J^2/2 I (x) b^-1 + mu J^-2/3 [ I_dev - 1/3 dev(b) (x) b^-1 ]
        const double K  = bulk_modulus();
        const double g  = mu * std::pow(J, -2.0 / 3.0);
        const Stress db = deviator(b);
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int l = 0; l < 3; ++l)
                {
                  const double Is = 0.5 * ((i == k) * (j == l) + (i == l) * (j == k));
                  A[i][j][k][l]   = 0.5 * K * J * J * (i == j) * binv[k][l] +
                                  g * (Is - (i == j) * (k == l) / 3.0 - db[i][j] * binv[k][l] / 3.0);
                }
      }
    *dtau_ddF = fs::chain_trial_b(A, dF, b_n);
  }

  void
  NeoHookean::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                            ArrayView<double> history) const
  {
    const Stress tau = finite_strain_rate_update(d_eps, d_omega, history);
    sigma            = tau / kirchhoff_jacobian(history);
  }

  double
  NeoHookean::elastic_energy_density(const Stress &s) const
  {
    // small-strain estimate, W = 1/2 sigma : C^-1 : sigma
    return isotropic_elastic_energy_density(E, nu, s);
  }

  double
  NeoHookean::kirchhoff_jacobian(ArrayView<const double> history) const
  {
    return std::sqrt(determinant(fs::load_sym(history, 0)));
  }

  double
  NeoHookean::elastic_jacobian(ArrayView<const double> history) const
  {
    return std::sqrt(determinant(fs::load_sym(history, 0))); // b_e in history[0..5]
  }
} // namespace talus::materials
