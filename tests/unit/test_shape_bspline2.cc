// Quadratic B-spline kernel (shape/bspline2.h), the GIMP kernel on the same
// window (shape/gimp.h), and the B-spline grid stencil
// (BackgroundGrid::setup_bspline_patches): analytic 1D functions with the
// ghost-extrapolation wall treatment, partition of unity, linear reproduction,
// C1 continuity, wall interpolation, support, finite differences, helpers; the
// patches against deal.II's support points and a P2G that conserves mass and
// momentum (also run on 2 ranks: unit.test_shape_bspline2_np2).
#include <talus/base/errors.h>
#include <talus/grid/background_grid.h>
#include <talus/io/grid_mesh.h>
#include <talus/shape/bspline2.h>
#include <talus/shape/gimp.h>

#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/component_mask.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <vector>

using namespace talus;

namespace
{
  // ---------------------------------------------------------------- references
  // Coefficient of the ghost functions (-1 and n+1) in the wall-modified
  // function of node I: ghosts carry 2 v_0 - v_1 resp. 2 v_n - v_(n-1).
  void
  ghost_coefficients(const int I, const int n, double &c_lo, double &c_hi)
  {
    c_lo = I == 0 ? 2.0 : I == 1 ? -1.0 : 0.0;
    c_hi = I == n ? 2.0 : I == n - 1 ? -1.0 : 0.0;
  }

  // The analytic quadratic B-spline N(r) and dN/dr.
  double
  spline(const double r)
  {
    const double a = std::abs(r);
    return a <= 0.5 ? 0.75 - r * r : a <= 1.5 ? 0.5 * (1.5 - a) * (1.5 - a) : 0.0;
  }
  double
  dspline(const double r)
  {
    const double a = std::abs(r);
    return a <= 0.5 ? -2 * r : a <= 1.5 ? -(r > 0 ? 1.0 : -1.0) * (1.5 - a) : 0.0;
  }

  // Linear hat and the exact average of a hat over [r - a, r + a] (piecewise
  // linear integrand: trapezoids between the kinks -1, 0, 1 are exact) — the
  // GIMP function from its definition, independent of gimp.h's closed form.
  double
  hat(const double r)
  {
    return std::max(0.0, 1.0 - std::abs(r));
  }
  double
  hat_average(const double r, const double a)
  {
    std::vector<double> t = {r - a, r + a};
    for (const double k : {-1.0, 0.0, 1.0})
      if (k > r - a && k < r + a)
        t.push_back(k);
    std::sort(t.begin(), t.end());
    double s = 0;
    for (std::size_t i = 0; i + 1 < t.size(); ++i)
      s += 0.5 * (hat(t[i]) + hat(t[i + 1])) * (t[i + 1] - t[i]);
    return s / (2 * a);
  }

  // ------------------------------------------------------------- kernel policies
  // The tests below run for both kernels through these adapters: evaluation,
  // the 1D reference function of node I (wall-modified), the reference
  // coordinates where a formula switches (both sides are compared for C1), the
  // extent of the linear wall zone, and the number of non-zero window nodes.
  template <int dim>
  struct BSplineKernel
  {
    using K = shape::BSpline2<dim>;
    static void
    evaluate(const unsigned int (&j)[dim], const unsigned int (&n)[dim], const double (&inv_h)[dim],
             const dealii::Point<dim> &xi, typename K::Eval &e)
    {
      K::evaluate(j, n, inv_h, xi, e);
    }
    static void
    reference(const int I, const int n, const double h, const double x, unsigned int, double &N, double &dN)
    {
      double c_lo, c_hi;
      ghost_coefficients(I, n, c_lo, c_hi);
      auto r = [&](int J) { return x / h - J; };
      N      = spline(r(I)) + c_lo * spline(r(-1)) + c_hi * spline(r(n + 1));
      dN     = (dspline(r(I)) + c_lo * dspline(r(-1)) + c_hi * dspline(r(n + 1))) / h;
    }
    static std::vector<double>
    switches(unsigned int)
    {
      return {0.5};
    }
    static double
    wall_zone(unsigned int)
    {
      return 0.5;
    }
    static unsigned int
    nonzero_1d(const unsigned int j, const unsigned int n, const double xi, unsigned int)
    {
      return (j == 0 && xi < 0.5) || (j + 1 == n && xi >= 0.5) ? 2 : 3;
    }
  };

  template <int dim>
  struct GIMPKernel
  {
    using K = shape::GIMP<dim>;
    // l_p/h per direction; 0.5 is one point per cell
    static double
    a(const unsigned int d)
    {
      return d == 0 ? 0.3 : d == 1 ? 0.2 : 0.5;
    }
    static void
    evaluate(const unsigned int (&j)[dim], const unsigned int (&n)[dim], const double (&inv_h)[dim],
             const dealii::Point<dim> &xi, typename K::Eval &e)
    {
      double aa[dim];
      for (unsigned int d = 0; d < dim; ++d)
        aa[d] = a(d);
      K::evaluate(j, n, inv_h, xi, aa, e);
    }
    static void
    reference(const int I, const int n, const double h, const double x, const unsigned int d, double &N, double &dN)
    {
      double c_lo, c_hi;
      ghost_coefficients(I, n, c_lo, c_hi);
      auto r = [&](int J) { return x / h - J; };
      N      = hat_average(r(I), a(d)) + c_lo * hat_average(r(-1), a(d)) + c_hi * hat_average(r(n + 1), a(d));
      // d/dx of the average over [r - a, r + a] (Leibniz): (hat(r + a) - hat(r - a)) / (2 a h)
      auto dh = [&](int J) { return (hat(r(J) + a(d)) - hat(r(J) - a(d))) / (2 * a(d) * h); };
      dN      = dh(I) + c_lo * dh(-1) + c_hi * dh(n + 1);
    }
    static std::vector<double>
    switches(const unsigned int d)
    {
      return {0.5, a(d), 1 - a(d)};
    }
    static double
    wall_zone(const unsigned int d)
    {
      return a(d);
    }
    static unsigned int
    nonzero_1d(const unsigned int j, const unsigned int n, const double xi, const unsigned int d)
    {
      if ((j == 0 && xi < a(d)) || (j + 1 == n && xi > 1 - a(d)))
        return 2;
      return 2 + (j > 0 && xi < a(d)) + (j + 1 < n && xi > 1 - a(d));
    }
  };

