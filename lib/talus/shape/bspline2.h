// talus — uniform node-centred quadratic B-spline shape functions on the box
// grid, with the wall treatment of docs/shape-functions.md.
//
// Nodes are the cell vertices (the FE_Q(1) DoFs), spacing h per direction:
//   N(r) = 3/4 - r^2           |r| <= 1/2
//        = (3/2 - |r|)^2 / 2   1/2 <= |r| <= 3/2,    r = (x - x_I)/h,
//        = 0                   beyond;
// tensor product in 2D/3D. A point in cell j (per direction: nodes j, j+1,
// reference coordinate xi in [0,1]) sees the three nodes j-1, j, j+1 if
// xi < 1/2, else j, j+1, j+2 (its "window").
//
// Walls: every face of the box is a wall. At the lower wall (node 0) the missing
// node -1 is a ghost with v_-1 = 2 v_0 - v_1 (linear extrapolation); eliminating
// it gives N_0^w = N_0 + 2 N_-1, N_1^w = N_1 - N_-1, which on the half cell
// [0, h/2) are exactly the linear hats 1 - xi, xi (likewise at the upper wall
// with nodes n, n-1 and ghost n+1). There the window is shifted into the grid
// (nodes 0, 1, 2 resp. n-2, n-1, n) and its third node gets weight and
// derivative exactly 0, so every window node is a real grid node: a hot loop
// needs no test for nodes outside the grid.
//
// Patch: a cell stores the 4^dim nodes j-1..j+2 per direction (slot p_d = node
// - (j-1), slot = p_0 + 4 p_1 + 16 p_2); the point's window starts at slot
// first[d] (0 or 1) per direction, window node w = a_0 + 3 a_1 + 9 a_2 has
// slot (first[d] + a_d)_d. Slots outside the grid (wall cells) are never
// part of a window. Needs >= 3 cells per direction (BackgroundGrid refuses
// fewer for a B-spline run).
#pragma once

#include <deal.II/base/point.h>

namespace talus::shape
{
  template <int dim>
  struct BSpline2
  {
    static_assert(dim >= 1 && dim <= 3, "BSpline2: dim 1, 2 or 3");
    /// nodes of a point's window (3^dim) and of a cell's patch (4^dim)
    static constexpr unsigned int n_nodes   = dim == 1 ? 3 : dim == 2 ? 9 : 27;
    static constexpr unsigned int n_patch   = dim == 1 ? 4 : dim == 2 ? 16 : 64;
    static constexpr unsigned int min_cells = 3;

    /// Per direction: first window slot in the patch, the 3 values and the 3
    /// real-space derivatives (d/dx_d, i.e. already divided by h).
    struct Eval
    {
      unsigned char first[dim];
      double        N[dim][3];
      double        dN[dim][3];
    };

    /// One direction: cell j of n, reference coordinate xi in [0,1].
    static inline void
    evaluate_1d(const unsigned int j,
                const unsigned int n,
                const double       inv_h,
                const double       xi,
                unsigned char &    first,
                double (&N)[3],
                double (&dN)[3])
    {
      double s; // point position relative to the window's middle node, in [-1/2, 1/2]
      if (xi < 0.5)
        {
          if (j == 0) // lower wall half cell: linear hats on nodes 0, 1
            {
              first = 1;
              N[0]  = 1.0 - xi;
              N[1]  = xi;
              N[2]  = 0.0;
              dN[0] = -inv_h;
              dN[1] = inv_h;
              dN[2] = 0.0;
              return;
            }
          first = 0;
          s     = xi;
        }
      else
        {
          if (j + 1 == n) // upper wall half cell: linear hats on nodes n-1, n
            {
              first = 0;
              N[0]  = 0.0;
              N[1]  = 1.0 - xi;
              N[2]  = xi;
              dN[0] = 0.0;
              dN[1] = -inv_h;
              dN[2] = inv_h;
              return;
            }
          first = 1;
          s     = xi - 1.0;
        }
      const double a = 0.5 - s, b = 0.5 + s;
      N[0]  = 0.5 * a * a;
      N[1]  = 0.75 - s * s;
      N[2]  = 0.5 * b * b;
      dN[0] = -a * inv_h;
      dN[1] = -2.0 * s * inv_h;
      dN[2] = b * inv_h;
    }

