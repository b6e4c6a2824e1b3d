// talus — the tensor-product window of three nodes per direction shared by the
// quadratic B-spline (bspline2.h) and GIMP (gimp.h) kernels: the per-point
// evaluation record, the window -> patch slot map and the hot-loop helpers.
//
// A point in cell j (per direction) has a window of 3 nodes, first[d] (0 or 1)
// slots into the cell's 4^dim patch of nodes j-1..j+2 (slot p_d = node - (j-1),
// slot = p_0 + 4 p_1 + 16 p_2); window node w = a_0 + 3 a_1 + 9 a_2 has slot
// (first[d] + a_d)_d.
#pragma once

namespace talus::shape
{
  template <int dim>
  struct Window3
  {
    static_assert(dim >= 1 && dim <= 3, "Window3: dim 1, 2 or 3");
    /// nodes of a point's window (3^dim) and of a cell's patch (4^dim)
    static constexpr unsigned int n_nodes = dim == 1 ? 3 : dim == 2 ? 9 : 27;
    static constexpr unsigned int n_patch = dim == 1 ? 4 : dim == 2 ? 16 : 64;

    /// Per direction: first window slot in the patch, the 3 values and the 3
    /// real-space derivatives (d/dx_d, i.e. already divided by h).
    struct Eval
    {
      unsigned char first[dim];
      double        N[dim][3];
      double        dN[dim][3];
    };

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
              const double nbc = e.N[1][b] * e.N[2][c], dbc = e.dN[1][b] * e.N[2][c], nbd = e.N[1][b] * e.dN[2][c];
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
      interpolate_strided<nc, 3, 9>(e, u, val, grad);
    }

