// transfer/stencil_ops.h (the semi-implicit family's point passes), for the Q1
// and the quadratic B-spline kernel in 2D and 3D, on 1 or 2 ranks:
//  * P2N through for_each_point_stencil conserves mass and momentum (sum over
//    the nodes = sum over the points, after compress);
//  * N2P of a linear nodal field: value, gradient and divergence exact at every
//    point (linear reproduction, walls included);
//  * PoissonWithSource over an ActiveSet: the matrix is symmetric and
//    annihilates the constant on the active nodes; the source vector sums to
//    sum_p V_p s_p (partition of unity);
//  * AssembleSystem's patch path (transfer/matrix_ops.h, window_path) gives the
//    generic path's system bit for bit, points on half-cell lines included.
#include <talus/grid/nodal_space.h>
#include <talus/particles/material_point_set.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/active_set.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

using namespace talus;

namespace
{
  /// A box grid of 4 x 5 (x 6) cells and one set of points (3 per direction)
  /// over a box that touches the lower walls, not the upper ones, with two
  /// extra properties.
  template <int dim>
  struct Scene
  {
    explicit Scene(const bool bspline)
        : grid(MPI_COMM_WORLD)
    {
      std::vector<unsigned int> cells;
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = 0;
          hi[d] = 1.0 + 0.25 * d;
          cells.push_back(4 + d);
        }
      grid.make_box(lo, hi, cells);
      grid.setup();
      if (bspline)
        grid.setup_bspline_patches();
      set         = std::make_unique<MaterialPointSet<dim>>(grid, "points");
      coefficient = set->layout.add_extra("coefficient", 1);
      source      = set->layout.add_extra("source", 1);
      set->initialize();
      BodyDescription<dim> body;
      for (unsigned int d = 0; d < dim; ++d)
        body.lower[d] = 0, body.upper[d] = 0.7 * hi[d];
      body.particles_per_direction = 3;
      seed_bodies(grid, {body}, {1500.0}, set->layout, set->handler);
      set->collect_active_cells();
    }
    BackgroundGrid<dim>                    grid;
    dealii::Point<dim>                     lo, hi;
    std::unique_ptr<MaterialPointSet<dim>> set;
    unsigned int                           coefficient = 0, source = 0;
  };

  template <int dim, class K>
  void
  run_checks(const bool bspline)
  {
    using L = PropertyLayout<dim>;
    Scene<dim>             scene(bspline);
    BackgroundGrid<dim>   &grid        = scene.grid;
    MaterialPointSet<dim> &set         = *scene.set;
    const unsigned int     coefficient = scene.coefficient, source = scene.source;

    // a linear velocity field v = a + B x on the points, varying coefficients
    const double a[3] = {0.3, -0.2, 0.1}, B[3][3] = {{0.5, -1.0, 0.2}, {0.7, 0.25, -0.4}, {0.1, 0.3, -0.6}};
    double       m_sum = 0, p_sum[dim] = {}, vs_sum = 0;
    for (auto &pt : set.handler)
      {
        auto       P = pt.get_properties();
        const auto x = pt.get_location();
        for (unsigned int i = 0; i < dim; ++i)
          {
            P[L::velocity + i] = a[i];
            for (unsigned int j = 0; j < dim; ++j)
              P[L::velocity + i] += B[i][j] * x[j];
          }
        P[coefficient] = 1.0 + x[0];
        P[source]      = std::sin(3 * x[dim - 1]);
        m_sum += P[L::mass];
        for (unsigned int i = 0; i < dim; ++i)
          p_sum[i] += P[L::mass] * P[L::velocity + i];
        vs_sum += P[L::volume] * P[source];
      }
    const MPI_Comm comm = MPI_COMM_WORLD;
    m_sum               = dealii::Utilities::MPI::sum(m_sum, comm);
    vs_sum              = dealii::Utilities::MPI::sum(vs_sum, comm);
    for (unsigned int i = 0; i < dim; ++i)
      p_sum[i] = dealii::Utilities::MPI::sum(p_sum[i], comm);

    // P2N of mass (scalar at component 0) and momentum
    Vector M, Pm;
    grid.reinit_vector(M);
    grid.reinit_vector(Pm);
    transfer::for_each_point_stencil<dim, K>(grid, set, [&](unsigned int, auto &it, const auto &s) {
      const double *P = it->get_properties().data();
      s.scatter(M.begin(), P[L::mass]);
      s.scatter_vector(Pm.begin(), P[L::mass], P + L::velocity);
    });
    M.compress(dealii::VectorOperation::add);
    Pm.compress(dealii::VectorOperation::add);
    // component of every owned grid DoF
    std::vector<unsigned int> comp(M.locally_owned_size() + grid.partitioner->n_ghost_indices(), 0);
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cell_iterator(c) != grid.tria.end())
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            comp[grid.cells[c].dofs[v * dim + d]] = d;
    double Mn = 0, Pn[dim] = {};
    for (unsigned int i = 0; i < M.locally_owned_size(); ++i)
      {
        Mn += M.local_element(i);
        Pn[comp[i]] += Pm.local_element(i);
      }
    EXPECT_NEAR(dealii::Utilities::MPI::sum(Mn, comm), m_sum, 1e-12 * m_sum);
    for (unsigned int i = 0; i < dim; ++i)
      EXPECT_NEAR(dealii::Utilities::MPI::sum(Pn[i], comm), p_sum[i], 1e-12 * m_sum);

    // a linear nodal field at the points: value, gradient (scalar and vector), divergence
    Vector V, S;
    grid.reinit_vector(V);
    grid.reinit_vector(S);
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cell_iterator(c) != grid.tria.end())
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            double x[dim];
            for (unsigned int e = 0; e < dim; ++e)
              x[e] = grid.cells[c].lower[e] + ((v >> e) & 1u) * grid.cells[c].h[e];
            for (unsigned int i = 0; i < dim; ++i)
              {
                double vi = a[i];
                for (unsigned int j = 0; j < dim; ++j)
                  vi += B[i][j] * x[j];
                V.local_element(grid.cells[c].dofs[v * dim + i]) = vi;
              }
            S.local_element(grid.cells[c].dofs[v * dim]) = 2.0 - x[0] + 0.5 * x[dim - 1];
          }
    double worst = 0;
    transfer::for_each_point_stencil<dim, K>(grid, set, [&](unsigned int, auto &it, const auto &s) {
      const double *P = it->get_properties().data();
      double        v[dim], gs[dim];
      s.vector_value(V.begin(), v);
      for (unsigned int i = 0; i < dim; ++i)
        worst = std::max(worst, std::abs(v[i] - P[L::velocity + i]));
      double tr = 0;
      for (unsigned int i = 0; i < dim; ++i)
        tr += B[i][i];
      worst = std::max(worst, std::abs(s.divergence(V.begin()) - tr));
      double gv[dim][dim];
      s.vector_gradient(V.begin(), gv);
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          worst = std::max(worst, std::abs(gv[i][j] - B[i][j]));
      const auto x = it->get_location();
      worst        = std::max(worst, std::abs(s.value(S.begin()) - (2.0 - x[0] + 0.5 * x[dim - 1])));
      s.gradient(S.begin(), gs);
      worst = std::max(worst, std::abs(gs[0] + 1.0) + std::abs(gs[dim - 1] - 0.5));
    });
    EXPECT_LT(dealii::Utilities::MPI::max(worst, comm), 1e-12);

    // the Poisson matrix and source over the active region
    NodalSpace<dim> space(grid, 1);
    space.setup();
    ActiveSet<dim> active(space);
    active.template reinit<K>({&set});
    dealii::TrilinosWrappers::SparseMatrix A;
    Vector                                 b, one, A_one;
    active.reinit_matrix(A);
    space.reinit_vector(b);
    space.reinit_vector(one);
    space.reinit_vector(A_one);
    transfer::PoissonWithSource                                      terms{coefficient, source};
    transfer::AssembleSystem<dim, K, 1, transfer::PoissonWithSource> op(active, active.constraints(), terms, &A, &b);
    transfer::for_each_active_cell(set, op);
    transfer::finish_assembly(active, op.diag_sum, op.diag_count, &A, &b);
    EXPECT_NEAR(b.mean_value() * b.size(), vs_sum, 1e-12 * std::max(1.0, std::abs(vs_sum)));
    for (const auto i : active.active_owned_dofs())
      one(i) = 1.0;
    A.vmult(A_one, one);
    EXPECT_LT(A_one.linfty_norm(), 1e-12 * A.linfty_norm());
    // symmetric: (A x, y) = (x, A y) for two fields on the active dofs
    Vector x, y, Ax, Ay;
    for (Vector *w : {&x, &y, &Ax, &Ay})
      space.reinit_vector(*w);
    for (const auto i : active.active_owned_dofs())
      {
        x(i) = std::sin(0.37 * i);
        y(i) = std::cos(1.3 * i);
      }
    A.vmult(Ax, x);
    A.vmult(Ay, y);
    EXPECT_NEAR(Ax * y, x * Ay, 1e-12 * A.linfty_norm() * x.l2_norm() * y.l2_norm());
  }

  /// StencilCache: a cached walk hands every point the stencil a fresh
  /// evaluation gives, bit for bit, after each change the points go through
  /// between walks (a move inside the cell, a reference coordinate 0.0 turned
  /// into -0.0, a move into another cell placed by deal.II's sort, a removed
  /// point), and evaluates nothing when nothing changed.
  template <int dim, class K>
  void
  stencil_cache_follows_the_points(const bool bspline)
  {
    using S = transfer::PointStencil<dim, K>;
    Scene<dim>                     scene(bspline);
    MaterialPointSet<dim>         &set  = *scene.set;
    const MPI_Comm                 comm = MPI_COMM_WORLD;
    transfer::StencilCache<dim, K> cache;
    const auto                     same_bits = [](const S &a, const S &b) {
      bool same = a.n == b.n;
      for (unsigned int w = 0; same && w < a.n; ++w)
        same = std::memcmp(a.dof[w], b.dof[w], sizeof(a.dof[w])) == 0 &&
               std::memcmp(&a.N[w], &b.N[w], sizeof(double)) == 0 && std::memcmp(a.G[w], b.G[w], sizeof(a.G[w])) == 0;
      return same;
    };
    // the number of stencils the cached walk evaluated; every one checked
    const auto walk = [&](const std::string &after) {
      std::vector<S> fresh;
      transfer::for_each_point_stencil<dim, K>(scene.grid, set,
                                               [&](unsigned int, auto &, const S &s) { fresh.push_back(s); });
      const unsigned long long before = cache.evaluations();
      unsigned int             k = 0, differ = 0;
      transfer::for_each_point_stencil<dim, K>(
        scene.grid, set, cache, [&](unsigned int, auto &, const S &s) { differ += !same_bits(s, fresh[k++]); });
      EXPECT_EQ(dealii::Utilities::MPI::sum(differ, comm), 0u) << after;
      EXPECT_EQ(k, fresh.size());
      return dealii::Utilities::MPI::sum(cache.evaluations() - before, comm);
    };
    const unsigned long long n = set.handler.n_global_particles();
    EXPECT_EQ(walk("the first walk"), n);
    EXPECT_EQ(walk("an unchanged set"), 0u) << "nothing changed: every stencil reused";

    // one point of an interior cell (direction 0; on the first rank that has
    // one) to 0.3 of its cell, then to 0.0 and -0.0
    auto moved = set.handler.begin();
    while (moved != set.handler.end() && !(moved->get_location()[0] > 0.3 && moved->get_location()[0] < 0.45))
      ++moved;
    const unsigned int rank  = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int first = dealii::Utilities::MPI::min(moved != set.handler.end() ? rank : ~0u, comm);
    const bool         moves = rank == first;
    EXPECT_EQ(dealii::Utilities::MPI::sum(unsigned(moves), comm), 1u);
    const auto place = [&](const double xi0) {
      if (!moves)
        return;
      dealii::Point<dim> ref = moved->get_reference_location();
      ref[0]                 = xi0;
      moved->set_reference_location(ref);
    };
    place(0.3);
    EXPECT_EQ(walk("a move inside the cell"), 1u);
    place(0.0);
    EXPECT_EQ(walk("xi = 0"), 1u);
    place(-0.0);
    EXPECT_EQ(walk("xi = -0 (the same value, other bits)"), 1u);

    // a point into the next cell (direction 0), placed by deal.II's sort
    if (moves)
      {
        dealii::Point<dim> x = moved->get_location();
        x[0] += 0.25;
        moved->set_location(x);
      }
    set.handler.sort_particles_into_subdomains_and_cells();
    set.collect_active_cells();
    walk("a move into another cell and a sort");
    EXPECT_EQ(walk("an unchanged set after the sort"), 0u);

    // a removed point: the walk's places shift
    if (rank == 0 && set.handler.n_locally_owned_particles() > 1)
      set.handler.remove_particle(set.handler.begin());
    set.collect_active_cells();
    walk("a removed point");
    EXPECT_EQ(walk("an unchanged set after the removal"), 0u);
  }

  /// A symmetric scalar integrand (a V grad N_i . grad N_j, f V N_i), each
  /// product formed once and added at (i, j) and (j, i): the generic path.
  struct SymmetricPoisson
  {
    unsigned int          coefficient = 0, source = 0;
    static constexpr bool matrix = true, vector = true;
    template <int dim, unsigned int nc, class PN>
    void
    add(const double *P, const PN &p, transfer::LocalSystem &ls) const
    {
      const double V = P[PropertyLayout<dim>::volume], a = P[coefficient] * V, f = P[source] * V;
      for (unsigned int i = 0; i < p.n; ++i)
        {
          for (unsigned int j = i; j < p.n; ++j)
            {
              double gg = 0;
              for (unsigned int d = 0; d < dim; ++d)
                gg += p.G[i][d] * p.G[j][d];
              ls.a(p.local[i], p.local[j]) += a * gg;
              if (j != i)
                ls.a(p.local[j], p.local[i]) += a * gg;
            }
          ls.b[p.local[i]] += f * p.N[i];
        }
    }
  };
  /// The same terms, the matrix as its upper triangle: AssembleSystem's patch path.
  struct SymmetricPoissonUpper : SymmetricPoisson
  {
    static constexpr bool upper_triangle = true;
    template <int dim, unsigned int nc, class PN>
    void
    add_upper(const double *P, const PN &p, transfer::LocalSystem &ls) const
    {
      const double V = P[PropertyLayout<dim>::volume], a = P[coefficient] * V, f = P[source] * V;
      for (unsigned int i = 0; i < p.n; ++i)
        {
          for (unsigned int j = i; j < p.n; ++j)
            {
              double gg = 0;
              for (unsigned int d = 0; d < dim; ++d)
                gg += p.G[i][d] * p.G[j][d];
              ls.a(p.local[i], p.local[j]) += a * gg;
            }
          ls.b[p.local[i]] += f * p.N[i];
        }
    }
  };

  /// AssembleSystem's patch path (window_path: each point's whole B-spline
  /// window summed on the cell's patch, untouched nodes included) gives the
  /// generic path's matrix, vector and diagonal scale bit for bit, with points
  /// on half-cell lines (xi = 0.5 exactly: window nodes with N = 0 and grad N
  /// = 0, which the generic path leaves out) and on the lower walls.
  template <int dim>
  void
  patch_assembly_is_bitwise()
  {
    using K = shape::BSpline2Box<dim>;
    static_assert(transfer::AssembleSystem<dim, K, 1, SymmetricPoissonUpper>::window_path);
    static_assert(!transfer::AssembleSystem<dim, K, 1, SymmetricPoisson>::window_path);
    Scene<dim>             scene(true);
    MaterialPointSet<dim> &set = *scene.set;
    unsigned int           k   = 0;
    for (auto &pt : set.handler)
      {
        auto       P           = pt.get_properties();
        const auto x           = pt.get_location();
        P[scene.coefficient]   = 1.0 + x[0] * x[dim - 1];
        P[scene.source]        = std::cos(2 * x[0]) - x[dim - 1];
        dealii::Point<dim> ref = pt.get_reference_location();
        if (k % 3 == 0)
          ref[0] = 0.5;
        if (k % 5 == 1)
          ref[dim - 1] = 0.5;
        pt.set_reference_location(ref);
        ++k;
      }
    NodalSpace<dim> space(scene.grid, 1);
    space.setup();
    ActiveSet<dim> active(space);
    active.template reinit<K>({&set});
    dealii::TrilinosWrappers::SparseMatrix A[2];
    Vector                                 b[2];
    double                                 diag[2][2];
    const auto                             run = [&](auto terms, const unsigned int r) {
      active.reinit_matrix(A[r]);
      space.reinit_vector(b[r]);
      transfer::AssembleSystem<dim, K, 1, decltype(terms)> op(active, active.constraints(), terms, &A[r], &b[r]);
      transfer::for_each_active_cell(set, op);
      transfer::finish_assembly(active, op.diag_sum, op.diag_count, &A[r], &b[r]);
      diag[r][0] = op.diag_sum;
      diag[r][1] = op.diag_count;
    };
    SymmetricPoissonUpper upper;
    upper.coefficient = scene.coefficient;
    upper.source      = scene.source;
    run(static_cast<const SymmetricPoisson &>(upper), 0);
    run(upper, 1);
    const auto   same   = [](const double x, const double y) { return std::memcmp(&x, &y, sizeof(double)) == 0; };
    unsigned int differ = 0, entries = 0;
    for (const auto r : A[0].locally_owned_range_indices())
      for (auto e = A[0].begin(r); e != A[0].end(r); ++e, ++entries)
        differ += !same(e->value(), A[1].el(r, e->column()));
    for (const auto r : b[0].locally_owned_elements())
      differ += !same(b[0](r), b[1](r));
    differ += !same(diag[0][0], diag[1][0]) + !same(diag[0][1], diag[1][1]);
    const MPI_Comm comm = MPI_COMM_WORLD;
    EXPECT_EQ(dealii::Utilities::MPI::sum(differ, comm), 0u);
    EXPECT_GT(dealii::Utilities::MPI::sum(entries, comm), 0u);
    EXPECT_EQ(A[0].n_nonzero_elements(), A[1].n_nonzero_elements());
    EXPECT_GT(A[0].frobenius_norm(), 0.0);
  }
} // namespace

