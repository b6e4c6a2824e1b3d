// Mohr-Coulomb and Tresca: closed-form failure, flow rule, edge/apex/tension
// returns, parameter validation.
#include <talus/base/errors.h>
#include <talus/materials/material.h>
#include <talus/materials/mohr_coulomb.h>
#include <talus/materials/single_element.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace talus::materials;

namespace
{
  constexpr double deg = M_PI / 180.0;

  std::array<double, 3>
  principal(const Stress &s)
  {
    const auto e = dealii::eigenvalues(s);
    return {{e[0], e[1], e[2]}};
  }

  // All six Mohr-Coulomb planes (unordered principal stresses) and the largest value.
  double
  mc_max(const std::array<double, 3> &s, const double c, const double phi)
  {
    double f = -1e300;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        if (i != j)
          f = std::max(f, (s[i] - s[j]) + (s[i] + s[j]) * std::sin(phi * deg) - 2 * c * std::cos(phi * deg));
    return f;
  }

  // Plastic strain of a single step from a stress-free start: eps - C^-1 sigma (principal,
  // same axes because the trial is diagonal here).
  std::array<double, 3>
  plastic_strain(const std::array<double, 3> &eps, const Stress &s, const double E, const double nu)
  {
    std::array<double, 3> ep;
    const double          tr = s[0][0] + s[1][1] + s[2][2];
    for (unsigned int i = 0; i < 3; ++i)
      ep[i] = eps[i] - ((1 + nu) * s[i][i] - nu * tr) / E;
    return ep;
  }

  // One step from a stress-free state with the strain increment whose elastic
  // trial stress is the given diagonal stress.
  std::array<double, 3>
  strain_for_trial(const std::array<double, 3> &st, const double E, const double nu)
  {
    const double          tr = st[0] + st[1] + st[2];
    std::array<double, 3> e;
    for (unsigned int i = 0; i < 3; ++i)
      e[i] = ((1 + nu) * st[i] - nu * tr) / E;
    return e;
  }

  Stress
  one_step(const Material &m, const std::array<double, 3> &eps, std::vector<double> &h)
  {
    Stress s;
    Strain d;
    for (unsigned int i = 0; i < 3; ++i)
      d[i][i] = eps[i];
    h.assign(m.n_history(), 0.0);
    m.initialize_history(s, ArrayView<double>(h.data(), h.size()));
    m.update_stress(d, Spin(), 1e-3, s, ArrayView<double>(h.data(), h.size()));
    return s;
  }
} // namespace

TEST(MohrCoulomb, DrainedTriaxialCompressionFailureAndDilatancy)
{
  const double        E = 30e6, nu = 0.25, c = 8e3, phi = 32, psi = 12;
  MohrCoulomb         m(E, nu, c, phi, psi);
  ElementTestSettings set;
  set.path             = ElementPath::drained_triaxial_compression;
  set.target_strain    = 0.03;
  set.n_increments     = 300;
  set.initial_pressure = 150e3;
  std::vector<ElementRecord> rec;
  run_element_test(m, set, [&](const ElementRecord &r) { rec.push_back(r); });
  ASSERT_EQ(rec.size(), 301u);

  const double         s3   = 150e3;
  const double         sf   = std::sin(phi * deg);
  const double         s1_f = s3 * (1 + sf) / (1 - sf) + 2 * c * std::cos(phi * deg) / (1 - sf);
  const ElementRecord &last = rec.back();
  // geotechnical: sigma_1' = -sigma_xx
  EXPECT_NEAR(-last.sigma[0][0], s1_f, 1e-8 * s1_f);
  EXPECT_NEAR(-last.sigma[1][1], s3, 1e-8 * s3);
  EXPECT_NEAR(-last.sigma[2][2], s3, 1e-8 * s3);
  // never above the strength on the way
  for (const auto &r : rec)
    EXPECT_LE(-r.sigma[0][0], s1_f * (1 + 1e-10));
  // yielded on the triaxial-compression edge
  EXPECT_EQ(last.history[MohrCoulomb::h_yield_state], 2.0);

  // plastic flow at constant stress: all of the strain rate is plastic and
  // d eps_v / d eps_a = -2 sin psi / (1 - sin psi) (compression positive)
  const ElementRecord &prev     = rec[rec.size() - 2];
  const double         dea      = last.eps_axial() - prev.eps_axial();
  const double         dev      = last.eps_vol() - prev.eps_vol();
  const double         sp       = std::sin(psi * deg);
  const double         expected = -2 * sp / (1 - sp);
  EXPECT_NEAR(dev / dea, expected, 1e-6 * std::abs(expected));
  // and the recorded plastic volumetric strain grows at the same rate (dilation positive)
  const double dvp = last.history[MohrCoulomb::h_plastic_vol_strain] - prev.history[MohrCoulomb::h_plastic_vol_strain];
  EXPECT_NEAR(dvp, -dev, 1e-6 * std::abs(dev));
}

