// The point diagnostics of every family (formulations/common/diagnostics.h) on
// four points of a 2 x 3 grid of cells of size 0.5 (a body over the lower 2 x 2
// cells), one point per cell at the cell centres (0.25 | 0.75, 0.25 | 0.75), mass 1, volume 1/4, velocity
// (x, 2 y), gravity (0, -10): the sums against values worked out by hand, with
// and without a second phase and a strain energy; the search for an invalid
// point names it and its field on every rank. ctest runs this on 1 and 2 ranks
// (unit.test_diagnostics_np2): the points then lie on both ranks.
#include <talus/formulations/common/diagnostics.h>
#include <talus/materials/linear_elastic.h>
#include <talus/particles/material_point_set.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

using namespace talus;

namespace
{
  using L = PropertyLayout<2>;

  struct Scene
  {
    Scene()
        : grid(MPI_COMM_WORLD)
        , points(grid, "soil")
    {
      // 2 x 3 coarse cells (one coarse cell refined would stay on one rank)
      grid.make_box(dealii::Point<2>(0, 0), dealii::Point<2>(1, 1.5), {2, 3});
      grid.setup();
      points.initialize();
      BodyDescription<2> body;
      body.shape                   = BodyDescription<2>::Shape::box;
      body.lower                   = dealii::Point<2>(0, 0);
      body.upper                   = dealii::Point<2>(1, 1);
      body.particles_per_direction = 1;
      seed_bodies(grid, {body}, {4.0}, points.layout, points.handler); // m = 4 x 1/4 = 1
      points.collect_active_cells();
      for (auto &pt : points.handler)
        {
          const auto x       = pt.get_location();
          auto       P       = pt.get_properties();
          P[L::velocity + 0] = x[0];
          P[L::velocity + 1] = 2 * x[1];
          // the second phase's velocity in the tests below: (1, 0)
          P[L::displacement + 0] = 1;
          P[L::displacement + 1] = 0;
          for (unsigned int q = 0; q < L::n_stress; ++q)
            P[L::stress + q] = 0;
          P[L::stress + 0] = 2; // sigma_xx = 2: psi = 2^2 / (2 E) = 2 with E = 1, nu = 0
        }
    }
    BackgroundGrid<2>    grid;
    MaterialPointSet<2>  points;
    dealii::Tensor<1, 2> gravity{{0.0, -10.0}};
  };

  /// Set property k of the point at `at` (on whichever rank holds it).
  void
  set_property(MaterialPointSet<2> &set, const dealii::Point<2> &at, const unsigned int k, const double value)
  {
    for (auto &pt : set.handler)
      if (pt.get_location().distance(at) < 1e-12)
        pt.get_properties()[k] = value;
  }
} // namespace

TEST(Diagnostics, AddByHand)
{
  diagnostics::PointSums<2>  s;
  const double               v[2] = {3, 4};
  const dealii::Tensor<1, 2> g{{0.0, -10.0}};
  EXPECT_DOUBLE_EQ(s.add(2, v, dealii::Point<2>(1, 0.5), g), 25);
  EXPECT_DOUBLE_EQ(s.mass, 2);
  EXPECT_DOUBLE_EQ(s.kinetic, 25); // 1/2 2 25
  EXPECT_DOUBLE_EQ(s.momentum[0], 6);
  EXPECT_DOUBLE_EQ(s.momentum[1], 8);
  EXPECT_DOUBLE_EQ(s.gravity_potential, 10); // -2 (-10 x 0.5)
  EXPECT_DOUBLE_EQ(s.mass_moment[0], 2);
  EXPECT_DOUBLE_EQ(s.mass_moment[1], 1);
  const double vL[2] = {0, 2};
  EXPECT_DOUBLE_EQ(s.add(1, v, 3, vL, dealii::Point<2>(0, 1), g), 25);
  EXPECT_DOUBLE_EQ(s.mass, 3);
  EXPECT_DOUBLE_EQ(s.second_mass, 3);
  EXPECT_DOUBLE_EQ(s.kinetic, 25 + 12.5 + 6); // + 1/2 1 25 + 1/2 3 4
  EXPECT_DOUBLE_EQ(s.momentum[0], 6 + 3);
  EXPECT_DOUBLE_EQ(s.momentum[1], 8 + 4 + 6);
  EXPECT_DOUBLE_EQ(s.gravity_potential, 10 + 40); // -(1 + 3) (-10 x 1)
  EXPECT_DOUBLE_EQ(s.mass_moment[1], 1 + 4);
  EXPECT_DOUBLE_EQ(s.n_points, 2);
  s.add_strain(1.5);
  EXPECT_DOUBLE_EQ(s.strain, 1.5);
}