    /// i_cell[d]: index of the point's cell per direction among n_cells[d];
    /// inv_h: 1/h per direction; xi: reference coordinates in [0,1]^dim.
    static inline void
    evaluate(const unsigned int (&i_cell)[dim],
             const unsigned int (&n_cells)[dim],
             const double (&inv_h)[dim],
             const dealii::Point<dim> &xi,
             Eval &                    e)
    {
      for (unsigned int d = 0; d < dim; ++d)
        evaluate_1d(i_cell[d], n_cells[d], inv_h[d], xi[d], e.first[d], e.N[d], e.dN[d]);
    }

    /// Digit a_d of window node w (w = a_0 + 3 a_1 + 9 a_2).
    static constexpr unsigned int
    digit(const unsigned int w, const unsigned int d)
    {
      return d == 0 ? w % 3 : d == 1 ? (w / 3) % 3 : w / 9;
    }

    /// Patch slot of window node w relative to the window's first slot.
    static constexpr unsigned int
    window_offset(const unsigned int w)
    {
      unsigned int s = 0, m = 1;
      for (unsigned int d = 0; d < dim; ++d, m *= 4)
        s += digit(w, d) * m;
      return s;
    }

    /// Patch slot of the window's first node; slot of node w = first_slot + window_offset(w).
    static inline unsigned int
    first_slot(const Eval &e)
    {
      unsigned int s = 0, m = 1;
      for (unsigned int d = 0; d < dim; ++d, m *= 4)
        s += e.first[d] * m;
      return s;
    }

    static inline unsigned int
    patch_slot(const Eval &e, const unsigned int w)
    {
      return first_slot(e) + window_offset(w);
    }

    static inline double
    value(const Eval &e, const unsigned int w)
    {
      double v = 1.0;
      for (unsigned int d = 0; d < dim; ++d)
        v *= e.N[d][digit(w, d)];
      return v;
    }

    static inline void
    gradient(const Eval &e, const unsigned int w, double (&g)[dim])
    {
      for (unsigned int k = 0; k < dim; ++k)
        {
          double v = 1.0;
          for (unsigned int d = 0; d < dim; ++d)
            v *= (d == k ? e.dN[d][digit(w, d)] : e.N[d][digit(w, d)]);
          g[k] = v;
        }
    }

    /// Values of all window nodes (tensor product, loops unrolled by the compiler).
    static inline void
    values(const Eval &e, double (&N)[n_nodes])
    {
      if constexpr (dim == 1)
        for (unsigned int a = 0; a < 3; ++a)
          N[a] = e.N[0][a];
      else if constexpr (dim == 2)
        for (unsigned int b = 0; b < 3; ++b)
          for (unsigned int a = 0; a < 3; ++a)
            N[a + 3 * b] = e.N[0][a] * e.N[1][b];
      else
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double nbc = e.N[1][b] * e.N[2][c];
              for (unsigned int a = 0; a < 3; ++a)
                N[a + 3 * b + 9 * c] = e.N[0][a] * nbc;
            }
    }