    /// interpolate() on nodal values whose window lines (direction 0) start S1
    /// apart and planes S2 apart: 3, 9 for a window array; 4, 16 for a 4^dim patch
    /// read from the window's first slot (the kernels contract the patch in place
    /// instead of copying the window out first). Same arithmetic for any strides.
    template <unsigned int nc, unsigned int S1, unsigned int S2>
    static inline void
    interpolate_strided(const Eval &e, const double (*u)[nc], double (&val)[nc], double (&grad)[nc][dim])
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
            {
              const double(*r)[nc] = u + S1 * b;
              for (unsigned int c = 0; c < nc; ++c)
                {
                  v0[b][c] = e.N[0][0] * r[0][c] + e.N[0][1] * r[1][c] + e.N[0][2] * r[2][c];
                  d0[b][c] = e.dN[0][0] * r[0][c] + e.dN[0][1] * r[1][c] + e.dN[0][2] * r[2][c];
                }
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
          // direction 0 over the 9 lines l = b + 3 c', then direction 1 over the 3 planes
          double v0[9][nc], d0[9][nc];
          for (unsigned int l = 0; l < 9; ++l)
            {
              const double(*r)[nc] = u + S1 * (l % 3) + S2 * (l / 3);
              for (unsigned int c = 0; c < nc; ++c)
                {
                  v0[l][c] = e.N[0][0] * r[0][c] + e.N[0][1] * r[1][c] + e.N[0][2] * r[2][c];
                  d0[l][c] = e.dN[0][0] * r[0][c] + e.dN[0][1] * r[1][c] + e.dN[0][2] * r[2][c];
                }
            }
          double v1[3][nc], dx1[3][nc], dy1[3][nc];
          for (unsigned int p = 0; p < 3; ++p)
            for (unsigned int c = 0; c < nc; ++c)
              {
                const unsigned int l = 3 * p;
                v1[p][c]             = e.N[1][0] * v0[l][c] + e.N[1][1] * v0[l + 1][c] + e.N[1][2] * v0[l + 2][c];
                dx1[p][c]            = e.N[1][0] * d0[l][c] + e.N[1][1] * d0[l + 1][c] + e.N[1][2] * d0[l + 2][c];
                dy1[p][c]            = e.dN[1][0] * v0[l][c] + e.dN[1][1] * v0[l + 1][c] + e.dN[1][2] * v0[l + 2][c];
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

    /// The value part of interpolate_strided() alone (direction by direction:
    /// sums of 3 terms, where a node-by-node sum chains 3^dim dependent additions).
    template <unsigned int nc, unsigned int S1, unsigned int S2>
    static inline void
    interpolate_value_strided(const Eval &e, const double (*u)[nc], double (&val)[nc])
    {
      auto along0 = [&](const double(*r)[nc], const unsigned int c) {
        return e.N[0][0] * r[0][c] + e.N[0][1] * r[1][c] + e.N[0][2] * r[2][c];
      };
      if constexpr (dim == 1)
        for (unsigned int c = 0; c < nc; ++c)
          val[c] = along0(u, c);
      else if constexpr (dim == 2)
        for (unsigned int c = 0; c < nc; ++c)
          val[c] = e.N[1][0] * along0(u, c) + e.N[1][1] * along0(u + S1, c) + e.N[1][2] * along0(u + 2 * S1, c);
      else
        for (unsigned int c = 0; c < nc; ++c)
          {
            double v1[3];
            for (unsigned int p = 0; p < 3; ++p)
              {
                const double(*r)[nc] = u + S2 * p;
                v1[p] = e.N[1][0] * along0(r, c) + e.N[1][1] * along0(r + S1, c) + e.N[1][2] * along0(r + 2 * S1, c);
              }
            val[c] = e.N[2][0] * v1[0] + e.N[2][1] * v1[1] + e.N[2][2] * v1[2];
          }
    }

    /// Calls f(o, N_w, G_w) for the window nodes w in order (a fastest): o is the
    /// node's patch slot relative to the window's first slot (patch strides 4, 16),
    /// N_w and G_w (real-space gradient) the same products as values_and_gradients().
    /// Explicit loops over the digits, so that no slot or digit is computed by
    /// division at run time (the w-indexed loops were not unrolled by gcc -O2).
    template <class F>
    static inline void
    for_each_window_node(const Eval &e, F &&f)
    {
      if constexpr (dim == 1)
        for (unsigned int a = 0; a < 3; ++a)
          {
            const double g[1] = {e.dN[0][a]};
            f(a, e.N[0][a], g);
          }
      else if constexpr (dim == 2)
        for (unsigned int b = 0; b < 3; ++b)
          for (unsigned int a = 0; a < 3; ++a)
            {
              const double g[2] = {e.dN[0][a] * e.N[1][b], e.N[0][a] * e.dN[1][b]};
              f(a + 4 * b, e.N[0][a] * e.N[1][b], g);
            }
      else
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double nbc = e.N[1][b] * e.N[2][c], dbc = e.dN[1][b] * e.N[2][c], nbd = e.N[1][b] * e.dN[2][c];
              for (unsigned int a = 0; a < 3; ++a)
                {
                  const double g[3] = {e.dN[0][a] * nbc, e.N[0][a] * dbc, e.N[0][a] * nbd};
                  f(a + 4 * b + 16 * c, e.N[0][a] * nbc, g);
                }
            }
    }

    /// The same with values only (f(o, N_w); no gradient products).
    template <class F>
    static inline void
    for_each_window_value(const Eval &e, F &&f)
    {
      if constexpr (dim == 1)
        for (unsigned int a = 0; a < 3; ++a)
          f(a, e.N[0][a]);
      else if constexpr (dim == 2)
        for (unsigned int b = 0; b < 3; ++b)
          for (unsigned int a = 0; a < 3; ++a)
            f(a + 4 * b, e.N[0][a] * e.N[1][b]);
      else
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double nbc = e.N[1][b] * e.N[2][c];
              for (unsigned int a = 0; a < 3; ++a)
                f(a + 4 * b + 16 * c, e.N[0][a] * nbc);
            }
    }
  };
} // namespace talus::shape
