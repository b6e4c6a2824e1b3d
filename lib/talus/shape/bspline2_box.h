// talus — the quadratic B-spline kernel (shape/bspline2.h, walls as in
// docs/shape-functions.md) as a compile-time policy for the transfer ops; the
// interface is the one described in shape/q1_box.h.
//
// A cell's stencil is its 4^dim node patch (BackgroundGrid::setup_bspline_patches);
// a point uses the 3^dim window of that patch its position selects. Nodal data
// are gathered once per cell for the whole patch; per point the window is
// contracted direction by direction (Window3::interpolate), and the per-cell
// sums of mass, force and momentum live on the patch, scattered once per cell.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/shape/bspline2.h>

#include <deal.II/base/numbers.h>
#include <deal.II/base/tensor.h>

#include <algorithm>
#include <iterator>

namespace talus::shape
{
  template <int dim>
  struct BSpline2Box
  {
    using W                                = Window3<dim>;
    using B                                = BSpline2<dim>;
    static constexpr unsigned int n_nodes  = W::n_patch;
    static constexpr unsigned int n_window = W::n_nodes;

    struct Cell
    {
      const CellCache<dim>    *cc    = nullptr;
      const BSplinePatch<dim> *patch = nullptr;
      const UniformBox<dim>   *box   = nullptr;
      const unsigned int      *dofs  = nullptr; // patch slot s, component d at [s * dim + d]
    };
    static inline Cell
    cell(const BackgroundGrid<dim> &grid, const unsigned int c)
    {
      const auto &p = grid.patch(c);
      return {&grid.cells[c], &p, &grid.box, p.dofs};
    }

    using Eval   = typename W::Eval;
    using Values = typename W::Eval;
    static inline void
    evaluate(const Cell &c, const dealii::Point<dim> &xi, Eval &e)
    {
      B::evaluate(c.patch->i_cell, c.box->n_cells, c.box->inv_h, xi, e);
    }
    static inline void
    values(const Cell &c, const dealii::Point<dim> &xi, Values &e)
    {
      evaluate(c, xi, e);
    }

    /// A vector field on the cell's patch (slots outside the grid: 0).
    struct Field
    {
      double u[n_nodes][dim];
    };
    static inline void
    gather(const Cell &c, const double *V, const double scale, Field &f, const bool)
    {
      for (unsigned int s = 0; s < n_nodes; ++s)
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int i = c.dofs[s * dim + d];
            f.u[s][d]            = i == dealii::numbers::invalid_unsigned_int ? 0.0 : scale * V[i];
          }
    }
    // The ops below read and write the patch in place from the window's first
    // slot (W::for_each_window_node / _value, W::interpolate_strided): no window
    // copy, no slot arithmetic by division; the products and the order of every
    // sum are those of W::values / values_and_gradients / interpolate.
    /// the value alone, sum-factorised (W::interpolate_value_strided)
    static inline void
    interpolate(const Field &f, const Eval &e, double (&out)[dim])
    {
      W::template interpolate_value_strided<dim, 4, 16>(e, f.u + W::first_slot(e), out);
    }
    /// grad[c][k] = d u_c / d x_k
    static inline void
    gradient(const Cell &, const Field &f, const Eval &e, double (&grad)[dim][dim])
    {
      double val[dim];
      W::template interpolate_strided<dim, 4, 16>(e, f.u + W::first_slot(e), val, grad);
    }
    /// value and gradient at once (one window contraction)
    static inline void
    value_and_gradient(const Cell &, const Field &f, const Eval &e, double (&val)[dim], double (&grad)[dim][dim])
    {
      W::template interpolate_strided<dim, 4, 16>(e, f.u + W::first_slot(e), val, grad);
    }

    /// The nodes one point touches, for matrix assembly (transfer/matrix_ops.h):
    /// the point's 3^dim window as patch slots, with values and real-space
    /// gradients (a window node is always inside the grid).
    static constexpr unsigned int n_point_nodes = n_window;
    static inline void
    point_stencil(const Cell &c, const dealii::Point<dim> &xi, unsigned int (&slot)[n_point_nodes],
                  double (&N)[n_point_nodes], double (&G)[n_point_nodes][dim])
    {
      Eval e;
      evaluate(c, xi, e);
      W::values_and_gradients(e, N, G);
      const unsigned int first = W::first_slot(e);
      for (unsigned int w = 0; w < n_point_nodes; ++w)
        slot[w] = first + W::window_offset(w);
    }

