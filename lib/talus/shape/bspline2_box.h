// talus — the quadratic B-spline kernel (shape/bspline2.h, walls as in
// docs/shape-functions.md) as a compile-time policy for the transfer ops; the
// interface is the one described in shape/q1_box.h.
//
// A cell's stencil is its 4^dim node patch (BackgroundGrid::setup_bspline_patches);
// a point uses the 3^dim window of that patch its position selects. Nodal data
// are gathered once per cell for the whole patch; per point the window is
// contracted direction by direction (Window3::interpolate), and the per-cell
// sums of mass, force and momentum live on the patch, scattered once per cell.
//
// The hot loops run on pairs of doubles (shape/pair.h): a node's record on the
// patch is a whole number of pairs (a vector field: its dim components, padded
// to 4 in 3D; the mass/force sums: lumped mass and dim force components, padded
// to 4), every lane doing the scalar arithmetic of the per-component form
// (bitwise the same results). A patch whose slots are all inside the grid with
// consecutive DoFs per node (BSplinePatch::full, every cell away from the box's
// walls) is gathered and scattered with one index per node.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/shape/bspline2.h>
#include <talus/shape/pair.h>

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
      return {&grid.cells.filled_entry(c), &p, &grid.box, p.dofs};
    }

    using Eval   = typename W::Eval;
    using Values = typename W::Eval;
    static inline void
    evaluate(const Cell &c, const dealii::Point<dim> &xi, Eval &e)
    {
      // a full patch (all 4^dim slots inside the grid) is a cell away from every
      // wall: no point of it is in a wall half cell
      if (c.patch->full)
        for (unsigned int d = 0; d < dim; ++d)
          B::evaluate_1d_inner(c.box->inv_h[d], xi[d], e.first[d], e.N[d], e.dN[d]);
      else
        B::evaluate(c.patch->i_cell, c.box->n_cells, c.box->inv_h, xi, e);
    }
    static inline void
    values(const Cell &c, const dealii::Point<dim> &xi, Values &e)
    {
      evaluate(c, xi, e);
    }

    /// pairs and doubles per node of a vector field on the patch (3D: padded)
    static constexpr unsigned int field_pairs = (dim + 1) / 2;
    static constexpr unsigned int field_width = 2 * field_pairs;

    /// A vector field on the cell's patch: u[s][c] (slots outside the grid: 0;
    /// the padding lane of 3D: 0).
    struct Field
    {
      alignas(16) double u[n_nodes][field_width];
    };
    static inline void
    gather(const Cell &c, const double *V, const double scale, Field &f, const bool)
    {
      if (c.patch->full)
        {
          const Pair s2 = broadcast(scale);
          for (unsigned int s = 0; s < n_nodes; ++s)
            {
              const double *v = V + c.dofs[s * dim];
              store_aligned(f.u[s], s2 * load_unaligned(v));
              if constexpr (dim == 3)
                store_aligned(f.u[s] + 2, Pair{scale * v[2], 0.0});
            }
          return;
        }
      for (unsigned int s = 0; s < n_nodes; ++s)
        {
          for (unsigned int d = 0; d < dim; ++d)
            {
              const unsigned int i = c.dofs[s * dim + d];
              f.u[s][d]            = i == dealii::numbers::invalid_unsigned_int ? 0.0 : scale * V[i];
            }
          for (unsigned int d = dim; d < field_width; ++d)
            f.u[s][d] = 0.0;
        }
    }

    /// The field on the point's window, contracted on pairs of components in
    /// the order of W::interpolate_strided (direction 0, then 1, then 2): the
    /// value (sums of N) and, with `with_gradient`, the gradient (one dN per
    /// term) as pairs: val[v], grad[k][v] hold components 2v, 2v + 1.
    template <bool with_gradient>
    static inline void
    contract(const Field &f, const Eval &e, Pair (&val)[field_pairs], Pair (&grad)[dim][field_pairs])
    {
      constexpr unsigned int P      = field_pairs;
      const double(*u)[field_width] = f.u + W::first_slot(e);
      Pair n[dim][3], dn[dim][3];
      for (unsigned int d = 0; d < dim; ++d)
        for (unsigned int a = 0; a < 3; ++a)
          {
            n[d][a]  = broadcast(e.N[d][a]);
            dn[d][a] = broadcast(e.dN[d][a]);
          }
      auto sum3 = [](const Pair(&w)[3], const Pair(*x)[P], const unsigned int v) {
        return w[0] * x[0][v] + w[1] * x[1][v] + w[2] * x[2][v];
      };
      // along direction 0 on the 3 window lines of plane k (the window itself in
      // 2D): value and x-derivative, contracted along direction 1 at once (a
      // plane's line sums only are live: fewer spills than all 9 lines first)
      auto plane = [&](const unsigned int k, Pair(&pv)[P], Pair(&pdx)[P], Pair(&pdy)[P]) {
        Pair v0[3][P], d0[3][P];
        for (unsigned int b = 0; b < 3; ++b)
          {
            const double(*r)[field_width] = u + 4 * b + 16 * k;
            for (unsigned int v = 0; v < P; ++v)
              {
                const Pair r0 = load_aligned(r[0] + 2 * v), r1 = load_aligned(r[1] + 2 * v),
                           r2 = load_aligned(r[2] + 2 * v);
                v0[b][v]      = n[0][0] * r0 + n[0][1] * r1 + n[0][2] * r2;
                if constexpr (with_gradient)
                  d0[b][v] = dn[0][0] * r0 + dn[0][1] * r1 + dn[0][2] * r2;
              }
          }
        for (unsigned int v = 0; v < P; ++v)
          {
            pv[v] = sum3(n[1], v0, v);
            if constexpr (with_gradient)
              {
                pdx[v] = sum3(n[1], d0, v);
                pdy[v] = sum3(dn[1], v0, v);
              }
          }
      };
      if constexpr (dim == 2)
        plane(0, val, grad[0], grad[1]);
      else
        {
          // then direction 2 over the 3 planes
          Pair v1[3][P], dx1[3][P], dy1[3][P];
          for (unsigned int k = 0; k < 3; ++k)
            plane(k, v1[k], dx1[k], dy1[k]);
          for (unsigned int v = 0; v < P; ++v)
            {
              val[v] = sum3(n[2], v1, v);
              if constexpr (with_gradient)
                {
                  grad[0][v] = sum3(n[2], dx1, v);
                  grad[1][v] = sum3(n[2], dy1, v);
                  grad[2][v] = sum3(dn[2], v1, v);
                }
            }
        }
    }

    /// the value alone, sum-factorised
    static inline void
    interpolate(const Field &f, const Eval &e, double (&out)[dim])
    {
      Pair val[field_pairs], grad[dim][field_pairs];
      contract<false>(f, e, val, grad);
      for (unsigned int c = 0; c < dim; ++c)
        out[c] = val[c / 2][c % 2];
    }
    /// grad[c][k] = d u_c / d x_k
    static inline void
    gradient(const Cell &c, const Field &f, const Eval &e, double (&grad)[dim][dim])
    {
      double val[dim];
      value_and_gradient(c, f, e, val, grad);
    }
    /// value and gradient at once (one window contraction)
    static inline void
    value_and_gradient(const Cell &, const Field &f, const Eval &e, double (&val)[dim], double (&grad)[dim][dim])
    {
      Pair v[field_pairs], g[dim][field_pairs];
      contract<true>(f, e, v, g);
      for (unsigned int c = 0; c < dim; ++c)
        {
          val[c] = v[c / 2][c % 2];
          for (unsigned int k = 0; k < dim; ++k)
            grad[c][k] = g[k][c / 2][c % 2];
        }
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

    /// Lumped mass and internal force of a cell's points on the patch: per
    /// slot s, a[s] = (lumped mass, force components..., 0 in 2D), two pairs.
    struct MassForce
    {
      alignas(16) double a[n_nodes][4];
      /// zero the sums in place (a new cell; `*this = MassForce()` built a
      /// zeroed temporary and copied its 2 KB: 6 % of a B-spline run in memmove)
      inline void
      clear()
      {
        std::fill(&a[0][0], &a[0][0] + n_nodes * 4, 0.0);
      }
      /// one point: mass m, t = -V sigma. The products and sums of
      /// for_each_window_force, two lanes at a time: per window line the pairs
      /// X = (0, X_0), (X_1, X_2) and Y = (w, Y_0), (Y_1, Y_2) (w the line's
      /// value factor), per node dN0_a X + N0_a Y = (N0_a w, F_0), (F_1, F_2),
      /// the first pair times (m, 1): the lumped mass m N and F_0.
      inline void
      add(const Eval &e, const double m, const double (&t)[dim][dim])
      {
        double(*aw)[4] = a + W::first_slot(e);
        Pair n0[3], d0[3];
        for (unsigned int i = 0; i < 3; ++i)
          {
            n0[i] = broadcast(e.N[0][i]);
            d0[i] = broadcast(e.dN[0][i]);
          }
        const Pair m1 = {m, 1.0};
        // columns of t as pairs: lo = (0, t_0k), hi = (t_1k, t_2k or 0)
        Pair lo[dim], hi[dim];
        for (unsigned int k = 0; k < dim; ++k)
          {
            lo[k] = Pair{0.0, t[0][k]};
            hi[k] = Pair{t[1][k], dim == 3 ? t[dim - 1][k] : 0.0};
          }
        auto line = [&](const unsigned int o, const double w, const Pair X0, const Pair X1, const Pair Yt0,
                        const Pair Y1) {
          const Pair Y0 = {w, Yt0[1]};
          for (unsigned int i = 0; i < 3; ++i)
            {
              double *r = aw[o + i];
              store_aligned(r, load_aligned(r) + (d0[i] * X0 + n0[i] * Y0) * m1);
              store_aligned(r + 2, load_aligned(r + 2) + (d0[i] * X1 + n0[i] * Y1));
            }
        };
        if constexpr (dim == 2)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const double n = e.N[1][b], dn = e.dN[1][b];
              line(4 * b, n, lo[0] * n, hi[0] * n, lo[1] * dn, hi[1] * dn);
            }
        else
          for (unsigned int k = 0; k < 3; ++k)
            for (unsigned int b = 0; b < 3; ++b)
              {
                const double nbc = e.N[1][b] * e.N[2][k], dbc = e.dN[1][b] * e.N[2][k], nbd = e.N[1][b] * e.dN[2][k];
                line(4 * b + 16 * k, nbc, lo[0] * nbc, hi[0] * nbc, lo[1] * dbc + lo[2] * nbd,
                     hi[1] * dbc + hi[2] * nbd);
              }
      }
      inline void
      scatter(const Cell &c, const dealii::Tensor<1, dim> &g, double *M, double *Fv) const
      {
        if (c.patch->full)
          {
            const Pair g01 = {g[0], g[1]};
            for (unsigned int s = 0; s < n_nodes; ++s)
              {
                const unsigned int i  = c.dofs[s * dim];
                const double       lm = a[s][0];
                const Pair         l2 = broadcast(lm);
                store_unaligned(M + i, load_unaligned(M + i) + l2);
                store_unaligned(Fv + i, load_unaligned(Fv + i) + (l2 * g01 + load_unaligned(a[s] + 1)));
                if constexpr (dim == 3)
                  {
                    M[i + 2] += lm;
                    Fv[i + 2] += lm * g[2] + a[s][3];
                  }
              }
            return;
          }
        for (unsigned int s = 0; s < n_nodes; ++s)
          if (c.dofs[s * dim] != dealii::numbers::invalid_unsigned_int) // else outside the grid: no weight
            for (unsigned int d = 0; d < dim; ++d)
              {
                const unsigned int i = c.dofs[s * dim + d];
                M[i] += a[s][0];
                Fv[i] += a[s][0] * g[d] + a[s][1 + d];
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

    /// sum_p m_p N(x_p) v_p of a cell's points on the patch: lp[s][c] (the
    /// padding lane of 3D stays 0)
    struct Momentum
    {
      alignas(16) double lp[n_nodes][field_width];
      /// zero the sums in place (see MassForce::clear)
      inline void
      clear()
      {
        std::fill(&lp[0][0], &lp[0][0] + n_nodes * field_width, 0.0);
      }
      /// the products of W::for_each_window_value: lp += (m (N0_a w)) v, two
      /// components at a time
      inline void
      add(const Eval &e, const double m, const double *vel)
      {
        double(*pw)[field_width] = lp + W::first_slot(e);
        Pair v[field_pairs];
        for (unsigned int p = 0; p < field_pairs; ++p)
          v[p] = Pair{vel[2 * p], 2 * p + 1 < dim ? vel[2 * p + 1] : 0.0};
        auto line = [&](const unsigned int o, const double w) {
          for (unsigned int i = 0; i < 3; ++i)
            {
              const Pair mN = broadcast(m * (e.N[0][i] * w));
              for (unsigned int p = 0; p < field_pairs; ++p)
                store_aligned(pw[o + i] + 2 * p, load_aligned(pw[o + i] + 2 * p) + mN * v[p]);
            }
        };
        if constexpr (dim == 2)
          for (unsigned int b = 0; b < 3; ++b)
            line(4 * b, e.N[1][b]);
        else
          for (unsigned int k = 0; k < 3; ++k)
            for (unsigned int b = 0; b < 3; ++b)
              line(4 * b + 16 * k, e.N[1][b] * e.N[2][k]);
      }
      inline void
      scatter(const Cell &c, double *P) const
      {
        if (c.patch->full)
          {
            for (unsigned int s = 0; s < n_nodes; ++s)
              {
                const unsigned int i = c.dofs[s * dim];
                store_unaligned(P + i, load_unaligned(P + i) + load_aligned(lp[s]));
                if constexpr (dim == 3)
                  P[i + 2] += lp[s][2];
              }
            return;
          }
        for (unsigned int s = 0; s < n_nodes; ++s)
          if (c.dofs[s * dim] != dealii::numbers::invalid_unsigned_int) // else outside the grid: no weight
            for (unsigned int d = 0; d < dim; ++d)
              P[c.dofs[s * dim + d]] += lp[s][d];
      }
    };
  };
} // namespace talus::shape
