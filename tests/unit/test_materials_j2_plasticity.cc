#include <talus/base/errors.h>
#include <talus/materials/j2_plasticity.h>

#include <gtest/gtest.h>

#include "finite_strain_test_utils.h"

#include <cmath>

using namespace talus::materials;
using namespace talus_test;

namespace
{
  // steel-like: yield strain sigma_Y / E = 1e-3
  const double E = 200e9, nu = 0.3, SY = 200e6, H = 20e9;

  T2
  shear_dF(const double g)
  {
    T2 f    = identity2();
    f[0][1] = g;
    f[1][2] = 0.3 * g;
    f[2][2] += 0.2 * g;
    return f;
  }

  std::vector<double>
  plastic_history(const J2Plasticity &m)
  {
    // a first plastic step so that bbar_e != I and alpha > 0
    T2 f    = identity2();
    f[0][0] = 1.01;
    f[1][0] = 0.004;
    f[2][2] = 0.995;
    return step(m, f, init_history(m), false).hist;
  }
} // namespace

TEST(J2Plasticity, TangentMatchesFiniteDifference)
{
  for (const double h : {H, 0.0})
    {
      J2Plasticity m(E, nu, SY, h);
      const auto   h0 = init_history(m);
      const auto   hp = plastic_history(m);
      ASSERT_GT(hp[7], 0.0);
      const double e_el  = tangent_error(m, shear_dF(2e-4), h0);            // elastic
      const double e_pl1 = tangent_error(m, shear_dF(5e-3), h0);            // plastic, from virgin state
      const double e_pl2 = tangent_error(m, shear_dF(-3e-3), hp);           // plastic, prestrained history
      const double e_eq  = tangent_error(m, diag(1.004, 0.998, 0.998), h0); // two equal stretches, plastic
      const double e_big = tangent_error(m, shear_dF(0.2), hp);             // large plastic step
      std::printf("J2 (H=%g) tangent FD rel. errors: elastic %.2e plastic %.2e %.2e equal-stretch %.2e large %.2e\n", h,
                  e_el, e_pl1, e_pl2, e_eq, e_big);
      EXPECT_LT(e_el, 1e-6);
      EXPECT_LT(e_pl1, 1e-6);
      EXPECT_LT(e_pl2, 1e-6);
      EXPECT_LT(e_eq, 1e-6);
      EXPECT_LT(e_big, 1e-6);
      // the equal-stretch step is indeed plastic
      EXPECT_GT(step(m, diag(1.004, 0.998, 0.998), h0, false).hist[7], 0.0);
    }
}

TEST(J2Plasticity, ObjectivityUnderSuperposedRotation)
{
  J2Plasticity m(E, nu, SY, H);
  const auto   hp = plastic_history(m);
  const T2     f  = shear_dF(4e-3);
  const T2     Q  = rotation(0.3, 1, -0.4, 2.1);
  const Step   a  = step(m, f, hp);
  const Step   b  = step(m, Q * f, hp);
  ASSERT_GT(a.hist[7], hp[7]); // plastic step
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
  EXPECT_NEAR(a.hist[6], b.hist[6], 1e-14);             // J unchanged
  EXPECT_NEAR(a.hist[7], b.hist[7], 1e-10 * a.hist[7]); // alpha unchanged
}

