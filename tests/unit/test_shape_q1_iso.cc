// Isoparametric Q1 (shape/q1_iso.h, the FEM / UL-FEM kernel) on distorted
// quads/hexes: values, real gradients and det J against deal.II's FE_Q(1) with
// MappingQ(1) (FEValues at the same reference point), and the patch property
// sum_v x_v (x) grad N_v = I; the Q1Iso kernel policy (FEM / UL-FEM) against
// that arithmetic: affine fields reproduced, mass and force sums conserved.
#include <talus/shape/q1_iso.h>

#include <deal.II/base/quadrature.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/grid/tria.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace talus;

template <int dim>
void
check_iso()
{
  constexpr unsigned int                 nv = 1u << dim;
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2), r(0.05, 0.95);
  for (int trial = 0; trial < 20; ++trial)
    {
      // a unit cell with every vertex moved by up to 0.2, scaled and sheared
      std::vector<dealii::Point<dim>> vertices(nv);
      double                          X[nv][dim];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          {
            X[v][d] = (((v >> d) & 1u) ? 1.0 : 0.0) * (1.0 + 0.5 * d) + u(rng) + (d == 0 ? 0.3 * ((v >> 1) & 1u) : 0.0);
            vertices[v][d] = X[v][d];
          }
      std::vector<dealii::CellData<dim>> cells(1);
      for (unsigned int v = 0; v < nv; ++v)
        cells[0].vertices[v] = v;
      dealii::Triangulation<dim> tria;
      tria.create_triangulation(vertices, cells, dealii::SubCellData());
      dealii::Point<dim> xi;
      for (unsigned int d = 0; d < dim; ++d)
        xi[d] = r(rng);
      dealii::FE_Q<dim>       fe(1);
      dealii::MappingQ<dim>   mapping(1);
      dealii::Quadrature<dim> q(std::vector<dealii::Point<dim>>{xi}, std::vector<double>{1.0});
      dealii::FEValues<dim>   fv(mapping, fe, q,
                                 dealii::update_values | dealii::update_gradients | dealii::update_JxW_values |
                                   dealii::update_quadrature_points);
      fv.reinit(tria.begin_active());
      double N[nv], dN[nv][dim], G[nv][dim];
      shape::IsoQ1<dim>::shape(xi, N, dN);
      const double det = shape::IsoQ1<dim>::gradients(X, dN, G);
      EXPECT_NEAR(det, fv.JxW(0), 1e-12) << "det J";
      double x[dim] = {}, xg[dim][dim] = {};
      for (unsigned int v = 0; v < nv; ++v)
        {
          EXPECT_NEAR(N[v], fv.shape_value(v, 0), 1e-13);
          for (unsigned int k = 0; k < dim; ++k)
            EXPECT_NEAR(G[v][k], fv.shape_grad(v, 0)[k], 1e-11) << "vertex " << v << " direction " << k;
          for (unsigned int d = 0; d < dim; ++d)
            {
              x[d] += N[v] * X[v][d];
              for (unsigned int k = 0; k < dim; ++k)
                xg[d][k] += X[v][d] * G[v][k];
            }
        }
      for (unsigned int d = 0; d < dim; ++d)
        {
          EXPECT_NEAR(x[d], fv.quadrature_point(0)[d], 1e-13) << "mapped point";
          for (unsigned int k = 0; k < dim; ++k)
            EXPECT_NEAR(xg[d][k], d == k ? 1.0 : 0.0, 1e-12) << "sum x_v grad N_v = I";
        }
    }
}

TEST(ShapeQ1Iso, DistortedQuad)
{
  check_iso<2>();
}
TEST(ShapeQ1Iso, DistortedHex)
{
  check_iso<3>();
}

