// Liquids: Newtonian, Bingham, frictional fluid — shear stress vs shear rate,
// pressure, cavitation, parameter validation.
#include <talus/base/errors.h>
#include <talus/materials/bingham.h>
#include <talus/materials/frictional_fluid.h>
#include <talus/materials/material.h>
#include <talus/materials/newtonian.h>
#include <talus/materials/single_element.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace talus::materials;

namespace
{
  // Steady simple shear at rate gdot: returns tau_xy after n steps of dt.
  ElementRecord
  shear(const Material &m, const double gdot, const double p0, const unsigned int n = 200, const double dt = 1e-3)
  {
    ElementTestSettings set;
    set.path             = ElementPath::simple_shear;
    set.time_increment   = dt;
    set.n_increments     = n;
    set.target_strain    = gdot * dt * n;
    set.initial_pressure = p0;
    ElementRecord last;
    run_element_test(m, set, [&](const ElementRecord &r) { last = r; });
    return last;
  }
} // namespace

TEST(Newtonian, ShearStressIsViscosityTimesShearRate)
{
  const double mu = 2.5e-3;
  Newtonian    m(2e9, mu, -1e5);
  for (const double gdot : {0.1, 1.0, 37.0, 1e3})
    {
      const ElementRecord r = shear(m, gdot, 1e5, 10);
      EXPECT_NEAR(r.sigma[0][1], mu * gdot, 1e-12 * mu * gdot) << gdot;
      EXPECT_NEAR(r.sigma[0][0], -1e5, 1e-9 * 1e5); // no normal stress in simple shear
    }
  // uniaxial straining: sigma_xx = -p + 4/3 mu eps_dot
  Stress              s;
  std::vector<double> h(1);
  m.initialize_history(s, ArrayView<double>(h.data(), 1));
  Strain d;
  d[0][0] = -1e-6;
  m.update_stress(d, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
  const double p = 2e9 * 1e-6;
  EXPECT_NEAR(s[0][0], -p + 4.0 / 3.0 * mu * (-1e-3), 1e-12 * p);
  EXPECT_NEAR(s[1][1], -p - 2.0 / 3.0 * mu * (-1e-3), 1e-12 * p);
}

TEST(Newtonian, CavitationThreshold)
{
  const double K = 2e9, p_cav = -50e3, mu = 1e-3;
  Newtonian    m(K, mu, p_cav);
  m.incremental_cavitation = false; // the density form (Eqs. 7.30-7.32)
  Stress s;
  s[0][0] = s[1][1] = s[2][2] = -100e3; // p0 = 100 kPa
  std::vector<double> h(1);
  m.initialize_history(s, ArrayView<double>(h.data(), 1));
  Strain       d;
  const double de = 1e-5; // isotropic expansion steps, dp = -K de = -20 kPa each (pure volumetric)
  for (unsigned int i = 0; i < 3; ++i)
    d[i][i] = de / 3;
  std::vector<double> p;
  for (int k = 0; k < 12; ++k)
    {
      m.update_stress(d, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
      p.push_back(-trace(s) / 3);
    }
  EXPECT_NEAR(p[0], 80e3, 1e-6);
  EXPECT_NEAR(p[6], -40e3, 1e-6);
  for (int k = 7; k < 12; ++k)
    EXPECT_DOUBLE_EQ(p[k], p_cav); // clamped at the threshold
  // recompression: stays at p_cav until the cavitated volume is closed again
  // (the unclamped pressure reached -140 kPa: -120, -100, -80, -60 are still below
  // the threshold, then -40, -20)
  const Strain        dc = -d;
  std::vector<double> pr;
  for (int k = 0; k < 6; ++k)
    {
      m.update_stress(dc, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
      pr.push_back(-trace(s) / 3);
    }
  EXPECT_DOUBLE_EQ(pr[0], p_cav);
  EXPECT_DOUBLE_EQ(pr[3], p_cav);
  EXPECT_NEAR(pr[4], -40e3, 1e-6);
  EXPECT_NEAR(pr[5], -20e3, 1e-6);
  // a cavitated liquid carries no shear stress
  Stress              sc = s;
  std::vector<double> hc = {1e-3}; // expanded far into the cavitated range
  Strain              g;
  g[0][1] = 1e-3;
  m.update_stress(g, Spin(), 1e-3, sc, ArrayView<double>(hc.data(), 1));
  EXPECT_DOUBLE_EQ(sc[0][1], 0.0);
  EXPECT_DOUBLE_EQ(-trace(sc) / 3, p_cav);
}

TEST(Newtonian, CavitationIncrementalRecovery)
{
  // seed 000 Eq. 7.33 (the default): the same path as above, but the pressure
  // rises again at the first compression after cavitation
  const double K = 2e9, p_cav = -50e3, mu = 1e-3;
  Newtonian    m(K, mu, p_cav);
  EXPECT_TRUE(m.incremental_cavitation);
  Stress s;
  s[0][0] = s[1][1] = s[2][2] = -100e3;
  std::vector<double> h(1);
  m.initialize_history(s, ArrayView<double>(h.data(), 1));
  Strain d;
  for (unsigned int i = 0; i < 3; ++i)
    d[i][i] = 1e-5 / 3; // dp = -20 kPa per step
  for (int k = 0; k < 12; ++k)
    m.update_stress(d, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
  EXPECT_DOUBLE_EQ(-trace(s) / 3, p_cav);
  const Strain dc = -d;
  m.update_stress(dc, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
  EXPECT_NEAR(-trace(s) / 3, p_cav + 20e3, 1e-6);
  m.update_stress(dc, Spin(), 1e-3, s, ArrayView<double>(h.data(), 1));
  EXPECT_NEAR(-trace(s) / 3, p_cav + 40e3, 1e-6);
}

TEST(Bingham, ShearStressVsShearRate)
{
  const double tau_y = 200, mu = 5, mu_max = 1e4;
  Bingham      m(1e6, 0.3, 1e8, tau_y, mu, mu_max, -1e9);
  // yielded regime: tau = tau_y + mu gdot (mu + tau_y/gdot < mu_max <=> gdot > 0.02)
  for (const double gdot : {0.5, 3.0, 40.0, 500.0})
    {
      const ElementRecord r = shear(m, gdot, 1e4, 2000, 1e-3);
      EXPECT_NEAR(r.sigma[0][1], tau_y + mu * gdot, 1e-12 * (tau_y + mu * gdot)) << gdot;
      EXPECT_NEAR(r.history[Bingham::h_effective_viscosity], mu + tau_y / gdot, 1e-12 * mu_max);
    }
  // below the yield stress: elastic, tau = G gamma
  {
    const double        G = 1e6 / 2.6;
    const ElementRecord r = shear(m, 0.01, 1e4, 10, 1e-3); // gamma = 1e-4, G gamma = 38 Pa
    EXPECT_NEAR(r.sigma[0][1], G * 1e-4, 1e-3 * G * 1e-4); // small Jaumann correction only
    EXPECT_EQ(r.history[Bingham::h_effective_viscosity], 0.0);
  }
  // capped: at tiny rates the effective viscosity is mu_max
  {
    Stress s;
    s[0][1]               = tau_y * (1 - 1e-7); // just below yield
    std::vector<double> h = {0.0, 0.0};
    Strain              d;
    d[0][1] = 0.5 * 1e-6 * 1e-3; // gdot = 1e-6, elastic trial exceeds tau_y
    m.update_stress(d, Spin(), 1e-3, s, ArrayView<double>(h.data(), 2));
    EXPECT_DOUBLE_EQ(h[Bingham::h_effective_viscosity], mu_max);
    EXPECT_NEAR(s[0][1], mu_max * 1e-6, 1e-12);
  }
}

TEST(FrictionalFluid, YieldStressFromPressure)
{
  const double    phi = 30, mu = 2, p0 = 40e3;
  FrictionalFluid m(5e6, 0.3, 1e8, phi, mu, 1e6, -1e9);
  for (const double gdot : {1.0, 10.0, 100.0})
    {
      const ElementRecord r        = shear(m, gdot, p0, 4000, 1e-3);
      const double        expected = p0 * std::sin(phi * M_PI / 180) + mu * gdot;
      EXPECT_NEAR(r.sigma[0][1], expected, 1e-12 * expected) << gdot;
      EXPECT_NEAR(-trace(r.sigma) / 3, p0, 1e-9 * p0);
    }
  // no pressure, no strength: behaves as the Newtonian liquid of viscosity mu
  const ElementRecord r = shear(m, 10.0, 0.0, 100, 1e-3);
  EXPECT_NEAR(r.sigma[0][1], mu * 10.0, 1e-12 * mu * 10);
}

TEST(Liquids, RejectBadParameters)
{
  EXPECT_THROW(Newtonian(0, 1e-3, 0), talus::InputError);
  EXPECT_THROW(Newtonian(1e9, -1, 0), talus::InputError);
  EXPECT_THROW(Newtonian(1e9, 1e-3, 10), talus::InputError); // threshold > 0
  EXPECT_THROW(Bingham(1e6, 0.3, 1e9, -1, 1, 10, 0), talus::InputError);
  EXPECT_THROW(Bingham(1e6, 0.3, 1e9, 1, 10, 5, 0), talus::InputError); // mu_max < mu
  EXPECT_THROW(Bingham(1e6, 0.6, 1e9, 1, 1, 5, 0), talus::InputError);
  EXPECT_THROW(FrictionalFluid(1e6, 0.3, 1e9, 95, 1, 5, 0), talus::InputError);
  EXPECT_THROW(FrictionalFluid(1e6, 0.3, 1e9, 30, 1, 0, 0), talus::InputError);

  dealii::ParameterHandler prm;
  prm.enter_subsection("water");
  declare_material_parameters(prm);
  prm.leave_subsection();
  prm.parse_input_from_string("subsection water\n set model = newtonian\n"
                              " subsection newtonian\n  set bulk modulus = -5\n end\nend\n");
  prm.enter_subsection("water");
  try
    {
      create_material(prm, "water", 0);
      FAIL() << "no exception";
    }
  catch (const talus::InputError &e)
    {
      EXPECT_NE(std::string(e.what()).find("water/newtonian/bulk modulus"), std::string::npos) << e.what();
    }
  prm.leave_subsection();
}