TEST(Diagnostics, SumsOverASet)
{
  Scene sc;
  ASSERT_EQ(sc.points.handler.n_global_particles(), 4u);
  if (dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 2) // three cells per rank
    {
      EXPECT_GT(sc.points.handler.n_locally_owned_particles(), 0u);
    }
  auto s = diagnostics::sum_points(sc.points);
  s.sum_over_ranks(MPI_COMM_WORLD);
  // x: 0.25, 0.75, 0.25, 0.75; y: 0.25, 0.25, 0.75, 0.75; m = 1
  EXPECT_DOUBLE_EQ(s.n_points, 4);
  EXPECT_DOUBLE_EQ(s.mass, 4);
  EXPECT_DOUBLE_EQ(s.second_mass, 0);
  EXPECT_DOUBLE_EQ(s.momentum[0], 2);    // sum x
  EXPECT_DOUBLE_EQ(s.momentum[1], 4);    // sum 2 y
  EXPECT_DOUBLE_EQ(s.kinetic, 3.125);    // 1/2 sum (x^2 + 4 y^2) = 1/2 (1.25 + 5)
  EXPECT_DOUBLE_EQ(s.mass_moment[0], 2); // centre of mass (0.5, 0.5)
  EXPECT_DOUBLE_EQ(s.mass_moment[1], 2);
  EXPECT_DOUBLE_EQ(s.gravity_potential, 0); // no gravity given
  EXPECT_DOUBLE_EQ(s.strain, 0);            // no materials given

  // gravity, strain energy (linear elastic, E = 1, nu = 0), a second phase of
  // mass 1/2 moving at (1, 0) on every point, and an extra strain energy 0.1
  const std::vector<std::shared_ptr<const materials::Material>> mats = {
    std::make_shared<materials::LinearElastic>(1.0, 0.0)};
  diagnostics::SumOptions<2> o;
  o.gravity      = sc.gravity;
  o.materials    = &mats;
  o.second_phase = [](const double *P, const double *&vL) {
    vL = P + L::displacement;
    return 0.5;
  };
  o.extra_strain = [](const double *) { return 0.1; };
  auto t         = diagnostics::sum_points(sc.points, o);
  auto u         = diagnostics::sum_points(sc.points); // a second set of sums, reduced together
  diagnostics::sum_over_ranks<2>({&t, &u}, MPI_COMM_WORLD);
  EXPECT_DOUBLE_EQ(t.mass, 4);
  EXPECT_DOUBLE_EQ(t.second_mass, 2);
  EXPECT_DOUBLE_EQ(t.kinetic, 3.125 + 1.0); // + 4 x 1/2 x 1/2 x 1
  EXPECT_DOUBLE_EQ(t.momentum[0], 2 + 2);   // + 4 x 1/2 x 1
  EXPECT_DOUBLE_EQ(t.momentum[1], 4);
  EXPECT_DOUBLE_EQ(t.gravity_potential, 20 + 10);     // -(1 + 1/2) (-10) sum y, sum y = 2
  EXPECT_DOUBLE_EQ(t.mass_moment[1], 3);              // (1 + 1/2) sum y
  EXPECT_NEAR(t.strain, 4 * (0.25 * 2 + 0.1), 1e-14); // V psi + 0.1 per point
  EXPECT_DOUBLE_EQ(u.kinetic, 3.125);
  EXPECT_DOUBLE_EQ(u.mass, 4);

  // FEM points: the position is the location plus the displacement (1, 0)
  diagnostics::SumOptions<2> f;
  f.add_displacement = true;
  f.gravity          = dealii::Tensor<1, 2>({-1.0, 0.0});
  auto w             = diagnostics::sum_points(sc.points, f);
  w.sum_over_ranks(MPI_COMM_WORLD);
  EXPECT_DOUBLE_EQ(w.mass_moment[0], 2 + 4);
  EXPECT_DOUBLE_EQ(w.gravity_potential, 6); // -sum m (-1) (x + 1)
}

TEST(Diagnostics, InvalidPointIsNamed)
{
  Scene sc;
  EXPECT_EQ(diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD), "");

  // a non-finite shear stress at (0.75, 0.75): named on every rank
  set_property(sc.points, dealii::Point<2>(0.75, 0.75), L::stress + 3, std::numeric_limits<double>::quiet_NaN());
  std::string m = diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD);
  EXPECT_NE(m.find("of 'soil' at (0.75, 0.75): stress_xy = nan"), std::string::npos) << m;
  EXPECT_EQ(m.rfind("point ", 0), 0u) << m;
  // only the fields before the stress checked: nothing found
  EXPECT_EQ(diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD, L::stress), "");

  // a velocity component names its direction; a non-positive volume is invalid
  set_property(sc.points, dealii::Point<2>(0.75, 0.75), L::stress + 3, 0.0);
  set_property(sc.points, dealii::Point<2>(0.25, 0.75), L::velocity + 1, std::numeric_limits<double>::infinity());
  m = diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD);
  EXPECT_NE(m.find("at (0.25, 0.75): velocity_y = inf"), std::string::npos) << m;
  set_property(sc.points, dealii::Point<2>(0.25, 0.75), L::velocity + 1, 0.0);
  set_property(sc.points, dealii::Point<2>(0.25, 0.25), L::volume, -1e-3);
  m = diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD);
  EXPECT_NE(m.find("at (0.25, 0.25): volume = -0.001 (must be > 0)"), std::string::npos) << m;
  EXPECT_EQ(diagnostics::find_invalid_point(sc.points, MPI_COMM_WORLD, L::history, false), "");
}
