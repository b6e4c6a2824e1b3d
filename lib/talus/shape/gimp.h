// talus — uniform GIMP (generalised interpolation material point) shape functions
// on the box grid: the linear hat averaged over the point's domain
// [x_p - l_p, x_p + l_p] per direction (half-width l_p fixed, e.g. from the
// initial volume: l_p = V^(1/dim)/2), with a = l_p/h in (0, 1/2] and
// r = (x_p - x_I)/h:
//   S(r) = 1 - (r^2 + a^2)/(2a)        |r| < a
//        = 1 - |r|                     a <= |r| <= 1 - a
//        = (1 + a - |r|)^2 / (4a)      1 - a < |r| < 1 + a
//        = 0                           beyond.
// A point in cell j touches at most nodes j-1..j+2 and at most 3 of them, so it
// uses the same window (window3.h) and the same 4^dim patch as the quadratic
// B-spline: first = 0 if xi < 1/2, else 1 (the unused node has weight 0).
//
// Walls: the same ghost extrapolation as bspline2.h (v_-1 = 2 v_0 - v_1). It
// only matters when the point's domain crosses the wall (xi < a in cell 0),
// and there S_0 + 2 S_-1 = 1 - xi, S_1 - S_-1 = xi exactly: the linear hats,
// interpolatory at the wall; the switch at xi = a is C1. Partition of unity and
// linear reproduction hold everywhere. Same patch, same >= 3 cells.
#pragma once

#include <talus/shape/window3.h>

#include <deal.II/base/point.h>

#include <algorithm>

namespace talus::shape
{
  template <int dim>
  struct GIMP : Window3<dim>
  {
    using Eval                              = typename Window3<dim>::Eval;
    static constexpr unsigned int min_cells = 3;

    /// S(r) and dS/dr for a = l_p/h.
    static inline void
    hat(const double r, const double a, double &S, double &dS)
    {
      const double q = r < 0 ? -r : r, sg = r < 0 ? -1.0 : 1.0;
      if (q < a)
        {
          S  = 1.0 - (r * r + a * a) / (2.0 * a);
          dS = -r / a;
        }
      else if (q <= 1.0 - a)
        {
          S  = 1.0 - q;
          dS = -sg;
        }
      else if (q < 1.0 + a)
        {
          const double t = 1.0 + a - q;
          S              = t * t / (4.0 * a);
          dS             = -sg * t / (2.0 * a);
        }
      else
        S = dS = 0.0;
    }

    /// One direction: cell j of n, reference coordinate xi, a = l_p/h (clamped
    /// to (0, 1/2]: a domain wider than a cell would reach a 4th node).
    static inline void
    evaluate_1d(const unsigned int j, const unsigned int n, const double inv_h, const double xi, double a,
                unsigned char &first, double (&N)[3], double (&dN)[3])
    {
      a = std::min(std::max(a, 1e-12), 0.5);
      if ((j == 0 && xi < a) || (j + 1 == n && xi > 1.0 - a))
        {
          // the domain crosses a wall: linear hats (ghost extrapolation)
          const bool lower     = j == 0 && xi < a;
          first                = lower ? 1 : 0;
          const unsigned int o = lower ? 0 : 1;
          N[o]                 = 1.0 - xi;
          N[o + 1]             = xi;
          N[lower ? 2 : 0]     = 0.0;
          dN[o]                = -inv_h;
          dN[o + 1]            = inv_h;
          dN[lower ? 2 : 0]    = 0.0;
          return;
        }
      // window j-1, j, j+1 (xi < 1/2) or j, j+1, j+2; in a wall cell the node
      // outside the grid has weight 0 here, so shift the window inside
      first = xi < 0.5 ? (j == 0 ? 1 : 0) : (j + 1 == n ? 0 : 1);
      for (unsigned int k = 0; k < 3; ++k)
        {
          const double r = xi + 1.0 - first - k; // (x_p - x_node)/h, node = j - 1 + first + k
          double       S, dS;
          hat(r, a, S, dS);
          N[k]  = S;
          dN[k] = dS * inv_h;
        }
    }

    /// As BSpline2::evaluate, with a[d] = l_p/h_d of the point.
    static inline void
    evaluate(const unsigned int (&i_cell)[dim], const unsigned int (&n_cells)[dim], const double (&inv_h)[dim],
             const dealii::Point<dim> &xi, const double (&a)[dim], Eval &e)
    {
      for (unsigned int d = 0; d < dim; ++d)
        evaluate_1d(i_cell[d], n_cells[d], inv_h[d], xi[d], a[d], e.first[d], e.N[d], e.dN[d]);
    }
  };
} // namespace talus::shape
