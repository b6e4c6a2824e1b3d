// talus — point ops for transfer::for_each_active_cell (cell_walk.h), templated
// on the shape kernel K (shape/q1_box.h describes the kernel interface). They
// hold the kinematics of the MPM cycle; the physics of a formulation (the
// constitutive update, diagnostics) comes in as a template parameter.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/particles/material_points.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/move_point.h>

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/tensor.h>

#include <algorithm>
#include <array>
#include <vector>

namespace talus::transfer
{
  /// What the P2G ops share: the current cell's stencil and its per-cell sums
  /// (the kernel's MassForce or Momentum), cleared at each cell.
  template <int dim, class K, class Sums>
  struct CellSums
  {
    explicit CellSums(const BackgroundGrid<dim> &grid)
        : grid(grid)
    {
    }
    const BackgroundGrid<dim> &grid;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    Sums                  sums;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      sums.clear();
    }
  };

  /// The stress a point's force takes as it is: no adjustment of -V sigma.
  struct PointStressAsIs
  {
    static constexpr bool active = false;
    template <int dim>
    inline void
    operator()(unsigned int, const double *, double, double (&)[dim][dim]) const
    {
    }
  };

  /// P2G of lumped mass and internal + gravity force (seed 000 Eqs. 4.32, 4.34,
  /// 4.41) at the points' current reference locations, added to M and F.
  /// `Adjust` (if active): adjust(c, P, V, t) changes a point's t = -V sigma in
  /// cell c before it is scattered (strain smoothing's transposed mean stress).
  template <int dim, class K, class Adjust = PointStressAsIs>
  struct ScatterMassForce : CellSums<dim, K, typename K::MassForce>
  {
    using Base = CellSums<dim, K, typename K::MassForce>;
    using Base::cell;
    using Base::grid;
    using Base::sums;
    ScatterMassForce(const BackgroundGrid<dim> &grid, const dealii::Tensor<1, dim> &g, double *M, double *F,
                     const Adjust &adjust = Adjust())
        : Base(grid)
        , g(g)
        , M(M)
        , F(F)
        , adjust(adjust)
    {
    }
    const dealii::Tensor<1, dim> g;
    double *const                M;
    double *const                F;
    const Adjust                 adjust;
    /// one point of cell c with properties P at reference location xi
    inline void
    add(const unsigned int c, const dealii::Point<dim> &xi, const double *P)
    {
      using L = PropertyLayout<dim>;
      typename K::Eval e;
      K::evaluate(cell, xi, e);
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      if constexpr (Adjust::active)
        adjust(c, P, P[L::volume], t);
      sums.add(e, P[L::mass], t);
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      add(c, it->get_reference_location(), it->get_properties().data());
      return true;
    }
    /// the same with the reference location known (a fused op after a move)
    inline bool
    point_at(const unsigned int c, PointIterator<dim> &it, const dealii::Point<dim> &xi)
    {
      add(c, xi, it->get_properties().data());
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      sums.scatter(cell, g, M, F);
    }
    /// a point of the walk that entered cell c (a fused op after a move; the
    /// walk hands it to the relocation with `added`)
    inline void
    point_entered(const unsigned int c, const dealii::Point<dim> &xi, const double *P)
    {
      scatter_one(c, xi, P);
    }
    /// the same for one point outside a walk (a point moved to cell c)
    inline void
    scatter_one(const unsigned int c, const dealii::Point<dim> &xi, const double *P)
    {
      using L                    = PropertyLayout<dim>;
      const typename K::Cell one = K::cell(grid, c);
      typename K::Eval       e;
      K::evaluate(one, xi, e);
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      if constexpr (Adjust::active)
        adjust(c, P, P[L::volume], t);
      K::scatter_point(one, e, P[L::mass], t, g, M, F);
    }
  };

  /// G2P of the nodal acceleration A into the point velocities (v_p += h a(x_p),
  /// Eq. 4.46) and P2G of the new momentum m_p v_p (Eq. 4.47) into Pn.
  template <int dim, class K>
  struct UpdateVelocityScatterMomentum
  {
    UpdateVelocityScatterMomentum(const BackgroundGrid<dim> &grid, const double *A, double *Pn, const double h)
        : grid(grid)
        , A(A)
        , Pn(Pn)
        , h(h)
    {
    }
    const BackgroundGrid<dim> &grid;
    const double *const        A;
    double *const              Pn;
    const double               h;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    typename K::Field     a;
    typename K::Momentum  sums;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      K::gather(cell, A, 1.0, a, false);
      sums.clear();
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      using L              = PropertyLayout<dim>;
      double            *P = it->get_properties().data();
      typename K::Values N;
      K::values(cell, it->get_reference_location(), N);
      double ap[dim];
      K::interpolate(a, N, ap);
      double *vel = P + L::velocity;
      for (unsigned int d = 0; d < dim; ++d)
        vel[d] += h * ap[d];
      sums.add(N, P[L::mass], vel);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      sums.scatter(cell, Pn);
    }
  };

  /// P2G of the points' momentum m_p v_p (Eq. 4.47) at their current reference
  /// locations into Pn (the nodal momentum p^t the loads use before a step).
  template <int dim, class K>
  struct ScatterMomentum : CellSums<dim, K, typename K::Momentum>
  {
    using Base = CellSums<dim, K, typename K::Momentum>;
    using Base::cell;
    using Base::sums;
    ScatterMomentum(const BackgroundGrid<dim> &grid, double *Pn)
        : Base(grid)
        , Pn(Pn)
    {
    }
    double *const Pn;
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      using L              = PropertyLayout<dim>;
      const double      *P = it->get_properties().data();
      typename K::Values N;
      K::values(cell, it->get_reference_location(), N);
      sums.add(N, P[L::mass], P + L::velocity);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      sums.scatter(cell, Pn);
    }
  };

  /// P2G of vectors that the caller computes per point (a traction point
  /// force, the momentum change of a prescribed point velocity), into n_out
  /// nodal vectors: `source(P, w, f)` (P the point's properties, which it may
  /// change) returns whether the point contributes and sets, per output k, a
  /// weight w[k] and a vector f[k]; Out[k]_i += sum_p N_i(x_p) w[k] f[k].
  template <int dim, class K, class Source, unsigned int n_out = 1>
  struct ScatterPointVectors
  {
    ScatterPointVectors(const BackgroundGrid<dim> &grid, Source &source, const std::array<double *, n_out> &out)
        : grid(grid)
        , source(source)
        , out(out)
    {
    }
    const BackgroundGrid<dim>        &grid;
    Source                           &source;
    const std::array<double *, n_out> out;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    typename K::Momentum  sums[n_out];
    bool                  any = false; ///< a point of the cell contributed

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      for (auto &s : sums)
        s.clear();
      any = false;
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      double *P = it->get_properties().data();
      double  w[n_out], f[n_out][dim];
      if (!source(P, w, f))
        return true;
      typename K::Values N;
      K::values(cell, it->get_reference_location(), N);
      for (unsigned int k = 0; k < n_out; ++k)
        if (out[k])
          sums[k].add(N, w[k], f[k]);
      any = true;
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      if (any)
        for (unsigned int k = 0; k < n_out; ++k)
          if (out[k])
            sums[k].scatter(cell, out[k]);
    }
  };

  /// An op that does nothing (a Fused second op when no P2G is fused).
  struct NoOp
  {
    static constexpr bool prefetch_location = false;
    inline void
    begin_cell(unsigned int)
    {
    }
    template <class It>
    inline bool
    point(unsigned int, It &)
    {
      return true;
    }
    template <class It, class Xi>
    inline bool
    point_at(unsigned int, It &, const Xi &)
    {
      return true;
    }
    inline void
    end_cell(unsigned int)
    {
    }
  };
  /// The update of the points from the nodal velocity V over a step h: the
  /// displacement increment du = h V is interpolated (Eq. 4.51) and its
  /// gradient handed to the formulation's point physics (strain, stress,
  /// volume); the point moves, and either stays in its cell (new reference
  /// location; point() returns true, so a Fused P2G op can add it at once) or
  /// is handed to the set's relocation.
  ///
  /// Physics provides
  ///   PointState                           what update() hands to moved() for one
  ///                                        point (a local of the walk: pointers to it
  ///                                        may go to opaque calls without pinning the
  ///                                        physics' sums in memory)
  ///   increments(cell, e, du, P, grad, dx)  grad du and dx at the point (default:
  ///                                         K::gradient, K::interpolate of du)
  ///   update(c, cell, P, grad, state)      constitutive update etc.
  ///   moved(it, P, x, state)               diagnostics at the new position
  /// The new reference location of a point that stayed is kept in `xi_new` for a
  /// fused P2G op (Fused hands it on instead of reading it back from storage).
  template <int dim, class K, class Physics>
  struct UpdateAndMove
  {
    UpdateAndMove(const BackgroundGrid<dim> &grid, MaterialPointSet<dim> &set, const double *V, const double h,
                  Physics &physics)
        : grid(grid)
        , set(set)
        , V(V)
        , h(h)
        , physics(physics)
    {
    }
    const BackgroundGrid<dim> &grid;
    MaterialPointSet<dim>     &set;
    const double *const        V;
    const double               h;
    Physics                   &physics;

    static constexpr bool prefetch_location = true;
    /// this op moves points: a fused second op gets the new reference location
    static constexpr bool moves_points = true;
    typename K::Cell      cell;
    typename K::Field     du;
    dealii::Point<dim>    xi_new;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      K::gather(cell, V, h, du, true);
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      using L            = PropertyLayout<dim>;
      double          *P = it->get_properties().data();
      typename K::Eval e;
      K::evaluate(cell, it->get_reference_location(), e);
      double gu[dim][dim], dx[dim];
      physics.increments(cell, e, du, P, gu, dx);
      typename Physics::PointState state;
      physics.update(c, cell, P, gu, state);
      auto x = it->get_location();
      for (unsigned int d = 0; d < dim; ++d)
        {
          x[d] += dx[d];
          P[L::displacement + d] += dx[d];
        }
      physics.moved(it, P, x, state);
      return place_moved_point(set, grid, c, it, x, xi_new);
    }
    inline void
    end_cell(const unsigned int)
    {
    }

    /// Physics with `static constexpr bool updates_whole_cells = true` and
    /// update_cell(c, cell, n, points) (points[k].P, .gu, .state) update the
    /// stresses of a whole cell at once: the walk then calls
    /// whole_cell(), which does per point exactly what point() does, in three
    /// loops: increments; the physics' update of all n points; move, moved()
    /// and the fused second op (same arithmetic and the same order of every
    /// sum as point() by point(): bitwise the same results).
    template <class Ph>
    static constexpr auto
    has_update_cell(int) -> decltype(Ph::updates_whole_cells, bool())
    {
      return Ph::updates_whole_cells;
    }
    template <class Ph>
    static constexpr bool
    has_update_cell(long)
    {
      return false;
    }
    static constexpr bool whole_cells = has_update_cell<Physics>(0);

    /// Whether a fused second op adds points that entered a neighbour cell
    /// (point_entered(c, xi, P)).
    template <class Op>
    static constexpr auto
    adds_entered(int) -> decltype(&Op::point_entered, bool())
    {
      return true;
    }
    template <class Op>
    static constexpr bool
    adds_entered(long)
    {
      return false;
    }

    /// One point of whole_cell() between its loops.
    struct CellPoint
    {
      double                       gu[dim][dim];
      double                       dx[dim];
      double                      *P;
      typename Physics::PointState state;
    };
    std::vector<CellPoint>          scratch;
    std::vector<PointIterator<dim>> iterators;

    template <class Ahead, class Second>
    inline void
    whole_cell(const unsigned int c, const unsigned int n, PointIterator<dim> &it, Ahead &ahead, Second &second)
    {
      using L = PropertyLayout<dim>;
      begin_cell(c);
      second.begin_cell(c);
      if (scratch.size() < n)
        scratch.resize(n);
      iterators.clear();
      for (unsigned int k = 0; k < n; ++k, ++it, ahead.next(prefetch_location))
        {
          CellPoint &q = scratch[k];
          q.P          = it->get_properties().data();
          typename K::Eval e;
          K::evaluate(cell, it->get_reference_location(), e);
          physics.increments(cell, e, du, q.P, q.gu, q.dx);
          iterators.push_back(it);
        }
      physics.update_cell(c, cell, n, scratch.data());
      for (unsigned int k = 0; k < n; ++k)
        {
          CellPoint &q = scratch[k];
          auto      &p = iterators[k];
          auto       x = p->get_location();
          for (unsigned int d = 0; d < dim; ++d)
            {
              x[d] += q.dx[d];
              q.P[L::displacement + d] += q.dx[d];
            }
          physics.moved(p, q.P, x, q.state);
          // a second op with point_entered() adds a point that entered an owned
          // neighbour cell at once (its nodal entries are in cache now)
          unsigned int add_to;
          if (place_moved_point(set, grid, c, p, x, xi_new, add_to, adds_entered<Second>(0)))
            second.point_at(c, p, xi_new);
          else if constexpr (adds_entered<Second>(0))
            if (add_to != dealii::numbers::invalid_unsigned_int)
              second.point_entered(add_to, xi_new, q.P);
        }
      second.end_cell(c);
      end_cell(c);
    }
    /// the same without a fused second op
    template <class Ahead>
    inline void
    whole_cell(const unsigned int c, const unsigned int n, PointIterator<dim> &it, Ahead &ahead)
    {
      NoOp none;
      whole_cell(c, n, it, ahead, none);
    }
  };

  /// Default kinematics of UpdateAndMove: the gradient and the interpolated
  /// value of the cell's displacement-increment field.
  template <int dim, class K>
  inline void
  default_increments(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du,
                     double (&gu)[dim][dim], double (&dx)[dim])
  {
    K::value_and_gradient(cell, du, e, dx, gu);
  }

  /// For rigid walls with friction: at each node of a cell face on such a wall,
  /// the minimum over the cell's points of their displacement away from that
  /// wall (the lift that releases the contact). `faces[c]` holds bit f for
  /// each face f of cell c on a friction wall (outward normal -+e_{f/2} for
  /// f even/odd); `lift` (local indices of the grid's vector space) must start
  /// at +max. Q1 vertices only (boundary friction is linear-only).
  template <int dim>
  struct MinDisplacementAwayFromWalls
  {
    MinDisplacementAwayFromWalls(const BackgroundGrid<dim> &grid, const std::vector<unsigned char> &faces, double *lift)
        : grid(grid)
        , faces(faces)
        , lift(lift)
    {
    }
    const BackgroundGrid<dim>        &grid;
    const std::vector<unsigned char> &faces;
    double *const                     lift;

    static constexpr bool prefetch_location = false;
    unsigned char         cell_faces        = 0;
    const unsigned int   *dofs              = nullptr;

    inline void
    begin_cell(const unsigned int c)
    {
      cell_faces = faces[c];
      dofs       = grid.cells[c].dofs;
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      if (!cell_faces)
        return true;
      const double *P = it->get_properties().data();
      for (unsigned int f = 0; f < 2 * dim; ++f)
        if (cell_faces & (1u << f))
          {
            const unsigned int axis = f / 2;
            const double       away = (f % 2 ? -1.0 : 1.0) * P[PropertyLayout<dim>::displacement + axis];
            for (unsigned int i = 0; i < dealii::GeometryInfo<dim>::vertices_per_face; ++i)
              {
                const unsigned int v = dealii::GeometryInfo<dim>::face_to_cell_vertices(f, i);
                double            &l = lift[dofs[v * dim + axis]];
                l                    = std::min(l, away);
              }
          }
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
    }
  };

} // namespace talus::transfer
