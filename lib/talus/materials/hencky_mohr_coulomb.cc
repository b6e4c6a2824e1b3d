#include <talus/base/errors.h>
#include <talus/materials/finite_strain_tools.h>
#include <talus/materials/hencky_mohr_coulomb.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <cmath>

namespace talus::materials
{
  namespace
  {
    inline double
    dot3(const double a[3], const double b[3])
    {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    }
  } // namespace

  HenckyMohrCoulomb::HenckyMohrCoulomb(const double young, const double poisson, const double cohesion,
                                       const double friction_angle_deg, const double dilatancy_angle_deg)
      : E(young)
      , nu(poisson)
      , c(cohesion)
      , phi(friction_angle_deg * M_PI / 180.0)
      , psi(dilatancy_angle_deg * M_PI / 180.0)
  {
    setup("hencky mohr coulomb");
  }

  HenckyMohrCoulomb::HenckyMohrCoulomb(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , c(prm.get_double("cohesion"))
      , phi(prm.get_double("friction angle") * M_PI / 180.0)
      , psi(prm.get_double("dilatancy angle") * M_PI / 180.0)
  {
    setup(where);
  }

  void
  HenckyMohrCoulomb::setup(const std::string &where)
  {
    check_isotropic_elasticity(E, nu, where);
    require(c >= 0, where + "/cohesion", "must be >= 0 (got " + std::to_string(c) + ")");
    require(phi > 0 && phi < M_PI / 2, where + "/friction angle",
            "must satisfy 0 < phi < 90 degrees (got " + std::to_string(phi * 180 / M_PI) + ")");
    require(psi >= 0 && psi <= phi, where + "/dilatancy angle",
            "must satisfy 0 <= psi <= phi (got " + std::to_string(psi * 180 / M_PI) + ")");
    lambda   = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu       = E / (2 * (1 + nu));
    k        = (1 + std::sin(phi)) / (1 - std::sin(phi));
    m        = (1 + std::sin(psi)) / (1 - std::sin(psi));
    sqk      = std::sqrt(k);
    tau_apex = 2 * c * sqk / (k - 1); // = c cot(phi)
  }

  void
  HenckyMohrCoulomb::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e7", dealii::Patterns::Double(),
                      "Young's modulus E of the Hencky law [Pa], > 0.");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(), "Poisson's ratio nu [-], -1 < nu < 0.5.");
    prm.declare_entry("cohesion", "0", dealii::Patterns::Double(), "Cohesion c [Pa], >= 0.");
    prm.declare_entry("friction angle", "30", dealii::Patterns::Double(),
                      "Friction angle phi [degrees], 0 < phi < 90.");
    prm.declare_entry("dilatancy angle", "0", dealii::Patterns::Double(),
                      "Dilatancy angle psi [degrees], 0 <= psi <= phi.");
  }

  std::vector<std::string>
  HenckyMohrCoulomb::history_names() const
  {
    return {"be_xx", "be_yy", "be_zz", "be_xy", "be_yz", "be_xz", "J", "accumulated plastic strain", "return region"};
  }

  double
  HenckyMohrCoulomb::yield_function(const double t[3]) const
  {
    return (t[0] - t[2]) + (t[0] + t[2]) * std::sin(phi) - 2 * c * std::cos(phi);
  }

  int
  HenckyMohrCoulomb::principal_return(const double e[3], double t[3], double D[3][3]) const
  {
    const double tr = e[0] + e[1] + e[2];
    for (unsigned int A = 0; A < 3; ++A)
      {
        t[A] = lambda * tr + 2 * mu * e[A];
        for (unsigned int B = 0; B < 3; ++B)
          D[A][B] = lambda + (A == B ? 2 * mu : 0.0);
      }
    const double f = k * t[0] - t[2] - 2 * c * sqk;
    if (f <= 0.0)
      return 0;

    // a^-1 v = v/(2 mu) - lambda/(2 mu (3 lambda + 2 mu)) (sum v) 1
    auto ainv = [&](const double v[3], double r[3]) {
      const double s = (v[0] + v[1] + v[2]) * lambda / (2 * mu * (3 * lambda + 2 * mu));
      for (unsigned int A = 0; A < 3; ++A)
        r[A] = v[A] / (2 * mu) - s;
    };
    auto amul = [&](const double v[3], double r[3]) {
      const double s = lambda * (v[0] + v[1] + v[2]);
      for (unsigned int A = 0; A < 3; ++A)
        r[A] = s + 2 * mu * v[A];
    };
    const double scale = std::abs(t[0]) + std::abs(t[2]) + c + tau_apex;
    const double tol   = 1e-12 * scale;

    // 1. return to the main plane
    const double a1[3] = {k, 0, -1}, b1[3] = {m, 0, -1};
    double       ab[3], aa[3];
    amul(b1, ab);
    amul(a1, aa);
    const double den = dot3(a1, ab);
    double       tp[3];
    for (unsigned int A = 0; A < 3; ++A)
      tp[A] = t[A] - f / den * ab[A];
    if (tp[0] >= tp[1] - tol && tp[1] >= tp[2] - tol)
      {
        for (unsigned int A = 0; A < 3; ++A)
          {
            for (unsigned int B = 0; B < 3; ++B)
              D[A][B] -= ab[A] * aa[B] / den;
            t[A] = tp[A];
          }
        return 1;
      }
    // 2. return to an edge: tau_1 = tau_2 (l1) or tau_2 = tau_3 (l2)
    const bool    l1     = tp[1] > tp[0];
    const double  rl1[3] = {1, 1, k}, rg1[3] = {1, 1, m};
    const double  rl2[3] = {1, k, k}, rg2[3] = {1, m, m};
    const double *rl = l1 ? rl1 : rl2, *rg = l1 ? rg1 : rg2;
    double        dt[3], w[3], arl[3];
    for (unsigned int A = 0; A < 3; ++A)
      dt[A] = t[A] - tau_apex;
    ainv(dt, w);
    ainv(rl, arl);
    const double dl   = dot3(rg, arl);
    const double tpar = dot3(rg, w) / dl;
    if (tpar <= 0.0)
      {
        for (unsigned int A = 0; A < 3; ++A)
          {
            t[A] = tau_apex + tpar * rl[A];
            for (unsigned int B = 0; B < 3; ++B)
              D[A][B] = rl[A] * rg[B] / dl;
          }
        return l1 ? 2 : 3;
      }
    // 3. apex
    for (unsigned int A = 0; A < 3; ++A)
      {
        t[A] = tau_apex;
        for (unsigned int B = 0; B < 3; ++B)
          D[A][B] = 0.0;
      }
    return 4;
  }

  void
  HenckyMohrCoulomb::finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> h_old,
                                          ArrayView<double> h_new, Stress &tau, dealii::Tensor<4, 3> *dtau_ddF) const
  {
    const double       detf = checked_increment_jacobian(dF, *this);
    const Stress       b_n  = fs::load_sym(h_old, 0);
    const Stress       b_tr = symmetrize(dF * dealii::Tensor<2, 3>(b_n) * transpose(dF));
    const fs::Spectral sp   = fs::spectral_decomposition(b_tr);
    double             e_tr[3], t[3], D[3][3];
    for (unsigned int A = 0; A < 3; ++A)
      e_tr[A] = 0.5 * std::log(sp.x[A]);
    const int region = principal_return(e_tr, t, D);
    tau              = fs::assemble(sp, t);

    // elastic log strains eps_e = a^-1 tau, b_e = sum exp(2 eps_e) e_A e_A
    const double s = (t[0] + t[1] + t[2]) * lambda / (2 * mu * (3 * lambda + 2 * mu));
    double       be[3], dp2 = 0;
    for (unsigned int A = 0; A < 3; ++A)
      {
        const double ee = t[A] / (2 * mu) - s;
        be[A]           = region == 0 ? sp.x[A] : std::exp(2 * ee);
        dp2 += (e_tr[A] - ee) * (e_tr[A] - ee);
      }
    fs::store_sym(region == 0 ? b_tr : fs::assemble(sp, be), h_new, 0);
    h_new[6] = h_old[6] * detf;
    h_new[7] = h_old[7] + (region == 0 ? 0.0 : std::sqrt(2.0 / 3.0 * dp2));
    h_new[8] = region;

    if (!dtau_ddF)
      return;
    // Eq. 3.145: d tau / d b_tr from the principal moduli D = d tau_A / d eps_B
    // (d eps_B / d x_B = 1 / (2 x_B)) and the eigenvector spin terms.
    double dydx[3][3];
    for (unsigned int A = 0; A < 3; ++A)
      for (unsigned int B = 0; B < 3; ++B)
        dydx[A][B] = D[A][B] / (2 * sp.x[B]);
    *dtau_ddF = fs::chain_trial_b(fs::isotropic_derivative(sp, t, dydx), dF, b_n);
  }

  void
  HenckyMohrCoulomb::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    const fs::Spectral sp = fs::spectral_decomposition(sigma);
    require(yield_function(sp.x) <= 1e-10 * (sigma.norm() + c), name.empty() ? "hencky mohr coulomb" : name,
            "initial stress lies outside the Mohr-Coulomb yield surface");
    const double s = (sp.x[0] + sp.x[1] + sp.x[2]) * lambda / (2 * mu * (3 * lambda + 2 * mu));
    double       be[3];
    for (unsigned int A = 0; A < 3; ++A)
      be[A] = std::exp(2 * (sp.x[A] / (2 * mu) - s));
    fs::store_sym(fs::assemble(sp, be), h, 0);
    h[6] = 1.0;
    h[7] = 0.0;
    h[8] = 0.0;
  }

  void
  HenckyMohrCoulomb::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                                   ArrayView<double> history) const
  {
    const Stress tau = finite_strain_rate_update(d_eps, d_omega, history);
    sigma            = tau / kirchhoff_jacobian(history);
  }

  double
  HenckyMohrCoulomb::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }

  double
  HenckyMohrCoulomb::kirchhoff_jacobian(ArrayView<const double> history) const
  {
    return history[6];
  }

  double
  HenckyMohrCoulomb::elastic_jacobian(ArrayView<const double> history) const
  {
    return std::sqrt(determinant(fs::load_sym(history, 0))); // b_e in history[0..5]
  }
} // namespace talus::materials