  // -------------------------------------------------------------- kernel, by node
  // All functions of a structured grid (nodes 0..n[d] per direction, lower corner
  // 0) evaluated with the kernel in cell j at reference point xi, scattered to
  // global node numbers node = sum_d k_d prod_(e<d) (n[e]+1).
  template <int dim>
  struct Nodal
  {
    std::vector<double>                  N;
    std::vector<std::array<double, dim>> G;
  };

  template <int dim>
  unsigned int
  n_grid_nodes(const unsigned int (&n)[dim])
  {
    unsigned int m = 1;
    for (unsigned int d = 0; d < dim; ++d)
      m *= n[d] + 1;
    return m;
  }

  template <template <int> class P, int dim>
  Nodal<dim>
  kernel_by_node(const unsigned int (&n)[dim], const double (&h)[dim], const unsigned int (&j)[dim],
                 const dealii::Point<dim> &xi)
  {
    using K = typename P<dim>::K;
    double inv_h[dim];
    for (unsigned int d = 0; d < dim; ++d)
      inv_h[d] = 1.0 / h[d];
    typename K::Eval e;
    P<dim>::evaluate(j, n, inv_h, xi, e);
    Nodal<dim> r;
    r.N.assign(n_grid_nodes<dim>(n), 0.0);
    r.G.assign(n_grid_nodes<dim>(n), std::array<double, dim>{});
    for (unsigned int w = 0; w < K::n_nodes; ++w)
      {
        unsigned int node = 0, m = 1;
        bool         in = true;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const int k = int(j[d]) - 1 + e.first[d] + int(K::digit(w, d));
            in          = in && k >= 0 && k <= int(n[d]);
            node += k * m;
            m *= n[d] + 1;
          }
        EXPECT_TRUE(in) << "window node outside the grid";
        if (!in)
          continue;
        double g[dim];
        K::gradient(e, w, g);
        r.N[node] += K::value(e, w);
        for (unsigned int d = 0; d < dim; ++d)
          r.G[node][d] += g[d];
      }
    return r;
  }

  // cell and reference coordinates of x (lower corner 0)
  template <template <int> class P, int dim>
  Nodal<dim>
  kernel_at(const unsigned int (&n)[dim], const double (&h)[dim], const dealii::Point<dim> &x)
  {
    unsigned int       j[dim];
    dealii::Point<dim> xi;
    for (unsigned int d = 0; d < dim; ++d)
      {
        const double r = x[d] / h[d];
        j[d]           = std::min<unsigned int>(static_cast<unsigned int>(std::max(0.0, std::floor(r))), n[d] - 1);
        xi[d]          = r - j[d];
      }
    return kernel_by_node<P, dim>(n, h, j, xi);
  }

  template <int dim>
  std::array<unsigned int, dim>
  node_digits(unsigned int node, const unsigned int (&n)[dim])
  {
    std::array<unsigned int, dim> k;
    for (unsigned int d = 0; d < dim; ++d)
      {
        k[d] = node % (n[d] + 1);
        node /= n[d] + 1;
      }
    return k;
  }

  // grid of the nD kernel tests: 3 x 4 x 5 cells, anisotropic h
  template <int dim>
  struct TestGrid
  {
    unsigned int n[dim];
    double       h[dim];
    TestGrid()
    {
      const unsigned int nn[3] = {3, 4, 5};
      const double       hh[3] = {0.3, 0.7, 1.1};
      for (unsigned int d = 0; d < dim; ++d)
        n[d] = nn[d], h[d] = hh[d];
    }
    unsigned int
    n_cells() const
    {
      unsigned int m = 1;
      for (unsigned int d = 0; d < dim; ++d)
        m *= n[d];
      return m;
    }
    void
    cell(unsigned int c, unsigned int (&j)[dim]) const
    {
      for (unsigned int d = 0; d < dim; ++d)
        {
          j[d] = c % n[d];
          c /= n[d];
        }
    }
  };

  // random reference points plus the corners, face centres and half points
  template <int dim>
  std::vector<dealii::Point<dim>>
  test_points(std::mt19937 &rng, const unsigned int n_random)
  {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<dealii::Point<dim>>        pts;
    for (unsigned int k = 0; k < n_random; ++k)
      {
        dealii::Point<dim> xi;
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = u(rng);
        pts.push_back(xi);
      }
    const double special[] = {0.0, 0.5, 1.0, std::nextafter(0.5, 0.0)};
    unsigned int m         = 1;
    for (unsigned int d = 0; d < dim; ++d)
      m *= 4;
    for (unsigned int k = 0; k < m; ++k)
      {
        dealii::Point<dim> xi;
        for (unsigned int d = 0, q = k; d < dim; ++d, q /= 4)
          xi[d] = special[q % 4];
        pts.push_back(xi);
      }
    return pts;
  }
} // namespace

// 1D: the kernel equals the analytic (wall-modified) functions at many points,
// including nodes, half points and the walls.
template <template <int> class P>
void
check_analytic(const double tol_value, const double tol_derivative)
{
  for (const unsigned int n : {3u, 4u, 7u})
    {
      const unsigned int  nn[1] = {n};
      const double        h[1]  = {0.37};
      std::vector<double> xs;
      for (unsigned int k = 0; k <= 4000; ++k)
        xs.push_back(n * h[0] * k / 4000.0);
      for (unsigned int k = 0; k <= 2 * n; ++k)
        xs.push_back(0.5 * k * h[0]);
      double worst = 0, worst_d = 0;
      for (const double x : xs)
        {
          const auto r = kernel_at<P, 1>(nn, h, dealii::Point<1>(x));
          for (unsigned int I = 0; I <= n; ++I)
            {
              double N, dN;
              P<1>::reference(I, n, h[0], x, 0, N, dN);
              EXPECT_NEAR(r.N[I], N, tol_value) << "n " << n << " x " << x << " node " << I;
              worst = std::max(worst, std::abs(r.N[I] - N));
              EXPECT_NEAR(r.G[I][0] * h[0], dN * h[0], tol_derivative) << "n " << n << " x " << x << " node " << I;
              worst_d = std::max(worst_d, std::abs(r.G[I][0] - dN) * h[0]);
            }
        }
      std::cout << "  n = " << n << ": max |N - N_ref| " << worst << ", max h |dN - dN_ref| " << worst_d << "\n";
    }
}

