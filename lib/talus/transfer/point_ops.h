// talus — point ops for transfer::for_each_active_cell (cell_walk.h), templated
// on the shape kernel K (shape/q1_box.h describes the kernel interface). They
// hold the kinematics of the MPM cycle; the physics of a formulation (the
// constitutive update, diagnostics) comes in as a template parameter.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/particles/material_points.h>
#include <talus/transfer/cell_walk.h>

#include <deal.II/base/tensor.h>

namespace talus::transfer
{
  /// P2G of lumped mass and internal + gravity force (seed 000 Eqs. 4.32, 4.34,
  /// 4.41) at the points' current reference locations, added to M and F.
  template <int dim, class K>
  struct ScatterMassForce
  {
    ScatterMassForce(const BackgroundGrid<dim> &grid, const dealii::Tensor<1, dim> &g, double *M, double *F)
      : grid(grid)
      , g(g)
      , M(M)
      , F(F)
    {}
    const BackgroundGrid<dim> &grid;
    const dealii::Tensor<1, dim> g;
    double *const                M;
    double *const                F;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    typename K::MassForce sums;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      sums.clear();
    }
    /// one point with properties P at reference location xi
    inline void
    add(const dealii::Point<dim> &xi, const double *P)
    {
      using L = PropertyLayout<dim>;
      typename K::Eval e;
      K::evaluate(cell, xi, e);
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      sums.add(e, P[L::mass], t);
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      add(it->get_reference_location(), it->get_properties().data());
      return true;
    }
    /// the same with the reference location known (a fused op after a move)
    inline bool
    point_at(const unsigned int, PointIterator<dim> &it, const dealii::Point<dim> &xi)
    {
      add(xi, it->get_properties().data());
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      sums.scatter(cell, g, M, F);
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
    {}
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
      using L   = PropertyLayout<dim>;
      double *P = it->get_properties().data();
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
  struct ScatterMomentum
  {
    ScatterMomentum(const BackgroundGrid<dim> &grid, double *Pn)
      : grid(grid)
      , Pn(Pn)
    {}
    const BackgroundGrid<dim> &grid;
    double *const              Pn;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    typename K::Momentum  sums;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      sums.clear();
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      using L         = PropertyLayout<dim>;
      const double *P = it->get_properties().data();
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
    UpdateAndMove(const BackgroundGrid<dim> &grid,
                  MaterialPointSet<dim> &    set,
                  const double *             V,
                  const double               h,
                  Physics &                  physics)
      : grid(grid)
      , set(set)
      , V(V)
      , h(h)
      , physics(physics)
    {}
    const BackgroundGrid<dim> &grid;
    MaterialPointSet<dim> &    set;
    const double *const        V;
    const double               h;
    Physics &                  physics;

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
      using L    = PropertyLayout<dim>;
      double *P  = it->get_properties().data();
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
      // new reference coordinates: same cell if still inside
      const auto &cc     = grid.cells[c];
      bool        inside = true;
      for (unsigned int d = 0; d < dim; ++d)
        {
          xi_new[d] = (x[d] - cc.lower[d]) * cc.inv_h[d];
          inside    = inside && xi_new[d] >= 0.0 && xi_new[d] <= 1.0;
        }
      it->set_location(x);
      if (inside)
        {
          it->set_reference_location(xi_new);
          return true;
        }
      set.leaving(it, c);
      return false;
    }
    inline void
    end_cell(const unsigned int)
    {}
  };

  /// Default kinematics of UpdateAndMove: the gradient and the interpolated
  /// value of the cell's displacement-increment field.
  template <int dim, class K>
  inline void
  default_increments(const typename K::Cell & cell,
                     const typename K::Eval & e,
                     const typename K::Field &du,
                     double (&gu)[dim][dim],
                     double (&dx)[dim])
  {
    K::value_and_gradient(cell, du, e, dx, gu);
  }

  /// An op that does nothing (a Fused second op when no P2G is fused).
  struct NoOp
  {
    static constexpr bool prefetch_location = false;
    inline void           begin_cell(unsigned int) {}
    template <class It>
    inline bool
    point(unsigned int, It &)
    {
      return true;
    }
    inline void end_cell(unsigned int) {}
  };
} // namespace talus::transfer
