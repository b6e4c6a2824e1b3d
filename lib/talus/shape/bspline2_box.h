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

namespace talus::shape
{
  template <int dim>
  struct BSpline2Box
  {
    using W                               = Window3<dim>;
    using B                               = BSpline2<dim>;
    static constexpr unsigned int n_nodes = W::n_patch;
    static constexpr unsigned int n_window = W::n_nodes;

    struct Cell
    {
      const CellCache<dim> *   cc    = nullptr;
      const BSplinePatch<dim> *patch = nullptr;
      const UniformBox<dim> *  box   = nullptr;
      const unsigned int *     dofs  = nullptr; // patch slot s, component d at [s * dim + d]
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
    /// the field's values on the point's window
    static inline void
    window(const Field &f, const Eval &e, double (&u)[n_window][dim])
    {
      const unsigned int first = W::first_slot(e);
      for (unsigned int w = 0; w < n_window; ++w)
        for (unsigned int d = 0; d < dim; ++d)
          u[w][d] = f.u[first + W::window_offset(w)][d];
    }
    static inline void
    interpolate(const Field &f, const Eval &e, double (&out)[dim])
    {
      double u[n_window][dim], N[n_window];
      window(f, e, u);
      W::values(e, N);
      for (unsigned int d = 0; d < dim; ++d)
        {
          double s = 0;
          for (unsigned int w = 0; w < n_window; ++w)
            s += N[w] * u[w][d];
          out[d] = s;
        }
    }
    /// grad[c][k] = d u_c / d x_k
    static inline void
    gradient(const Cell &, const Field &f, const Eval &e, double (&grad)[dim][dim])
    {
      double u[n_window][dim], val[dim];
      window(f, e, u);
      W::template interpolate<dim>(e, u, val, grad);
    }
    /// value and gradient at once (one window contraction)
    static inline void
    value_and_gradient(const Cell &, const Field &f, const Eval &e, double (&val)[dim], double (&grad)[dim][dim])
    {
      double u[n_window][dim];
      window(f, e, u);
      W::template interpolate<dim>(e, u, val, grad);
    }

    /// The nodes one point touches, for matrix assembly (transfer/matrix_ops.h):
    /// the point's 3^dim window as patch slots, with values and real-space
    /// gradients (a window node is always inside the grid).
    static constexpr unsigned int n_point_nodes = n_window;
    static inline void
    point_stencil(const Cell &              c,
                  const dealii::Point<dim> &xi,
                  unsigned int (&slot)[n_point_nodes],
                  double (&N)[n_point_nodes],
                  double (&G)[n_point_nodes][dim])
    {
      Eval e;
      evaluate(c, xi, e);
      W::values_and_gradients(e, N, G);
      const unsigned int first = W::first_slot(e);
      for (unsigned int w = 0; w < n_point_nodes; ++w)
        slot[w] = first + W::window_offset(w);
    }

    /// Lumped mass and internal force of a cell's points on the patch.
    struct MassForce
    {
      double lm[n_nodes]     = {};
      double f[n_nodes][dim] = {};
      /// one point: mass m, t = -V sigma
      inline void
      add(const Eval &e, const double m, const double (&t)[dim][dim])
      {
        double N[n_window], G[n_window][dim];
        W::values_and_gradients(e, N, G);
        const unsigned int first = W::first_slot(e);
        for (unsigned int w = 0; w < n_window; ++w)
          {
            const unsigned int s = first + W::window_offset(w);
            lm[s] += m * N[w];
            for (unsigned int c = 0; c < dim; ++c)
              {
                double q = 0;
                for (unsigned int k = 0; k < dim; ++k)
                  q += t[c][k] * G[w][k];
                f[s][c] += q;
              }
          }
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
    scatter_point(const Cell &                  c,
                  const Eval &                  e,
                  const double                  m,
                  const double (&t)[dim][dim],
                  const dealii::Tensor<1, dim> &g,
                  double *                      M,
                  double *                      Fv)
    {
      double N[n_window], G[n_window][dim];
      W::values_and_gradients(e, N, G);
      const unsigned int first = W::first_slot(e);
      for (unsigned int w = 0; w < n_window; ++w)
        {
          const unsigned int s  = first + W::window_offset(w);
          const double       mn = m * N[w];
          for (unsigned int d = 0; d < dim; ++d)
            {
              double q = 0;
              for (unsigned int k = 0; k < dim; ++k)
                q += t[d][k] * G[w][k];
              const unsigned int i = c.dofs[s * dim + d]; // a window node is always in the grid
              M[i] += mn;
              Fv[i] += mn * g[d] + q;
            }
        }
    }

    /// sum_p m_p N(x_p) v_p of a cell's points on the patch
    struct Momentum
    {
      double lp[n_nodes][dim] = {};
      inline void
      add(const Eval &e, const double m, const double *vel)
      {
        double N[n_window];
        W::values(e, N);
        const unsigned int first = W::first_slot(e);
        for (unsigned int w = 0; w < n_window; ++w)
          {
            const unsigned int s = first + W::window_offset(w);
            for (unsigned int d = 0; d < dim; ++d)
              lp[s][d] += m * N[w] * vel[d];
          }
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
