#include <talus/base/errors.h>
#include <talus/materials/finite_strain_tools.h>
#include <talus/materials/j2_plasticity.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace talus::materials
{
  namespace
  {
    void
    check(const double E, const double nu, const double sy, const double H, const std::string &where)
    {
      check_isotropic_elasticity(E, nu, where);
      require(sy > 0, where + "/yield stress", "must be > 0 (got " + std::to_string(sy) + ")");
      require(H >= 0, where + "/hardening modulus", "must be >= 0 (got " + std::to_string(H) + ")");
    }

    const dealii::SymmetricTensor<2, 3> I2 = dealii::unit_symmetric_tensor<3>();
  } // namespace

  J2Plasticity::J2Plasticity(const double young, const double poisson, const double yield_stress,
                             const double hardening_modulus)
      : E(young)
      , nu(poisson)
      , sigma_y(yield_stress)
      , H(hardening_modulus)
  {
    check(E, nu, sigma_y, H, "j2 plasticity");
    mu = E / (2 * (1 + nu));
    K  = E / (3 * (1 - 2 * nu));
  }

  J2Plasticity::J2Plasticity(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , sigma_y(prm.get_double("yield stress"))
      , H(prm.get_double("hardening modulus"))
  {
    check(E, nu, sigma_y, H, where);
    mu = E / (2 * (1 + nu));
    K  = E / (3 * (1 - 2 * nu));
  }

  void
  J2Plasticity::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "2e11", dealii::Patterns::Double(), "Small-strain Young's modulus E [Pa], > 0.");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(),
                      "Small-strain Poisson's ratio nu [-], -1 < nu < 0.5.");
    prm.declare_entry("yield stress", "2e8", dealii::Patterns::Double(),
                      "Initial uniaxial yield stress sigma_Y (Kirchhoff) [Pa], > 0.");
    prm.declare_entry("hardening modulus", "0", dealii::Patterns::Double(),
                      "Linear isotropic hardening modulus H [Pa], >= 0: yield stress "
                      "sigma_Y + H alpha with alpha the equivalent plastic strain.");
  }

  std::vector<std::string>
  J2Plasticity::history_names() const
  {
    return {"bebar_xx", "bebar_yy", "bebar_zz", "bebar_xy", "bebar_yz", "bebar_xz", "J", "equivalent plastic strain"};
  }

  void
  J2Plasticity::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    const std::string where = name.empty() ? "j2 plasticity" : name;
    const Stress      s     = deviator(sigma);
    require(s.norm() <= std::sqrt(2.0 / 3.0) * sigma_y, where, "initial stress lies outside the yield surface");
    const double sm = trace(sigma) / 3.0;
    require(1.0 + 2.0 * sm / K > 0, where, "initial mean stress not reachable");
    const double J = std::sqrt(1.0 + 2.0 * sm / K);
    // bbar = s/mu + c I with det bbar = 1
    const Stress D = s / mu;
    double       c = 1.0;
    for (int it = 0; it < 50; ++it)
      {
        const Stress m  = D + c * I2;
        const double d  = determinant(m);
        const double dc = (d - 1.0) / (d * trace(invert(m)));
        c -= dc;
        if (std::abs(dc) < 1e-15)
          break;
      }
    fs::store_sym(D + c * I2, h, 0);
    h[6] = J;
    h[7] = 0.0;
  }

  void
  J2Plasticity::finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> h_old,
                                     ArrayView<double> h_new, Stress &tau, dealii::Tensor<4, 3> *dtau_ddF) const
  {
    const double detf    = checked_increment_jacobian(dF, *this);
    const Stress bbar_n  = fs::load_sym(h_old, 0);
    const double J       = h_old[6] * detf;
    const double alpha_n = h_old[7];

    const dealii::Tensor<2, 3> fbar    = std::pow(detf, -1.0 / 3.0) * dF;
    const Stress               bbar_tr = symmetrize(fbar * dealii::Tensor<2, 3>(bbar_n) * transpose(fbar));
    const Stress               s_tr    = mu * deviator(bbar_tr);
    const double               ns      = s_tr.norm();
    const double               f_tr    = ns - std::sqrt(2.0 / 3.0) * (sigma_y + H * alpha_n);
    const double               Jp      = 0.5 * K * (J * J - 1.0);
    const double               mubar   = mu * trace(bbar_tr) / 3.0;

    double dgamma = 0.0;
    Stress s      = s_tr;
    Stress nn;
    if (f_tr > 0.0)
      {
        nn     = s_tr / ns;
        dgamma = f_tr / (2.0 * mubar) / (1.0 + H / (3.0 * mubar));
        s      = s_tr - 2.0 * mubar * dgamma * nn;
        fs::store_sym(s / mu + (trace(bbar_tr) / 3.0) * I2, h_new, 0);
      }
    else
      fs::store_sym(bbar_tr, h_new, 0);
    h_new[6] = J;
    h_new[7] = alpha_n + std::sqrt(2.0 / 3.0) * dgamma;
    tau      = Jp * I2 + s;

    if (!dtau_ddF)
      return;
    // Spatial tangent: c = c_vol + cbar_tr [ - beta1 cbar_tr - 2 mubar beta3 n(x)n
    //                      - 2 mubar beta4 n (x) dev(n^2) ]     (Eq. 3.93)
    // c_vol = (J p + J^2 p') I(x)I - 2 J p I_sym = K J^2 I(x)I - K (J^2 - 1) I_sym
    // cbar_tr = 2 mubar I_dev - 2/3 ||s_tr|| (n (x) I + I (x) n)      (Eq. 3.52)
    double b1 = 0, b3 = 0, b4 = 0;
    Stress dn2;
    if (dgamma > 0)
      {
        const double inv_b0 = 1.0 / (1.0 + H / (3.0 * mubar));
        b1                  = 2.0 * mubar * dgamma / ns;
        const double b2     = (1.0 - inv_b0) * (2.0 / 3.0) * ns / mubar * dgamma;
        b3                  = inv_b0 - b1 + b2;
        b4                  = (inv_b0 - b1) * ns / mubar;
        dn2                 = deviator(symmetrize(dealii::Tensor<2, 3>(nn) * dealii::Tensor<2, 3>(nn)));
      }
    const Stress         n_tr = ns > 0 ? s_tr / ns : Stress();
    dealii::Tensor<4, 3> c;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              const double dij = (i == j), dkl = (k == l);
              const double Is = 0.5 * ((i == k) * (j == l) + (i == l) * (j == k));
              const double cbar =
                2.0 * mubar * (Is - dij * dkl / 3.0) - 2.0 / 3.0 * ns * (n_tr[i][j] * dkl + dij * n_tr[k][l]);
              double v = K * J * J * dij * dkl - K * (J * J - 1.0) * Is + (1.0 - b1) * cbar;
              if (dgamma > 0)
                v -= 2.0 * mubar * (b3 * nn[i][j] * nn[k][l] + b4 * nn[i][j] * dn2[k][l]);
              c[i][j][k][l] = v;
            }
    *dtau_ddF = fs::lie_tangent_to_dF(c, tau, dF);
  }

  void
  J2Plasticity::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                              ArrayView<double> history) const
  {
    const Stress tau = finite_strain_rate_update(d_eps, d_omega, history);
    sigma            = tau / kirchhoff_jacobian(history);
  }

  double
  J2Plasticity::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }

  double
  J2Plasticity::kirchhoff_jacobian(ArrayView<const double> history) const
  {
    return history[6];
  }
} // namespace talus::materials