TEST(ShapeBSpline2, Analytic1D)
{
  check_analytic<BSplineKernel>(1e-14, 1e-13);
}
// GIMP reference: exact average of the hats over the point's domain
TEST(ShapeGIMP, Analytic1D)
{
  check_analytic<GIMPKernel>(1e-14, 1e-13);
}

// Partition of unity, sum of gradients = 0, linear reproduction (sum x_I N_I = x,
// sum x_I (x) grad N_I = identity) at random points of every cell, walls included.
template <template <int> class P, int dim>
void
check_consistency()
{
  const TestGrid<dim> g;
  std::mt19937        rng(7 + dim);
  double              worst_pu = 0, worst_lin = 0, worst_grad = 0;
  for (unsigned int c = 0; c < g.n_cells(); ++c)
    {
      unsigned int j[dim];
      g.cell(c, j);
      for (const auto &xi : test_points<dim>(rng, 25))
        {
          const auto r   = kernel_by_node<P, dim>(g.n, g.h, j, xi);
          double     sum = 0, sumg[dim] = {}, xN[dim] = {}, xG[dim][dim] = {};
          for (unsigned int node = 0; node < r.N.size(); ++node)
            {
              const auto k = node_digits<dim>(node, g.n);
              sum += r.N[node];
              for (unsigned int d = 0; d < dim; ++d)
                {
                  sumg[d] += r.G[node][d];
                  xN[d] += k[d] * g.h[d] * r.N[node];
                  for (unsigned int e = 0; e < dim; ++e)
                    xG[d][e] += k[d] * g.h[d] * r.G[node][e];
                }
            }
          worst_pu = std::max(worst_pu, std::abs(sum - 1.0));
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double x = (j[d] + xi[d]) * g.h[d];
              worst_lin      = std::max(worst_lin, std::abs(xN[d] - x));
              worst_grad     = std::max(worst_grad, std::abs(sumg[d]) * g.h[d]);
              for (unsigned int e = 0; e < dim; ++e)
                worst_grad = std::max(worst_grad, std::abs(xG[d][e] - (d == e ? 1.0 : 0.0)));
            }
        }
    }
  EXPECT_LT(worst_pu, 1e-15) << "partition of unity";
  EXPECT_LT(worst_lin, 1e-14) << "linear reproduction sum x_I N_I = x";
  EXPECT_LT(worst_grad, 1e-14) << "sum grad N_I = 0, sum x_I (x) grad N_I = I";
  std::cout << "  " << dim << "D: |sum N - 1| " << worst_pu << ", |sum x N - x| " << worst_lin << ", gradients "
            << worst_grad << "\n";
}

TEST(ShapeBSpline2, PartitionOfUnityAndLinearReproduction1D)
{
  check_consistency<BSplineKernel, 1>();
}
TEST(ShapeBSpline2, PartitionOfUnityAndLinearReproduction2D)
{
  check_consistency<BSplineKernel, 2>();
}
TEST(ShapeBSpline2, PartitionOfUnityAndLinearReproduction3D)
{
  check_consistency<BSplineKernel, 3>();
}
TEST(ShapeGIMP, PartitionOfUnityAndLinearReproduction1D)
{
  check_consistency<GIMPKernel, 1>();
}
TEST(ShapeGIMP, PartitionOfUnityAndLinearReproduction2D)
{
  check_consistency<GIMPKernel, 2>();
}
TEST(ShapeGIMP, PartitionOfUnityAndLinearReproduction3D)
{
  check_consistency<GIMPKernel, 3>();
}

// C1: at every switch of formula (xi = 1/2 for both kernels; xi = a, 1 - a for
// GIMP) both sides (xi and the next double below) give the same values and
// derivatives node by node; across a cell face, cell j at xi = 1 and cell j+1 at
// xi = 0 agree exactly. A C0 kink would show an O(1/h) jump.
template <template <int> class P>
void
check_c1()
{
  for (const unsigned int n : {3u, 4u, 6u})
    {
      const unsigned int nn[1] = {n};
      const double       h[1]  = {0.25};
      for (unsigned int j = 0; j < n; ++j)
        {
          const unsigned int jj[1] = {j};
          for (const double s : P<1>::switches(0))
            {
              const auto a = kernel_by_node<P, 1>(nn, h, jj, dealii::Point<1>(std::nextafter(s, 0.0)));
              const auto b = kernel_by_node<P, 1>(nn, h, jj, dealii::Point<1>(s));
              for (unsigned int I = 0; I <= n; ++I)
                {
                  EXPECT_NEAR(a.N[I], b.N[I], 1e-15) << "value at xi = " << s << ", cell " << j << " node " << I;
                  EXPECT_NEAR(a.G[I][0] * h[0], b.G[I][0] * h[0], 1e-14)
                    << "derivative at xi = " << s << ", cell " << j << " node " << I;
                }
            }
          if (j + 1 < n)
            {
              const unsigned int jn[1] = {j + 1};
              const auto         l     = kernel_by_node<P, 1>(nn, h, jj, dealii::Point<1>(1.0));
              const auto         r     = kernel_by_node<P, 1>(nn, h, jn, dealii::Point<1>(0.0));
              for (unsigned int I = 0; I <= n; ++I)
                {
                  EXPECT_NEAR(l.N[I], r.N[I], 1e-15) << "value across face " << j + 1 << " node " << I;
                  EXPECT_NEAR(l.G[I][0] * h[0], r.G[I][0] * h[0], 1e-15)
                    << "derivative across face " << j + 1 << " node " << I;
                }
            }
        }
    }
}