// The Q1Iso policy on a distorted cell: the same numbers as IsoQ1; an affine
// field u = A x + b interpolated with value and gradient exact; the per-cell
// sums scatter the total mass and, with the gradients summing to zero, a total
// force of exactly (sum m) g; moving the vertices by an affine map F scales
// det J by det F.
template <int dim>
void
check_policy()
{
  using K                                   = shape::Q1Iso<dim>;
  constexpr unsigned int                 nv = K::n_nodes;
  std::mt19937                           rng(11);
  std::uniform_real_distribution<double> u(-0.2, 0.2), r(0.05, 0.95);
  for (int trial = 0; trial < 10; ++trial)
    {
      typename K::Cell cell;
      unsigned int     dofs[nv * dim];
      for (unsigned int i = 0; i < nv * dim; ++i)
        dofs[i] = i;
      cell.dofs = dofs;
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          cell.X[v][d] = (((v >> d) & 1u) ? 1.0 : 0.0) * (1.0 + 0.5 * d) + u(rng);
      dealii::Point<dim> xi;
      for (unsigned int d = 0; d < dim; ++d)
        xi[d] = r(rng);
      typename K::Eval e;
      K::evaluate(cell, xi, e);
      double N[nv], dN[nv][dim], G[nv][dim];
      shape::IsoQ1<dim>::shape(xi, N, dN);
      const double det = shape::IsoQ1<dim>::gradients(cell.X, dN, G);
      EXPECT_EQ(e.det, det);
      for (unsigned int v = 0; v < nv; ++v)
        {
          EXPECT_EQ(e.N[v], N[v]);
          for (unsigned int k = 0; k < dim; ++k)
            EXPECT_EQ(e.G[v][k], G[v][k]);
        }
      dealii::Point<dim> x;
      K::position(cell, e, x);

      // affine field: nodal vector V (scaled by 2 in the gather)
      double A[dim][dim], b[dim];
      for (unsigned int a = 0; a < dim; ++a)
        {
          b[a] = u(rng);
          for (unsigned int k = 0; k < dim; ++k)
            A[a][k] = u(rng) + (a == k ? 1.0 : 0.0);
        }
      std::vector<double> V(nv * dim);
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int a = 0; a < dim; ++a)
          {
            V[v * dim + a] = b[a];
            for (unsigned int k = 0; k < dim; ++k)
              V[v * dim + a] += A[a][k] * cell.X[v][k];
          }
      typename K::Field f;
      K::gather(cell, V.data(), 2.0, f);
      double val[dim], grad[dim][dim];
      K::value_and_gradient(f, e, val, grad);
      for (unsigned int a = 0; a < dim; ++a)
        {
          double exact = b[a];
          for (unsigned int k = 0; k < dim; ++k)
            exact += A[a][k] * x[k];
          EXPECT_NEAR(val[a], 2.0 * exact, 1e-12) << "value, component " << a;
          for (unsigned int k = 0; k < dim; ++k)
            EXPECT_NEAR(grad[a][k], 2.0 * A[a][k], 1e-11) << "gradient " << a << "," << k;
        }

      // mass and force of two points
      typename K::MassForce sums;
      sums.clear();
      double t[dim][dim];
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int k = 0; k < dim; ++k)
          t[a][k] = u(rng);
      sums.add(e, 3.0, t);
      dealii::Point<dim> xi2;
      for (unsigned int d = 0; d < dim; ++d)
        xi2[d] = r(rng);
      typename K::Eval e2;
      K::evaluate(cell, xi2, e2);
      sums.add(e2, 0.5, t);
      dealii::Tensor<1, dim> g;
      g[dim - 1] = -9.81;
      std::vector<double> M(nv * dim, 0.0), F(nv * dim, 0.0);
      sums.scatter(cell, g, M.data(), F.data());
      for (unsigned int a = 0; a < dim; ++a)
        {
          double m = 0, force = 0;
          for (unsigned int v = 0; v < nv; ++v)
            {
              m += M[v * dim + a];
              force += F[v * dim + a];
            }
          EXPECT_NEAR(m, 3.5, 1e-13) << "mass, component " << a;
          EXPECT_NEAR(force, 3.5 * g[a], 1e-12) << "force, component " << a;
        }

      // the cell deformed by an affine map: det J scales with det F
      double X1[nv][dim];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int a = 0; a < dim; ++a)
          {
            X1[v][a] = 0;
            for (unsigned int k = 0; k < dim; ++k)
              X1[v][a] += A[a][k] * cell.X[v][k];
          }
      dealii::Tensor<2, dim> Ft;
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int k = 0; k < dim; ++k)
          Ft[a][k] = A[a][k];
      const double det0 = e.det;
      EXPECT_NEAR(K::move_vertices(X1, e), det0 * dealii::determinant(Ft), 1e-12 * std::abs(det0));
    }
}

TEST(ShapeQ1Iso, PolicyQuad)
{
  check_policy<2>();
}
TEST(ShapeQ1Iso, PolicyHex)
{
  check_policy<3>();
}