TEST(MohrCoulomb, DrainedTriaxialExtensionFailure)
{
  // extension at constant lateral stress: sigma_a' drops until
  // sigma_r' = sigma_a' (1+sin phi)/(1-sin phi) + 2c cos phi/(1-sin phi)
  const double        c = 5e3, phi = 25;
  MohrCoulomb         m(20e6, 0.3, c, phi, 5);
  ElementTestSettings set;
  set.path             = ElementPath::drained_triaxial_extension;
  set.target_strain    = 0.02;
  set.n_increments     = 200;
  set.initial_pressure = 100e3;
  ElementRecord last;
  run_element_test(m, set, [&](const ElementRecord &r) { last = r; });
  const double sf  = std::sin(phi * deg);
  const double s3f = (100e3 * (1 - sf) - 2 * c * std::cos(phi * deg)) / (1 + sf);
  EXPECT_NEAR(-last.sigma[0][0], s3f, 1e-8 * s3f);
}

TEST(MohrCoulomb, FaceReturnIsOnFaceWithPotentialFlow)
{
  const double E = 10e6, nu = 0.3, c = 10e3, phi = 30, psi = 10;
  MohrCoulomb  m(E, nu, c, phi, psi);
  // well-separated principal strains: lands on the face (1,3) only
  std::vector<double>         h;
  const std::array<double, 3> eps = {{2e-3, 0.0, -6e-3}};
  const Stress                s   = one_step(m, eps, h);
  const auto                  p   = principal(s);
  const double                sf = std::sin(phi * deg), sp = std::sin(psi * deg);
  EXPECT_NEAR((p[0] - p[2]) + (p[0] + p[2]) * sf - 2 * c * std::cos(phi * deg), 0.0, 1e-9 * c);
  EXPECT_GT(p[0] - p[1], 1e3);
  EXPECT_GT(p[1] - p[2], 1e3);
  EXPECT_EQ(h[MohrCoulomb::h_yield_state], 1.0);
  const auto ep = plastic_strain(eps, s, E, nu);
  // flow along dP/dsigma = (1 + sin psi, 0, -(1 - sin psi))
  EXPECT_NEAR(ep[1], 0.0, 1e-12);
  EXPECT_GT(ep[0], 0.0);
  EXPECT_NEAR(ep[2] / ep[0], -(1 - sp) / (1 + sp), 1e-9);
}

TEST(MohrCoulomb, EdgeReturnsLandOnEdges)
{
  const double        E = 10e6, nu = 0.3, c = 10e3, phi = 30, psi = 10;
  MohrCoulomb         m(E, nu, c, phi, psi);
  const double        sf = std::sin(phi * deg), sp = std::sin(psi * deg), cf = std::cos(phi * deg);
  std::vector<double> h;
  {
    // triaxial-compression edge sigma_1 = sigma_2 (tension positive): slightly
    // unequal lateral strains that a face-only return would reorder
    const auto   eps = strain_for_trial({{-40e3, -42e3, -200e3}}, E, nu);
    const Stress s   = one_step(m, eps, h);
    const auto   p   = principal(s);
    EXPECT_NEAR(p[0], p[1], 1e-9 * std::abs(p[2]));
    EXPECT_NEAR((p[0] - p[2]) + (p[0] + p[2]) * sf - 2 * c * cf, 0.0, 1e-9 * c);
    EXPECT_LE(mc_max(p, c, phi), 1e-9 * c);
    EXPECT_EQ(h[MohrCoulomb::h_yield_state], 2.0);
    // plastic strain in the cone of the two potentials: ep = x b13 + y b23, x, y >= 0
    const auto   ep = plastic_strain(eps, s, E, nu);
    const double x = ep[0] / (1 + sp), y = ep[1] / (1 + sp);
    EXPECT_GT(x, 0.0);
    EXPECT_GT(y, 0.0);
    EXPECT_NEAR(ep[2], -(x + y) * (1 - sp), 1e-9 * std::abs(ep[2]));
  }
  {
    // triaxial-extension edge sigma_2 = sigma_3
    const auto   eps = strain_for_trial({{-20e3, -150e3, -152e3}}, E, nu);
    const Stress s   = one_step(m, eps, h);
    const auto   p   = principal(s);
    EXPECT_NEAR(p[1], p[2], 1e-9 * std::abs(p[2]));
    EXPECT_NEAR((p[0] - p[2]) + (p[0] + p[2]) * sf - 2 * c * cf, 0.0, 1e-9 * c);
    EXPECT_LE(mc_max(p, c, phi), 1e-9 * c);
    EXPECT_EQ(h[MohrCoulomb::h_yield_state], 2.0);
    const auto ep = plastic_strain(eps, s, E, nu);
    // ep = x b13 + y b12 with b12 = (1+sp, -(1-sp), 0)
    const double x = -ep[2] / (1 - sp), y = -ep[1] / (1 - sp);
    EXPECT_GT(x, 0.0);
    EXPECT_GT(y, 0.0);
    EXPECT_NEAR(ep[0], (x + y) * (1 + sp), 1e-9 * std::abs(ep[0]));
  }
}

