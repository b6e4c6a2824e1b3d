#include <talus/base/errors.h>
#include <talus/materials/finite_strain_tools.h>
#include <talus/materials/nor_sand.h>

#include <deal.II/base/parameter_handler.h>

#include <Eigen/Dense>

#include <cmath>

namespace talus::materials
{
  NorSand::NorSand(const Parameters &p)
      : P(p)
  {
    check("nor sand");
  }

  NorSand::NorSand(dealii::ParameterHandler &prm, const std::string &where)
  {
    P.G          = prm.get_double("shear modulus");
    P.kappa      = prm.get_double("swelling index");
    P.lambda     = prm.get_double("compression index");
    P.v_c0       = prm.get_double("reference specific volume");
    P.M          = prm.get_double("critical state ratio");
    P.N          = prm.get_double("yield constant N");
    P.N_bar      = prm.get_double("potential constant N bar");
    P.h          = prm.get_double("hardening coefficient");
    P.alpha      = prm.get_double("dilatancy multiplier");
    P.v0         = prm.get_double("initial specific volume");
    P.p0         = prm.get_double("reference pressure");
    P.eps_v0     = prm.get_double("reference elastic volumetric strain");
    P.ocr        = prm.get_double("overconsolidation ratio");
    P.p_unit     = prm.get_double("critical state pressure unit");
    P.cut_start  = prm.get_double("dilatancy cutoff start");
    P.cut_end    = prm.get_double("dilatancy cutoff end");
    P.gas_factor = prm.get_double("gas cutoff factor");
    check(where);
  }

  void
  NorSand::check(const std::string &w) const
  {
    auto pos = [&](const double v, const char *e) {
      require(v > 0, w + "/" + e, "must be > 0 (got " + std::to_string(v) + ")");
    };
    pos(P.G, "shear modulus");
    pos(P.kappa, "swelling index");
    pos(P.lambda, "compression index");
    pos(P.M, "critical state ratio");
    pos(P.h, "hardening coefficient");
    pos(P.p0, "reference pressure");
    pos(P.p_unit, "critical state pressure unit");
    require(P.v_c0 > 1, w + "/reference specific volume", "must be > 1 (got " + std::to_string(P.v_c0) + ")");
    require(P.v0 > 1, w + "/initial specific volume", "must be > 1 (got " + std::to_string(P.v0) + ")");
    require(P.N > 0 && P.N < 1, w + "/yield constant N", "must satisfy 0 < N < 1 (got " + std::to_string(P.N) + ")");
    require(P.N_bar > 0 && P.N_bar < 1, w + "/potential constant N bar",
            "must satisfy 0 < N bar < 1 (got " + std::to_string(P.N_bar) + ")");
    require(P.alpha < 0, w + "/dilatancy multiplier",
            "must be < 0 (tension-positive convention, D* = alpha psi; got " + std::to_string(P.alpha) + ")");
    require(P.ocr >= 1, w + "/overconsolidation ratio", "must be >= 1 (got " + std::to_string(P.ocr) + ")");
    require(P.cut_start > 0 && P.cut_end > P.cut_start, w + "/dilatancy cutoff end",
            "must satisfy 0 < start < end (got " + std::to_string(P.cut_start) + ", " + std::to_string(P.cut_end) +
              ")");
    require(P.gas_factor > 1, w + "/gas cutoff factor", "must be > 1 (got " + std::to_string(P.gas_factor) + ")");
  }

