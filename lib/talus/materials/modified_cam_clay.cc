#include <talus/base/errors.h>
#include <talus/materials/modified_cam_clay.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace talus::materials
{
  ModifiedCamClay::ModifiedCamClay(const double M_, const double lambda_, const double kappa_, const double nu_,
                                   const double e0_, const double ocr_, const double p_min_, const std::string &where)
      : M(M_)
      , lam(lambda_)
      , kap(kappa_)
      , nu(nu_)
      , e0(e0_)
      , ocr(ocr_)
      , p_min(p_min_)
  {
    setup(where);
  }

  ModifiedCamClay::ModifiedCamClay(dealii::ParameterHandler &prm, const std::string &where)
      : M(prm.get_double("slope of critical state line"))
      , lam(prm.get_double("compression index"))
      , kap(prm.get_double("swelling index"))
      , nu(prm.get_double("poisson ratio"))
      , e0(prm.get_double("initial void ratio"))
      , ocr(prm.get_double("overconsolidation ratio"))
      , p_min(prm.get_double("minimum mean effective stress"))
  {
    setup(where);
  }

  void
  ModifiedCamClay::setup(const std::string &where)
  {
    require(M > 0, where + "/slope of critical state line", "must be > 0 (got " + std::to_string(M) + ")");
    require(lam > 0, where + "/compression index", "must be > 0 (got " + std::to_string(lam) + ")");
    require(kap > 0 && kap < lam, where + "/swelling index",
            "must satisfy 0 < kappa < lambda (got kappa = " + std::to_string(kap) +
              ", lambda = " + std::to_string(lam) + ")");
    require(nu > -1.0 && nu < 0.5, where + "/poisson ratio",
            "must satisfy -1 < nu < 0.5 (got " + std::to_string(nu) + ")");
    require(e0 > 0, where + "/initial void ratio", "must be > 0 (got " + std::to_string(e0) + ")");
    require(ocr >= 1, where + "/overconsolidation ratio", "must be >= 1 (got " + std::to_string(ocr) + ")");
    require(p_min > 0, where + "/minimum mean effective stress", "must be > 0 (got " + std::to_string(p_min) + ")");
  }

  void
  ModifiedCamClay::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("slope of critical state line", "1.0", dealii::Patterns::Double(),
                      "M = q/p' at critical state [-], > 0 (triaxial compression: M = 6 sin phi_cs/(3 - sin phi_cs)).");
    prm.declare_entry("compression index", "0.2", dealii::Patterns::Double(),
                      "lambda [-], > 0: slope of the normal compression line in v - ln p'.");
    prm.declare_entry("swelling index", "0.04", dealii::Patterns::Double(),
                      "kappa [-], 0 < kappa < lambda: slope of the unloading-reloading line in v - ln p'.");
    prm.declare_entry("poisson ratio", "0.25", dealii::Patterns::Double(),
                      "Poisson's ratio nu [-], -1 < nu < 0.5 (shear modulus from the bulk modulus).");
    prm.declare_entry("initial void ratio", "1.0", dealii::Patterns::Double(),
                      "Initial void ratio e0 [-], > 0 (specific volume v0 = 1 + e0).");
    prm.declare_entry(
      "overconsolidation ratio", "1.0", dealii::Patterns::Double(),
      "OCR [-], >= 1: initial p_c = OCR times the p_c that puts the initial stress on the yield surface.");
    prm.declare_entry("minimum mean effective stress", "1e3", dealii::Patterns::Double(),
                      "p_min [Pa], > 0: floor of p' used for the elastic stiffness and the initial p_c "
                      "(stress-free or tensile states).");
  }

  double
  ModifiedCamClay::constrained_modulus() const
  {
    const double v = 1 + e0;
    const double K = std::max(reference_pressure, p_min) * v / kap;
    const double G = 3 * K * (1 - 2 * nu) / (2 * (1 + nu));
    return K + 4 * G / 3;
  }

  std::vector<std::string>
  ModifiedCamClay::history_names() const
  {
    return {"preconsolidation pressure", "specific volume", "plastic volumetric strain", "plastic shear strain"};
  }

  void
  ModifiedCamClay::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    const double p            = std::max(-trace(sigma) / 3.0, p_min);
    const Stress s            = deviator(sigma);
    const double q2           = 1.5 * scalar_product(s, s);
    h[h_preconsolidation]     = ocr * (p + q2 / (M * M * p));
    h[h_specific_volume]      = 1 + e0;
    h[h_plastic_vol_strain]   = 0;
    h[h_plastic_shear_strain] = 0;
  }

  bool
  ModifiedCamClay::integrate(const Strain &d_eps, Stress &sigma, double *h) const
  {
    const double v     = h[h_specific_volume];
    const double ks    = kap / v;
    const double ls    = lam / v;
    const double pc_n  = h[h_preconsolidation];
    const double p_n   = -trace(sigma) / 3.0;
    const double p_eff = std::max(p_n, p_min); // stiffness reference
    const Stress s_n   = deviator(sigma);
    const double dev   = -trace(d_eps); // compression positive
    const double K     = p_eff / ks;
    const double G     = 3 * K * (1 - 2 * nu) / (2 * (1 + nu));

    // elastic pressure as a function of the elastic volumetric strain increment
    auto p_of  = [&](const double dee) { return p_n + p_eff * (std::exp(dee / ks) - 1.0); };
    auto dp_of = [&](const double dee) { return p_eff * std::exp(dee / ks) / ks; };

    const Stress s_tr = s_n + 2 * G * deviator(d_eps);
    const double q_tr = std::sqrt(1.5 * scalar_product(s_tr, s_tr));
    const double p_tr = p_of(dev);
    const double M2   = M * M;
    const double f_tr = q_tr * q_tr / M2 + p_tr * (p_tr - pc_n);
    const double fsc  = pc_n * pc_n;

    h[h_specific_volume] = v * std::exp(-dev);
    if (f_tr <= 1e-12 * fsc)
      {
        sigma = s_tr;
        for (unsigned int i = 0; i < 3; ++i)
          sigma[i][i] -= p_tr;
        return true;
      }

    // unknowns x = d eps_v^p (compression positive), y = plastic multiplier
    const double c6       = 6 * G / M2;
    auto         residual = [&](const double x, const double y, double &p, double &pc, double &q, double r[2]) {
      p    = p_of(dev - x);
      pc   = pc_n * std::exp(x / (ls - ks));
      q    = q_tr / (1 + c6 * y);
      r[0] = x - y * (2 * p - pc);
      r[1] = q * q / M2 + p * (p - pc);
    };
    // initial guess from the linearised consistency condition at the trial state
    double x = 0, y = 0;
    {
      const double a   = 2 * p_tr - pc_n;
      const double dfy = -2 * c6 * q_tr * q_tr / M2 - a * a * dp_of(dev) - p_tr * pc_n * a / (ls - ks);
      y                = (dfy < 0) ? -f_tr / dfy : 0.0;
      x                = y * a;
    }
    double p, pc, q, r[2];
    residual(x, y, p, pc, q, r);
    auto norm = [&](const double rr[2]) {
      return std::max(std::abs(rr[0]) / std::max(std::abs(x), 1e-8), std::abs(rr[1]) / fsc);
    };
    bool ok = false;
    for (int it = 0; it < 50; ++it)
      {
        if (std::abs(r[0]) <= 1e-15 + 1e-13 * std::abs(x) && std::abs(r[1]) <= 1e-13 * fsc)
          {
            ok = true;
            break;
          }
        const double dp  = -dp_of(dev - x);
        const double dpc = pc / (ls - ks);
        const double dq  = -q * c6 / (1 + c6 * y);
        const double J00 = 1 - y * (2 * dp - dpc), J01 = -(2 * p - pc);
        const double J10 = (2 * p - pc) * dp - p * dpc, J11 = 2 * q * dq / M2;
        const double det = J00 * J11 - J01 * J10;
        if (!(std::abs(det) > 0) || !std::isfinite(det))
          break;
        const double dx = -(J11 * r[0] - J01 * r[1]) / det;
        const double dy = -(-J10 * r[0] + J00 * r[1]) / det;
        double       a  = 1, pn, pcn, qn, rn[2];
        const double n0 = norm(r);
        for (;;)
          {
            residual(x + a * dx, std::max(y + a * dy, 0.0), pn, pcn, qn, rn);
            if (norm(rn) < n0 || a < 1e-4)
              break;
            a *= 0.5;
          }
        x += a * dx;
        y = std::max(y + a * dy, 0.0);
        p = pn, pc = pcn, q = qn;
        r[0] = rn[0], r[1] = rn[1];
      }
    if (!ok || !(p > 0) || !std::isfinite(pc))
      return false;
    sigma = (q_tr > 0) ? Stress(s_tr * (q / q_tr)) : Stress();
    for (unsigned int i = 0; i < 3; ++i)
      sigma[i][i] -= p;
    h[h_preconsolidation] = pc;
    h[h_plastic_vol_strain] -= x;
    h[h_plastic_shear_strain] += y * 2 * q / M2;
    return true;
  }

  void
  ModifiedCamClay::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                                 ArrayView<double> history) const
  {
    sigma = apply_jaumann_rotation(sigma, d_omega);
    // try the whole step, then halve it until every sub-step converges
    for (unsigned int n = 1; n <= 1024; n *= 2)
      {
        Stress       s = sigma;
        double       h[4];
        const Strain d = d_eps / double(n);
        for (unsigned int k = 0; k < 4; ++k)
          h[k] = history[k];
        bool ok = true;
        for (unsigned int i = 0; i < n && ok; ++i)
          ok = integrate(d, s, h);
        if (ok)
          {
            sigma = s;
            for (unsigned int k = 0; k < 4; ++k)
              history[k] = h[k];
            return;
          }
      }
    throw InstabilityError("modified cam clay: the implicit return did not converge even with "
                           "1024 sub-steps");
  }
} // namespace talus::materials
