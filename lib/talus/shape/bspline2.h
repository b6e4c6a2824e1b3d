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
// Patch and window layout, Eval and the hot-loop helpers (values, gradients,
// sum-factorised interpolation): window3.h. Slots of the 4^dim patch outside the
// grid (wall cells) are never part of a window. Needs >= 3 cells per direction
// (BackgroundGrid refuses fewer for a B-spline run).
#pragma once

#include <talus/shape/window3.h>

#include <deal.II/base/point.h>

namespace talus::shape
{
  template <int dim>
  struct BSpline2 : Window3<dim>
  {
    using Eval = typename Window3<dim>::Eval;
    /// cells per direction the wall treatment needs (BackgroundGrid refuses fewer)
    static constexpr unsigned int min_cells = 3;

    /// One direction: cell j of n, reference coordinate xi in [0,1].
    static inline void
    evaluate_1d(const unsigned int j, const unsigned int n, const double inv_h, const double xi, unsigned char &first,
                double (&N)[3], double (&dN)[3])
    {
      // Which half of the cell is data-dependent and unpredictable for the points of a
      // cell: select it without a branch; only the (rare, predictable) wall test branches.
      const bool upper = xi >= 0.5;
      if (upper ? j + 1 == n : j == 0)
        {
          // wall half cell: linear hats on nodes 0, 1 (window 0, 1, 2) resp. n-1, n
          // (window n-2, n-1, n)
          const unsigned int o = upper ? 1 : 0, z = upper ? 0 : 2;
          first     = upper ? 0 : 1;
          N[o]      = 1.0 - xi;
          N[o + 1]  = xi;
          N[z]      = 0.0;
          dN[o]     = -inv_h;
          dN[o + 1] = inv_h;
          dN[z]     = 0.0;
          return;
        }
      evaluate_1d_inner(inv_h, xi, first, N, dN);
    }

    /// evaluate_1d() for a cell that is not next to a wall in this direction
    /// (0 < j < n - 1): no wall test
    static inline void
    evaluate_1d_inner(const double inv_h, const double xi, unsigned char &first, double (&N)[3], double (&dN)[3])
    {
      const bool upper = xi >= 0.5;
      first            = upper ? 1 : 0;
      const double s   = upper ? xi - 1.0 : xi; // relative to the window's middle node, in [-1/2, 1/2]
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
    evaluate(const unsigned int (&i_cell)[dim], const unsigned int (&n_cells)[dim], const double (&inv_h)[dim],
             const dealii::Point<dim> &xi, Eval &e)
    {
      for (unsigned int d = 0; d < dim; ++d)
        evaluate_1d(i_cell[d], n_cells[d], inv_h[d], xi[d], e.first[d], e.N[d], e.dN[d]);
    }
  };
} // namespace talus::shape
