#include <talus/base/errors.h>
#include <talus/materials/nor_sand.h>

#include <gtest/gtest.h>

#include "finite_strain_test_utils.h"

#include <cmath>

using namespace talus::materials;
using namespace talus_test;

namespace
{
  /// Hostun sand, seed 002 Table 6 (CSL logarithm with p in Pa).
  NorSand::Parameters
  hostun(const double v0, const double p0)
  {
    NorSand::Parameters P;
    P.G      = 40e6;
    P.kappa  = 0.002;
    P.v_c0   = 1.892;
    P.lambda = 0.02;
    P.M      = 1.0;
    P.N      = 0.1;
    P.N_bar  = 0.1;
    P.h      = 100;
    P.alpha  = -2.0;
    P.v0     = v0;
    P.p0     = p0;
    P.ocr    = 1.0;
    return P;
  }

  struct Path
  {
    std::vector<double> ea, p, q; // axial strain (compression +), p', q (compression +)
  };

  /// Undrained triaxial compression, seed 002 App. B.2.1 Eq. 106:
  /// dF = diag(1 + de, 1/sqrt(1+de), 1/sqrt(1+de)), J = 1.
  Path
  undrained(const NorSand &m, const double ea_max, const int n)
  {
    auto h = init_history(m);
    Path r;
    r.ea.push_back(0);
    r.p.push_back(m.parameters().p0);
    r.q.push_back(0);
    const double l_end = std::exp(-ea_max);
    double       l     = 1.0;
    for (int s = 1; s <= n; ++s)
      {
        const double ln = std::exp(std::log(l_end) * s / n);
        const double a  = ln / l;
        const Step   st = step(m, diag(a, 1 / std::sqrt(a), 1 / std::sqrt(a)), h, false);
        h               = st.hist;
        l               = ln;
        r.ea.push_back(-std::log(l));
        r.p.push_back(-trace(st.tau) / 3);
        r.q.push_back(st.tau[1][1] - st.tau[0][0]);
      }
    return r;
  }
} // namespace

TEST(NorSand, TangentMatchesFiniteDifference)
{
  NorSand    m(hostun(1.63, 100e3));
  const auto h0 = init_history(m);
  // a plastic history: 5 % undrained compression
  std::vector<double> h = h0;
  for (int s = 0; s < 50; ++s)
    h = step(m, diag(std::exp(-1e-3), std::exp(5e-4), std::exp(5e-4)), h, false).hist;
  T2 f    = diag(0.999, 1.0004, 1.0005);
  f[0][1] = 3e-4;
  f[2][0] = -2e-4;
  struct Case
  {
    const char                *name;
    T2                         f;
    const std::vector<double> *h;
  };
  const T2   fe      = diag(1.00001, 0.99999, 1.0);
  const Case cases[] = {{"plastic, general", f, &h},
                        {"plastic, two equal stretches", diag(0.999, 1.0005, 1.0005), &h},
                        {"plastic from the initial (tip) state", diag(0.999, 1.0005, 1.0005), &h0},
                        {"elastic unloading", diag(1.0002, 0.9999, 0.9999), &h}};
  (void)fe;
  for (const auto &c : cases)
    {
      const Step   st  = step(m, c.f, *c.h, false);
      const double err = tangent_error(m, c.f, *c.h, 0.0, 1e-7);
      std::printf("NorSand tangent FD rel. error, %-40s %.2e (dEd = %.2e)\n", c.name, err, st.hist[9] - (*c.h)[9]);
      EXPECT_LT(err, 1e-6) << c.name;
    }
  EXPECT_GT(step(m, f, h, false).hist[9], h[9]);                            // plastic
  EXPECT_EQ(step(m, diag(1.0002, 0.9999, 0.9999), h, false).hist[9], h[9]); // elastic
}

