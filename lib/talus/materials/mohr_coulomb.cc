#include <talus/base/errors.h>
#include <talus/materials/mohr_coulomb.h>
#include <talus/materials/principal_return.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <limits>

namespace talus::materials
{
  using namespace internal;

  namespace
  {
    constexpr double deg = M_PI / 180.0;

    // Plastic strain bookkeeping shared by the plastic branches.
    void
    record(const Vec3 &dep, const unsigned int n_active, ArrayView<double> h)
    {
      const double ev = dep[0] + dep[1] + dep[2];
      double       q  = 0;
      for (unsigned int i = 0; i < 3; ++i)
        q += (dep[i] - ev / 3) * (dep[i] - ev / 3);
      h[MohrCoulomb::h_plastic_shear_strain] += std::sqrt(2.0 / 3.0 * q);
      h[MohrCoulomb::h_plastic_vol_strain] += ev;
      h[MohrCoulomb::h_yield_state] = std::min(n_active, 3u);
    }
  } // namespace

  MohrCoulomb::MohrCoulomb(const double young, const double poisson, const double cohesion,
                           const double friction_angle_deg, const double dilatancy_angle_deg,
                           const double tensile_strength, const std::string &where)
      : E(young)
      , nu(poisson)
      , c(cohesion)
      , phi(friction_angle_deg)
      , psi(dilatancy_angle_deg)
      , T_in(tensile_strength)
  {
    setup(where);
  }

  MohrCoulomb::MohrCoulomb(dealii::ParameterHandler &prm, const std::string &where)
      : E(prm.get_double("young modulus"))
      , nu(prm.get_double("poisson ratio"))
      , c(prm.get_double("cohesion"))
      , phi(prm.get_double("friction angle"))
      , psi(prm.get_double("dilatancy angle"))
      , T_in(prm.get_bool("tension cut-off") ? prm.get_double("tensile strength") : -1.0)
  {
    if (prm.get_bool("tension cut-off"))
      require(T_in >= 0, where + "/tensile strength", "must be >= 0 (got " + std::to_string(T_in) + ")");
    setup(where);
  }

  void
  MohrCoulomb::setup(const std::string &where)
  {
    check_isotropic_elasticity(E, nu, where);
    require(c >= 0, where + "/cohesion", "must be >= 0 (got " + std::to_string(c) + ")");
    require(phi >= 0 && phi < 90, where + "/friction angle",
            "must satisfy 0 <= phi < 90 degrees (got " + std::to_string(phi) + ")");
    require(psi >= 0 && psi <= phi, where + "/dilatancy angle",
            "must satisfy 0 <= psi <= phi (got psi = " + std::to_string(psi) + ", phi = " + std::to_string(phi) + ")");
    require(phi > 0 || c > 0, where + "/cohesion", "must be > 0 when the friction angle is 0 (no strength at all)");
    G                 = E / (2 * (1 + nu));
    K                 = E / (3 * (1 - 2 * nu));
    lambda            = K - 2.0 * G / 3.0;
    has_apex          = phi > 0;
    const double apex = has_apex ? c / std::tan(phi * deg) : std::numeric_limits<double>::infinity();
    T                 = (T_in >= 0) ? std::min(T_in, apex) : apex;
  }

