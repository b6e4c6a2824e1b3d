#include <talus/base/errors.h>
#include <talus/materials/hencky_mohr_coulomb.h>

#include <gtest/gtest.h>

#include "finite_strain_test_utils.h"

#include <cmath>

using namespace talus::materials;
using namespace talus_test;

namespace
{
  const double E = 20e6, nu = 0.3, C = 10e3, PHI = 30, PSI = 10;

  std::vector<double>
  iso(const HenckyMohrCoulomb &m, const double p = -100e3)
  {
    return init_history(m, p * dealii::unit_symmetric_tensor<3>());
  }

  T2
  with_shear(T2 f, const double g)
  {
    f[0][1] += g;
    f[1][2] += 0.5 * g;
    f[2][0] -= 0.3 * g;
    return f;
  }

  int
  region(const HenckyMohrCoulomb &m, const T2 &f, const std::vector<double> &h)
  {
    return int(step(m, f, h, false).hist[8]);
  }
} // namespace

TEST(HenckyMohrCoulomb, TangentMatchesFiniteDifferenceInEveryRegion)
{
  HenckyMohrCoulomb m(E, nu, C, PHI, PSI);
  const auto        h = iso(m);
  struct Case
  {
    const char *name;
    T2          f;
    int         region;
    double      floor;
  };
  const Case cases[] = {
    {"elastic", with_shear(diag(1.0005, 1.0, 0.9995), 2e-4), 0, 0.0},
    {"elastic equal stretches", diag(1.0, 1.0, 0.999), 0, 0.0},
    {"plane", with_shear(diag(1.004, 1.001, 0.99), 3e-3), 1, 0.0},
    {"edge tau1=tau2 (equal stretches)", diag(1.005, 1.005, 0.98), 2, 0.0},
    {"edge tau1=tau2 (general)", with_shear(diag(1.005, 1.0051, 0.98), 1e-3), 2, 0.0},
    {"edge tau2=tau3 (equal stretches)", diag(1.015, 0.985, 0.985), 3, 0.0},
    {"edge tau2=tau3 (general)", with_shear(diag(1.015, 0.9851, 0.985), 1e-3), 3, 0.0},
    // apex: tau = c cot(phi) I is constant, the exact tangent is zero; the error is
    // measured relative to the elastic scale E.
    {"apex", with_shear(diag(1.03, 1.03, 1.03), 1e-3), 4, E},
  };
  for (const auto &cs : cases)
    {
      ASSERT_EQ(region(m, cs.f, h), cs.region) << cs.name;
      const double err = tangent_error(m, cs.f, h, cs.floor);
      std::printf("Hencky MC tangent FD rel. error, %-36s %.2e\n", cs.name, err);
      EXPECT_LT(err, 1e-6) << cs.name;
    }
  // from a plastically deformed history (b_e != sym. state)
  const auto hp = step(m, with_shear(diag(1.004, 1.001, 0.99), 3e-3), h, false).hist;
  const T2   f2 = with_shear(diag(1.002, 1.0005, 0.995), 1.5e-3);
  ASSERT_GT(region(m, f2, hp), 0);
  const double err = tangent_error(m, f2, hp);
  std::printf("Hencky MC tangent FD rel. error, plastic from plastic history   %.2e\n", err);
  EXPECT_LT(err, 1e-6);
}

TEST(HenckyMohrCoulomb, ReturnsSatisfyYieldAndFlowRule)
{
  HenckyMohrCoulomb m(E, nu, C, PHI, PSI);
  const auto        h    = iso(m);
  const double      sphi = std::sin(PHI * M_PI / 180), spsi = std::sin(PSI * M_PI / 180);
  const double      k = (1 + sphi) / (1 - sphi), mm = (1 + spsi) / (1 - spsi);
  // plane: f = 0 and plastic log-strain increment parallel to (m, 0, -1)
  {
    const double e_tr[3] = {0.004, -0.001, -0.012};
    double       t[3], D[3][3];
    ASSERT_EQ(m.principal_return(e_tr, t, D), 1);
    EXPECT_NEAR(m.yield_function(t), 0.0, 1e-9 * C);
    const double G = m.shear_modulus(), L = m.lame_lambda();
    const double s = (t[0] + t[1] + t[2]) * L / (2 * G * (3 * L + 2 * G));
    double       dp[3];
    for (int A = 0; A < 3; ++A)
      dp[A] = e_tr[A] - (t[A] / (2 * G) - s);
    EXPECT_NEAR(dp[1], 0.0, 1e-12);
    EXPECT_NEAR(dp[0] / dp[2], -mm, 1e-9 * mm);
  }
  // triaxial compression edge (tau1 = tau2 lateral, tau3 axial): closed form
  //   sigma_a' = sigma_r' (1+sin phi)/(1-sin phi) + 2 c cos phi/(1-sin phi) (compression +)
  {
    const Step st = step(m, diag(1.005, 1.005, 0.98), h, false);
    ASSERT_EQ(int(st.hist[8]), 2);
    const double sr = -st.tau[0][0], sa = -st.tau[2][2];
    EXPECT_NEAR(st.tau[0][0], st.tau[1][1], 1e-9 * C);
    EXPECT_NEAR(sa, sr * k + 2 * C * std::sqrt(k), 1e-9 * sa);
  }
  // apex: tau = c cot(phi) I
  {
    const Step st = step(m, diag(1.03, 1.03, 1.03), h, false);
    ASSERT_EQ(int(st.hist[8]), 4);
    const double ta = C / std::tan(PHI * M_PI / 180);
    EXPECT_LT((st.tau - ta * dealii::unit_symmetric_tensor<3>()).norm(), 1e-9 * ta);
  }
}