TEST(NorSand, ObjectivityUnderSuperposedRotation)
{
  NorSand m(hostun(1.63, 100e3));
  auto    h = init_history(m);
  for (int s = 0; s < 20; ++s)
    h = step(m, diag(std::exp(-1e-3), std::exp(5e-4), std::exp(5e-4)), h, false).hist;
  T2 f         = diag(0.998, 1.001, 1.0008);
  f[0][2]      = 5e-4;
  const T2   Q = rotation(-0.5, 1, 0.25, 0.9);
  const Step a = step(m, f, h, false), b = step(m, Q * f, h, false);
  EXPECT_LT((rotate(a.tau, Q) - b.tau).norm(), 1e-10 * a.tau.norm());
  for (unsigned int i = 6; i < 13; ++i)
    EXPECT_NEAR(a.hist[i], b.hist[i], 1e-10 * (std::abs(a.hist[i]) + 1e-12)) << i;
}

TEST(NorSand, UndrainedTriaxialDenseDilatesLooseContracts)
{
  // Hostun sand (seed 002 Table 6), isotropic start p0' = 100 kPa with OCR = 1
  // (image pressure from Eq. 113, i.e. the state sits on the yield-surface tip),
  // undrained compression to 30 % axial log strain in 3000 steps (Eq. 106).
  // Where the expected numbers come from:
  //  * Phase transformation (dense): undrained => eps_v = 0 => d eps_v^e = -d eps_v^p,
  //    and with p depending on eps_v^e only, dp' = 0 exactly where the plastic
  //    dilatancy dQ/dp vanishes, i.e. p = p_i, where the yield function gives
  //    eta = q/p' = M. So the minimum of p' lies on q = M p' (physics, to step size).
  //  * Critical state: p_i -> p_i* -> p and psi_i -> 0, so the end state satisfies
  //    v0 = v_c0 - lambda ln(p'_cs / 1 Pa): p'_cs = exp((v_c0 - v0)/lambda) Pa.
  //    Loose v0 = 2.0: p'_cs = exp(-5.4) Pa ~ 0 (static liquefaction, as Doanh et
  //    al.'s very loose Hostun RF specimens in seed 002 Fig. 14).
  //    Dense v0 = 1.63: p'_cs = 491 kPa (q keeps rising towards M p'_cs).
  //  * Peak q of the loose specimen and the PT point values: no closed form; the
  //    numbers below are this implementation's (regression, 2 %), with physical
  //    side conditions (peak below the CSL, eta_peak < M; magnitude ~ 1/3 p0' as
  //    in the very loose Hostun tests). Seed 002 Fig. 14 is not available as data.
  const double M = 1.0;
  {
    NorSand    m(hostun(1.63, 100e3)); // dense: psi_i = -0.08 at the start
    const Path r   = undrained(m, 0.3, 3000);
    size_t     ipt = 0;
    for (size_t i = 1; i < r.p.size(); ++i)
      if (r.p[i] < r.p[ipt] || ipt == 0)
        ipt = i;
    std::printf("dense: PT at ea = %.4f, p' = %.1f Pa, q = %.1f Pa, eta = %.4f; end q = %.1f, eta = %.4f\n", r.ea[ipt],
                r.p[ipt], r.q[ipt], r.q[ipt] / r.p[ipt], r.q.back(), r.q.back() / r.p.back());
    EXPECT_NEAR(r.q[ipt] / r.p[ipt], M, 0.005);   // physics: PT on q = M p'
    EXPECT_NEAR(r.ea[ipt], 0.0070, 0.0005);       // regression
    EXPECT_NEAR(r.p[ipt], 49.0e3, 0.02 * 49.0e3); // regression
    // dilation after PT: q and p' rise monotonically to the end
    for (size_t i = ipt + 1; i < r.q.size(); ++i)
      {
        ASSERT_GT(r.q[i], r.q[i - 1]) << "at ea = " << r.ea[i];
        ASSERT_GT(r.p[i], r.p[i - 1]) << "at ea = " << r.ea[i];
      }
    EXPECT_GT(r.q.back(), 3.5 * r.q[ipt]);
    EXPECT_LT(r.p.back(), 491e3);                  // still below p'_cs
    EXPECT_NEAR(r.q.back() / r.p.back(), M, 0.01); // along the CSL direction
  }
  {
    NorSand    m(hostun(2.0, 100e3)); // loose: psi_i = +0.32 at the start
    const Path r   = undrained(m, 0.3, 3000);
    size_t     ipk = 0;
    for (size_t i = 1; i < r.q.size(); ++i)
      if (r.q[i] > r.q[ipk])
        ipk = i;
    std::printf("loose: peak q = %.1f Pa at ea = %.4f, p' = %.1f Pa, eta = %.4f; end p' = %.1f q = %.1f\n", r.q[ipk],
                r.ea[ipk], r.p[ipk], r.q[ipk] / r.p[ipk], r.p.back(), r.q.back());
    EXPECT_NEAR(r.q[ipk], 36.8e3, 0.02 * 36.8e3); // regression
    EXPECT_NEAR(r.ea[ipk], 0.0030, 0.0005);       // regression
    EXPECT_LT(r.q[ipk] / r.p[ipk], M);            // peak below the CSL
    // contraction throughout: p' falls monotonically; q softens after the peak
    // (checked while p' > 100 Pa = 1e-3 p0': below ~20 Pa the return hits the
    //  yield-surface tip branch and p' jitters by a few Pa; known limitation)
    for (size_t i = 1; i < r.p.size() && r.p[i] > 100; ++i)
      ASSERT_LT(r.p[i], r.p[i - 1]) << "at ea = " << r.ea[i];
    for (size_t i = ipk + 1; i < r.q.size() && r.p[i] > 100; ++i)
      ASSERT_LT(r.q[i], r.q[i - 1]) << "at ea = " << r.ea[i];
    // static liquefaction towards p'_cs ~ 0
    EXPECT_LT(r.q.back(), 0.001 * r.q[ipk]);
    EXPECT_LT(r.p.back(), 30.0);
    EXPECT_LT(r.p.back(), 0.001 * 100e3);
  }
}