  void
  MohrCoulomb::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("young modulus", "1e7", dealii::Patterns::Double(), "Young's modulus E [Pa], > 0.");
    prm.declare_entry("poisson ratio", "0.3", dealii::Patterns::Double(), "Poisson's ratio nu [-], -1 < nu < 0.5.");
    prm.declare_entry("cohesion", "0", dealii::Patterns::Double(), "Effective cohesion c' [Pa], >= 0.");
    prm.declare_entry("friction angle", "30", dealii::Patterns::Double(),
                      "Effective friction angle phi' [degrees], 0 <= phi' < 90.");
    prm.declare_entry("dilatancy angle", "0", dealii::Patterns::Double(),
                      "Dilatancy angle psi [degrees], 0 <= psi <= phi' (psi = phi': associated flow).");
    prm.declare_entry("tension cut-off", "false", dealii::Patterns::Bool(),
                      "Limit the largest principal stress (tension positive) to the tensile strength "
                      "(Rankine surface, associated flow).");
    prm.declare_entry("tensile strength", "0", dealii::Patterns::Double(),
                      "Tensile strength T [Pa], >= 0, used with 'tension cut-off = true'. Values above "
                      "the apex c' cot(phi') have no effect.");
  }

  std::vector<std::string>
  MohrCoulomb::history_names() const
  {
    return {"plastic shear strain", "plastic volumetric strain", "yield state"};
  }

  void
  MohrCoulomb::update_stress(const Strain &d_eps, const Spin &d_omega, const double, Stress &sigma,
                             ArrayView<double> history) const
  {
    sigma           = apply_jaumann_rotation(sigma, d_omega);
    const double tr = trace(d_eps);
    sigma += 2 * G * d_eps;
    for (unsigned int i = 0; i < 3; ++i)
      sigma[i][i] += lambda * tr;

    const double sf = std::sin(phi * deg), cf = std::cos(phi * deg);
    const double sp = std::sin(psi * deg);
    const double k  = 2 * c * cf;

    // cheap elastic pre-check on the closed-form eigenvalues
    const Vec3   pv    = principal_values(sigma);
    const double scale = std::max({std::abs(pv[0]), std::abs(pv[2]), c, 1e-300});
    const double tol   = 1e-12 * scale;
    const double f13   = (pv[0] - pv[2]) + (pv[0] + pv[2]) * sf - k;
    if (f13 <= tol && pv[0] <= T + tol)
      {
        if (history.size() > 0)
          history[h_yield_state] = 0;
        return;
      }

    const Spectral sd = spectral_decomposition(sigma);
    // candidates in the ordered sector: main face (1,3), the two neighbouring
    // faces (2,3) [edge sigma_1 = sigma_2] and (1,2) [edge sigma_2 = sigma_3],
    // and the three tension planes
    auto mc = [&](const unsigned int i, const unsigned int j) {
      PlanarSurface s{{{0, 0, 0}}, k, {{0, 0, 0}}};
      s.a[i] = 1 + sf;
      s.a[j] = -(1 - sf);
      s.b[i] = 1 + sp;
      s.b[j] = -(1 - sp);
      return s;
    };
    auto tension = [&](const unsigned int i) {
      PlanarSurface s{{{0, 0, 0}}, T, {{0, 0, 0}}};
      s.a[i] = 1;
      s.b[i] = 1;
      return s;
    };
    const bool         cutoff  = std::isfinite(T) && (!has_apex || T < c / std::tan(phi * deg));
    PlanarSurface      cand[6] = {mc(0, 2), mc(1, 2), mc(0, 1), tension(0), tension(1), tension(2)};
    const unsigned int n_cand  = cutoff ? 6 : 3;
    PlanarSurface      chk[9]  = {mc(0, 2), mc(1, 2),   mc(0, 1),   mc(2, 0),  mc(2, 1),
                                  mc(1, 0), tension(0), tension(1), tension(2)};
    const unsigned int n_chk   = cutoff ? 9 : 6;

    PrincipalReturnResult r = return_to_planar_surfaces(sd.values, lambda, G, cand, n_cand, chk, n_chk, tol);
    if (!r.converged)
      {
        // beyond every edge and corner: the stress goes to the apex of the
        // admissible region (MC apex, or the tension apex T(1,1,1))
        if (!std::isfinite(T))
          throw InstabilityError("mohr coulomb: return mapping found no admissible stress");
        r.sigma = {{T, T, T}};
        // plastic strain = C^-1 (trial - returned)
        const Vec3   d  = {{sd.values[0] - T, sd.values[1] - T, sd.values[2] - T}};
        const double dm = (d[0] + d[1] + d[2]) / 3.0;
        for (unsigned int i = 0; i < 3; ++i)
          r.dep[i] = dm / (3 * K) + (d[i] - dm) / (2 * G);
        r.n_active = 3;
      }
    if (r.n_active == 0)
      {
        // within tolerance after the accurate decomposition: elastic
        if (history.size() > 0)
          history[h_yield_state] = 0;
        return;
      }
    sigma = compose(r.sigma, sd);
    if (history.size() > 0)
      record(r.dep, r.n_active, history);
  }

  double
  MohrCoulomb::elastic_energy_density(const Stress &s) const
  {
    return isotropic_elastic_energy_density(E, nu, s);
  }
  void
  MohrCoulomb::update_stresses(RateUpdate *points, const unsigned int n, const double dt) const
  {
    update_stresses_with(*this, points, n, dt);
  }
} // namespace talus::materials