  void
  NorSand::declare_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    prm.declare_entry("shear modulus", "40e6", Double(), "Shear modulus G [Pa], > 0 (seed 002 Table 6: 40 MPa).");
    prm.declare_entry("swelling index", "0.002", Double(),
                      "Elastic compressibility kappa [-], > 0: p = p_ref exp(-(eps_v - eps_v,ref)/kappa).");
    prm.declare_entry("compression index", "0.02", Double(),
                      "Slope lambda of the critical state line v_c = v_c0 - lambda ln(p/p_unit) [-], > 0.");
    prm.declare_entry("reference specific volume", "1.892", Double(),
                      "v_c0, specific volume of the CSL at p = p_unit [-], > 1.");
    prm.declare_entry("critical state ratio", "1.0", Double(), "Critical state stress ratio M = q/p [-], > 0.");
    prm.declare_entry("yield constant N", "0.1", Double(), "Yield function constant N [-], 0 < N < 1.");
    prm.declare_entry("potential constant N bar", "0.1", Double(),
                      "Plastic potential constant N bar [-], 0 < N bar < 1.");
    prm.declare_entry("hardening coefficient", "100", Double(), "Hardening coefficient h [-], > 0.");
    prm.declare_entry("dilatancy multiplier", "-2.0", Double(),
                      "alpha [-], < 0: maximum plastic dilatancy D* = alpha psi_i (dilation positive).");
    prm.declare_entry("initial specific volume", "2.0", Double(), "Initial specific volume v0 [-], > 1.");
    prm.declare_entry(
      "reference pressure", "2e3", Double(),
      "Initial reference mean effective pressure p0, compression positive [Pa], > 0 (seed 002 App. B.4: 2 kPa).");
    prm.declare_entry("reference elastic volumetric strain", "0", Double(),
                      "Elastic volumetric strain at the reference pressure [-] (tension positive).");
    prm.declare_entry("overconsolidation ratio", "1", Double(),
                      "OCR [-], >= 1, for the initial image pressure (seed 002 Eq. 113).");
    prm.declare_entry(
      "critical state pressure unit", "1", Double(),
      "Pressure unit of the logarithm in the CSL and in psi_i [Pa], > 0 (1 Pa for the Table 6 values).");
    prm.declare_entry(
      "dilatancy cutoff start", "1.0", Double(),
      "Accumulated deviatoric plastic strain where the dilatancy cut-off starts [-] (seed 002 Eq. 92).");
    prm.declare_entry("dilatancy cutoff end", "1.5", Double(),
                      "Accumulated deviatoric plastic strain where psi_i reaches 0 [-], > start.");
    prm.declare_entry("gas cutoff factor", "1.6", Double(),
                      "Gas-like cut-off: zero stress when v > factor x v0 [-], > 1 (seed 002 Eq. 93).");
  }

  double
  NorSand::constrained_modulus() const
  {
    return P.p0 / P.kappa + 4.0 / 3.0 * P.G;
  }

  std::vector<std::string>
  NorSand::history_names() const
  {
    return {"be_xx",
            "be_yy",
            "be_zz",
            "be_xy",
            "be_yz",
            "be_xz",
            "J",
            "specific volume",
            "image pressure",
            "deviatoric plastic strain",
            "psi at cutoff start",
            "reference pressure",
            "reference elastic volumetric strain"};
  }

  double
  NorSand::image_pressure_through(const double p, const double q) const
  {
    // F = 0: eta = q/(-p) = M/N [1 - (1-N) r]  =>  r = (1 - N eta/M)/(1-N), p_i = p r^(-(1-N)/N)
    const double N   = P.N;
    const double eta = q / (-p);
    const double r   = (1.0 - N * eta / P.M) / (1.0 - N);
    require(r > 0, name.empty() ? "nor sand" : name, "stress ratio q/p >= M/N: no yield surface through the state");
    return p * std::pow(r, -(1.0 - N) / N);
  }

  void
  NorSand::initialize_history(const Stress &sigma, ArrayView<double> h) const
  {
    const double p  = trace(sigma) / 3.0;
    const Stress s  = deviator(sigma);
    const bool   z  = sigma.norm() == 0.0;
    const double pr = z ? -P.p0 : p;
    require(pr < 0, name.empty() ? "nor sand" : name, "initial mean stress must be compressive");
    const double q = std::sqrt(1.5) * s.norm();
    // elastic log strain: eps_v = eps_v,ref (p = p_ref), e = s / (2G)
    Stress eps = s / (2 * P.G);
    for (unsigned int i = 0; i < 3; ++i)
      eps[i][i] += P.eps_v0 / 3.0;
    const fs::Spectral sp = fs::spectral_decomposition(eps);
    double             be[3];
    for (unsigned int A = 0; A < 3; ++A)
      be[A] = std::exp(2 * sp.x[A]);
    fs::store_sym(fs::assemble(sp, be), h, 0);
    h[6]  = 1.0;
    h[7]  = P.v0;
    h[8]  = P.ocr * image_pressure_through(pr, q);
    h[9]  = 0.0;
    h[10] = 0.0;
    h[11] = pr;
    h[12] = P.eps_v0;
  }

  bool
  NorSand::reinitialize_reference(ArrayView<double> h) const
  {
    const Stress       be = fs::load_sym(h, 0);
    const fs::Spectral sp = fs::spectral_decomposition(be);
    double             ev = 0;
    for (unsigned int A = 0; A < 3; ++A)
      ev += 0.5 * std::log(sp.x[A]);
    const double p = h[11] * std::exp(-(ev - h[12]) / P.kappa);
    h[11]          = p;
    h[12]          = ev;
    h[8]           = P.ocr * image_pressure_through(p, 0.0);
    // v0 <- J v0: the specific volume in the history already is J v0.
    return true;
  }

  std::shared_ptr<const Material>
  NorSand::initialisation_model() const
  {
    auto elastic = std::make_shared<NorSand>(P);
    elastic->set_plasticity(false);
    return elastic;
  }

  int
  NorSand::principal_update(const double eps[3], const State &s0, double t[3], double (*D)[3], State &s1) const
  {
    const double G = P.G, M = P.M, N = P.N, Nb = P.N_bar, kap = P.kappa;
    const double a = N / (1 - N), ab = Nb / (1 - Nb);
    s1                 = s0;
    const double ev_tr = eps[0] + eps[1] + eps[2];
    double       etr[3];
    for (unsigned int A = 0; A < 3; ++A)
      etr[A] = eps[A] - ev_tr / 3.0;
    const double ne    = std::sqrt(etr[0] * etr[0] + etr[1] * etr[1] + etr[2] * etr[2]);
    const double es_tr = std::sqrt(2.0 / 3.0) * ne;
    auto         pres  = [&](const double ev) { return s0.p_ref * std::exp(-(ev - s0.ev_ref) / kap); };

    auto set_elastic = [&](const double ev, const double factor) {
      const double p = pres(ev);
      for (unsigned int A = 0; A < 3; ++A)
        t[A] = p + 2 * G * etr[A] * factor;
    };
    // trial
    {
      const double p = pres(ev_tr), q = 3 * G * es_tr;
      const double r = std::pow(p / s0.pi, a);
      const double F = q + M / N * (1 - (1 - N) * r) * p;
      if (!plastic || F <= 1e-12 * std::abs(p))
        {
          set_elastic(ev_tr, 1.0);
          if (D)
            {
              const double K = -p / kap;
              for (unsigned int A = 0; A < 3; ++A)
                for (unsigned int B = 0; B < 3; ++B)
                  D[A][B] = K + 2 * G * ((A == B) - 1.0 / 3.0);
            }
          return 0;
        }
    }

    // dilatancy cut-off (seed 002 Eq. 92)
    const bool   cut    = s0.Ed >= P.cut_start;
    const double dcut   = P.cut_end - P.cut_start;
    auto         psi_of = [&](const double pi, const double dl, double &dpsi_dpi, double &dpsi_ddl) {
      if (!cut)
        {
          dpsi_dpi = P.lambda / pi;
          dpsi_ddl = 0;
          return s0.v - P.v_c0 + P.lambda * std::log(-pi / P.p_unit);
        }
      dpsi_dpi       = 0;
      const double E = s0.Ed + dl;
      if (E >= P.cut_end)
        {
          dpsi_ddl = 0;
          return 0.0;
        }
      dpsi_ddl = -s0.psi_start / dcut;
      return (1 - (E - P.cut_start) / dcut) * s0.psi_start;
    };

    const double    sc = std::abs(s0.pi);
    double          ev = ev_tr, dl = 0, pi = s0.pi;
    Eigen::Matrix3d Jm;
    bool            ok = false;
    for (int it = 0; it < 60; ++it)
      {
        const double p = pres(ev), K = -p / kap;
        // one pow when N = N_bar (the paper's Table 6), the same value to the bit
        const double r = std::pow(p / pi, a), rb = ab == a ? r : std::pow(p / pi, ab);
        const double eta = M / N * (1 - (1 - N) * r);
        const double Qp  = M / Nb * (1 - rb);
        const double Qpp = -M / Nb * ab * rb / p, Qppi = M / Nb * ab * rb / pi;
        const double Fp = M / N * (1 - r), Fpi = M * r * p / pi;
        double       dpsi_dpi, dpsi_ddl;
        const double psi = psi_of(pi, dl, dpsi_dpi, dpsi_ddl);
        const double sg  = 1 - N * P.alpha * psi / M;
        if (!(sg > 0))
          break;
        const double    g   = std::pow(sg, (N - 1) / N);
        const double    gp  = (1 - N) * P.alpha / M * (g / sg); // sg^(-1/N) = sg^((N-1)/N) / sg
        const double    pis = p * g;
        Eigen::Vector3d R(ev - ev_tr + dl * Qp, (3 * G * (es_tr - dl) + eta * p) / sc,
                          (pi - s0.pi - P.h * dl * (pis - pi)) / sc);
        Jm(0, 0) = 1 + dl * Qpp * K;
        Jm(0, 1) = Qp;
        Jm(0, 2) = dl * Qppi * sc;
        Jm(1, 0) = Fp * K / sc;
        Jm(1, 1) = -3 * G / sc;
        Jm(1, 2) = Fpi;
        Jm(2, 0) = -P.h * dl * g * K / sc;
        Jm(2, 1) = (-P.h * (pis - pi) - P.h * dl * p * gp * dpsi_ddl) / sc;
        Jm(2, 2) = 1 - P.h * dl * (p * gp * dpsi_dpi - 1);
        if (!R.allFinite())
          break;
        if (std::abs(R(0)) < 1e-14 && std::abs(R(1)) < 1e-13 && std::abs(R(2)) < 1e-13 && it > 0)
          {
            ok = true;
            break;
          }
        // 3 x 3: the cofactor inverse (a few dozen flops; Eigen's full-pivot LU
        // was 5 % of a landslide step), the LU only where Jm is near singular
        const double    det   = Jm.determinant();
        const double    scale = Jm.row(0).norm() * Jm.row(1).norm() * Jm.row(2).norm();
        Eigen::Vector3d dx    = std::abs(det) > 1e-10 * scale ? Eigen::Vector3d(Jm.inverse() * (-R))
                                                              : Eigen::Vector3d(Jm.fullPivLu().solve(-R));
        // damping: keep p_i on the compression side and eps_v steps moderate
        double w = 1.0;
        while (w > 1e-4 && (!(pi + w * dx(2) * sc < 0) || std::abs(w * dx(0)) > 5 * kap))
          w *= 0.5;
        ev += w * dx(0);
        dl += w * dx(1);
        pi += w * dx(2) * sc;
      }

    if (ok && dl >= 0 && dl <= es_tr)
      {
        set_elastic(ev, es_tr > 0 ? 1.0 - dl / es_tr : 0.0);
        s1.pi = pi;
        s1.Ed = s0.Ed + dl;
        if (!cut && s1.Ed >= P.cut_start)
          s1.psi_start = s0.v - P.v_c0 + P.lambda * std::log(-pi / P.p_unit);
        if (D)
          {
            // implicit differentiation: Jm dx = -dR/d(input)
            const Eigen::Matrix3d Ji = Jm.inverse();
            // v = v_n det(dF) also depends on the trial strains: dv/d eps_B = v,
            // entering R3 through psi_i (not within the dilatancy cut-off).
            double                dpsi_dpi, dpsi_ddl;
            const double          psi   = psi_of(pi, dl, dpsi_dpi, dpsi_ddl);
            const double          gpv   = (1 - N) * P.alpha / M * std::pow(1 - N * P.alpha * psi / M, -1.0 / N);
            const double          dR3dv = cut ? 0.0 : -P.h * dl * pres(ev) * gpv * s0.v / sc;
            const Eigen::Vector3d dv    = Ji * Eigen::Vector3d(1, 0, -dR3dv);      // d x / d ev_tr
            const Eigen::Vector3d ds    = Ji * Eigen::Vector3d(0, -3 * G / sc, 0); // d x / d es_tr
            const double          p = pres(ev), K = -p / kap;
            const double          fac = 1.0 - dl / es_tr;
            for (unsigned int B = 0; B < 3; ++B)
              {
                const double desB = 2.0 / 3.0 * etr[B] / es_tr; // d es_tr / d eps_B
                const double dev  = dv(0) + ds(0) * desB;
                const double ddl  = dv(1) + ds(1) * desB;
                for (unsigned int A = 0; A < 3; ++A)
                  D[A][B] = K * dev + 2 * G * ((A == B) - 1.0 / 3.0) * fac -
                            2 * G * etr[A] * (ddl / es_tr - dl / (es_tr * es_tr) * desB);
              }
          }
        return 1;
      }

    // ---- tip of the yield surface: q = 0, p = p_tip(p_i) = p_i (1-N)^(-(1-N)/N)
    const double ctip = std::pow(1 - N, -(1 - N) / N);
    auto         R3   = [&](const double x) {
      double       d1, d2;
      const double psi = psi_of(x, es_tr, d1, d2);
      const double sg  = std::max(1 - N * P.alpha * psi / M, 1e-300);
      return x - s0.pi - P.h * es_tr * (x * ctip * std::pow(sg, (N - 1) / N) - x);
    };
    // bracket on the compression side, then bisection (robust). Not rare in a
    // liquefying loose landslide, so it stops as soon as the bracket cannot
    // shrink any more (mid equal to an end): the iterations the fixed count of
    // 200 ran past that point changed nothing, so the result is the same to the
    // bit, at about a quarter of the R3 calls (each a pow and a log).
    double lo = s0.pi, hi = s0.pi;
    double flo = R3(lo);
    for (int i = 0; i < 200 && flo * R3(hi) > 0; ++i)
      hi = (flo > 0) ? hi * 2 : hi * 0.5;
    for (int i = 0; i < 200; ++i)
      {
        const double mid = 0.5 * (lo + hi);
        if (mid == lo || mid == hi)
          break;
        const double fmid = R3(mid);
        if ((fmid > 0) == (flo > 0))
          lo = mid, flo = fmid;
        else
          hi = mid;
      }
    pi             = 0.5 * (lo + hi);
    const double p = pi * ctip;
    for (unsigned int A = 0; A < 3; ++A)
      t[A] = p;
    s1.pi = pi;
    s1.Ed = s0.Ed + es_tr;
    if (D)
      {
        const double hh = 1e-7;
        for (unsigned int B = 0; B < 3; ++B)
          {
            double e1[3] = {eps[0], eps[1], eps[2]}, e2[3] = {eps[0], eps[1], eps[2]};
            e1[B] += hh;
            e2[B] -= hh;
            double t1[3], t2[3];
            State  x, s0p = s0, s0m = s0;
            s0p.v *= std::exp(hh); // v = v_n det dF follows the trial volume change
            s0m.v *= std::exp(-hh);
            principal_update(e1, s0p, t1, nullptr, x);
            principal_update(e2, s0m, t2, nullptr, x);
            for (unsigned int A = 0; A < 3; ++A)
              D[A][B] = (t1[A] - t2[A]) / (2 * hh);
          }
      }
    return 2;
  }

  void
  NorSand::finite_strain_update(const dealii::Tensor<2, 3> &dF, ArrayView<const double> h_old, ArrayView<double> h_new,
                                Stress &tau, dealii::Tensor<4, 3> *dtau_ddF) const
  {
    const double detf = checked_increment_jacobian(dF, *this);
    for (unsigned int i = 0; i < 13; ++i)
      h_new[i] = h_old[i];
    h_new[6] = h_old[6] * detf;
    h_new[7] = h_old[7] * detf;
    // gas-like cut-off (seed 002 Eq. 93): zero stress, b_e = I (our spectral
    // tangent is robust at repeated eigenvalues, so no artificial perturbation)
    if (h_new[7] > P.gas_factor * P.v0)
      {
        tau = Stress();
        fs::store_sym(dealii::unit_symmetric_tensor<3>(), h_new, 0);
        if (dtau_ddF)
          *dtau_ddF = dealii::Tensor<4, 3>();
        return;
      }
    const Stress       b_n  = fs::load_sym(h_old, 0);
    const Stress       b_tr = symmetrize(dF * dealii::Tensor<2, 3>(b_n) * transpose(dF));
    const fs::Spectral sp   = fs::spectral_decomposition(b_tr);
    double             e_tr[3], t[3], D[3][3];
    for (unsigned int A = 0; A < 3; ++A)
      e_tr[A] = 0.5 * std::log(sp.x[A]);
    State     s0{h_old[8], h_old[9], h_old[10], h_old[11], h_old[12], h_new[7]}, s1;
    const int region = principal_update(e_tr, s0, t, dtau_ddF ? D : nullptr, s1);
    if (region == 1 || region == 2)
      {
        if (!(std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2])))
          throw InstabilityError("material '" + name + "' (nor sand): return mapping failed");
      }
    tau = fs::assemble(sp, t);
    if (region == 0)
      fs::store_sym(b_tr, h_new, 0);
    else
      {
        // elastic log strains from tau: eps_v from p, e = dev tau / (2G)
        const double p  = (t[0] + t[1] + t[2]) / 3.0;
        const double ev = s1.ev_ref - P.kappa * std::log(p / s1.p_ref);
        double       be[3];
        for (unsigned int A = 0; A < 3; ++A)
          be[A] = std::exp(2 * ((t[A] - p) / (2 * P.G) + ev / 3.0));
        fs::store_sym(fs::assemble(sp, be), h_new, 0);
      }
    h_new[8]  = s1.pi;
    h_new[9]  = s1.Ed;
    h_new[10] = s1.psi_start;
    if (!dtau_ddF)
      return;
    double dydx[3][3];
    for (unsigned int A = 0; A < 3; ++A)
      for (unsigned int B = 0; B < 3; ++B)
        dydx[A][B] = D[A][B] / (2 * sp.x[B]);
    *dtau_ddF = fs::chain_trial_b(fs::isotropic_derivative(sp, t, dydx), dF, b_n);
  }

  void
  NorSand::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                         ArrayView<double> history) const
  {
    const Stress tau = finite_strain_rate_update(d_eps, d_omega, history);
    sigma            = tau / kirchhoff_jacobian(history);
  }

  double
  NorSand::kirchhoff_jacobian(ArrayView<const double> history) const
  {
    return history[6];
  }

  double
  NorSand::elastic_jacobian(ArrayView<const double> history) const
  {
    return std::sqrt(determinant(fs::load_sym(history, 0))); // b_e in history[0..5]
  }
} // namespace talus::materials