TEST(NorSand, GasCutoffAndInitialisation)
{
  NorSand m(hostun(2.0, 100e3));
  auto    h = init_history(m);
  // Eq. 113 with OCR = 1, N = 0.1: p_i = p0 (1-N)^((1-N)/N) = 0.3874 p0 (compression)
  EXPECT_NEAR(h[8], -100e3 * std::pow(0.9, 9.0), 1e-6);
  // isotropic stretch to v > 1.6 v0: zero stress and tangent, b_e = I
  const double a  = std::cbrt(1.7);
  const Step   st = step(m, diag(a, a, a), h);
  EXPECT_EQ(st.tau.norm(), 0.0);
  EXPECT_EQ(norm4(st.tangent), 0.0);
  EXPECT_NEAR(st.hist[7], 2.0 * 1.7, 1e-12);
  EXPECT_EQ(st.hist[0], 1.0);
  // App. B.4: elastic gravity phase, then the reference is re-taken
  m.set_plasticity(false);
  const double c = std::exp(-0.002);
  const Step   e = step(m, diag(c, c, c), h, false); // eps_v = -0.006: p = p0 e^3
  EXPECT_EQ(e.hist[9], 0.0);
  EXPECT_NEAR(trace(e.tau) / 3, -100e3 * std::exp(3.0), 1e-6 * 100e3 * std::exp(3.0));
  std::vector<double> h2 = e.hist;
  m.reinitialize_reference(dealii::ArrayView<double>(h2.data(), h2.size()));
  EXPECT_NEAR(h2[11], -100e3 * std::exp(3.0), 1e-3);
  EXPECT_NEAR(h2[8], h2[11] * std::pow(0.9, 9.0), 1e-3);
  EXPECT_EQ(m.history_names().size(), m.n_history());
}

TEST(NorSand, RejectsBadParameters)
{
  auto bad = [](auto mod) {
    NorSand::Parameters P = hostun(2.0, 100e3);
    mod(P);
    return P;
  };
  EXPECT_THROW(NorSand(bad([](auto &P) { P.G = 0; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.kappa = -1; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.N = 1.0; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.N_bar = 0.0; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.alpha = 2.0; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.ocr = 0.5; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.cut_end = 0.5; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.gas_factor = 1.0; })), talus::InputError);
  EXPECT_THROW(NorSand(bad([](auto &P) { P.v0 = 0.9; })), talus::InputError);
}