TEST(ShapeBSpline2, C1Continuity)
{
  check_c1<BSplineKernel>();
}
TEST(ShapeGIMP, C1Continuity)
{
  check_c1<GIMPKernel>();
}

// The wall functions are interpolatory: at x = 0 only node 0 is non-zero (= 1),
// at x = n h only node n; in the wall zone they are the linear hats.
template <template <int> class P>
void
check_wall_interpolation()
{
  const unsigned int n     = 5;
  const unsigned int nn[1] = {n};
  const double       h[1]  = {0.4};
  const auto         lo    = kernel_at<P, 1>(nn, h, dealii::Point<1>(0.0));
  const auto         hi    = kernel_at<P, 1>(nn, h, dealii::Point<1>(n * h[0]));
  for (unsigned int I = 0; I <= n; ++I)
    {
      EXPECT_EQ(lo.N[I], I == 0 ? 1.0 : 0.0) << "lower wall, node " << I;
      EXPECT_EQ(hi.N[I], I == n ? 1.0 : 0.0) << "upper wall, node " << I;
    }
  const double zone = P<1>::wall_zone(0);
  for (const double f : {0.0, 0.2, 0.6, 0.98})
    {
      const double xi = f * zone;
      const auto   a  = kernel_at<P, 1>(nn, h, dealii::Point<1>(xi * h[0]));
      EXPECT_NEAR(a.N[0], 1 - xi, 1e-15);
      EXPECT_NEAR(a.N[1], xi, 1e-15);
      EXPECT_EQ(a.N[2], 0.0);
      const auto b = kernel_at<P, 1>(nn, h, dealii::Point<1>((n - xi) * h[0]));
      EXPECT_NEAR(b.N[n], 1 - xi, 1e-15);
      EXPECT_NEAR(b.N[n - 1], xi, 1e-15);
      EXPECT_EQ(b.N[n - 2], 0.0);
    }
}

TEST(ShapeBSpline2, WallInterpolation1D)
{
  check_wall_interpolation<BSplineKernel>();
}
TEST(ShapeGIMP, WallInterpolation1D)
{
  check_wall_interpolation<GIMPKernel>();
}

// On every face of the box: wall nodes carry a prescribed linear velocity field
// (zero = fixed; normal component zero = roller), the other nodes random values.
// The interpolated velocity at random wall points equals the prescribed field
// (so fixed gives exactly 0 and a roller a zero normal component).
template <template <int> class P, int dim>
void
check_wall_velocity()
{
  const TestGrid<dim>                    g;
  const unsigned int                     nn = n_grid_nodes<dim>(g.n);
  std::mt19937                           rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), p(0.0, 1.0);
  for (unsigned int face = 0; face < 2 * dim; ++face)
    for (const int kind : {0, 1, 2}) // fixed, roller, prescribed linear field
      {
        const unsigned int normal = face / 2;
        const unsigned int wall   = (face % 2) ? g.n[normal] : 0;
        double             a[dim], B[dim][dim];
        for (unsigned int c = 0; c < dim; ++c)
          {
            a[c] = u(rng);
            for (unsigned int d = 0; d < dim; ++d)
              B[c][d] = u(rng);
          }
        std::vector<std::array<double, dim>> v(nn);
        auto                                 prescribed = [&](const double *x, const unsigned int c) {
          if (kind == 0 || (kind == 1 && c == normal))
            return 0.0;
          double s = a[c];
          for (unsigned int d = 0; d < dim; ++d)
            s += B[c][d] * x[d];
          return s;
        };
        for (unsigned int node = 0; node < nn; ++node)
          {
            const auto k = node_digits<dim>(node, g.n);
            double     x[dim];
            for (unsigned int d = 0; d < dim; ++d)
              x[d] = k[d] * g.h[d];
            for (unsigned int c = 0; c < dim; ++c)
              v[node][c] = k[normal] == wall ? prescribed(x, c) : u(rng);
          }
        for (unsigned int t = 0; t < 200; ++t)
          {
            // a wall point, given by its cell and reference coordinates (exactly 0 or 1
            // in the normal direction)
            unsigned int       j[dim];
            dealii::Point<dim> xi;
            double             xa[dim];
            for (unsigned int d = 0; d < dim; ++d)
              {
                j[d]  = std::min<unsigned int>(static_cast<unsigned int>(p(rng) * g.n[d]), g.n[d] - 1);
                xi[d] = p(rng);
              }
            j[normal]  = wall == 0 ? 0 : g.n[normal] - 1;
            xi[normal] = wall == 0 ? 0.0 : 1.0;
            for (unsigned int d = 0; d < dim; ++d)
              xa[d] = (j[d] + xi[d]) * g.h[d];
            const auto r = kernel_by_node<P, dim>(g.n, g.h, j, xi);
            for (unsigned int c = 0; c < dim; ++c)
              {
                double s = 0;
                for (unsigned int node = 0; node < nn; ++node)
                  s += r.N[node] * v[node][c];
                if (kind == 0 || (kind == 1 && c == normal))
                  {
                    EXPECT_EQ(s, 0.0) << "face " << face << " kind " << kind << " component " << c;
                  }
                else if (kind == 2)
                  {
                    EXPECT_NEAR(s, prescribed(xa, c), 1e-14) << "face " << face << " component " << c;
                  }
              }
          }
      }
}

TEST(ShapeBSpline2, WallVelocity2D)
{
  check_wall_velocity<BSplineKernel, 2>();
}
TEST(ShapeBSpline2, WallVelocity3D)
{
  check_wall_velocity<BSplineKernel, 3>();
}
TEST(ShapeGIMP, WallVelocity2D)
{
  check_wall_velocity<GIMPKernel, 2>();
}
TEST(ShapeGIMP, WallVelocity3D)
{
  check_wall_velocity<GIMPKernel, 3>();
}