    /// Values and real-space gradients of all window nodes.
    static inline void
    values_and_gradients(const Eval &e, double (&N)[n_nodes], double (&G)[n_nodes][dim])
    {
      if constexpr (dim == 1)
        for (unsigned int a = 0; a < 3; ++a)
          {
            N[a]    = e.N[0][a];
            G[a][0] = e.dN[0][a];
          }
      else if constexpr (dim == 2)
        for (unsigned int b = 0; b < 3; ++b)
          for (unsigned int a = 0; a < 3; ++a)
            {
              const unsigned int w = a + 3 * b;
              N[w]                 = e.N[0][a] * e.N[1][b];
              G[w][0]              = e.dN[0][a] * e.N[1][b];
              G[w][1]              = e.N[0][a] * e.dN[1][b];
            }
      else
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double nbc = e.N[1][b] * e.N[2][c], dbc = e.dN[1][b] * e.N[2][c],
                           nbd = e.N[1][b] * e.dN[2][c];
              for (unsigned int a = 0; a < 3; ++a)
                {
                  const unsigned int w = a + 3 * b + 9 * c;
                  N[w]                 = e.N[0][a] * nbc;
                  G[w][0]              = e.dN[0][a] * nbc;
                  G[w][1]              = e.N[0][a] * dbc;
                  G[w][2]              = e.N[0][a] * nbd;
                }
            }
    }

    /// Value u_c(x) = sum_w N_w u[w][c] and gradient grad[c][k] = d u_c/d x_k of a
    /// field with nc components from its window nodal values u[w][c], sum-factorised
    /// (contract direction 0 first, then 1, then 2): no per-node gradients needed.
    template <unsigned int nc>
    static inline void
    interpolate(const Eval &e, const double (&u)[n_nodes][nc], double (&val)[nc], double (&grad)[nc][dim])
    {
      if constexpr (dim == 1)
        {
          for (unsigned int c = 0; c < nc; ++c)
            {
              val[c]     = e.N[0][0] * u[0][c] + e.N[0][1] * u[1][c] + e.N[0][2] * u[2][c];
              grad[c][0] = e.dN[0][0] * u[0][c] + e.dN[0][1] * u[1][c] + e.dN[0][2] * u[2][c];
            }
        }
      else if constexpr (dim == 2)
        {
          // along direction 0 for each of the 3 lines b: value and x-derivative
          double v0[3][nc], d0[3][nc];
          for (unsigned int b = 0; b < 3; ++b)
            for (unsigned int c = 0; c < nc; ++c)
              {
                v0[b][c] = e.N[0][0] * u[3 * b][c] + e.N[0][1] * u[3 * b + 1][c] + e.N[0][2] * u[3 * b + 2][c];
                d0[b][c] = e.dN[0][0] * u[3 * b][c] + e.dN[0][1] * u[3 * b + 1][c] + e.dN[0][2] * u[3 * b + 2][c];
              }
          for (unsigned int c = 0; c < nc; ++c)
            {
              val[c]     = e.N[1][0] * v0[0][c] + e.N[1][1] * v0[1][c] + e.N[1][2] * v0[2][c];
              grad[c][0] = e.N[1][0] * d0[0][c] + e.N[1][1] * d0[1][c] + e.N[1][2] * d0[2][c];
              grad[c][1] = e.dN[1][0] * v0[0][c] + e.dN[1][1] * v0[1][c] + e.dN[1][2] * v0[2][c];
            }
        }
      else
        {
          // direction 0 over the 9 lines (b, c'), then direction 1 over the 3 planes
          double v0[9][nc], d0[9][nc];
          for (unsigned int l = 0; l < 9; ++l)
            for (unsigned int c = 0; c < nc; ++c)
              {
                v0[l][c] = e.N[0][0] * u[3 * l][c] + e.N[0][1] * u[3 * l + 1][c] + e.N[0][2] * u[3 * l + 2][c];
                d0[l][c] = e.dN[0][0] * u[3 * l][c] + e.dN[0][1] * u[3 * l + 1][c] + e.dN[0][2] * u[3 * l + 2][c];
              }
          double v1[3][nc], dx1[3][nc], dy1[3][nc];
          for (unsigned int p = 0; p < 3; ++p)
            for (unsigned int c = 0; c < nc; ++c)
              {
                const unsigned int l = 3 * p;
                v1[p][c]  = e.N[1][0] * v0[l][c] + e.N[1][1] * v0[l + 1][c] + e.N[1][2] * v0[l + 2][c];
                dx1[p][c] = e.N[1][0] * d0[l][c] + e.N[1][1] * d0[l + 1][c] + e.N[1][2] * d0[l + 2][c];
                dy1[p][c] = e.dN[1][0] * v0[l][c] + e.dN[1][1] * v0[l + 1][c] + e.dN[1][2] * v0[l + 2][c];
              }
          for (unsigned int c = 0; c < nc; ++c)
            {
              val[c]     = e.N[2][0] * v1[0][c] + e.N[2][1] * v1[1][c] + e.N[2][2] * v1[2][c];
              grad[c][0] = e.N[2][0] * dx1[0][c] + e.N[2][1] * dx1[1][c] + e.N[2][2] * dx1[2][c];
              grad[c][1] = e.N[2][0] * dy1[0][c] + e.N[2][1] * dy1[1][c] + e.N[2][2] * dy1[2][c];
              grad[c][2] = e.dN[2][0] * v1[0][c] + e.dN[2][1] * v1[1][c] + e.dN[2][2] * v1[2][c];
            }
        }
    }
  };
} // namespace talus::shape
