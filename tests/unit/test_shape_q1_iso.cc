// Isoparametric Q1 (shape/q1_iso.h, the FEM / UL-FEM kernel) on distorted
// quads/hexes: values, real gradients and det J against deal.II's FE_Q(1) with
// MappingQ(1) (FEValues at the same reference point), and the patch property
// sum_v x_v (x) grad N_v = I.
#include <talus/shape/q1_iso.h>

#include <deal.II/base/quadrature.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/grid/tria.h>

#include <gtest/gtest.h>

#include <random>

using namespace talus;

template <int dim>
void
check_iso()
{
  constexpr unsigned int nv = 1u << dim;
  std::mt19937           rng(7);
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
      dealii::FEValues<dim>   fv(mapping, fe, q, dealii::update_values | dealii::update_gradients |
                                                  dealii::update_JxW_values | dealii::update_quadrature_points);
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

TEST(ShapeQ1Iso, DistortedQuad) { check_iso<2>(); }
TEST(ShapeQ1Iso, DistortedHex) { check_iso<3>(); }