// Support: strictly inside a cell exactly the expected window nodes are non-zero
// (B-spline: all 3^dim, except the third node of a wall half cell, which has
// value and derivative exactly 0; GIMP: the nodes the point's domain reaches);
// window nodes are grid nodes (checked in kernel_by_node), weights >= 0, and
// nothing outside the window is touched.
template <template <int> class P, int dim>
void
check_support()
{
  using K = typename P<dim>::K;
  const TestGrid<dim> g;
  std::mt19937        rng(3);
  double              inv_h[dim];
  for (unsigned int d = 0; d < dim; ++d)
    inv_h[d] = 1 / g.h[d];
  unsigned int n_points = 0;
  for (unsigned int c = 0; c < g.n_cells(); ++c)
    {
      unsigned int j[dim];
      g.cell(c, j);
      for (const auto &xi : test_points<dim>(rng, 30))
        {
          bool open = true;
          for (unsigned int d = 0; d < dim; ++d)
            for (const double s : P<dim>::switches(d))
              open = open && xi[d] > 0 && xi[d] < 1 && xi[d] != s && xi[d] != std::nextafter(s, 0.0);
          if (!open)
            continue;
          ++n_points;
          typename K::Eval e;
          P<dim>::evaluate(j, g.n, inv_h, xi, e);
          unsigned int nonzero = 0, expected = 1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              const unsigned int nz = P<dim>::nonzero_1d(j[d], g.n[d], xi[d], d);
              expected *= nz;
              unsigned int count = 0;
              for (unsigned int k = 0; k < 3; ++k)
                {
                  count += e.N[d][k] != 0.0;
                  if (e.N[d][k] == 0.0)
                    {
                      EXPECT_EQ(e.dN[d][k], 0.0) << "derivative of a zero window node";
                    }
                }
              EXPECT_EQ(count, nz) << "direction " << d << " cell " << j[d] << " xi " << xi[d];
            }
          double N[K::n_nodes];
          K::values(e, N);
          for (unsigned int w = 0; w < K::n_nodes; ++w)
            {
              EXPECT_GE(N[w], 0.0);
              nonzero += N[w] > 0;
              EXPECT_LT(K::patch_slot(e, w), K::n_patch);
            }
          EXPECT_EQ(nonzero, expected) << "cell " << c;
          const auto   r  = kernel_by_node<P, dim>(g.n, g.h, j, xi);
          unsigned int nz = 0;
          for (const double v : r.N)
            nz += v != 0.0;
          EXPECT_EQ(nz, expected);
        }
    }
  EXPECT_GT(n_points, 20 * g.n_cells());
}

TEST(ShapeBSpline2, Support1D)
{
  check_support<BSplineKernel, 1>();
}
TEST(ShapeBSpline2, Support2D)
{
  check_support<BSplineKernel, 2>();
}
TEST(ShapeBSpline2, Support3D)
{
  check_support<BSplineKernel, 3>();
}
TEST(ShapeGIMP, Support1D)
{
  check_support<GIMPKernel, 1>();
}
TEST(ShapeGIMP, Support2D)
{
  check_support<GIMPKernel, 2>();
}
TEST(ShapeGIMP, Support3D)
{
  check_support<GIMPKernel, 3>();
}

// Gradients against central differences of the values (global node numbering,
// so the difference may cross a switch or a cell face).
template <template <int> class P, int dim>
void
check_finite_differences()
{
  const TestGrid<dim>                    g;
  std::mt19937                           rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double                           eps = 1e-6;
  for (unsigned int t = 0; t < 400; ++t)
    {
      dealii::Point<dim> x;
      for (unsigned int d = 0; d < dim; ++d)
        x[d] = (eps + u(rng) * (g.n[d] - 2 * eps)) * g.h[d];
      const auto r = kernel_at<P, dim>(g.n, g.h, x);
      for (unsigned int e = 0; e < dim; ++e)
        {
          dealii::Point<dim> a = x, b = x;
          a[e] += eps * g.h[e];
          b[e] -= eps * g.h[e];
          const auto ra = kernel_at<P, dim>(g.n, g.h, a), rb = kernel_at<P, dim>(g.n, g.h, b);
          for (unsigned int node = 0; node < r.N.size(); ++node)
            EXPECT_NEAR(r.G[node][e] * g.h[e], (ra.N[node] - rb.N[node]) / (2 * eps), 2e-9)
              << "node " << node << " direction " << e;
        }
    }
}

TEST(ShapeBSpline2, FiniteDifferences1D)
{
  check_finite_differences<BSplineKernel, 1>();
}
TEST(ShapeBSpline2, FiniteDifferences2D)
{
  check_finite_differences<BSplineKernel, 2>();
}
TEST(ShapeBSpline2, FiniteDifferences3D)
{
  check_finite_differences<BSplineKernel, 3>();
}
TEST(ShapeGIMP, FiniteDifferences1D)
{
  check_finite_differences<GIMPKernel, 1>();
}
TEST(ShapeGIMP, FiniteDifferences2D)
{
  check_finite_differences<GIMPKernel, 2>();
}
TEST(ShapeGIMP, FiniteDifferences3D)
{
  check_finite_differences<GIMPKernel, 3>();
}