TEST(MohrCoulomb, ApexReturn)
{
  const double        c = 10e3, phi = 30;
  MohrCoulomb         m(10e6, 0.3, c, phi, 20);
  const double        apex = c / std::tan(phi * deg);
  std::vector<double> h;
  for (const std::array<double, 3> eps :
       {std::array<double, 3>{{5e-3, 5e-3, 5e-3}}, std::array<double, 3>{{9e-3, 6e-3, 4e-3}}})
    {
      const Stress s = one_step(m, eps, h);
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = 0; j < 3; ++j)
          EXPECT_NEAR(s[i][j], i == j ? apex : 0.0, 1e-10 * apex);
      EXPECT_EQ(h[MohrCoulomb::h_yield_state], 3.0);
    }
}

TEST(MohrCoulomb, TensionCutOff)
{
  const double c = 20e3, phi = 30, T = 5e3, E = 10e6, nu = 0.2;
  MohrCoulomb  m(E, nu, c, phi, 10, T);
  EXPECT_DOUBLE_EQ(m.tension_limit(), T);
  std::vector<double> h;
  {
    // uniaxial-strain extension: sigma_xx exceeds T, lands on the tension plane
    const std::array<double, 3> eps = {{2e-3, 0, 0}};
    const Stress                s   = one_step(m, eps, h);
    const auto                  p   = principal(s);
    EXPECT_NEAR(p[0], T, 1e-10 * T);
    EXPECT_LE(mc_max(p, c, phi), 1e-9 * c);
    EXPECT_LT(p[1], T);
    // associated Rankine flow: plastic strain only along the x axis
    const auto ep = plastic_strain(eps, s, E, nu);
    EXPECT_GT(ep[0], 0.0);
    EXPECT_NEAR(ep[1], 0.0, 1e-12);
    EXPECT_NEAR(ep[2], 0.0, 1e-12);
    EXPECT_EQ(h[MohrCoulomb::h_yield_state], 1.0);
  }
  {
    // isotropic extension far beyond: tension apex T (1,1,1), not the MC apex
    const Stress s = one_step(m, {{1e-2, 1e-2, 1e-2}}, h);
    for (unsigned int i = 0; i < 3; ++i)
      EXPECT_NEAR(s[i][i], T, 1e-10 * T);
    EXPECT_NEAR(s[0][1], 0.0, 1e-10 * T);
  }
  {
    // corner between the MC face and the tension plane
    const auto   eps = strain_for_trial({{20e3, -10e3, -60e3}}, E, nu);
    const Stress s   = one_step(m, eps, h);
    const auto   p   = principal(s);
    EXPECT_NEAR(p[0], T, 1e-10 * T);
    EXPECT_NEAR(mc_max(p, c, phi), 0.0, 1e-9 * c);
  }
}

