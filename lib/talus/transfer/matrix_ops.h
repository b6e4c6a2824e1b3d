// talus — point ops for matrices over a NodalSpace (the implicit families), on
// the walk of cell_walk.h. The kernel K tells which nodes a point touches
// (K::point_stencil: stencil slots, values, real-space gradients); a node is
// named by the grid DoF of its component 0 (K::Cell::dofs[slot * dim]) and
// NodalSpace::node_dof maps it to the space's DoFs.
//
//   CollectCouplings   the nodes every point touches and which of them share a
//                      point (ActiveSet::reinit builds its sparsity from it)
//   AssembleSystem     per cell a local matrix and vector summed over the cell's
//                      points by an Integrand, distributed with constraints at
//                      end_cell (the Integrands below: consistent mass, linear
//                      elastic stiffness, body force, and sums of them)
//   InterpolateField   G2P of a nodal field's value and gradient per point
//
// `assemble(...)` runs AssembleSystem over several point sets and finishes the
// matrix (inactive rows get a diagonal of the matrix's scale).
#pragma once

#include <talus/particles/material_points.h>
#include <talus/shape/window3.h>
#include <talus/transfer/active_set.h>
#include <talus/transfer/cell_walk.h>

#include <deal.II/base/numbers.h>
#include <deal.II/base/tensor.h>

#include <bitset>
#include <tuple>
#include <type_traits>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

namespace talus::transfer
{
  /// A point's share of a node: shape value or gradient non-zero (a Q1 point on
  /// a face still has a gradient at the far nodes; a B-spline window node can
  /// carry exactly zero when the point sits on a half-cell line).
  template <int dim>
  inline bool
  touches(const double N, const double (&G)[dim])
  {
    bool t = N != 0.0;
    for (unsigned int d = 0; d < dim; ++d)
      t = t || G[d] != 0.0;
    return t;
  }