// The hot-loop helpers agree with value()/gradient(): values(),
// values_and_gradients(), and the sum-factorised interpolate().
template <template <int> class P, int dim>
void
check_helpers()
{
  using K = typename P<dim>::K;
  const TestGrid<dim>                    g;
  std::mt19937                           rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double                                 inv_h[dim];
  for (unsigned int d = 0; d < dim; ++d)
    inv_h[d] = 1 / g.h[d];
  for (unsigned int c = 0; c < g.n_cells(); ++c)
    {
      unsigned int j[dim];
      g.cell(c, j);
      for (const auto &xi : test_points<dim>(rng, 5))
        {
          typename K::Eval e;
          P<dim>::evaluate(j, g.n, inv_h, xi, e);
          double N[K::n_nodes], N2[K::n_nodes], G[K::n_nodes][dim];
          K::values(e, N);
          K::values_and_gradients(e, N2, G);
          double U[K::n_nodes][dim + 1];
          for (unsigned int w = 0; w < K::n_nodes; ++w)
            for (unsigned int q = 0; q <= dim; ++q)
              U[w][q] = u(rng);
          double val[dim + 1] = {}, grad[dim + 1][dim] = {};
          for (unsigned int w = 0; w < K::n_nodes; ++w)
            {
              double gw[dim];
              K::gradient(e, w, gw);
              EXPECT_DOUBLE_EQ(N[w], K::value(e, w));
              EXPECT_DOUBLE_EQ(N2[w], K::value(e, w));
              for (unsigned int d = 0; d < dim; ++d)
                EXPECT_DOUBLE_EQ(G[w][d], gw[d]);
              for (unsigned int q = 0; q <= dim; ++q)
                {
                  val[q] += N[w] * U[w][q];
                  for (unsigned int d = 0; d < dim; ++d)
                    grad[q][d] += G[w][d] * U[w][q];
                }
            }
          double fval[dim + 1], fgrad[dim + 1][dim];
          K::template interpolate<dim + 1>(e, U, fval, fgrad);
          for (unsigned int q = 0; q <= dim; ++q)
            {
              EXPECT_NEAR(fval[q], val[q], 1e-14);
              for (unsigned int d = 0; d < dim; ++d)
                EXPECT_NEAR(fgrad[q][d] * g.h[d], grad[q][d] * g.h[d], 1e-14);
            }
        }
    }
}

TEST(ShapeBSpline2, Helpers1D)
{
  check_helpers<BSplineKernel, 1>();
}
TEST(ShapeBSpline2, Helpers2D)
{
  check_helpers<BSplineKernel, 2>();
}
TEST(ShapeBSpline2, Helpers3D)
{
  check_helpers<BSplineKernel, 3>();
}
TEST(ShapeGIMP, Helpers3D)
{
  check_helpers<GIMPKernel, 3>();
}

// ------------------------------------------------------------------ grid stencil
namespace
{
  template <int dim>
  void
  make_grid(BackgroundGrid<dim> &grid, const std::vector<unsigned int> &n, dealii::Point<dim> &lower, double (&h)[dim])
  {
    dealii::Point<dim> upper;
    const double       hh[3] = {0.25, 0.4, 0.3};
    for (unsigned int d = 0; d < dim; ++d)
      {
        lower[d] = -0.3 + 0.1 * d;
        h[d]     = hh[d];
        upper[d] = lower[d] + n[d] * h[d];
      }
    grid.make_box(lower, upper, n);
    grid.setup();
    grid.setup_bspline_patches();
  }
} // namespace

// Every slot of every owned cell's patch holds the DoF whose support point is
// the expected structured node, of the right component; invalid exactly outside
// the grid. On 2 ranks this also shows that the ghost layer holds every patch node.
template <int dim>
void
check_patches(const std::vector<unsigned int> &n)
{
  BackgroundGrid<dim> grid(MPI_COMM_WORLD);
  dealii::Point<dim>  lower;
  double              h[dim];
  make_grid<dim>(grid, n, lower, h);
  const unsigned int invalid = dealii::numbers::invalid_unsigned_int;

  std::vector<std::map<dealii::types::global_dof_index, dealii::Point<dim>>> support(dim);
  for (unsigned int c = 0; c < dim; ++c)
    {
      std::vector<bool> mask(dim, false);
      mask[c] = true;
      dealii::DoFTools::map_dofs_to_support_points(grid.mapping, grid.dof_handler, support[c],
                                                   dealii::ComponentMask(mask));
    }
  for (unsigned int d = 0; d < dim; ++d)
    {
      EXPECT_EQ(grid.box.n_cells[d], n[d]);
      EXPECT_NEAR(grid.box.lower[d], lower[d], 1e-14);
      EXPECT_NEAR(grid.box.h[d], h[d], 1e-14);
    }
  unsigned int n_owned = 0, n_checked = 0, n_outside = 0;
  for (unsigned int c = 0; c < grid.cells.size(); ++c)
    {
      if (!grid.cells[c].locally_owned)
        {
          EXPECT_TRUE(grid.patch_of_cell[c] == invalid);
          continue;
        }
      ++n_owned;
      const auto &p = grid.patch(c);
      for (unsigned int d = 0; d < dim; ++d)
        EXPECT_NEAR(grid.cells[c].lower[d], lower[d] + p.i_cell[d] * h[d], 1e-12);
      for (unsigned int slot = 0; slot < BSplinePatch<dim>::n_slots; ++slot)
        {
          bool               inside = true;
          dealii::Point<dim> x;
          for (unsigned int d = 0, s = slot; d < dim; ++d, s /= 4)
            {
              const int node = int(p.i_cell[d]) - 1 + int(s % 4);
              inside         = inside && node >= 0 && node <= int(n[d]);
              x[d]           = lower[d] + node * h[d];
            }
          for (unsigned int comp = 0; comp < dim; ++comp)
            {
              const unsigned int local = p.dofs[slot * dim + comp];
              if (!inside)
                {
                  EXPECT_EQ(local, invalid) << "slot outside the grid";
                  ++n_outside;
                  continue;
                }
              ASSERT_NE(local, invalid) << "slot inside the grid without a DoF";
              ASSERT_LT(local, grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices());
              const auto global = grid.partitioner->local_to_global(local);
              const auto it     = support[comp].find(global);
              ASSERT_TRUE(it != support[comp].end()) << "DoF of another component or not relevant";
              EXPECT_LT(it->second.distance(x), 1e-12) << "cell " << c << " slot " << slot;
              ++n_checked;
            }
        }
    }
  EXPECT_EQ(n_owned, grid.tria.n_locally_owned_active_cells());
  EXPECT_EQ(grid.patches.size(), n_owned);
  const unsigned int total_outside = dealii::Utilities::MPI::sum(n_outside, MPI_COMM_WORLD);
  EXPECT_GT(total_outside, 0u);
  EXPECT_GT(dealii::Utilities::MPI::sum(n_checked, MPI_COMM_WORLD), 0u);
}

TEST(BSplinePatches, SupportPoints2D)
{
  check_patches<2>({6, 4});
}
TEST(BSplinePatches, SupportPoints3D)
{
  check_patches<3>({4, 3, 6});
}

