// MPM-MIXED cell stress (formulations/explicit/mixed_integration.h): the
// least-squares fit reproduces a linear stress field, the Gauss-point force
// equals the exact integral -int sigma grad N dV of that field, degenerate point
// sets fall back to fewer slopes or a constant, the limiter bounds the field at
// the Gauss points, and the constant mode is Eq. 6.32 integrated over the cell.
#include <talus/formulations/explicit/mixed_integration.h>

#include <gtest/gtest.h>

#include <random>

using namespace talus;
using talus::explicit_mpm::CellStressFit;

namespace
{
  template <int dim>
  using Fit = CellStressFit<dim>;
  template <int dim>
  using QF = shape::Q1Factorised<dim>;

  /// linear field s_q(xi) = a_q + sum_k b_qk xi_k
  template <int dim>
  struct Linear
  {
    double a[Fit<dim>::nst], b[Fit<dim>::nst][dim];
    void
    eval(const dealii::Point<dim> &xi, double *s) const
    {
      for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
        {
          s[q] = a[q];
          for (unsigned int k = 0; k < dim; ++k)
            s[q] += b[q][k] * xi[k];
        }
    }
  };

  template <int dim>
  Linear<dim>
  random_linear(std::mt19937 &rng)
  {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Linear<dim>                            f;
    for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
      {
        f.a[q] = 1e3 * u(rng);
        for (unsigned int k = 0; k < dim; ++k)
          f.b[q][k] = 1e3 * u(rng);
      }
    return f;
  }

  /// vertex forces from pair moments on a cell with extents h
  template <int dim>
  void
  forces(const double (&T)[dim][QF<dim>::npairs][dim], const double (&h)[dim], double (&f)[QF<dim>::nv][dim])
  {
    double inv_h[dim];
    for (unsigned int d = 0; d < dim; ++d)
      inv_h[d] = 1.0 / h[d];
    for (auto &r : f)
      for (auto &x : r)
        x = 0;
    QF<dim>::expand_moments(T, inv_h, f);
  }

  /// exact -int sigma grad N dV of a linear field by a 3-point Gauss rule per direction
  template <int dim>
  void
  exact_forces(const Linear<dim> &field, const double (&h)[dim], double (&f)[QF<dim>::nv][dim])
  {
    const double g[3]                         = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
    const double w[3]                         = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    double       T[dim][QF<dim>::npairs][dim] = {};
    double       volume                       = 1;
    for (unsigned int d = 0; d < dim; ++d)
      volume *= h[d];
    unsigned int n = 1;
    for (unsigned int d = 0; d < dim; ++d)
      n *= 3;
    for (unsigned int p = 0; p < n; ++p)
      {
        dealii::Point<dim> xi;
        double             wt = volume;
        unsigned int       r  = p;
        for (unsigned int d = 0; d < dim; ++d, r /= 3)
          {
            xi[d] = g[r % 3];
            wt *= w[r % 3];
          }
        double s[Fit<dim>::nst];
        field.eval(xi, s);
        double t[dim][dim];
        t[0][0] = -wt * s[0];
        t[1][1] = -wt * s[1];
        t[0][1] = t[1][0] = -wt * s[3];
        if constexpr (dim == 3)
          {
            t[2][2] = -wt * s[2];
            t[1][2] = t[2][1] = -wt * s[4];
            t[0][2] = t[2][0] = -wt * s[5];
          }
        double N[QF<dim>::nv], pw[dim][QF<dim>::npairs];
        QF<dim>::weights(xi, N, pw);
        QF<dim>::add_moments(t, pw, T);
      }
    forces<dim>(T, h, f);
  }