TEST(AssembleSystem, PatchPathIsBitwiseIn2D)
{
  patch_assembly_is_bitwise<2>();
}
TEST(AssembleSystem, PatchPathIsBitwiseIn3D)
{
  patch_assembly_is_bitwise<3>();
}

TEST(StencilCache, FollowsThePointsQ1In2D)
{
  stencil_cache_follows_the_points<2, shape::Q1Box<2>>(false);
}
TEST(StencilCache, FollowsThePointsQ1In3D)
{
  stencil_cache_follows_the_points<3, shape::Q1Box<3>>(false);
}
TEST(StencilCache, FollowsThePointsBSplineIn2D)
{
  stencil_cache_follows_the_points<2, shape::BSpline2Box<2>>(true);
}
TEST(StencilCache, FollowsThePointsBSplineIn3D)
{
  stencil_cache_follows_the_points<3, shape::BSpline2Box<3>>(true);
}

TEST(StencilOps, Q1In2D)
{
  run_checks<2, shape::Q1Box<2>>(false);
}
TEST(StencilOps, Q1In3D)
{
  run_checks<3, shape::Q1Box<3>>(false);
}
TEST(StencilOps, BSplineIn2D)
{
  run_checks<2, shape::BSpline2Box<2>>(true);
}
TEST(StencilOps, BSplineIn3D)
{
  run_checks<3, shape::BSpline2Box<3>>(true);
}
