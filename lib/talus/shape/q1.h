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
    values_and_gradients(const dealii::Point<dim> &xi, const double (&inv_h)[dim], double (&N)[n_vertices],
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

namespace talus::shape
{
  /// Sum-factorised Q1 operations on a box cell. For axis k, the 2^(dim-1) vertex
  /// pairs (v0, v1 = v0 + 2^k) differ only in coordinate k; the derivative of a Q1
  /// field along k is inv_h[k] * sum_j w_k(j) (u[v1] - u[v0]), with w_k(j) the
  /// product of the 1D factors of the other axes. The particle loops use this to
  ///  * take gradients from per-cell nodal differences (no per-vertex gradients);
  ///  * accumulate the internal force of many particles in dim * 2^(dim-1) * dim
  ///    sums per cell, expanded to the 2^dim vertices once per cell.
  template <int dim>
  struct Q1Factorised
  {
    static constexpr unsigned int nv     = 1u << dim;
    static constexpr unsigned int npairs = 1u << (dim - 1);

    /// vertex v0 of pair j along axis k: insert a zero bit at position k of j
    static constexpr unsigned int
    pair_vertex(const unsigned int k, const unsigned int j)
    {
      const unsigned int low = j & ((1u << k) - 1u);
      return low | ((j >> k) << (k + 1));
    }

    /// 1D factors f[d][0] = 1 - xi_d, f[d][1] = xi_d; values N_v; pair weights.
    static inline void
    weights(const dealii::Point<dim> &xi, double (&N)[nv], double (&w)[dim][npairs])
    {
      double f[dim][2];
      for (unsigned int d = 0; d < dim; ++d)
        {
          f[d][0] = 1.0 - xi[d];
          f[d][1] = xi[d];
        }
      if constexpr (dim == 2)
        {
          // axis 0 pairs are indexed by b1, axis 1 pairs by b0
          w[0][0] = f[1][0];
          w[0][1] = f[1][1];
          w[1][0] = f[0][0];
          w[1][1] = f[0][1];
          N[0]    = f[0][0] * f[1][0];
          N[1]    = f[0][1] * f[1][0];
          N[2]    = f[0][0] * f[1][1];
          N[3]    = f[0][1] * f[1][1];
        }
      else
        {
          // axis 0: j = b1 + 2 b2; axis 1: j = b0 + 2 b2; axis 2: j = b0 + 2 b1
          for (unsigned int a = 0; a < 2; ++a)
            for (unsigned int b = 0; b < 2; ++b)
              {
                w[0][a + 2 * b] = f[1][a] * f[2][b];
                w[1][a + 2 * b] = f[0][a] * f[2][b];
                w[2][a + 2 * b] = f[0][a] * f[1][b];
              }
          for (unsigned int v = 0; v < nv; ++v)
            N[v] = w[2][(v & 1u) + ((v >> 1) & 1u) * 2] * f[2][(v >> 2) & 1u];
        }
    }

    /// Per-cell nodal differences D[k][j][c] = u[v1][c] - u[v0][c] of a vector
    /// field u[v][c] (c < dim).
    static inline void
    differences(const double (&u)[nv][dim], double (&D)[dim][npairs][dim])
    {
      for (unsigned int k = 0; k < dim; ++k)
        for (unsigned int j = 0; j < npairs; ++j)
          {
            const unsigned int v0 = pair_vertex(k, j), v1 = v0 | (1u << k);
            for (unsigned int c = 0; c < dim; ++c)
              D[k][j][c] = u[v1][c] - u[v0][c];
          }
    }

    /// grad[c][k] = d u_c / d x_k at the point with pair weights w.
    static inline void
    gradient(const double (&D)[dim][npairs][dim], const double (&w)[dim][npairs], const double (&inv_h)[dim],
             double (&grad)[dim][dim])
    {
      for (unsigned int k = 0; k < dim; ++k)
        for (unsigned int c = 0; c < dim; ++c)
          {
            double s = 0;
            for (unsigned int j = 0; j < npairs; ++j)
              s += w[k][j] * D[k][j][c];
            grad[c][k] = s * inv_h[k];
          }
    }

    /// Add the pair moments of one particle: T[k][j][c] += t[c][k] w[k][j], with
    /// t = -V sigma (the internal force integrand).
    static inline void
    add_moments(const double (&t)[dim][dim], const double (&w)[dim][npairs], double (&T)[dim][npairs][dim])
    {
      for (unsigned int k = 0; k < dim; ++k)
        for (unsigned int j = 0; j < npairs; ++j)
          for (unsigned int c = 0; c < dim; ++c)
            T[k][j][c] += t[c][k] * w[k][j];
    }

    /// Expand accumulated pair moments into vertex forces f[v][c] (added).
    static inline void
    expand_moments(const double (&T)[dim][npairs][dim], const double (&inv_h)[dim], double (&f)[nv][dim])
    {
      for (unsigned int k = 0; k < dim; ++k)
        for (unsigned int j = 0; j < npairs; ++j)
          {
            const unsigned int v0 = pair_vertex(k, j), v1 = v0 | (1u << k);
            for (unsigned int c = 0; c < dim; ++c)
              {
                const double q = T[k][j][c] * inv_h[k];
                f[v0][c] -= q;
                f[v1][c] += q;
              }
          }
    }
  };
} // namespace talus::shape
