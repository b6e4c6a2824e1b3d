// talus — linear (Q1) shape functions on an axis-aligned box cell, evaluated from
// the reference coordinates of a point. This is the kernel of every particle loop:
// it costs a handful of multiplications, so the loops evaluate it from the
// particle's reference location in each pass instead of storing 2^dim values and
// dim*2^dim gradients per particle (which would cost more in memory traffic).
//
// Vertex numbering follows deal.II (lexicographic): vertex v has the reference
// coordinate bit d of v in direction d.
#pragma once

#include <deal.II/base/point.h>

namespace talus::shape
{
  template <int dim>
  struct Q1
  {
    static constexpr unsigned int n_vertices = 1u << dim;

    /// Values N_v(xi).
    static inline void
    values(const dealii::Point<dim> &xi, double (&N)[n_vertices])
    {
      for (unsigned int v = 0; v < n_vertices; ++v)
        {
          double n = 1.0;
          for (unsigned int d = 0; d < dim; ++d)
            n *= ((v >> d) & 1u) ? xi[d] : 1.0 - xi[d];
          N[v] = n;
        }
    }

    /// Values N_v(xi) and real-space gradients dN_v/dx_d for a box cell with
    /// extents h (inv_h = 1/h per direction).
    static inline void
    values_and_gradients(const dealii::Point<dim> &xi,
                         const double (&inv_h)[dim],
                         double (&N)[n_vertices],
                         double (&G)[n_vertices][dim])
    {
      double f[dim][2], df[dim][2];
      for (unsigned int d = 0; d < dim; ++d)
        {
          f[d][0]  = 1.0 - xi[d];
          f[d][1]  = xi[d];
          df[d][0] = -inv_h[d];
          df[d][1] = inv_h[d];
        }
      for (unsigned int v = 0; v < n_vertices; ++v)
        {
          const unsigned int b0 = v & 1u;
          if constexpr (dim == 1)
            {
              N[v]    = f[0][b0];
              G[v][0] = df[0][b0];
            }
          else if constexpr (dim == 2)
            {
              const unsigned int b1 = (v >> 1) & 1u;
              N[v]                  = f[0][b0] * f[1][b1];
              G[v][0]               = df[0][b0] * f[1][b1];
              G[v][1]               = f[0][b0] * df[1][b1];
            }
          else
            {
              const unsigned int b1 = (v >> 1) & 1u, b2 = (v >> 2) & 1u;
              N[v]    = f[0][b0] * f[1][b1] * f[2][b2];
              G[v][0] = df[0][b0] * f[1][b1] * f[2][b2];
              G[v][1] = f[0][b0] * df[1][b1] * f[2][b2];
              G[v][2] = f[0][b0] * f[1][b1] * df[2][b2];
            }
        }
    }
  };
} // namespace talus::shape
