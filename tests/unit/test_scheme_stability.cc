// Stability limit of the implemented explicit step on a uniform 1D grid (issue 6):
// the eigenvalues of the full point-state amplification matrix (LAPACK) must give
// the closed form of the reduced nodal recurrence, docs/stability-analysis.md.
#include <talus/analysis/scheme_stability.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace talus::analysis;

TEST(SchemeStability, ClosedFormValues)
{
  EXPECT_NEAR(scheme_critical_factor_closed_form(1), 2.0, 1e-14);
  EXPECT_NEAR(scheme_critical_factor_closed_form(2), std::sqrt(3.0), 1e-14);
}

TEST(SchemeStability, EigenvaluesMatchClosedForm)
{
  // the fixed-free bar of 32 cells (the verification bar): within 0.2 % for n = 1..4
  for (unsigned int n = 1; n <= 4; ++n)
    {
      const double f = scheme_critical_factor(n, 32, false);
      EXPECT_NEAR(f / scheme_critical_factor_closed_form(n), 1.0, 2e-3) << "n = " << n;
    }
  // periodic grid of 48 cells: the Bloch wavenumbers 2 pi k / 48 sample the critical one
  for (unsigned int n = 1; n <= 3; ++n)
    {
      const double f = scheme_critical_factor(n, 48, true);
      EXPECT_GE(f, scheme_critical_factor_closed_form(n) * (1 - 1e-5)) << "n = " << n;
      EXPECT_NEAR(f / scheme_critical_factor_closed_form(n), 1.0, 5e-3) << "n = " << n;
    }
}

TEST(SchemeStability, SpectralRadius)
{
  // undamped below the limit, growth above it (n = 2: sqrt(3))
  EXPECT_LE(scheme_spectral_radius(2, 32, false, 1.0), 1 + 1e-7);
  EXPECT_LE(scheme_spectral_radius(2, 32, false, 1.70), 1 + 1e-7);
  EXPECT_GT(scheme_spectral_radius(2, 32, false, 1.76), 1.05);
}

TEST(SchemeStability, CellCrossingGrowth)
{
  // at rest: no growth below the limit
  EXPECT_LE(crossing_growth_per_step(2, 0.5, 0.0, 8), 1 + 1e-7);
  // translating at V/c = 0.2, dt c/h = 0.5: parametric growth, the same on 8 and 16 cells
  // (a per-step factor independent of h), and it grows with the step (~ 1 + a C^2)
  double       v   = 0;
  const double g8  = crossing_growth_per_step(2, 0.5, 0.2, 8, &v);
  const double g16 = crossing_growth_per_step(2, 0.5, 0.2, 16);
  EXPECT_NEAR(v, 0.2, 1e-12);
  EXPECT_GT(g8, 1.03);
  EXPECT_LT(g8, 1.04);
  EXPECT_NEAR(g8, g16, 1e-4);
  const double g01 = crossing_growth_per_step(2, 0.1, 0.2, 8);
  EXPECT_GT(g01, 1.0);
  EXPECT_LT(g01 - 1, 0.1 * (g8 - 1));
}

TEST(SchemeStability, MovedPoints)
{
  EXPECT_NEAR(scheme_critical_factor_moved(1), 1.0, 1e-14);
  EXPECT_NEAR(scheme_critical_factor_moved(2), std::sqrt(2.0), 1e-14);
  for (unsigned int n = 1; n <= 4; ++n)
    {
      const double f = scheme_critical_factor_moved(n);
      // points on the nodes (shift of half a point spacing): the worst case, the limit is sharp
      // (48 periodic cells sample the critical wavenumber to < 1 %)
      EXPECT_LE(shifted_spectral_radius(n, 48, 0.5 / n, 0.995 * f), 1 + 1e-7) << "n = " << n;
      EXPECT_GT(shifted_spectral_radius(n, 48, 0.5 / n, 1.01 * f), 1 + 1e-4) << "n = " << n;
      // any other shift is at least as stable
      for (const double s : {0.0, 0.1, 0.2, 0.3, 0.4})
        EXPECT_LE(shifted_spectral_radius(n, 48, s / n, 0.995 * f), 1 + 1e-7) << "n = " << n << ", shift " << s;
    }
}