TEST(MohrCoulomb, RejectsBadParameters)
{
  EXPECT_THROW(MohrCoulomb(-1, 0.3, 0, 30, 0), talus::InputError);
  EXPECT_THROW(MohrCoulomb(1e6, 0.5, 0, 30, 0), talus::InputError);
  EXPECT_THROW(MohrCoulomb(1e6, 0.3, -1, 30, 0), talus::InputError);
  EXPECT_THROW(MohrCoulomb(1e6, 0.3, 0, 30, 35), talus::InputError); // psi > phi
  EXPECT_THROW(MohrCoulomb(1e6, 0.3, 0, 30, -1), talus::InputError);
  EXPECT_THROW(MohrCoulomb(1e6, 0.3, 0, 95, 0), talus::InputError);
  EXPECT_NO_THROW(MohrCoulomb(1e6, 0.3, 0, 30, 30));

  // through the registry: the message names the material and the entry
  dealii::ParameterHandler prm;
  prm.enter_subsection("material");
  declare_material_parameters(prm);
  prm.leave_subsection();
  prm.parse_input_from_string("subsection material\n set model = mohr coulomb\n"
                              " subsection mohr coulomb\n  set friction angle = 20\n"
                              "  set dilatancy angle = 25\n end\nend\n");
  prm.enter_subsection("material");
  try
    {
      create_material(prm, "material", 0);
      FAIL() << "no exception";
    }
  catch (const talus::InputError &e)
    {
      const std::string w = e.what();
      EXPECT_NE(w.find("material/mohr coulomb/dilatancy angle"), std::string::npos) << w;
    }
  prm.leave_subsection();
}

// ---------------------------------------------------------------- Tresca
#include <talus/materials/tresca.h>

TEST(Tresca, UndrainedTriaxialFailsAtTwiceSu)
{
  const double su = 25e3;
  for (const auto path : {ElementPath::undrained_triaxial_compression, ElementPath::undrained_triaxial_extension,
                          ElementPath::drained_triaxial_compression})
    {
      Tresca              m(15e6, 0.45, su);
      ElementTestSettings set;
      set.path             = path;
      set.target_strain    = 0.02;
      set.n_increments     = 100;
      set.initial_pressure = 80e3;
      std::vector<ElementRecord> rec;
      run_element_test(m, set, [&](const ElementRecord &r) { rec.push_back(r); });
      const ElementRecord &last = rec.back();
      EXPECT_NEAR(last.q(), 2 * su, 1e-10 * su);
      // the deviator is reached, never exceeded
      for (const auto &r : rec)
        EXPECT_LE(r.q(), 2 * su * (1 + 1e-12));
      // elastic start: q = 3 G eps_q (undrained: eps_q = eps_a)
      if (path == ElementPath::undrained_triaxial_compression)
        {
          const double G = 15e6 / (2 * 1.45);
          EXPECT_NEAR(rec[1].q(), 3 * G * rec[1].eps_axial(), 1e-9 * rec[1].q());
        }
      EXPECT_GT(last.history[Tresca::h_plastic_shear_strain], 0.0);
    }
}

TEST(Tresca, SimpleShearFailsAtSu)
{
  const double        su = 10e3;
  Tresca              m(5e6, 0.3, su);
  ElementTestSettings set;
  set.path             = ElementPath::simple_shear;
  set.target_strain    = 0.05;
  set.n_increments     = 500;
  set.initial_pressure = 50e3;
  ElementRecord last;
  run_element_test(m, set, [&](const ElementRecord &r) { last = r; });
  // pure shear plane stress state: tau_xy -> s_u (no normal stress change)
  EXPECT_NEAR(std::abs(last.sigma[0][1]), su, 1e-3 * su); // Jaumann spin rotates slightly
  const auto p = dealii::eigenvalues(last.sigma);
  EXPECT_NEAR(p[0] - p[2], 2 * su, 1e-10 * su);
}

TEST(Tresca, EdgeReturn)
{
  const double        E = 10e6, nu = 0.3, su = 20e3;
  Tresca              m(E, nu, su);
  std::vector<double> h;
  const Stress        s = one_step(m, strain_for_trial({{-50e3, -52e3, -120e3}}, E, nu), h);
  const auto          p = principal(s);
  EXPECT_NEAR(p[0], p[1], 1e-9 * su);
  EXPECT_NEAR(p[0] - p[2], 2 * su, 1e-9 * su);
  EXPECT_EQ(h[Tresca::h_yield_state], 2.0);
  // associated flow is deviatoric: no volume change across the return
  EXPECT_NEAR(trace(s), -50e3 - 52e3 - 120e3, 1e-9 * su);
}

TEST(Tresca, RejectsBadParameters)
{
  EXPECT_THROW(Tresca(0, 0.3, 1e3), talus::InputError);
  EXPECT_THROW(Tresca(1e6, 0.5, 1e3), talus::InputError);
  EXPECT_THROW(Tresca(1e6, 0.3, 0), talus::InputError);
  EXPECT_NO_THROW(Tresca(1e6, 0.49, 1e3));
}
