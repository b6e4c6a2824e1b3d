// talus — point ops on a point's own stencil (K::point_stencil: the nodes one
// point touches, with values and real-space gradients), for passes whose
// per-point arithmetic is a short formula over those nodes: the semi-implicit
// family's P2N and N2P of two point sets (mass, momentum, porosity, pressure,
// divergence, pressure gradient). The walk is cell_walk.h's; the formula comes
// in as a callable visit(c, it, stencil).
//
// Nodal data live in grid vectors (BackgroundGrid::reinit_vector): a vector
// field at the node's DoFs of every component, a scalar field at the node's
// component-0 DoF (the other components unused). Indices are the grid's local
// (owned + ghost) indices, as the kernels' Cell::dofs hold them.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/matrix_ops.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace talus::transfer
{
  /// The nodes one point touches (N or grad N non-zero), with grid local DoF
  /// indices per component.
  template <int dim, class K>
  struct PointStencil
  {
    static constexpr unsigned int max_nodes = K::n_point_nodes;
    unsigned int                  n         = 0;
    unsigned int                  dof[max_nodes][dim]; ///< dof[w][0]: the node's scalar slot
    double                        N[max_nodes];
    double                        G[max_nodes][dim];

    /// f(w) for the nodes w = 0 ... n - 1 in order. A whole window (n ==
    /// max_nodes: every point but those on a B-spline half-cell line) takes a
    /// loop of fixed length, which the compiler unrolls and schedules across
    /// the nodes; the same operations in the same order either way.
    template <class F>
    inline void
    for_nodes(F &&f) const
    {
      if (n == max_nodes)
        for (unsigned int w = 0; w < max_nodes; ++w)
          f(w);
      else
        for (unsigned int w = 0; w < n; ++w)
          f(w);
    }

    /// A scalar nodal field at the point.
    inline double
    value(const double *f) const
    {
      double s = 0;
      for_nodes([&](const unsigned int w) { s += N[w] * f[dof[w][0]]; });
      return s;
    }
    /// A vector nodal field at the point.
    inline void
    vector_value(const double *f, double (&out)[dim]) const
    {
      for (unsigned int d = 0; d < dim; ++d)
        out[d] = 0;
      for_nodes([&](const unsigned int w) {
        for (unsigned int d = 0; d < dim; ++d)
          out[d] += N[w] * f[dof[w][d]];
      });
    }
    /// Gradient of a scalar nodal field at the point.
    inline void
    gradient(const double *f, double (&out)[dim]) const
    {
      for (unsigned int d = 0; d < dim; ++d)
        out[d] = 0;
      for_nodes([&](const unsigned int w) {
        const double fw = f[dof[w][0]];
        for (unsigned int d = 0; d < dim; ++d)
          out[d] += G[w][d] * fw;
      });
    }
    /// Gradient of a vector nodal field at the point, out[i][j] = d f_i / d x_j.
    inline void
    vector_gradient(const double *f, double (&out)[dim][dim]) const
    {
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          out[i][j] = 0;
      for_nodes([&](const unsigned int w) {
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int j = 0; j < dim; ++j)
            out[i][j] += f[dof[w][i]] * G[w][j];
      });
    }
    /// Divergence of a vector nodal field at the point.
    inline double
    divergence(const double *f) const
    {
      double s = 0;
      for_nodes([&](const unsigned int w) {
        for (unsigned int d = 0; d < dim; ++d)
          s += G[w][d] * f[dof[w][d]];
      });
      return s;
    }
    /// f[node] += a N (scalar field)
    inline void
    scatter(double *f, const double a) const
    {
      for_nodes([&](const unsigned int w) { f[dof[w][0]] += a * N[w]; });
    }
    /// f[node][d] += a N v[d] (vector field)
    inline void
    scatter_vector(double *f, const double a, const double *v) const
    {
      for_nodes([&](const unsigned int w) {
        for (unsigned int d = 0; d < dim; ++d)
          f[dof[w][d]] += a * N[w] * v[d];
      });
    }
    /// f[node][i] += sum_j t[i][j] dN/dx_j (a stress-like tensor t)
    inline void
    scatter_divergence(double *f, const double (&t)[dim][dim]) const
    {
      for_nodes([&](const unsigned int w) {
        for (unsigned int i = 0; i < dim; ++i)
          {
            double q = 0;
            for (unsigned int j = 0; j < dim; ++j)
              q += t[i][j] * G[w][j];
            f[dof[w][i]] += q;
          }
      });
    }
  };

  /// Fill the stencil of the point at reference location xi of `cell`.
  template <int dim, class K>
  inline void
  point_stencil(const typename K::Cell &cell, const dealii::Point<dim> &xi, PointStencil<dim, K> &s)
  {
    unsigned int slot[K::n_point_nodes];
    double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
    K::point_stencil(cell, xi, slot, N, G);
    s.n = 0;
    for (unsigned int w = 0; w < K::n_point_nodes; ++w)
      if (touches<dim>(N[w], G[w]))
        {
          const unsigned int k = s.n++;
          s.N[k]               = N[w];
          for (unsigned int d = 0; d < dim; ++d)
            {
              s.G[k][d]   = G[w][d];
              s.dof[k][d] = cell.dofs[slot[w] * dim + d];
            }
        }
  }

  /// The stencil at x + offset, a position near a point of cell c (e.g. the
  /// point's share of a loaded face: a traction acts on the surface, not at
  /// the point), in c or the vertex neighbour of c that contains it; a
  /// position beyond the grid (no such cell) is clamped into c.
  template <int dim, class K>
  inline void
  offset_stencil(const BackgroundGrid<dim> &grid, const unsigned int c, const dealii::Point<dim> &x,
                 const double *offset, PointStencil<dim, K> &s)
  {
    dealii::Point<dim> y = x, xi;
    for (unsigned int d = 0; d < dim; ++d)
      y[d] += offset[d];
    unsigned int n = grid.find_cell_near(c, y, xi);
    if (n == dealii::numbers::invalid_unsigned_int)
      {
        n  = c;
        xi = grid.reference_point(c, y);
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = std::clamp(xi[d], 0.0, 1.0);
      }
    point_stencil<dim, K>(K::cell(grid, n), xi, s);
  }

  /// The op: visit(c, it, stencil) for every point of the walk.
  template <int dim, class K, class Visit>
  struct VisitStencils
  {
    const BackgroundGrid<dim> &grid;
    Visit                     &visit;
    static constexpr bool      prefetch_location = false;
    typename K::Cell           cell;
    PointStencil<dim, K>       stencil;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      point_stencil<dim, K>(cell, it->get_reference_location(), stencil);
      visit(c, it, stencil);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
    }
  };

  /// One walk over `set` calling visit(c, it, stencil) per point.
  template <int dim, class K, class Visit>
  inline void
  for_each_point_stencil(const BackgroundGrid<dim> &grid, MaterialPointSet<dim> &set, Visit &&visit)
  {
    VisitStencils<dim, K, std::remove_reference_t<Visit>> op{grid, visit, {}, {}};
    for_each_active_cell(set, op);
  }

  /// The stencils of a set's points as the last walk with this cache met
  /// them, in walk order, each with the cell and reference location it was
  /// evaluated at. A walk reuses the entry at a point's place in the walk when
  /// the point has that cell and bitwise that reference location, and
  /// evaluates (and stores) the stencil otherwise: the points themselves say
  /// at every use whether an entry holds, so moves, relocations, sorts,
  /// restarts and points that come or go need no notice, and a reused stencil
  /// is bitwise the one the evaluation would give. Only a change of the grid
  /// (its DoF numbering: a repartition) is not seen by the points: clear() then.
  /// The semi-implicit step walks each set 5-7 times between two moves
  /// (docs/semi-implicit.md).
  template <int dim, class K>
  class StencilCache
  {
  public:
    void
    clear()
    {
      entries.clear();
    }
    /// one entry per point of the coming walk (entries beyond a walk's points
    /// hold for nobody; the checks sort out the rest)
    void
    fit(const std::size_t n_points)
    {
      entries.resize(n_points);
    }
    /// stencils evaluated (not reused) since the cache was made
    unsigned long long
    evaluations() const
    {
      return n_evaluated;
    }

  private:
    template <int, class, class>
    friend struct VisitCachedStencils;
    struct Entry
    {
      unsigned int         cell = dealii::numbers::invalid_unsigned_int;
      dealii::Point<dim>   xi;
      PointStencil<dim, K> stencil;
    };
    std::vector<Entry> entries;
    unsigned long long n_evaluated = 0;
  };

  /// VisitStencils through a StencilCache.
  template <int dim, class K, class Visit>
  struct VisitCachedStencils
  {
    const BackgroundGrid<dim> &grid;
    Visit                     &visit;
    StencilCache<dim, K>      &cache;
    static constexpr bool      prefetch_location = false;
    unsigned int               index             = 0; ///< the point's place in the walk
    typename K::Cell           cell{};                ///< of cell `cell_of`, made at its first miss
    unsigned int               cell_of = dealii::numbers::invalid_unsigned_int;

    inline void
    begin_cell(const unsigned int)
    {
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      auto                     &e  = cache.entries[index++];
      const dealii::Point<dim> &xi = it->get_reference_location();
      // the same bits, not the same value: -0.0 == 0.0, but the stencil's
      // derivatives keep the sign of a zero xi, and a restarted run evaluates
      if (e.cell != c || std::memcmp(&e.xi, &xi, sizeof(xi)) != 0)
        {
          if (cell_of != c) // once per cell (after a move every point misses)
            {
              cell    = K::cell(grid, c);
              cell_of = c;
            }
          point_stencil<dim, K>(cell, xi, e.stencil);
          e.cell = c;
          e.xi   = xi;
          ++cache.n_evaluated;
        }
      visit(c, it, static_cast<const PointStencil<dim, K> &>(e.stencil));
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
    }
  };

  /// for_each_point_stencil with the stencils kept in `cache` for the next walk.
  template <int dim, class K, class Visit>
  inline void
  for_each_point_stencil(const BackgroundGrid<dim> &grid, MaterialPointSet<dim> &set, StencilCache<dim, K> &cache,
                         Visit &&visit)
  {
    cache.fit(set.handler.n_locally_owned_particles());
    VisitCachedStencils<dim, K, std::remove_reference_t<Visit>> op{grid, visit, cache};
    for_each_active_cell(set, op);
  }

  /// f[node][d] += V_p N (grad phi)(x_p) over every point of `set`: the weak
  /// gradient force of a nodal scalar phi (the pressure terms G p of the
  /// semi-implicit predictor and correction), V_p in the point's `volume_slot`.
  /// `also(it, s)` runs first at every point, for per-point work that wants
  /// the same stencil (it may be a no-op).
  template <int dim, class K, class Also>
  inline void
  scatter_weak_gradient(const BackgroundGrid<dim> &grid, MaterialPointSet<dim> &set, StencilCache<dim, K> &cache,
                        const double *phi, const unsigned int volume_slot, double *f, Also &&also)
  {
    for_each_point_stencil<dim, K>(grid, set, cache,
                                   [&](unsigned int, PointIterator<dim> &it, const PointStencil<dim, K> &s) {
                                     also(it, s);
                                     double g[dim];
                                     s.gradient(phi, g);
                                     s.scatter_vector(f, it->get_properties()[volume_slot], g);
                                   });
  }
  template <int dim, class K>
  inline void
  scatter_weak_gradient(const BackgroundGrid<dim> &grid, MaterialPointSet<dim> &set, StencilCache<dim, K> &cache,
                        const double *phi, const unsigned int volume_slot, double *f)
  {
    scatter_weak_gradient<dim, K>(grid, set, cache, phi, volume_slot, f,
                                  [](PointIterator<dim> &, const PointStencil<dim, K> &) {});
  }

  /// Integrand of a scalar Poisson matrix and its source (transfer::assemble,
  /// AssembleSystem with nc = 1): A_ij += P[coefficient] V_p grad N_i . grad N_j,
  /// b_i += P[source] V_p N_i. One pass for both, so inhomogeneous Dirichlet
  /// values reach b (deal.II moves -A_ij g_j from the local matrix).
  struct PoissonWithSource
  {
    unsigned int          coefficient = 0, source = 0; ///< property offsets
    static constexpr bool matrix = true, vector = true;
    template <int dim, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == 1, "PoissonWithSource: a scalar space");
      const double V = P[PropertyLayout<dim>::volume];
      const double a = P[coefficient] * V, f = P[source] * V;
      for (unsigned int i = 0; i < p.n; ++i)
        {
          for (unsigned int j = 0; j < p.n; ++j)
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
} // namespace talus::transfer
