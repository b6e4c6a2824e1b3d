// Particle-to-grid transfer conserves mass and momentum to round-off; local
// relocation keeps every particle (ids and properties) when particles cross
// cells; one explicit step with no forces conserves momentum. Runs on any
// number of MPI ranks (ctest also runs it on 2).
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/materials/linear_elastic.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <random>

using namespace talus;

using Shape = explicit_mpm::NumericsOptions::ShapeFunction;

template <int dim>
explicit_mpm::Parameters<dim>
scene(const Shape shape = Shape::linear)
{
  explicit_mpm::Parameters<dim> p;
  p.numerics.shape_function = shape;
  // B-splines couple points up to 1.5 cells apart, so the bodies of these
  // scenes (no boundary conditions) drift towards the walls as one: the grid
  // gets two more cells on every side, so that no point leaves it
  const double pad = shape == Shape::linear ? 0.0 : 0.25;
  for (unsigned int d = 0; d < dim; ++d)
    {
      p.grid_lower[d] = -pad;
      p.grid_upper[d] = 1 + pad;
      p.grid_cells.push_back(shape == Shape::linear ? 8 : 12);
    }
  auto m = std::make_shared<materials::LinearElastic>(1e4, 0.3);
  m->set_density(1000);
  p.materials.push_back(m);
  BodyDescription<dim> b;
  b.shape  = BodyDescription<dim>::Shape::ball;
  b.center = dealii::Point<dim>();
  for (unsigned int d = 0; d < dim; ++d)
    b.center[d] = 0.5;
  b.radius                  = 0.3;
  b.particles_per_direction = 3;
  // a non-uniform velocity field: rotation + shear
  b.velocity_field = [](const dealii::Point<dim> &x) {
    dealii::Tensor<1, dim> v;
    v[0] = 0.3 * (x[1] - 0.5) + 0.1;
    v[1] = -0.2 * (x[0] - 0.5) + 0.05 * x[0] * x[0];
    return v;
  };
  p.bodies.push_back(b);
  return p;
}

template <int dim>
void
conservation(const Shape shape = Shape::linear)
{
  const auto               p = scene<dim>(shape);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  const double m_particles = s.total_mass();
  const auto   p_particles = s.total_momentum();
  const auto [m_grid, p_grid] = s.grid_mass_and_momentum();
  EXPECT_GT(m_particles, 0.0);
  EXPECT_NEAR(m_grid, m_particles, 1e-13 * m_particles);
  for (unsigned int d = 0; d < dim; ++d)
    EXPECT_NEAR(p_grid[d], p_particles[d], 1e-13 * m_particles);
}

TEST(ExplicitTransfer, P2GConservesMassAndMomentum2D) { conservation<2>(); }
TEST(ExplicitTransfer, P2GConservesMassAndMomentum3D) { conservation<3>(); }
TEST(ExplicitTransfer, BSplineP2GConservesMassAndMomentum2D) { conservation<2>(Shape::quadratic_bspline); }
TEST(ExplicitTransfer, BSplineP2GConservesMassAndMomentum3D) { conservation<3>(Shape::quadratic_bspline); }

template <int dim>
void
relocation_and_momentum(const Shape shape = Shape::linear)
{
  auto p = scene<dim>(shape);
  p.gravity = dealii::Tensor<1, dim>();
  // two small bodies slide along the bottom, one behind the other: cells become
  // active for the first time, are vacated, and are re-entered (stale nodal entries)
  auto b2      = p.bodies[0];
  b2.radius    = 0.04;
  b2.center[0] = 0.72;
  b2.center[1] = 0.08;
  b2.velocity_field = [](const dealii::Point<dim> &) {
    dealii::Tensor<1, dim> v;
    v[0] = -0.4;
    v[1] = 0.0;
    return v;
  };
  p.bodies.push_back(b2);
  auto b3      = b2; // follows b2 into the cells it vacates
  b3.center[0] = 0.94;
  p.bodies.push_back(b3);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  const auto         n0  = s.n_particles();
  const double       m0  = s.total_mass();
  const auto         p0  = s.total_momentum();
  // large steps (still below the critical one) so that particles cross cells;
  // after each, the fused P2G and the kept (cell, count) list must match a
  // fresh computation
  double worst = 0;
  for (int i = 0; i < 40; ++i)
    {
      s.step(s.time_step());
      const auto [err, same_cells] = s.check_incremental_state();
      worst                        = std::max(worst, err);
      EXPECT_TRUE(same_cells) << "step " << i;

    }
  EXPECT_LT(worst, 1e-12) << "fused P2G differs from a fresh P2G";
  EXPECT_EQ(s.n_particles(), n0);
  unsigned long long local = s.points.handler.n_locally_owned_particles();
  EXPECT_EQ(dealii::Utilities::MPI::sum(local, MPI_COMM_WORLD), n0);
  EXPECT_GT(dealii::Utilities::MPI::sum(s.points.relocation_stats.moved_locally, MPI_COMM_WORLD) +
              s.points.relocation_stats.global_sorts,
            0u)
    << "the test must move particles across cells";
  EXPECT_NEAR(s.total_mass(), m0, 1e-13 * m0);
  const auto p1 = s.total_momentum();
  for (unsigned int d = 0; d < dim; ++d)
    EXPECT_NEAR(p1[d], p0[d], 1e-12 * m0) << "no external force: momentum conserved";
  // every particle sits inside the cell it is stored in, with consistent
  // reference coordinates
  for (const auto &pt : s.points.handler)
    {
      const auto c  = pt.get_surrounding_cell()->active_cell_index();
      const auto xi = s.grid.reference_point(c, pt.get_location());
      for (unsigned int d = 0; d < dim; ++d)
        {
          EXPECT_GE(xi[d], -1e-12);
          EXPECT_LE(xi[d], 1 + 1e-12);
          EXPECT_NEAR(xi[d], pt.get_reference_location()[d], 1e-12);
        }
    }
  // ids unique and complete
  std::vector<dealii::types::particle_index> ids;
  for (const auto &pt : s.points.handler)
    ids.push_back(pt.get_id());
  auto all = dealii::Utilities::MPI::all_gather(MPI_COMM_WORLD, ids);
  std::vector<dealii::types::particle_index> merged;
  for (auto &v : all)
    merged.insert(merged.end(), v.begin(), v.end());
  std::sort(merged.begin(), merged.end());
  ASSERT_EQ(merged.size(), n0);
  for (std::size_t i = 0; i < merged.size(); ++i)
    EXPECT_EQ(merged[i], i);
}

TEST(ExplicitTransfer, RelocationKeepsParticles2D) { relocation_and_momentum<2>(); }
TEST(ExplicitTransfer, RelocationKeepsParticles3D) { relocation_and_momentum<3>(); }
// the same with quadratic B-splines: the fused P2G of the update pass and of
// the moved points equals a fresh P2G on the 4^dim patches after every step
TEST(ExplicitTransfer, BSplineRelocationKeepsParticles2D) { relocation_and_momentum<2>(Shape::quadratic_bspline); }
TEST(ExplicitTransfer, BSplineRelocationKeepsParticles3D) { relocation_and_momentum<3>(Shape::quadratic_bspline); }