    /// One point's mass weight and internal force on its window: calls
    /// f(o, N_w, F_w) for the window nodes in order (o: patch slot relative to
    /// the first window slot), F_w[c] = sum_k t[c][k] dN_w/dx_k with t = -V sigma.
    /// Sum-factorised: along a window line (direction 0) the factors of the other
    /// directions are constant, so F_w[c] = dN0_a X_c + N0_a Y_c with X, Y formed
    /// once per line (4 flops per node and component instead of 6 plus the
    /// gradient; differs from the per-node form in round-off only).
    template <class Fn>
    static inline void
    for_each_window_force(const Eval &e, const double (&t)[dim][dim], Fn &&f)
    {
      double N0[3], dN0[3]; // locals: the caller's stores cannot alias them
      for (unsigned int a = 0; a < 3; ++a)
        {
          N0[a]  = e.N[0][a];
          dN0[a] = e.dN[0][a];
        }
      auto line = [&](const unsigned int o, const double w, const double(&X)[dim], const double(&Y)[dim]) {
        for (unsigned int a = 0; a < 3; ++a)
          {
            double F[dim];
            for (unsigned int c = 0; c < dim; ++c)
              F[c] = dN0[a] * X[c] + N0[a] * Y[c];
            f(o + a, N0[a] * w, F);
          }
      };
      if constexpr (dim == 2)
        for (unsigned int b = 0; b < 3; ++b)
          {
            const double n = e.N[1][b], dn = e.dN[1][b];
            double       X[dim], Y[dim];
            for (unsigned int c = 0; c < dim; ++c)
              {
                X[c] = t[c][0] * n;
                Y[c] = t[c][1] * dn;
              }
            line(4 * b, n, X, Y);
          }
      else
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double nbc = e.N[1][b] * e.N[2][k], dbc = e.dN[1][b] * e.N[2][k], nbd = e.N[1][b] * e.dN[2][k];
              double       X[dim], Y[dim];
              for (unsigned int c = 0; c < dim; ++c)
                {
                  X[c] = t[c][0] * nbc;
                  Y[c] = t[c][1] * dbc + t[c][2] * nbd;
                }
              line(4 * b + 16 * k, nbc, X, Y);
            }
    }

    /// Lumped mass and internal force of a cell's points on the patch.
    struct MassForce
    {
      double lm[n_nodes]     = {};
      double f[n_nodes][dim] = {};
      /// zero the sums in place (a new cell; `*this = MassForce()` built a
      /// zeroed temporary and copied its 2 KB: 6 % of a B-spline run in memmove)
      inline void
      clear()
      {
        std::fill(std::begin(lm), std::end(lm), 0.0);
        std::fill(&f[0][0], &f[0][0] + n_nodes * dim, 0.0);
      }
      /// one point: mass m, t = -V sigma
      inline void
      add(const Eval &e, const double m, const double (&t)[dim][dim])
      {
        const unsigned int first = W::first_slot(e);
        double            *lw    = lm + first;
        double(*fw)[dim]         = f + first;
        for_each_window_force(e, t, [&](const unsigned int o, const double N, const double(&F)[dim]) {
          lw[o] += m * N;
          for (unsigned int c = 0; c < dim; ++c)
            fw[o][c] += F[c];
        });
      }
      inline void
      scatter(const Cell &c, const dealii::Tensor<1, dim> &g, double *M, double *Fv) const
      {
        for (unsigned int s = 0; s < n_nodes; ++s)
          if (c.dofs[s * dim] != dealii::numbers::invalid_unsigned_int) // else outside the grid: no weight
            for (unsigned int d = 0; d < dim; ++d)
              {
                const unsigned int i = c.dofs[s * dim + d];
                M[i] += lm[s];
                Fv[i] += lm[s] * g[d] + f[s][d];
              }
      }
    };

    /// Mass and force of one point scattered on its window only (a point moved
    /// into another cell: no per-cell sums over the whole patch).
    static inline void
    scatter_point(const Cell &c, const Eval &e, const double m, const double (&t)[dim][dim],
                  const dealii::Tensor<1, dim> &g, double *M, double *Fv)
    {
      const unsigned int *dofs = c.dofs + W::first_slot(e) * dim;
      for_each_window_force(e, t, [&](const unsigned int o, const double N, const double(&F)[dim]) {
        const double mn = m * N;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int i = dofs[o * dim + d]; // a window node is always in the grid
            M[i] += mn;
            Fv[i] += mn * g[d] + F[d];
          }
      });
    }

    /// sum_p m_p N(x_p) v_p of a cell's points on the patch
    struct Momentum
    {
      double lp[n_nodes][dim] = {};
      /// zero the sums in place (see MassForce::clear)
      inline void
      clear()
      {
        std::fill(&lp[0][0], &lp[0][0] + n_nodes * dim, 0.0);
      }
      inline void
      add(const Eval &e, const double m, const double *vel)
      {
        double(*pw)[dim] = lp + W::first_slot(e);
        W::for_each_window_value(e, [&](const unsigned int o, const double N) {
          const double mN = m * N;
          for (unsigned int d = 0; d < dim; ++d)
            pw[o][d] += mN * vel[d];
        });
      }
      inline void
      scatter(const Cell &c, double *P) const
      {
        for (unsigned int s = 0; s < n_nodes; ++s)
          if (c.dofs[s * dim] != dealii::numbers::invalid_unsigned_int) // else outside the grid: no weight
            for (unsigned int d = 0; d < dim; ++d)
              P[c.dofs[s * dim + d]] += lp[s][d];
      }
    };
  };
} // namespace talus::shape