  /// The patch slots a quadratic B-spline point touches (as `touches` on each
  /// node of its point_stencil), found from its 1D factors alone (no products):
  /// a window node's value and gradient components are products of one 1D
  /// value or derivative per direction, so the node is touched iff every
  /// direction's value is non-zero, or all but one are and that one's
  /// derivative is. Exact unless a product of non-zero factors underflows
  /// (inside a cell the 1D factors are 0 or above 2^-110, except a wall hat
  /// of a point within ~1e-290 of its node); then it names more nodes than the
  /// products do, never fewer. Slots in window order, as point_stencil's
  /// filter gives them; returns their number.
  template <int dim>
  inline unsigned int
  touched_window_slots(const typename shape::Window3<dim>::Eval &e, unsigned int (&slot)[shape::Window3<dim>::n_nodes])
  {
    using W                  = shape::Window3<dim>;
    const unsigned int first = W::first_slot(e);
    unsigned int       n     = 0;
    for (unsigned int w = 0; w < W::n_nodes; ++w)
      {
        unsigned int zero_values = 0;
        bool         dead        = false; // a direction with value and derivative 0
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int a = W::digit(w, d);
            if (e.N[d][a] == 0.0)
              {
                ++zero_values;
                dead = dead || e.dN[d][a] == 0.0;
              }
          }
        if (!dead && zero_values <= 1)
          slot[n++] = first + W::window_offset(w);
      }
    return n;
  }

  /// The nodes of each cell that points touch and the node pairs that share a
  /// point. `Sink` is called once per cell as sink(c, cell, touched, pairs)
  /// with std::bitsets over stencil slots (pairs: bit a * K::n_nodes + b).
  template <int dim, class K, class Sink>
  struct CollectCouplings
  {
    CollectCouplings(const BackgroundGrid<dim> &grid, Sink &sink)
        : grid(grid)
        , sink(sink)
    {
    }
    const BackgroundGrid<dim> &grid;
    Sink                      &sink;

    static constexpr unsigned int  n_nodes           = K::n_nodes;
    static constexpr bool          prefetch_location = false;
    typename K::Cell               cell;
    std::bitset<n_nodes>           touched;
    std::bitset<n_nodes * n_nodes> pairs;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      touched.reset();
      pairs.reset();
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      unsigned int slot[K::n_point_nodes], t[K::n_point_nodes], n = 0;
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      for (unsigned int w = 0; w < K::n_point_nodes; ++w)
        if (touches<dim>(N[w], G[w]))
          t[n++] = slot[w];
      for (unsigned int a = 0; a < n; ++a)
        {
          touched.set(t[a]);
          for (unsigned int b = 0; b < n; ++b)
            pairs.set(t[a] * n_nodes + t[b]);
        }
      return true;
    }
    inline void
    end_cell(const unsigned int c)
    {
      sink(c, cell, touched, pairs);
    }
  };

  /// The nodes one point touches, as indices into the cell's local system, with
  /// their shape values and real-space gradients.
  template <int dim, unsigned int max_nodes>
  struct PointNodes
  {
    static constexpr unsigned int capacity = max_nodes;
    unsigned int                  n        = 0;
    unsigned int                  local[max_nodes];
    double                        N[max_nodes];
    double                        G[max_nodes][dim];
  };

  /// A cell's local matrix (row-major, `stride` columns) and vector; row of
  /// component k at local node a: a * nc + k. `u`: the values of the field the
  /// assembly gathers (AssembleSystem's `field`) at the same indices, or null.
  struct LocalSystem
  {
    double       *A;
    double       *b;
    unsigned int  stride;
    const double *u = nullptr;
    double &
    a(const unsigned int i, const unsigned int j)
    {
      return A[i * stride + j];
    }
  };

  // ------------------------------------------------------------------ integrands
  // An integrand adds one point's contribution (properties P) to the local
  // system: add<dim, nc>(P, nodes, local). `matrix` / `vector` say what it fills.

  /// Consistent mass factor * m_p N_i N_j (every component); factor = 1/(beta h^2)
  /// gives the Newmark inertia term.
  struct ConsistentMass
  {
    double                factor = 1.0;
    static constexpr bool matrix = true, vector = false;
    template <int dim, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      const double m = factor * P[PropertyLayout<dim>::mass];
      for (unsigned int i = 0; i < p.n; ++i)
        for (unsigned int j = 0; j < p.n; ++j)
          {
            const double v = m * p.N[i] * p.N[j];
            for (unsigned int k = 0; k < nc; ++k)
              ls.a(p.local[i] * nc + k, p.local[j] * nc + k) += v;
          }
    }
  };

  /// Small-strain isotropic linear elasticity B^T C B V_p with C from Lame's
  /// lambda and mu (in 2D the in-plane block of the 3D C: plane strain).
  struct LinearElasticStiffness
  {
    double                lambda = 0, mu = 0;
    static constexpr bool matrix = true, vector = false;
    static LinearElasticStiffness
    from_E_nu(const double E, const double nu)
    {
      return {E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))};
    }
    template <int dim, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim, "LinearElasticStiffness: a vector space (nc = dim)");
      const double V = P[PropertyLayout<dim>::volume];
      for (unsigned int i = 0; i < p.n; ++i)
        for (unsigned int j = 0; j < p.n; ++j)
          {
            const auto &Gi = p.G[i];
            const auto &Gj = p.G[j];
            double      gg = 0;
            for (unsigned int d = 0; d < dim; ++d)
              gg += Gi[d] * Gj[d];
            for (unsigned int c = 0; c < dim; ++c)
              for (unsigned int d = 0; d < dim; ++d)
                ls.a(p.local[i] * dim + c, p.local[j] * dim + d) +=
                  V * (lambda * Gi[c] * Gj[d] + mu * Gi[d] * Gj[c] + (c == d ? mu * gg : 0.0));
          }
    }
  };

  /// The lumped vector term m_p N_i q_c of a point (P: its properties, p: its
  /// stencil) for a per-component value q(c), on the first dim of the nc
  /// components of each node (the displacements of a u or u-p space).
  template <int dim, unsigned int nc, class PN, class Value>
  inline void
  add_lumped(const double *P, const PN &p, LocalSystem &ls, const Value &q)
  {
    static_assert(nc >= dim, "add_lumped: the dim displacement components come first");
    const double m = P[PropertyLayout<dim>::mass];
    for (unsigned int i = 0; i < p.n; ++i)
      for (unsigned int c = 0; c < dim; ++c)
        ls.b[p.local[i] * nc + c] += m * p.N[i] * q(c);
  }

  /// Body force m_p g N_i.
  template <int dim>
  struct BodyForce
  {
    dealii::Tensor<1, dim> g;
    static constexpr bool  matrix = false, vector = true;
    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim && d_ == dim, "BodyForce: a vector space (nc = dim)");
      add_lumped<dim, nc>(P, p, ls, [this](const unsigned int c) { return g[c]; });
    }
  };

  /// Whether an integrand has terms over the points of a whole cell (static
  /// constexpr bool cell_terms = true): AssembleSystem then calls
  /// begin_cell_terms(c) at each cell c and end_cell_terms<dim, nc>(local system,
  /// number of local nodes) before distributing it (e.g. the pressure
  /// projection onto cell means of the mixed u-p stabilisation).
  template <class T, class = void>
  struct has_cell_terms : std::false_type
  {
  };
  template <class T>
  struct has_cell_terms<T, std::void_t<decltype(T::cell_terms)>> : std::bool_constant<T::cell_terms>
  {
  };

  /// Whether an integrand can add a point's matrix as its upper triangle only
  /// (add_upper<dim, nc>(P, nodes, local): the same terms as add, the matrix
  /// entries (i, j) with local[i] <= local[j] alone; a symmetric integrand).
  /// AssembleSystem then sums a window kernel's points on the cell's patch
  /// (AssembleSystem::window_path).
  template <class T, class = void>
  struct has_add_upper : std::false_type
  {
  };
  template <class T>
  struct has_add_upper<T, std::void_t<decltype(T::upper_triangle)>> : std::bool_constant<T::upper_triangle>
  {
  };

  /// The sum of integrands.
  template <class... T>
  struct Sum
  {
    std::tuple<T...>      terms;
    static constexpr bool matrix = (T::matrix || ...), vector = (T::vector || ...);
    template <int dim, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      std::apply([&](const auto &...t) { (t.template add<dim, nc>(P, p, ls), ...); }, terms);
    }
  };
  template <class... T>
  Sum(T...) -> Sum<T...>;
  template <class... T>
  Sum<T...>
  sum(const T &...t)
  {
    return Sum<T...>{std::tuple<T...>(t...)};
  }

  /// Distribute a local system (m x m, row-major with `stride`) with the
  /// constraints into A and/or b (either may be null); global indices `dofs`.
  /// (Out of line: keeps deal.II's Trilinos and constraint templates in a .cc.)
  void distribute_local(const dealii::AffineConstraints<double> &constraints, const unsigned int m,
                        const double *A_local, const double *b_local, const unsigned int stride,
                        const std::vector<dealii::types::global_dof_index> &dofs,
                        dealii::TrilinosWrappers::SparseMatrix *A, Vector *b);

  /// distribute_local for constraints that only fix values (u_i = g_i: every
  /// line without entries, e.g. ActiveSet::constraints_with(Dirichlet)) into a
  /// filled Trilinos matrix: the same sums as deal.II's
  /// AffineConstraints::distribute_local_to_global (the same values added to
  /// the same entries, the inhomogeneity terms of b subtracted in the same
  /// order, the same diagonal for constrained rows), so the assembled system
  /// is bitwise the one of distribute_local; but the locally owned rows are
  /// added straight into Epetra's row storage (a merge along the sorted row
  /// instead of a global-to-local look-up and a binary search per entry) and
  /// the constraint state is read from an array instead of the IndexSet.
  /// Rows of other ranks go through SparseMatrix::add as before. A non-zero
  /// entry outside A's pattern throws, as deal.II's add does.
  class FixedValueDistributor
  {
  public:
    FixedValueDistributor(const dealii::AffineConstraints<double>   &constraints,
                          const dealii::Utilities::MPI::Partitioner &partitioner,
                          dealii::TrilinosWrappers::SparseMatrix *A, Vector *b);
    ~FixedValueDistributor();
    /// Whether the fast path applies: A given, filled, with sorted local
    /// indices; every constraint line without entries and on a DoF of the
    /// partitioner; b null or on the partitioner. Otherwise use distribute_local.
    bool usable() const;
    /// As distribute_local (A_local given; b_local may be null when b is).
    void distribute(unsigned int m, const double *A_local, const double *b_local, unsigned int stride,
                    const std::vector<dealii::types::global_dof_index> &dofs);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };

  /// After a walk: compress A and b; give every locally owned inactive row the
  /// diagonal `mean |diagonal|` of all local matrices (diag_sum / diag_count
  /// over all ranks), so that the system stays regular and well scaled.
  /// Collective.
  template <int dim>
  void finish_assembly(const ActiveSet<dim> &active, double diag_sum, double diag_count,
                       dealii::TrilinosWrappers::SparseMatrix *A, Vector *b);

  /// Assembly of A and/or b over a cell's points (the integrand's sums),
  /// distributed at end_cell with `constraints` (ActiveSet::constraints() or
  /// constraints_with(Dirichlet)). nc = the space's components. With `field`
  /// (a vector of the space with ghost values) the integrand also sees that
  /// field's values at the cell's nodes (LocalSystem::u): a residual that
  /// depends on the iterate (the implicit families' Newton step).
  template <int dim, class K, unsigned int nc, class Integrand>
  struct AssembleSystem
  {
    static constexpr unsigned int max_rows = K::n_nodes * nc;
    /// The patch path (docs/semi-implicit.md, "Performance"): a scalar system
    /// of a 3-per-direction window kernel (quadratic B-splines) with a
    /// symmetric integrand (has_add_upper) and no field. Each point adds its
    /// whole window, untouched nodes included (their terms are products with a
    /// zero factor, +-0, which leave every sum bitwise as it is), as the upper
    /// triangle of a patch-indexed matrix (the window's slots increase with the
    /// window index); no per-node look-up or filter in the point loop. The
    /// cell's local system (the touched nodes in the order the points first
    /// touch them, as the generic path numbers them) is read from it at
    /// end_cell: the same local matrix and vector, bit for bit.
    static constexpr bool window_path = nc == 1 && has_add_upper<Integrand>::value &&
                                        std::is_same_v<typename K::Eval, typename shape::Window3<dim>::Eval> &&
                                        K::n_nodes == shape::Window3<dim>::n_patch;

    AssembleSystem(const ActiveSet<dim> &active, const dealii::AffineConstraints<double> &constraints,
                   const Integrand &integrand, dealii::TrilinosWrappers::SparseMatrix *A, Vector *b,
                   const Vector *field = nullptr)
        : grid(active.space.grid)
        , space(active.space)
        , constraints(constraints)
        , integrand(integrand)
        , A(A)
        , b(b)
        , field(field)
        , Al(max_rows * max_rows)
        , bl(max_rows)
        , ul(field ? max_rows : 0)
        , Aw(window_path ? K::n_nodes * K::n_nodes : 0, 0.0)
        , bw(window_path ? K::n_nodes : 0, 0.0)
    {
      if (space.n_components() != nc)
        throw std::logic_error("transfer::AssembleSystem: nc differs from the space's number of components");
      if (window_path && field != nullptr)
        throw std::logic_error("transfer::AssembleSystem: the patch path takes no field");
      std::fill(std::begin(local_of_slot), std::end(local_of_slot), dealii::numbers::invalid_unsigned_int);
      if (Integrand::matrix && A != nullptr)
        {
          fast = std::make_unique<FixedValueDistributor>(constraints, *space.partitioner(), A,
                                                         Integrand::vector ? b : nullptr);
          if (!fast->usable())
            fast.reset();
        }
    }
    const BackgroundGrid<dim>               &grid;
    const NodalSpace<dim>                   &space;
    const dealii::AffineConstraints<double> &constraints;
    /// (not const: a walk over several sets, for_each_cell_of_sets, switches it per set)
    Integrand                               integrand;
    dealii::TrilinosWrappers::SparseMatrix *A;
    Vector                                 *b;
    const Vector                           *field;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    /// local node of each stencil slot used in this cell, and the slots in order
    unsigned int                                 local_of_slot[K::n_nodes];
    unsigned int                                 slot_of_local[K::n_nodes];
    unsigned int                                 n_local = 0;
    std::vector<double>                          Al, bl, ul;
    std::vector<dealii::types::global_dof_index> dofs;
    /// sum of |diagonal| and count of the local matrices (the scale of inactive rows)
    double diag_sum = 0, diag_count = 0;
    /// the fast distribution (constraints that only fix values), or null
    std::unique_ptr<FixedValueDistributor> fast;
    /// window_path: the cell's sums on the patch (upper triangle, row-major
    /// K::n_nodes columns; zero outside a cell), and the slots any point's
    /// window covered in this cell (the entries to zero again at end_cell)
    std::vector<double> Aw, bw;
    unsigned long long  window_slots = 0;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      for (unsigned int a = 0; a < n_local; ++a)
        local_of_slot[slot_of_local[a]] = dealii::numbers::invalid_unsigned_int;
      n_local = 0;
      if constexpr (has_cell_terms<Integrand>::value)
        integrand.begin_cell_terms(c);
    }
    /// local node of slot s; a new one gets zero rows and columns
    inline unsigned int
    local_node(const unsigned int s)
    {
      if (local_of_slot[s] != dealii::numbers::invalid_unsigned_int)
        return local_of_slot[s];
      const unsigned int a  = n_local++;
      local_of_slot[s]      = a;
      slot_of_local[a]      = s;
      const unsigned int r0 = a * nc, r1 = r0 + nc;
      for (unsigned int i = 0; i < r1; ++i)
        for (unsigned int j = (i < r0 ? r0 : 0); j < r1; ++j) // new columns; new rows in full
          Al[i * max_rows + j] = 0.0;
      for (unsigned int i = r0; i < r1; ++i)
        bl[i] = 0.0;
      if (field)
        for (unsigned int k = 0; k < nc; ++k)
          ul[r0 + k] = (*field)(space.node_dof(cell.dofs[s * dim], k));
      return a;
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      if constexpr (window_path)
        {
          using W = shape::Window3<dim>;
          typename K::Eval e;
          K::evaluate(cell, it->get_reference_location(), e);
          PointNodes<dim, K::n_point_nodes> p;
          p.n = K::n_point_nodes;
          W::values_and_gradients(e, p.N, p.G); // the products of K::point_stencil
          const unsigned int first = W::first_slot(e);
          for (unsigned int w = 0; w < K::n_point_nodes; ++w)
            {
              const unsigned int s = first + W::window_offset(w);
              p.local[w]           = s;
              window_slots |= 1ull << s;
              if (local_of_slot[s] == dealii::numbers::invalid_unsigned_int && touches<dim>(p.N[w], p.G[w]))
                {
                  local_of_slot[s]         = n_local;
                  slot_of_local[n_local++] = s;
                }
            }
          LocalSystem ls{Aw.data(), bw.data(), K::n_nodes, nullptr};
          integrand.template add_upper<dim, nc>(it->get_properties().data(), p, ls);
          return true;
        }
      unsigned int slot[K::n_point_nodes];
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      PointNodes<dim, K::n_point_nodes> p;
      for (unsigned int w = 0; w < K::n_point_nodes; ++w)
        if (touches<dim>(N[w], G[w]))
          {
            const unsigned int k = p.n++;
            p.local[k]           = local_node(slot[w]);
            p.N[k]               = N[w];
            for (unsigned int d = 0; d < dim; ++d)
              p.G[k][d] = G[w][d];
          }
      LocalSystem ls{Al.data(), bl.data(), max_rows, field ? ul.data() : nullptr};
      integrand.template add<dim, nc>(it->get_properties().data(), p, ls);
      return true;
    }
    /// window_path: the local system from the patch sums; the sums zeroed
    inline void
    window_to_local()
    {
      constexpr unsigned int n = K::n_nodes;
      for (unsigned int i = 0; i < n_local; ++i)
        {
          const unsigned int si = slot_of_local[i];
          if (Integrand::matrix)
            for (unsigned int j = 0; j < n_local; ++j)
              {
                const unsigned int sj = slot_of_local[j];
                Al[i * max_rows + j]  = si <= sj ? Aw[si * n + sj] : Aw[sj * n + si];
              }
          bl[i] = bw[si];
        }
      for (unsigned long long m = window_slots; m != 0; m &= m - 1)
        {
          const unsigned int s = __builtin_ctzll(m);
          bw[s]                = 0.0;
          if (Integrand::matrix)
            for (unsigned long long k = window_slots >> s; k != 0; k &= k - 1) // the row's upper part
              Aw[s * n + s + __builtin_ctzll(k)] = 0.0;
        }
      window_slots = 0;
    }
    inline void
    end_cell(const unsigned int)
    {
      if constexpr (window_path)
        window_to_local();
      if (n_local == 0)
        return;
      if constexpr (has_cell_terms<Integrand>::value)
        {
          LocalSystem ls{Al.data(), bl.data(), max_rows, field ? ul.data() : nullptr};
          integrand.template end_cell_terms<dim, nc>(ls, n_local);
        }
      const unsigned int m = n_local * nc;
      dofs.resize(m);
      for (unsigned int a = 0; a < n_local; ++a)
        for (unsigned int k = 0; k < nc; ++k)
          dofs[a * nc + k] = space.node_dof(cell.dofs[slot_of_local[a] * dim], k);
      if (Integrand::matrix)
        for (unsigned int i = 0; i < m; ++i)
          diag_sum += std::abs(Al[i * max_rows + i]);
      diag_count += m;
      if (fast)
        fast->distribute(m, Al.data(), Integrand::vector ? bl.data() : nullptr, max_rows, dofs);
      else
        distribute_local(constraints, m, Integrand::matrix ? Al.data() : nullptr,
                         Integrand::vector ? bl.data() : nullptr, max_rows, dofs, Integrand::matrix ? A : nullptr,
                         Integrand::vector ? b : nullptr);
    }
  };

  /// The walk of several point sets cell by cell: for every cell that holds
  /// points of any set, op.begin_cell(c), then for each set k (in the order
  /// given) with points in c select_set(k) and op.point(c, it) for those
  /// points, then op.end_cell(c). An assembly then distributes one local
  /// system per cell for all sets instead of one per set (the semi-implicit
  /// Poisson matrix over soil and water: docs/semi-implicit.md). Cells in the
  /// storage order of the first set, then the cells of the second that the
  /// first has no points in, and so on: the order follows the storage only,
  /// so a restart that restores the storage repeats it.
  template <int dim, class Op, class SelectSet>
  void
  for_each_cell_of_sets(const BackgroundGrid<dim> &grid, const std::vector<MaterialPointSet<dim> *> &sets, Op &op,
                        SelectSet &&select_set)
  {
    if (sets.empty())
      return;
    // every set but the first: its cell groups (first point, count) and the
    // group of each cell
    struct Group
    {
      unsigned int       cell, n;
      PointIterator<dim> first;
      bool               walked;
    };
    const unsigned int                     none = dealii::numbers::invalid_unsigned_int;
    std::vector<std::vector<Group>>        groups(sets.size());
    std::vector<std::vector<unsigned int>> group_of_cell(sets.size());
    for (unsigned int k = 1; k < sets.size(); ++k)
      {
        group_of_cell[k].assign(grid.cells.size(), none);
        groups[k].reserve(sets[k]->active_cells().size());
        auto it = sets[k]->handler.begin();
        for (const auto [c, n] : sets[k]->active_cells())
          {
            group_of_cell[k][c] = groups[k].size();
            groups[k].push_back({c, n, it, false});
            for (unsigned int i = 0; i < n; ++i)
              ++it;
          }
      }
    // the points of the sets from k on in cell c, except those of the driving set
    const auto other_sets_in = [&](const unsigned int c, const unsigned int from) {
      for (unsigned int k = from; k < sets.size(); ++k)
        if (const unsigned int g = group_of_cell[k][c]; g != none && !groups[k][g].walked)
          {
            Group &group = groups[k][g];
            group.walked = true;
            select_set(k);
            auto it = group.first;
            for (unsigned int i = 0; i < group.n; ++i, ++it)
              op.point(c, it);
          }
    };
    {
      auto            pt = sets[0]->handler.begin();
      Prefetcher<dim> ahead(sets[0]->handler, prefetch_distance);
      for (const auto [c, n] : sets[0]->active_cells())
        {
          op.begin_cell(c);
          select_set(0);
          for (unsigned int i = 0; i < n; ++i, ++pt, ahead.next(Op::prefetch_location))
            op.point(c, pt);
          other_sets_in(c, 1);
          op.end_cell(c);
        }
    }
    for (unsigned int k = 1; k < sets.size(); ++k)
      for (const Group &group : groups[k])
        if (!group.walked)
          {
            op.begin_cell(group.cell);
            other_sets_in(group.cell, k);
            op.end_cell(group.cell);
          }
  }

  /// A += and/or b += the integrand summed over the points of all `sets`, then
  /// finish_assembly. A (reinit by ActiveSet::reinit_matrix) and b (the space's
  /// partitioner) are not zeroed here; either may be null. `field`: see
  /// AssembleSystem. Collective.
  template <int dim, class K, unsigned int nc, class Integrand>
  void
  assemble(const std::vector<MaterialPointSet<dim> *> &sets, const ActiveSet<dim> &active,
           const dealii::AffineConstraints<double> &constraints, const Integrand &integrand,
           dealii::TrilinosWrappers::SparseMatrix *A, Vector *b, const Vector *field = nullptr)
  {
    AssembleSystem<dim, K, nc, Integrand> op(active, constraints, integrand, A, b, field);
    for (auto *set : sets)
      for_each_active_cell(*set, op);
    finish_assembly(active, op.diag_sum, op.diag_count, Integrand::matrix ? A : nullptr, b);
  }

  /// The nc components of a space vector u (ghost values up to date) at a
  /// cell's stencil nodes; 0 at nodes without a DoF (B-spline slots beyond the grid).
  template <int dim, class K, unsigned int nc>
  inline void
  gather_space_vector(const NodalSpace<dim> &space, const typename K::Cell &cell, const Vector &u,
                      double (&un)[K::n_nodes][nc])
  {
    for (unsigned int s = 0; s < K::n_nodes; ++s)
      for (unsigned int k = 0; k < nc; ++k)
        {
          const unsigned int i = cell.dofs[s * dim];
          un[s][k]             = i == dealii::numbers::invalid_unsigned_int ? 0.0 : u(space.node_dof(i, k));
        }
  }

  /// G2P of a nodal field u of the space (ghost values up to date): per point
  /// callback(it, val[nc], grad[nc][dim]) with grad[c][k] = d u_c / d x_k.
  template <int dim, class K, unsigned int nc, class Callback>
  struct InterpolateField
  {
    InterpolateField(const NodalSpace<dim> &space, const Vector &u, Callback &callback)
        : grid(space.grid)
        , space(space)
        , u(u)
        , callback(callback)
    {
    }
    const BackgroundGrid<dim> &grid;
    const NodalSpace<dim>     &space;
    const Vector              &u;
    Callback                  &callback;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    double                un[K::n_nodes][nc];

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      gather_space_vector<dim, K, nc>(space, cell, u, un);
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      unsigned int slot[K::n_point_nodes];
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      double val[nc] = {}, grad[nc][dim] = {};
      for (unsigned int w = 0; w < K::n_point_nodes; ++w)
        for (unsigned int k = 0; k < nc; ++k)
          {
            const double v = un[slot[w]][k];
            val[k] += N[w] * v;
            for (unsigned int d = 0; d < dim; ++d)
              grad[k][d] += G[w][d] * v;
          }
      callback(it, val, grad);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
    }
  };
} // namespace talus::transfer
