// Q1 kernel: partition of unity, gradient consistency, gradients vs finite
// differences, and agreement with deal.II's FE_Q(1) shape functions.
#include <talus/shape/q1.h>

#include <deal.II/fe/fe_q.h>

#include <gtest/gtest.h>

#include <random>

using namespace talus;

template <int dim>
void
check_kernel()
{
  constexpr unsigned int                 nv = shape::Q1<dim>::n_vertices;
  std::mt19937                           rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double                           h[3] = {0.3, 0.7, 1.9};
  double                                 inv_h[dim];
  for (unsigned int d = 0; d < dim; ++d)
    inv_h[d] = 1.0 / h[d];
  dealii::FE_Q<dim> fe(1);
  for (int trial = 0; trial < 200; ++trial)
    {
      dealii::Point<dim> xi;
      for (unsigned int d = 0; d < dim; ++d)
        xi[d] = u(rng);
      double N[nv], G[nv][dim];
      shape::Q1<dim>::values_and_gradients(xi, inv_h, N, G);
      double sum = 0, sumg[dim] = {}, xg[dim][dim] = {};
      for (unsigned int v = 0; v < nv; ++v)
        {
          sum += N[v];
          // deal.II FE_Q(1) numbers its support points lexicographically too
          EXPECT_NEAR(N[v], fe.shape_value(v, xi), 1e-14);
          for (unsigned int d = 0; d < dim; ++d)
            {
              sumg[d] += G[v][d];
              const double xv = ((v >> d) & 1u) ? h[d] : 0.0;
              for (unsigned int e = 0; e < dim; ++e)
                xg[(d)][e] += (((v >> d) & 1u) ? h[d] : 0.0) * G[v][e];
              (void)xv;
            }
        }
      EXPECT_NEAR(sum, 1.0, 1e-14) << "partition of unity";
      for (unsigned int d = 0; d < dim; ++d)
        {
          EXPECT_NEAR(sumg[d], 0.0, 1e-13) << "gradients sum to zero";
          for (unsigned int e = 0; e < dim; ++e)
            EXPECT_NEAR(xg[d][e], d == e ? 1.0 : 0.0, 1e-13) << "sum x_v grad N_v = I";
        }
      // gradients against central differences of the values
      for (unsigned int e = 0; e < dim; ++e)
        {
          const double       eps = 1e-6;
          dealii::Point<dim> a = xi, b = xi;
          a[e] += eps;
          b[e] -= eps;
          double Na[nv], Nb[nv];
          shape::Q1<dim>::values(a, Na);
          shape::Q1<dim>::values(b, Nb);
          for (unsigned int v = 0; v < nv; ++v)
            EXPECT_NEAR(G[v][e], (Na[v] - Nb[v]) / (2 * eps) * inv_h[e], 1e-8);
        }
      // values() agrees with values_and_gradients()
      double N2[nv];
      shape::Q1<dim>::values(xi, N2);
      for (unsigned int v = 0; v < nv; ++v)
        EXPECT_DOUBLE_EQ(N[v], N2[v]);
    }
}

TEST(ShapeQ1, Kernel2D)
{
  check_kernel<2>();
}
TEST(ShapeQ1, Kernel3D)
{
  check_kernel<3>();
}

// The sum-factorised kernel gives the same gradients and internal forces as the
// direct per-vertex evaluation.
template <int dim>
void
check_factorised()
{
  using QF                                  = shape::Q1Factorised<dim>;
  constexpr unsigned int                 nv = QF::nv;
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  double                                 inv_h[dim];
  for (unsigned int d = 0; d < dim; ++d)
    inv_h[d] = 1.0 / (0.5 + d * 0.3);
  for (int trial = 0; trial < 100; ++trial)
    {
      double nodal[nv][dim];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          nodal[v][d] = u(rng);
      double D[dim][QF::npairs][dim];
      QF::differences(nodal, D);
      double T[dim][QF::npairs][dim] = {}, f_direct[nv][dim] = {};
      for (int p = 0; p < 5; ++p)
        {
          dealii::Point<dim> xi;
          for (unsigned int d = 0; d < dim; ++d)
            xi[d] = u01(rng);
          double N[nv], G[nv][dim], Nf[nv], w[dim][QF::npairs];
          shape::Q1<dim>::values_and_gradients(xi, inv_h, N, G);
          QF::weights(xi, Nf, w);
          double grad[dim][dim];
          QF::gradient(D, w, inv_h, grad);
          for (unsigned int v = 0; v < nv; ++v)
            EXPECT_NEAR(Nf[v], N[v], 1e-15);
          for (unsigned int c = 0; c < dim; ++c)
            for (unsigned int k = 0; k < dim; ++k)
              {
                double direct = 0;
                for (unsigned int v = 0; v < nv; ++v)
                  direct += nodal[v][c] * G[v][k];
                EXPECT_NEAR(grad[c][k], direct, 1e-13);
              }
          double t[dim][dim];
          for (unsigned int c = 0; c < dim; ++c)
            for (unsigned int k = 0; k < dim; ++k)
              t[c][k] = u(rng);
          QF::add_moments(t, w, T);
          for (unsigned int v = 0; v < nv; ++v)
            for (unsigned int c = 0; c < dim; ++c)
              for (unsigned int k = 0; k < dim; ++k)
                f_direct[v][c] += t[c][k] * G[v][k];
        }
      double f[nv][dim] = {};
      QF::expand_moments(T, inv_h, f);
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int c = 0; c < dim; ++c)
          EXPECT_NEAR(f[v][c], f_direct[v][c], 1e-12);
    }
}

TEST(ShapeQ1, Factorised2D)
{
  check_factorised<2>();
}
TEST(ShapeQ1, Factorised3D)
{
  check_factorised<3>();
}