// P2G with the patches: random points in every owned cell (placed from the cell's
// global index, so the point set does not depend on the rank count) scatter m N
// and m v N into distributed vectors, compress(add): total mass and momentum are
// those of the points to round-off.
template <int dim>
void
check_p2g(const std::vector<unsigned int> &n)
{
  using K = shape::BSpline2<dim>;
  BackgroundGrid<dim> grid(MPI_COMM_WORLD);
  dealii::Point<dim>  lower;
  double              h[dim];
  make_grid<dim>(grid, n, lower, h);

  Vector mass, momentum;
  grid.reinit_vector(mass);
  grid.reinit_vector(momentum);
  // the points of the cell with flat index i_0 + n_0 (i_1 + n_1 i_2): reference
  // coordinates, mass, velocity
  struct Pt
  {
    dealii::Point<dim> xi;
    double             m, v[dim];
  };
  auto points_of = [&](const unsigned int flat) {
    std::mt19937                           rng(1000 + flat);
    std::uniform_real_distribution<double> u(0.0, 1.0), s(-1.0, 1.0);
    std::vector<Pt>                        pts(5);
    for (auto &q : pts)
      {
        for (unsigned int d = 0; d < dim; ++d)
          q.xi[d] = u(rng);
        q.m = 0.5 + u(rng);
        for (unsigned int d = 0; d < dim; ++d)
          q.v[d] = s(rng);
      }
    return pts;
  };
  double m_points = 0, p_points[dim] = {};
  for (unsigned int c = 0; c < grid.cells.size(); ++c)
    {
      if (!grid.cells[c].locally_owned)
        continue;
      const auto  &p    = grid.patch(c);
      unsigned int flat = 0;
      for (unsigned int d = dim; d-- > 0;)
        flat = flat * n[d] + p.i_cell[d];
      for (const Pt &q : points_of(flat))
        {
          const auto      &xi = q.xi;
          const double     m  = q.m;
          const double    *v  = q.v;
          typename K::Eval e;
          K::evaluate(p.i_cell, grid.box.n_cells, grid.box.inv_h, xi, e);
          double N[K::n_nodes];
          K::values(e, N);
          const unsigned int first = K::first_slot(e);
          for (unsigned int w = 0; w < K::n_nodes; ++w)
            {
              const unsigned int *dofs = &p.dofs[(first + K::window_offset(w)) * dim];
              mass.local_element(dofs[0]) += m * N[w];
              for (unsigned int d = 0; d < dim; ++d)
                momentum.local_element(dofs[d]) += m * v[d] * N[w];
            }
          m_points += m;
          for (unsigned int d = 0; d < dim; ++d)
            p_points[d] += m * v[d];
        }
    }
  mass.compress(dealii::VectorOperation::add);
  momentum.compress(dealii::VectorOperation::add);
  m_points = dealii::Utilities::MPI::sum(m_points, MPI_COMM_WORLD);
  for (unsigned int d = 0; d < dim; ++d)
    p_points[d] = dealii::Utilities::MPI::sum(p_points[d], MPI_COMM_WORLD);

  // component of every owned DoF from deal.II's own per-component support maps
  std::vector<unsigned int> component(grid.partitioner->locally_owned_size(), dim);
  for (unsigned int c = 0; c < dim; ++c)
    {
      std::vector<bool> mask(dim, false);
      mask[c] = true;
      std::map<dealii::types::global_dof_index, dealii::Point<dim>> sp;
      dealii::DoFTools::map_dofs_to_support_points(grid.mapping, grid.dof_handler, sp, dealii::ComponentMask(mask));
      for (const auto &[g, x] : sp)
        if (grid.partitioner->in_local_range(g))
          component[grid.partitioner->global_to_local(g)] = c;
    }
  // every owned nodal mass against a brute-force sum over all points of all
  // cells with the analytic 1D functions (so a scatter to a wrong node fails
  // even though it would conserve the totals)
  {
    std::map<dealii::types::global_dof_index, dealii::Point<dim>> sp;
    std::vector<bool>                                             mask(dim, false);
    mask[0] = true;
    dealii::DoFTools::map_dofs_to_support_points(grid.mapping, grid.dof_handler, sp, dealii::ComponentMask(mask));
    unsigned int n_all = 1;
    for (unsigned int d = 0; d < dim; ++d)
      n_all *= n[d];
    std::vector<std::pair<dealii::Point<dim>, double>> all; // (position relative to lower, mass)
    for (unsigned int flat = 0; flat < n_all; ++flat)
      for (const Pt &q : points_of(flat))
        {
          dealii::Point<dim> x;
          unsigned int       f = flat;
          for (unsigned int d = 0; d < dim; ++d)
            {
              x[d] = (f % n[d] + q.xi[d]) * h[d];
              f /= n[d];
            }
          all.emplace_back(x, q.m);
        }
    double worst = 0;
    for (const auto &[g, xs] : sp)
      {
        if (!grid.partitioner->in_local_range(g))
          continue;
        double expected = 0;
        for (const auto &[x, m] : all)
          {
            double w = m;
            for (unsigned int d = 0; d < dim; ++d)
              {
                const int I = int(std::lround((xs[d] - lower[d]) / h[d]));
                double    N, dN;
                BSplineKernel<1>::reference(I, n[d], h[d], x[d], 0, N, dN);
                w *= N;
              }
            expected += w;
          }
        const double got = mass.local_element(grid.partitioner->global_to_local(g));
        EXPECT_NEAR(got, expected, 1e-13) << "nodal mass at " << xs;
        worst = std::max(worst, std::abs(got - expected));
      }
    worst = dealii::Utilities::MPI::max(worst, MPI_COMM_WORLD);
    if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::cout << "  " << dim << "D nodal masses vs brute force: max difference " << worst << "\n";
  }

  double m_grid = 0, p_grid[dim] = {};
  for (unsigned int i = 0; i < component.size(); ++i)
    {
      ASSERT_LT(component[i], dim);
      if (component[i] == 0)
        m_grid += mass.local_element(i);
      else
        EXPECT_EQ(mass.local_element(i), 0.0);
      p_grid[component[i]] += momentum.local_element(i);
    }
  m_grid = dealii::Utilities::MPI::sum(m_grid, MPI_COMM_WORLD);
  EXPECT_NEAR(m_grid, m_points, 1e-14 * m_points) << "mass";
  for (unsigned int d = 0; d < dim; ++d)
    {
      p_grid[d] = dealii::Utilities::MPI::sum(p_grid[d], MPI_COMM_WORLD);
      EXPECT_NEAR(p_grid[d], p_points[d], 1e-14 * m_points) << "momentum " << d;
    }
  if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    std::cout << "  " << dim << "D P2G on " << dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD)
              << " rank(s): mass " << m_grid << " vs " << m_points << " (diff " << m_grid - m_points
              << "), momentum x diff " << p_grid[0] - p_points[0] << "\n";
}