TEST(HenckyMohrCoulomb, ObjectivityUnderSuperposedRotation)
{
  HenckyMohrCoulomb m(E, nu, C, PHI, PSI);
  const auto        h = iso(m);
  const T2          Q = rotation(1, 0.2, -0.7, -1.3);
  for (const T2 &f : {with_shear(diag(1.004, 1.001, 0.99), 3e-3), T2(diag(1.005, 1.005, 0.98)),
                      with_shear(diag(1.03, 1.03, 1.03), 1e-3)})
    {
      const Step a = step(m, f, h, false), b = step(m, Q * f, h, false);
      EXPECT_LT((rotate(a.tau, Q) - b.tau).norm(), 1e-10 * a.tau.norm());
      Stress ba, bb;
      for (unsigned int c = 0; c < 3; ++c)
        {
          ba[c][c] = a.hist[c];
          bb[c][c] = b.hist[c];
        }
      ba[0][1] = a.hist[3];
      ba[1][2] = a.hist[4];
      ba[0][2] = a.hist[5];
      bb[0][1] = b.hist[3];
      bb[1][2] = b.hist[4];
      bb[0][2] = b.hist[5];
      EXPECT_LT((rotate(ba, Q) - bb).norm(), 1e-10 * ba.norm());
      for (unsigned int i = 6; i < 9; ++i)
        EXPECT_NEAR(a.hist[i], b.hist[i], 1e-10 * (1 + std::abs(a.hist[i])));
    }
}

TEST(HenckyMohrCoulomb, RateFormAndModulus)
{
  HenckyMohrCoulomb m(E, nu, C, PHI, PSI);
  auto              h1 = iso(m);
  auto              h2 = h1;
  Stress            sigma;
  for (int s = 0; s < 30; ++s)
    {
      T2 g;
      g[2][2] = -1e-3;
      g[0][0] = g[1][1] = 3e-4;
      g[0][2]           = 5e-4;
      m.update_stress(symmetrize(g), 0.5 * (g - transpose(g)), 1e-3, sigma,
                      dealii::ArrayView<double>(h1.data(), h1.size()));
      const Step st = step(m, identity2() + g, h2, false);
      h2            = st.hist;
      EXPECT_LT((sigma - st.tau / h2[6]).norm(), 1e-10 * st.tau.norm());
    }
  EXPECT_GT(h1[7], 0.0);
  EXPECT_NEAR(m.constrained_modulus(), E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)), 1e-6);
  EXPECT_EQ(m.history_names().size(), m.n_history());
}

TEST(HenckyMohrCoulomb, RejectsBadParameters)
{
  EXPECT_THROW(HenckyMohrCoulomb(-1, nu, C, PHI, PSI), talus::InputError);
  EXPECT_THROW(HenckyMohrCoulomb(E, 0.5, C, PHI, PSI), talus::InputError);
  EXPECT_THROW(HenckyMohrCoulomb(E, nu, -1, PHI, PSI), talus::InputError);
  EXPECT_THROW(HenckyMohrCoulomb(E, nu, C, 0, 0), talus::InputError);
  EXPECT_THROW(HenckyMohrCoulomb(E, nu, C, PHI, PHI + 1), talus::InputError);
  EXPECT_THROW(HenckyMohrCoulomb(E, nu, C, PHI, -1), talus::InputError);
  HenckyMohrCoulomb m(E, nu, C, PHI, PSI);
  Stress            bad;
  bad[0][0] = -1e6; // uniaxial compression far beyond the strength
  std::vector<double> h(m.n_history());
  EXPECT_THROW(m.initialize_history(bad, dealii::ArrayView<double>(h.data(), h.size())), talus::InputError);
}
