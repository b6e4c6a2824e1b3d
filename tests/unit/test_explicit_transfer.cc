// Particle-to-grid transfer conserves mass and momentum to round-off; local
// relocation keeps every particle (ids and properties) when particles cross
// cells; one explicit step with no forces conserves momentum. Runs on any
// number of MPI ranks (ctest also runs it on 2).
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/materials/linear_elastic.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <random>

using namespace talus;

using Shape = talus::ShapeFunction;

template <int dim>
explicit_mpm::Parameters<dim>
scene(const Shape shape = Shape::linear)
{
  explicit_mpm::Parameters<dim> p;
  p.shape_function = shape;
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
  const auto                p = scene<dim>(shape);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  const double m_particles    = s.total_mass();
  const auto   p_particles    = s.total_momentum();
  const auto [m_grid, p_grid] = s.grid_mass_and_momentum();
  EXPECT_GT(m_particles, 0.0);
  EXPECT_NEAR(m_grid, m_particles, 1e-13 * m_particles);
  for (unsigned int d = 0; d < dim; ++d)
    EXPECT_NEAR(p_grid[d], p_particles[d], 1e-13 * m_particles);
}

TEST(ExplicitTransfer, P2GConservesMassAndMomentum2D)
{
  conservation<2>();
}
TEST(ExplicitTransfer, P2GConservesMassAndMomentum3D)
{
  conservation<3>();
}
TEST(ExplicitTransfer, BSplineP2GConservesMassAndMomentum2D)
{
  conservation<2>(Shape::quadratic_bspline);
}
TEST(ExplicitTransfer, BSplineP2GConservesMassAndMomentum3D)
{
  conservation<3>(Shape::quadratic_bspline);
}

/// The ball of scene() plus two small bodies sliding along the bottom, one
/// behind the other: cells become active for the first time, are vacated, and
/// are re-entered (stale nodal entries); no gravity.
template <int dim>
explicit_mpm::Parameters<dim>
sliding_scene(const Shape shape, const bool apic)
{
  auto p = scene<dim>(shape);
  if (apic)
    p.numerics.velocity_transfer = explicit_mpm::NumericsOptions::VelocityTransfer::apic;
  p.gravity = dealii::Tensor<1, dim>();
  // two small bodies slide along the bottom, one behind the other: cells become
  // active for the first time, are vacated, and are re-entered (stale nodal entries)
  auto b2           = p.bodies[0];
  b2.radius         = 0.04;
  b2.center[0]      = 0.72;
  b2.center[1]      = 0.08;
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
  return p;
}