TEST(BSplinePatches, P2GConservation2D)
{
  check_p2g<2>({8, 6});
}
TEST(BSplinePatches, P2GConservation3D)
{
  check_p2g<3>({4, 6, 4});
}

// Grids the kernel cannot use are refused with an InputError naming the reason;
// anisotropic uniform boxes are fine.
TEST(BSplinePatches, RefusesNonUniformGrids)
{
  {
    BackgroundGrid<2> grid(MPI_COMM_WORLD);
    dealii::Point<2>  lower;
    double            h[2];
    EXPECT_NO_THROW(make_grid<2>(grid, {3, 5}, lower, h));
  }
  {
    BackgroundGrid<2> grid(MPI_COMM_WORLD);
    grid.make_box(dealii::Point<2>(0, 0), dealii::Point<2>(1, 1), {2, 4});
    grid.setup();
    try
      {
        grid.setup_bspline_patches();
        ADD_FAILURE() << "2 cells in x accepted";
      }
    catch (const InputError &e)
      {
        EXPECT_NE(std::string(e.what()).find("at least 3 cells"), std::string::npos) << e.what();
      }
  }
  {
    // one cell refined: cell sizes differ
    BackgroundGrid<2> grid(MPI_COMM_WORLD);
    grid.make_box(dealii::Point<2>(0, 0), dealii::Point<2>(1, 1), {4, 4});
    for (const auto &cell : grid.tria.active_cell_iterators())
      if (cell->is_locally_owned() && cell->center().distance(dealii::Point<2>(0.125, 0.125)) < 1e-9)
        cell->set_refine_flag();
    grid.tria.execute_coarsening_and_refinement();
    grid.setup();
    try
      {
        grid.setup_bspline_patches();
        ADD_FAILURE() << "refined grid accepted";
      }
    catch (const InputError &e)
      {
        EXPECT_NE(std::string(e.what()).find("cell size in x varies"), std::string::npos) << e.what();
      }
  }
  {
    // a grid file whose vertex lines are off by 1e-9 of the extent (rounded
    // coordinates) is still a uniform box
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    auto         mesh = io::make_box_mesh(2, lo, hi, {5, 4});
    for (auto &v : mesh.vertices)
      if (std::lround(v[0] * 5) % 2 == 1)
        v[0] += 1e-9;
    BackgroundGrid<2> grid(MPI_COMM_WORLD);
    grid.make_from_mesh(mesh);
    grid.setup();
    EXPECT_NO_THROW(grid.setup_bspline_patches());
    EXPECT_EQ(grid.box.n_cells[0], 5u);
  }
  {
    // L-shaped: a uniform lattice that does not fill its bounding box
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
    auto         mesh = io::make_box_mesh(2, lo, hi, {4, 4});
    mesh.cells.erase(mesh.cells.end() - 4, mesh.cells.end());
    mesh.cell_material.pop_back();
    mesh.faces.clear();
    mesh.face_boundary.clear();
    BackgroundGrid<2> grid(MPI_COMM_WORLD);
    grid.make_from_mesh(mesh);
    grid.setup();
    try
      {
        grid.setup_bspline_patches();
        ADD_FAILURE() << "L-shaped grid accepted";
      }
    catch (const InputError &e)
      {
        EXPECT_NE(std::string(e.what()).find("bounding box holds 16"), std::string::npos) << e.what();
      }
  }
}

// The memory figures of docs/shape-functions.md.
TEST(BSplinePatches, Memory)
{
  EXPECT_EQ(sizeof(BSplinePatch<2>), 140u);
  EXPECT_EQ(sizeof(BSplinePatch<3>), 784u);
  std::cout << "  sizeof: BSplinePatch<2> " << sizeof(BSplinePatch<2>) << ", BSplinePatch<3> "
            << sizeof(BSplinePatch<3>) << ", CellCache<2> " << sizeof(CellCache<2>) << ", CellCache<3> "
            << sizeof(CellCache<3>) << "\n";
}

// setup() again (repartition, restart) rebuilds a requested stencil; a grid
// that never asked for it has none (a Q1 run keeps its memory).
TEST(BSplinePatches, RebuiltBySetup)
{
  BackgroundGrid<2> q1(MPI_COMM_WORLD);
  q1.make_box(dealii::Point<2>(0, 0), dealii::Point<2>(1, 1), {4, 4});
  q1.setup();
  EXPECT_FALSE(q1.has_patches());
  EXPECT_TRUE(q1.patches.empty());

  BackgroundGrid<2> grid(MPI_COMM_WORLD);
  dealii::Point<2>  lower;
  double            h[2];
  make_grid<2>(grid, {6, 4}, lower, h);
  ASSERT_TRUE(grid.has_patches());
  const std::vector<BSplinePatch<2>> before = grid.patches;
  grid.patches.clear();
  grid.setup();
  ASSERT_EQ(grid.patches.size(), before.size());
  for (std::size_t k = 0; k < before.size(); ++k)
    for (unsigned int i = 0; i < BSplinePatch<2>::n_slots * 2; ++i)
      EXPECT_EQ(grid.patches[k].dofs[i], before[k].dofs[i]);
}