TEST(J2Plasticity, UniaxialTensionYieldAndHardeningSlope)
{
  // Uniaxial Kirchhoff stress, F = diag(l, r, r) with tau22 = tau33 = 0 (lateral
  // stretch by Newton on the consistent tangent), log strain eps = ln l in steps
  // of 1e-4 to 5 %.
  // * Yield: with s = dev tau, ||s|| = sqrt(2/3) tau11, so f = 0 <=> tau11 = sigma_Y + H alpha;
  //   first yield at tau11 = sigma_Y, at eps_y = sigma_Y/E (to O(eps_y) = 0.1 %).
  // * Hardening: with additive log strains eps = eps_e + eps_p, eps_e = tau11/E and
  //   alpha = eps_p (isochoric flow along n = diag(2,-1,-1)/sqrt 6), the slope is
  //   d tau11 / d eps = E H / (E + H)   (= 18.18 GPa here), to O(eps_e) = 1e-3.
  J2Plasticity        m(E, nu, SY, H);
  auto                h               = init_history(m);
  const double        de              = 1e-4;
  const int           n               = 500;
  double              eps_first_yield = -1, tau_last_elastic = 0;
  std::vector<double> tau11(n + 1, 0.0), alpha(n + 1, 0.0);
  for (int s = 1; s <= n; ++s)
    {
      const double a = std::exp(de);
      double       r = 1.0;
      Step         st;
      for (int it = 0; it < 40; ++it)
        {
          st             = step(m, diag(a, r, r), h);
          const double g = st.tau[1][1];
          r -= g / (st.tangent[1][1][1][1] + st.tangent[1][1][2][2]);
          if (std::abs(g) < 1e-6)
            break;
        }
      st       = step(m, diag(a, r, r), h, false);
      h        = st.hist;
      tau11[s] = st.tau[0][0];
      alpha[s] = h[7];
      EXPECT_NEAR(st.tau[1][1], 0.0, 1e-3);
      if (h[7] > 0)
        {
          if (eps_first_yield < 0)
            eps_first_yield = s * de;
          // on the yield surface: tau11 = sigma_Y + H alpha
          EXPECT_NEAR(tau11[s], SY + H * h[7], 1e-8 * SY);
        }
      else
        tau_last_elastic = tau11[s];
    }
  // yield onset between the last elastic and the first plastic step
  EXPECT_LT(tau_last_elastic, SY);
  EXPECT_GT(tau_last_elastic, SY - 1.01 * E * de);
  EXPECT_NEAR(eps_first_yield, SY / E, 1.01 * de);
  // hardening slope between 2 % and 5 %
  const double slope = (tau11[500] - tau11[200]) / (300 * de);
  const double Et    = E * H / (E + H);
  std::printf("J2 uniaxial: first yield at eps = %.4e (sigma_Y/E = %.4e), slope %.5e vs E H/(E+H) = %.5e\n",
              eps_first_yield, SY / E, slope, Et);
  EXPECT_NEAR(slope, Et, 0.01 * Et);
  // and the plastic strain follows the same closed form: alpha ~ eps - tau11/E
  EXPECT_NEAR(alpha[500], 0.05 - tau11[500] / E, 0.01 * alpha[500]);
}

TEST(J2Plasticity, RateFormMatchesFiniteStrainForm)
{
  // update_stress builds dF = I + d_eps + d_omega: for an exact grad du the two
  // forms coincide, and sigma = tau / J.
  J2Plasticity m(E, nu, SY, H);
  auto         h1 = init_history(m);
  auto         h2 = h1;
  Stress       sigma;
  for (int s = 0; s < 20; ++s)
    {
      T2 g; // grad du
      g[0][1]   = 4e-4;
      g[0][0]   = 1e-4;
      g[2][2]   = -2e-4;
      Strain de = symmetrize(g);
      Spin   w  = 0.5 * (g - transpose(g));
      m.update_stress(de, w, 1e-3, sigma, dealii::ArrayView<double>(h1.data(), h1.size()));
      const Step st = step(m, identity2() + g, h2, false);
      h2            = st.hist;
      EXPECT_LT((sigma - st.tau / h2[6]).norm(), 1e-12 * st.tau.norm());
    }
  EXPECT_GT(h1[7], 0.0);
}

TEST(J2Plasticity, InitialStressAndModulus)
{
  J2Plasticity m(E, nu, SY, H);
  Stress       s;
  s[0][0]      = -50e6;
  s[1][1]      = -80e6;
  s[2][2]      = -60e6;
  s[1][2]      = 20e6;
  const auto h = init_history(m, s);
  EXPECT_LT((step(m, identity2(), h, false).tau - s).norm(), 1e-8 * s.norm());
  Stress big;
  big[0][1] = SY;
  EXPECT_THROW(init_history(m, big), talus::InputError);
  EXPECT_NEAR(m.constrained_modulus(), E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)), 1e-3);
  EXPECT_EQ(m.history_names().size(), m.n_history());
}

TEST(J2Plasticity, RejectsBadParameters)
{
  EXPECT_THROW(J2Plasticity(-E, nu, SY, H), talus::InputError);
  EXPECT_THROW(J2Plasticity(E, 0.5, SY, H), talus::InputError);
  EXPECT_THROW(J2Plasticity(E, nu, 0.0, H), talus::InputError);
  EXPECT_THROW(J2Plasticity(E, nu, SY, -1.0), talus::InputError);
}