template <int dim>
void
relocation_and_momentum(const Shape shape = Shape::linear, const bool apic = false)
{
  const auto                p = sliding_scene<dim>(shape, apic);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  const auto   n0 = s.n_particles();
  const double m0 = s.total_mass();
  const auto   p0 = s.total_momentum();
  // large steps (still below the critical one) so that particles cross cells;
  // after each, the fused P2G and the kept (cell, count) list must match a
  // fresh computation
  double                                                                 worst = 0;
  std::map<dealii::types::particle_index, dealii::types::particle_index> slot_of_id;
  unsigned long long                                                     moved_keeping_slot = 0;
  for (int i = 0; i < 40; ++i)
    {
      slot_of_id.clear();
      for (const auto &pt : s.points.handler)
        slot_of_id[pt.get_id()] = pt.get_local_index();
      const auto moved_before = s.points.relocation_stats.moved_locally;
      s.step(s.time_step());
      const auto [err, same_cells] = s.check_incremental_state();
      worst                        = std::max(worst, err);
      EXPECT_TRUE(same_cells) << "step " << i;
      // a point moved to a neighbour cell on this rank keeps its storage slot
      // (the relocator removes and at once re-inserts it; deal.II's pool hands
      // the freed slot to the next insertion), unless a full sort or a
      // memory-order rebuild ran
      if (!s.points.relocator().sorted_last && !s.points.relocator().reordered_last &&
          dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 1)
        {
          for (const auto &pt : s.points.handler)
            EXPECT_EQ(pt.get_local_index(), slot_of_id.at(pt.get_id())) << "step " << i << ", point " << pt.get_id();
          moved_keeping_slot += s.points.relocation_stats.moved_locally - moved_before;
        }
    }
  if (dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 1)
    {
      EXPECT_GT(moved_keeping_slot, 0u) << "the slot check must see moved points";
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
  auto                                       all = dealii::Utilities::MPI::all_gather(MPI_COMM_WORLD, ids);
  std::vector<dealii::types::particle_index> merged;
  for (auto &v : all)
    merged.insert(merged.end(), v.begin(), v.end());
  std::sort(merged.begin(), merged.end());
  ASSERT_EQ(merged.size(), n0);
  for (std::size_t i = 0; i < merged.size(); ++i)
    EXPECT_EQ(merged[i], i);
}

/// The relocator's memory-order rebuild (Relocator::restore_memory_order):
/// run A rebuilds after every step in which a point changed cell, run B never.
/// After a rebuild the walk reads the storage slots in increasing order, the
/// kept cell list and the fused P2G equal fresh ones (so every point kept its
/// cell and data), no deal.II sort ran, and A's points equal B's to round-off
/// (only the order of the sums differs).
template <int dim>
void
memory_order(const Shape shape = Shape::linear)
{
  const auto                p = sliding_scene<dim>(shape, false);
  explicit_mpm::Solver<dim> a(p, MPI_COMM_WORLD), b(p, MPI_COMM_WORLD);
  a.setup();
  b.setup();
  a.points.relocator().resort_fraction = 0.0;  // rebuild whenever a point moved
  b.points.relocator().resort_fraction = 1e30; // never
  unsigned int rebuilds                = 0;
  for (int i = 0; i < 40; ++i)
    {
      const double h = a.time_step();
      a.step(h);
      b.step(h);
      const auto [err, same_cells] = a.check_incremental_state();
      EXPECT_LT(err, 1e-12) << "step " << i << ": fused P2G differs from a fresh P2G after a rebuild";
      EXPECT_TRUE(same_cells) << "step " << i;
      if (!a.points.relocator().reordered_last)
        continue;
      ++rebuilds;
      EXPECT_FALSE(a.points.relocator().sorted_last);
      bool         ascending = true;
      unsigned int last = 0, k = 0;
      for (const auto &pt : a.points.handler)
        {
          ascending = ascending && (k++ == 0 || pt.get_local_index() > last);
          last      = pt.get_local_index();
        }
      EXPECT_TRUE(ascending) << "step " << i << ": the walk must read the slots in increasing order";
    }
  EXPECT_GT(dealii::Utilities::MPI::max(rebuilds, MPI_COMM_WORLD), 5u) << "the test must rebuild";
  EXPECT_EQ(a.points.relocation_stats.global_sorts, 0u);
  EXPECT_EQ(b.points.relocation_stats.storage_sorts, 0u);
  // the points of A and B, by id: all properties and the position
  auto by_id = [](explicit_mpm::Solver<dim> &s) {
    std::map<dealii::types::particle_index, std::vector<double>> m;
    for (const auto &pt : s.points.handler)
      {
        std::vector<double> r(pt.get_properties().begin(), pt.get_properties().end());
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(pt.get_location()[d]);
        m[pt.get_id()] = r;
      }
    return m;
  };
  const auto ma = by_id(a), mb = by_id(b);
  ASSERT_EQ(ma.size(), mb.size());
  ASSERT_FALSE(ma.empty());
  // per column (property or coordinate): largest difference over its scale
  const std::size_t   n_columns = ma.begin()->second.size();
  std::vector<double> worst(n_columns, 0.0), scale(n_columns, 0.0);
  for (const auto &[id, ra] : ma)
    {
      const auto &rb = mb.at(id);
      for (std::size_t j = 0; j < n_columns; ++j)
        {
          worst[j] = std::max(worst[j], std::abs(ra[j] - rb[j]));
          scale[j] = std::max(scale[j], std::abs(rb[j]));
        }
    }
  for (std::size_t j = 0; j < n_columns; ++j)
    EXPECT_LE(worst[j], 1e-12 * scale[j]) << "column " << j << ": the rebuild changed the points beyond round-off";
}
TEST(ExplicitTransfer, MemoryOrderRebuild2D)
{
  memory_order<2>();
}
TEST(ExplicitTransfer, MemoryOrderRebuild3D)
{
  memory_order<3>();
}
TEST(ExplicitTransfer, BSplineMemoryOrderRebuild3D)
{
  memory_order<3>(Shape::quadratic_bspline);
}

/// The rebuild itself, against its definition: run with rebuilds switched off
/// until the storage is scattered, (optionally) remove every 7th point so that
/// the pool has free slots, then restore_memory_order(). The walk afterwards
/// must be the walk before with the cell groups in active-cell order (each
/// cell's points in their old order), every point's location, reference
/// location, id and properties bit for bit the same, and the slots increasing
/// along the walk (free slots stay free: the pool keeps its size).
template <int dim>
void
rebuild_in_place(const bool with_free_slots)
{
  const auto                p = sliding_scene<dim>(Shape::linear, false);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  s.points.relocator().resort_fraction = 1e30; // never
  for (int i = 0; i < 30; ++i)
    s.step(s.time_step());
  auto &handler = s.points.handler;
  if (with_free_slots)
    {
      // remove from the back of each cell's points (deal.II moves a cell's last
      // point into the hole a removal leaves)
      std::vector<typename dealii::Particles::ParticleHandler<dim>::particle_iterator> doomed;
      for (auto it = handler.begin(); it != handler.end(); ++it)
        if (it->get_id() % 7 == 3)
          doomed.push_back(it);
      for (auto k = doomed.size(); k-- > 0;)
        handler.remove_particle(doomed[k]);
    }
  struct Row
  {
    unsigned int        cell;
    std::vector<double> bits; // location, reference location, id, properties
  };
  auto walk = [&]() {
    std::vector<Row> rows;
    for (const auto &pt : handler)
      {
        Row r{pt.get_surrounding_cell()->active_cell_index(), {}};
        for (unsigned int d = 0; d < dim; ++d)
          r.bits.push_back(pt.get_location()[d]);
        for (unsigned int d = 0; d < dim; ++d)
          r.bits.push_back(pt.get_reference_location()[d]);
        r.bits.push_back(static_cast<double>(pt.get_id()));
        r.bits.insert(r.bits.end(), pt.get_properties().begin(), pt.get_properties().end());
        rows.push_back(r);
      }
    return rows;
  };
  auto expected = walk();
  std::stable_sort(expected.begin(), expected.end(), [](const Row &a, const Row &b) { return a.cell < b.cell; });
  // the storage must be scattered before, or the test shows nothing
  unsigned int descents = 0, last = 0, k = 0;
  for (const auto &pt : handler)
    {
      descents += k++ > 0 && pt.get_local_index() < last;
      last = pt.get_local_index();
    }
  EXPECT_GT(dealii::Utilities::MPI::sum(descents, MPI_COMM_WORLD), 10u) << "the storage was not scattered";
  const auto slots_before = handler.get_property_pool().n_slots();

  s.points.relocator().restore_memory_order();

  const auto got = walk();
  ASSERT_EQ(got.size(), expected.size());
  bool same = true;
  for (std::size_t i = 0; i < got.size(); ++i)
    same = same && got[i].cell == expected[i].cell &&
           std::memcmp(got[i].bits.data(), expected[i].bits.data(), got[i].bits.size() * sizeof(double)) == 0;
  EXPECT_TRUE(same) << "the rebuild must keep every point's cell, place in its cell and data bit for bit";
  bool ascending = true;
  k              = 0;
  for (const auto &pt : handler)
    {
      ascending = ascending && (k++ == 0 || pt.get_local_index() > last);
      last      = pt.get_local_index();
    }
  EXPECT_TRUE(ascending) << "the walk must read the slots in increasing order";
  EXPECT_EQ(handler.get_property_pool().n_slots(), slots_before);
  EXPECT_EQ(handler.n_locally_owned_particles(), got.size());
}
TEST(ExplicitTransfer, MemoryOrderRebuildInPlace2D)
{
  rebuild_in_place<2>(false);
}
TEST(ExplicitTransfer, MemoryOrderRebuildInPlace3D)
{
  rebuild_in_place<3>(false);
}
TEST(ExplicitTransfer, MemoryOrderRebuildInPlaceFreeSlots3D)
{
  rebuild_in_place<3>(true);
}

/// The grid's caches hold only what the points use: on a grid much larger than
/// the body, after set-up and steps in which points change cell, only the cells
/// holding points and their vertex neighbours have a filled cache entry, and
/// only cells that points left have a neighbour list. The fields of an entry
/// filled on first read equal the triangulation's.
TEST(ExplicitTransfer, GridCachesOnlyNearPoints3D)
{
  auto p = scene<3>(Shape::linear);
  for (unsigned int d = 0; d < 3; ++d)
    p.grid_cells[d] = 24;
  p.bodies[0].radius = 0.15;
  explicit_mpm::Solver<3> s(p, MPI_COMM_WORLD);
  s.setup();
  for (int i = 0; i < 20; ++i)
    s.step(s.time_step());
  const auto &grid = s.grid;
  EXPECT_GT(dealii::Utilities::MPI::sum(s.points.relocation_stats.moved_locally, MPI_COMM_WORLD), 0u)
    << "points must change cell";
  // the walks and the kernels read the entries of the cells with points
  // unchecked (CellCaches::filled_entry): all of them are filled, on 2 ranks
  // also those of cells that got points from the other rank
  bool all_filled = true;
  for (const auto &pt : s.points.handler)
    all_filled = all_filled && grid.cells.is_filled(pt.get_surrounding_cell()->active_cell_index());
  for (const auto &ac : s.points.active_cells())
    all_filled = all_filled && grid.cells.is_filled(ac.cell);
  EXPECT_TRUE(all_filled) << "a cell with points has no filled cache entry";
  EXPECT_TRUE(s.check_incremental_state().second);
  // every cell within one cell of a point may be filled, no other
  std::vector<char> near(grid.cells.size(), 0);
  for (const auto &pt : s.points.handler)
    {
      const unsigned int *nb = grid.neighbours_of(pt.get_surrounding_cell()->active_cell_index());
      for (unsigned int k = 1; k <= nb[0]; ++k)
        near[nb[k]] = 1;
    }
  std::size_t n_near = 0;
  for (const char x : near)
    n_near += x;
  EXPECT_LE(grid.cells.n_filled(), 2 * n_near) << "cache entries filled far from the points";
  EXPECT_LT(grid.cells.n_filled(), grid.cells.size() / 4);
  EXPECT_LT(grid.n_neighbour_lists(), grid.cells.size() / 4);
  // a lazily filled entry holds the triangulation's box and owner
  for (unsigned int c = 0; c < grid.cells.size(); c += 97)
    {
      double      lower[3], h[3];
      const bool  owned = grid.owned_cell_box(c, lower, h);
      const auto &cc    = grid.cells[c];
      EXPECT_EQ(owned, cc.locally_owned);
      if (owned)
        for (unsigned int d = 0; d < 3; ++d)
          {
            EXPECT_EQ(cc.lower[d], lower[d]);
            EXPECT_EQ(cc.h[d], h[d]);
            EXPECT_EQ(cc.lower[d], grid.cell_iterator(c)->vertex(0)[d]);
          }
    }
}

TEST(ExplicitTransfer, RelocationKeepsParticles2D)
{
  relocation_and_momentum<2>();
}
TEST(ExplicitTransfer, RelocationKeepsParticles3D)
{
  relocation_and_momentum<3>();
}
// the same with quadratic B-splines: the fused P2G of the update pass and of
// the moved points equals a fresh P2G on the 4^dim patches after every step
TEST(ExplicitTransfer, BSplineRelocationKeepsParticles2D)
{
  relocation_and_momentum<2>(Shape::quadratic_bspline);
}
TEST(ExplicitTransfer, BSplineRelocationKeepsParticles3D)
{
  relocation_and_momentum<3>(Shape::quadratic_bspline);
}
// the APIC step (velocity transfer = apic): same relocation, fused = fresh P2G, and sum m v_p
// conserved without external forces (sum_i m_i v_i^L = sum_p m_p v_p, G2P returns it exactly)
TEST(ExplicitTransfer, ApicBSplineRelocationKeepsParticles2D)
{
  relocation_and_momentum<2>(Shape::quadratic_bspline, true);
}
TEST(ExplicitTransfer, ApicBSplineRelocationKeepsParticles3D)
{
  relocation_and_momentum<3>(Shape::quadratic_bspline, true);
}

// ---------------------------------------------------------------- APIC (issue 12)
// numerics/velocity transfer = apic (formulations/explicit/affine_ops.h). A rigidly rotating
// body: the P2G with the affine term must hand the grid exactly the points'
// linear momentum sum m v and angular momentum sum m (x x v + eps : (C D)^T),
// for any C_p (here the rotation's W plus a random perturbation); and the
// affine transfer must reproduce the rotation's linear field exactly both ways
// (G2P of v_i = W x_i gives v_p = W x_p, C_p = W; P2G of that gives back
// v_i = W x_i at every node with mass), which FLIP/PIC do not (PIC loses the
// rotation's angular momentum). Both kernels; 1 and 2 ranks.
#include <talus/formulations/explicit/affine_ops.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>

/// node positions into a vector of the grid's layout (component d at the DoF of component d)
template <int dim>
void
node_positions(const explicit_mpm::Solver<dim> &s, talus::Vector &X)
{
  s.grid.reinit_vector(X);
  for (unsigned int c = 0; c < s.grid.cells.size(); ++c)
    {
      const auto &cc = s.grid.cells[c];
      for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_cell; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          X.local_element(cc.dofs[v * dim + d]) = cc.lower[d] + ((v >> d) & 1u) * cc.h[d];
    }
}

/// the rotation's skew matrix W (v = W (x - x0)): about z in 2D, about (1, 2, 3)/|.| in 3D
template <int dim>
dealii::Tensor<2, dim>
rotation_W(const double omega)
{
  dealii::Tensor<2, dim> W;
  if constexpr (dim == 2)
    {
      W[0][1] = -omega;
      W[1][0] = omega;
    }
  else
    {
      const double n = std::sqrt(14.0), a = omega / n, b = 2 * omega / n, c = 3 * omega / n;
      W[0][1] = -c, W[1][0] = c;
      W[0][2] = b, W[2][0] = -b;
      W[1][2] = -a, W[2][1] = a;
    }
  return W;
}

template <int dim, class K>
void
apic_transfer(const Shape shape)
{
  using L                      = PropertyLayout<dim>;
  auto p                       = scene<dim>(shape);
  p.numerics.velocity_transfer = explicit_mpm::NumericsOptions::VelocityTransfer::apic;
  // the rotation about the body's centre, so the body stays in the grid
  const auto         W = rotation_W<dim>(2.0);
  dealii::Point<dim> x0;
  for (unsigned int d = 0; d < dim; ++d)
    x0[d] = 0.5;
  dealii::Tensor<1, dim> v0;
  v0[0]                      = 0.1; // plus a translation
  p.bodies[0].velocity_field = [=](const dealii::Point<dim> &x) { return dealii::Tensor<1, dim>(W * (x - x0) + v0); };
  // and a second, small body against the lower wall (wall half cells of the B-spline)
  auto b2      = p.bodies[0];
  b2.radius    = 0.06;
  b2.center[0] = 0.2;
  b2.center[1] = shape == Shape::linear ? 0.05 : -0.2;
  p.bodies.push_back(b2);
  explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
  s.setup();
  ASSERT_GT(s.affine_offset, 0u);
  const unsigned int A = s.affine_offset;

  // (1) P2G conservation with C_p = W + a random perturbation
  std::mt19937                           rng(17 + dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto &pt : s.points.handler)
    {
      double *P = pt.get_properties().data();
      for (unsigned int c = 0; c < dim; ++c)
        for (unsigned int k = 0; k < dim; ++k)
          P[A + c * dim + k] = W[c][k] + 0.5 * u(rng);
    }
  constexpr unsigned int na                   = dim == 2 ? 1 : 3;
  double                 point_sums[dim + na] = {}, mass = 0;
  for (auto &pt : s.points.handler)
    {
      const double *P = pt.get_properties().data();
      const auto    c = pt.get_surrounding_cell()->active_cell_index();
      for (unsigned int d = 0; d < dim; ++d)
        point_sums[d] += P[L::mass] * P[L::velocity + d];
      transfer::affine_angular_momentum<dim, K>(K::cell(s.grid, c), pt.get_reference_location(), pt.get_location(),
                                                P[L::mass], P + L::velocity, P + A, point_sums + dim);
      mass += P[L::mass];
    }
  talus::Vector X, Pn;
  node_positions(s, X);
  s.grid.reinit_vector(Pn);
  s.scatter_point_momentum(Pn);
  double             grid_sums[dim + na] = {};
  const unsigned int n_owned             = Pn.locally_owned_size();
  // owned nodes: the component-0 DoFs; the node's components follow from its cells
  std::vector<std::array<unsigned int, dim>> node_dofs;
  {
    std::vector<char> seen(n_owned + Pn.get_partitioner()->n_ghost_indices(), 0);
    for (unsigned int c = 0; c < s.grid.cells.size(); ++c)
      for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_cell; ++v)
        {
          const unsigned int *dofs = s.grid.cells[c].dofs + v * dim;
          if (dofs[0] < n_owned && !seen[dofs[0]])
            {
              seen[dofs[0]] = 1;
              std::array<unsigned int, dim> a;
              for (unsigned int d = 0; d < dim; ++d)
                a[d] = dofs[d];
              node_dofs.push_back(a);
            }
        }
  }
  for (const auto &a : node_dofs)
    {
      double x[dim], q[dim];
      for (unsigned int d = 0; d < dim; ++d)
        {
          x[d] = X.local_element(a[d]);
          q[d] = Pn.local_element(a[d]);
          grid_sums[d] += q[d];
        }
      if constexpr (dim == 2)
        grid_sums[dim] += x[0] * q[1] - x[1] * q[0];
      else
        {
          grid_sums[dim + 0] += x[1] * q[2] - x[2] * q[1];
          grid_sums[dim + 1] += x[2] * q[0] - x[0] * q[2];
          grid_sums[dim + 2] += x[0] * q[1] - x[1] * q[0];
        }
    }
  dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(point_sums, dim + na), MPI_COMM_WORLD,
                              dealii::ArrayView<double>(point_sums, dim + na));
  dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(grid_sums, dim + na), MPI_COMM_WORLD,
                              dealii::ArrayView<double>(grid_sums, dim + na));
  mass = dealii::Utilities::MPI::sum(mass, MPI_COMM_WORLD);
  // scale: mass x speed (x lever arm 1 m): ~ mass
  for (unsigned int d = 0; d < dim; ++d)
    EXPECT_NEAR(grid_sums[d], point_sums[d], 1e-13 * mass) << "linear momentum, component " << d;
  for (unsigned int d = 0; d < na; ++d)
    {
      EXPECT_NEAR(grid_sums[dim + d], point_sums[dim + d], 1e-13 * mass) << "angular momentum, component " << d;
      // without the affine term the sums would differ by O(m |C| h^2): the check can fail
      EXPECT_GT(std::abs(point_sums[dim + d]), 1e-3 * mass);
    }

  // (2) the rotation's linear nodal field v_i = W (x_i - x0) + v0 both ways
  talus::Vector V;
  s.grid.reinit_vector(V);
  for (unsigned int i = 0; i < n_owned + V.get_partitioner()->n_ghost_indices(); ++i)
    ; // filled per node below (ghosts included, from the cells)
  for (unsigned int c = 0; c < s.grid.cells.size(); ++c)
    for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_cell; ++v)
      {
        const unsigned int *dofs = s.grid.cells[c].dofs + v * dim;
        for (unsigned int a = 0; a < dim; ++a)
          {
            double w = v0[a];
            for (unsigned int k = 0; k < dim; ++k)
              w += W[a][k] * (X.local_element(dofs[k]) - x0[k]);
            V.local_element(dofs[a]) = w;
          }
      }
  V.update_ghost_values();     // B-spline patches reach ghost nodes of ghost cells: take owners' values
  const double h       = 1e-3; // any scale: du = h V
  double       worst_v = 0, worst_C = 0;
  transfer::for_each_active_cell(
    s.points, [](unsigned int) {},
    [&](const unsigned int c, auto &it) {
      const auto        cell = K::cell(s.grid, c);
      typename K::Field du;
      K::gather(cell, V.begin(), h, du, true);
      typename K::Eval e;
      K::evaluate(cell, it->get_reference_location(), e);
      double gu[dim][dim], dx[dim];
      transfer::default_increments<dim, K>(cell, e, du, gu, dx);
      double *P = it->get_properties().data();
      transfer::apic_point_velocity<dim, K>(cell, e, du, h, gu, dx, P + L::velocity, P + A);
      const auto x = it->get_location();
      for (unsigned int a = 0; a < dim; ++a)
        {
          double w = v0[a];
          for (unsigned int k = 0; k < dim; ++k)
            {
              w += W[a][k] * (x[k] - x0[k]);
              worst_C = std::max(worst_C, std::abs(P[A + a * dim + k] - W[a][k]));
            }
          worst_v = std::max(worst_v, std::abs(P[L::velocity + a] - w));
        }
    },
    [](unsigned int) {});
  worst_v = dealii::Utilities::MPI::max(worst_v, MPI_COMM_WORLD);
  worst_C = dealii::Utilities::MPI::max(worst_C, MPI_COMM_WORLD);
  EXPECT_LT(worst_v, 1e-12) << "G2P: v_p = W x_p";
  EXPECT_LT(worst_C, 1e-10) << "G2P: C_p = W";
  s.scatter_point_momentum(Pn);
  talus::Vector M, F;
  s.grid.reinit_vector(M);
  s.grid.reinit_vector(F);
  {
    transfer::ScatterMassForce<dim, K> op{s.grid, dealii::Tensor<1, dim>(), M.begin(), F.begin()};
    transfer::for_each_active_cell(s.points, op);
  }
  M.compress(dealii::VectorOperation::add);
  double       worst_node = 0;
  unsigned int n_mass     = 0;
  for (unsigned int i = 0; i < n_owned; ++i)
    if (M.local_element(i) > 1e-12 * mass)
      {
        ++n_mass;
        worst_node = std::max(worst_node, std::abs(Pn.local_element(i) / M.local_element(i) - V.local_element(i)));
      }
  worst_node = dealii::Utilities::MPI::max(worst_node, MPI_COMM_WORLD);
  EXPECT_GT(dealii::Utilities::MPI::sum(n_mass, MPI_COMM_WORLD), 0u);
  EXPECT_LT(worst_node, 1e-12) << "P2G: v_i = W x_i at every node with mass";
  if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    {
      double dl = 0, da = 0;
      for (unsigned int d = 0; d < dim; ++d)
        dl = std::max(dl, std::abs(grid_sums[d] - point_sums[d]) / mass);
      for (unsigned int d = 0; d < na; ++d)
        da = std::max(da, std::abs(grid_sums[dim + d] - point_sums[dim + d]) / mass);
      std::cout << "  APIC " << dim << "D: |P_grid - P_points| / M " << dl << ", |L_grid - L_points| / M " << da
                << ", G2P |v_p - W x_p| " << worst_v << ", |C_p - W| " << worst_C << ", P2G |v_i - W x_i| "
                << worst_node << std::endl;
    }
}

TEST(ExplicitTransfer, ApicConservesMomentumQ1_2D)
{
  apic_transfer<2, shape::Q1Box<2>>(Shape::linear);
}
TEST(ExplicitTransfer, ApicConservesMomentumQ1_3D)
{
  apic_transfer<3, shape::Q1Box<3>>(Shape::linear);
}
TEST(ExplicitTransfer, ApicConservesMomentumBSpline2D)
{
  apic_transfer<2, shape::BSpline2Box<2>>(Shape::quadratic_bspline);
}
TEST(ExplicitTransfer, ApicConservesMomentumBSpline3D)
{
  apic_transfer<3, shape::BSpline2Box<3>>(Shape::quadratic_bspline);
}