  template <int dim>
  void
  check_linear_field()
  {
    std::mt19937                           rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double                           extents[3] = {0.3, 0.7, 1.9};
    double                                 hh[dim];
    for (unsigned int d = 0; d < dim; ++d)
      hh[d] = extents[d];
    for (int trial = 0; trial < 20; ++trial)
      {
        const auto field = random_linear<dim>(rng);
        Fit<dim>   fit;
        // 4 points per direction on a regular sub-grid, jittered, random volumes
        unsigned int n = 1;
        for (unsigned int d = 0; d < dim; ++d)
          n *= 4;
        for (unsigned int p = 0; p < n; ++p)
          {
            dealii::Point<dim> xi;
            unsigned int       r = p;
            for (unsigned int d = 0; d < dim; ++d, r /= 4)
              xi[d] = (r % 4 + 0.5 + 0.2 * (u(rng) - 0.5)) / 4;
            double s[Fit<dim>::nst];
            field.eval(xi, s);
            fit.add(xi, 0.5 + u(rng), s);
          }
        double mean[Fit<dim>::nst], slope[Fit<dim>::nst][dim], centre[dim];
        EXPECT_EQ(fit.fit(mean, slope, centre), static_cast<unsigned int>(dim));
        for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
          {
            double expected = field.a[q];
            for (unsigned int k = 0; k < dim; ++k)
              {
                expected += field.b[q][k] * centre[k];
                EXPECT_NEAR(slope[q][k], field.b[q][k], 1e-9);
              }
            EXPECT_NEAR(mean[q], expected, 1e-9);
          }
        // force of the fitted field at the Gauss points = exact integral
        double volume = 1;
        for (unsigned int d = 0; d < dim; ++d)
          volume *= hh[d];
        double T[dim][QF<dim>::npairs][dim];
        fit.moments(volume, true, T);
        double f[QF<dim>::nv][dim], fe[QF<dim>::nv][dim];
        forces<dim>(T, hh, f);
        exact_forces<dim>(field, hh, fe);
        for (unsigned int v = 0; v < QF<dim>::nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            EXPECT_NEAR(f[v][d], fe[v][d], 1e-9 * 1e3 * volume);
        // constant mode: the mean stress over the whole cell
        Linear<dim> flat = field;
        for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
          {
            flat.a[q] = mean[q];
            for (unsigned int k = 0; k < dim; ++k)
              flat.b[q][k] = 0;
          }
        fit.moments(volume, false, T);
        forces<dim>(T, hh, f);
        exact_forces<dim>(flat, hh, fe);
        for (unsigned int v = 0; v < QF<dim>::nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            EXPECT_NEAR(f[v][d], fe[v][d], 1e-9 * 1e3 * volume);
      }
  }

  template <int dim>
  void
  check_degenerate()
  {
    std::mt19937 rng(3);
    const auto   field = random_linear<dim>(rng);
    double       mean[Fit<dim>::nst], slope[Fit<dim>::nst][dim], centre[dim];
    // one point: constant
    {
      Fit<dim>           fit;
      dealii::Point<dim> xi;
      for (unsigned int d = 0; d < dim; ++d)
        xi[d] = 0.3;
      double s[Fit<dim>::nst];
      field.eval(xi, s);
      fit.add(xi, 1.0, s);
      EXPECT_EQ(fit.fit(mean, slope, centre), 0u);
      for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
        EXPECT_NEAR(mean[q], s[q], 1e-9);
    }
    // a row of points along axis 0 (same xi_k for k > 0): only the slope along 0
    {
      Fit<dim> fit;
      for (int p = 0; p < 4; ++p)
        {
          dealii::Point<dim> xi;
          for (unsigned int d = 0; d < dim; ++d)
            xi[d] = 0.6;
          xi[0] = 0.125 + 0.25 * p;
          double s[Fit<dim>::nst];
          field.eval(xi, s);
          fit.add(xi, 1.0, s);
        }
      EXPECT_EQ(fit.fit(mean, slope, centre), 1u);
      for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
        {
          EXPECT_NEAR(slope[q][0], field.b[q][0], 1e-9);
          for (unsigned int k = 1; k < dim; ++k)
            EXPECT_EQ(slope[q][k], 0.0);
        }
    }
    // points on the diagonal (spread in every direction, but collinear): constant
    {
      Fit<dim> fit;
      for (int p = 0; p < 4; ++p)
        {
          dealii::Point<dim> xi;
          for (unsigned int d = 0; d < dim; ++d)
            xi[d] = 0.125 + 0.25 * p;
          double s[Fit<dim>::nst];
          field.eval(xi, s);
          fit.add(xi, 1.0, s);
        }
      EXPECT_EQ(fit.fit(mean, slope, centre), 0u);
    }
  }

  template <int dim>
  void
  check_limiter()
  {
    // points clustered in [0, 0.4]^dim with a steep field: unlimited, the fit
    // would reach ~ 2 x the points' range at the far Gauss points; limited, the
    // field there stays within the range widened by half of it on each side
    std::mt19937                           rng(11);
    std::uniform_real_distribution<double> u(0.0, 0.4);
    Linear<dim>                            field{};
    for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
      for (unsigned int k = 0; k < dim; ++k)
        field.b[q][k] = 1000.0 * (q + 1);
    Fit<dim> fit;
    double   lo[Fit<dim>::nst], hi[Fit<dim>::nst];
    std::fill(lo, lo + Fit<dim>::nst, 1e300);
    std::fill(hi, hi + Fit<dim>::nst, -1e300);
    for (int p = 0; p < 30; ++p)
      {
        dealii::Point<dim> xi;
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = u(rng);
        double s[Fit<dim>::nst];
        field.eval(xi, s);
        for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
          {
            lo[q] = std::min(lo[q], s[q]);
            hi[q] = std::max(hi[q], s[q]);
          }
        fit.add(xi, 1.0, s);
      }
    double mean[Fit<dim>::nst], slope[Fit<dim>::nst][dim], centre[dim];
    fit.field(true, mean, slope, centre);
    bool limited = false;
    for (unsigned int q = 0; q < Fit<dim>::nst; ++q)
      {
        const double r    = hi[q] - lo[q];
        double       vmax = -1e300;
        for (unsigned int gp = 0; gp < QF<dim>::nv; ++gp)
          {
            double v = mean[q];
            for (unsigned int k = 0; k < dim; ++k)
              v += slope[q][k] * (Fit<dim>::gauss((gp >> k) & 1u) - centre[k]);
            EXPECT_LE(v, hi[q] + 0.5 * r + 1e-9 * r);
            EXPECT_GE(v, lo[q] - 0.5 * r - 1e-9 * r);
            vmax = std::max(vmax, v);
          }
        // the bound is active (the far Gauss point sits on it) and the slopes keep their direction
        limited = limited || std::abs(vmax - (hi[q] + 0.5 * r)) < 1e-9 * r;
        for (unsigned int k = 0; k < dim; ++k)
          EXPECT_GT(slope[q][k], 0.0);
      }
    EXPECT_TRUE(limited);
  }
} // namespace

TEST(MixedIntegration, LinearField2D)
{
  check_linear_field<2>();
}
TEST(MixedIntegration, LinearField3D)
{
  check_linear_field<3>();
}
TEST(MixedIntegration, Degenerate2D)
{
  check_degenerate<2>();
}
TEST(MixedIntegration, Degenerate3D)
{
  check_degenerate<3>();
}
TEST(MixedIntegration, Limiter2D)
{
  check_limiter<2>();
}
TEST(MixedIntegration, Limiter3D)
{
  check_limiter<3>();
}
