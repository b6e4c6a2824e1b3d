// talus — the Q1 kernel on axis-aligned box cells as a compile-time policy for
// the transfer ops (transfer/point_ops.h). A kernel K<dim> provides
//
//   K::n_nodes                      nodes of a cell's stencil (the nodal data a
//                                   cell's points read and write)
//   K::Cell    K::cell(grid, c)     the stencil (local DoF index of node n,
//                                   component d at dofs[n * dim + d]) and geometry;
//                                   c's cache entry must be filled (a cell with
//                                   points: CellCaches::filled_entry)
//   K::Values  K::values(cell, xi)  shape values at a point (interpolation, P2G)
//   K::Eval    K::evaluate(cell,xi) values and what gradients need
//   K::Field   gather(cell, V, s)   s * the nodal vector V on the stencil, prepared
//                                   for interpolation and gradients
//   interpolate(field, values|eval, out), gradient(cell, field, eval, grad)
//   K::MassForce                    per-cell sums of lumped mass and internal
//                                   force (-V sigma grad N), scattered once per cell
//   K::Momentum                     per-cell sums of m N v, scattered once per cell
//   K::point_stencil(cell, xi, ...) the nodes a point touches (stencil slots) with
//                                   values and gradients (matrix assembly)
//
// Q1Box is today's sum-factorised Q1 (shape/q1.h): gradients from per-cell
// nodal differences and the internal force from per-cell pair moments.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/shape/q1.h>

namespace talus::shape
{
  template <int dim>
  struct Q1Box
  {
    using F                               = Q1Factorised<dim>;
    static constexpr unsigned int n_nodes = F::nv;

    struct Cell
    {
      const CellCache<dim> *cc   = nullptr;
      const unsigned int   *dofs = nullptr;
    };
    static inline Cell
    cell(const BackgroundGrid<dim> &grid, const unsigned int c)
    {
      const auto &cc = grid.cells.filled_entry(c);
      return {&cc, cc.dofs};
    }

    struct Values
    {
      double N[n_nodes];
    };
    static inline void
    values(const Cell &, const dealii::Point<dim> &xi, Values &v)
    {
      Q1<dim>::values(xi, v.N);
    }

    struct Eval
    {
      double N[n_nodes];
      double w[dim][F::npairs];
    };
    static inline void
    evaluate(const Cell &, const dealii::Point<dim> &xi, Eval &e)
    {
      F::weights(xi, e.N, e.w);
    }

    /// A vector field on the cell's nodes, with its pair differences when
    /// gradients are wanted.
    struct Field
    {
      double u[n_nodes][dim];
      double D[dim][F::npairs][dim];
    };
    static inline void
    gather(const Cell &c, const double *V, const double scale, Field &f, const bool with_gradient)
    {
      for (unsigned int v = 0; v < n_nodes; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          f.u[v][d] = scale * V[c.dofs[v * dim + d]];
      if (with_gradient)
        F::differences(f.u, f.D);
    }
    template <class E>
    static inline void
    interpolate(const Field &f, const E &e, double (&out)[dim])
    {
      for (unsigned int d = 0; d < dim; ++d)
        {
          double s = 0;
          for (unsigned int v = 0; v < n_nodes; ++v)
            s += e.N[v] * f.u[v][d];
          out[d] = s;
        }
    }
    /// grad[c][k] = d u_c / d x_k
    static inline void
    gradient(const Cell &c, const Field &f, const Eval &e, double (&grad)[dim][dim])
    {
      F::gradient(f.D, e.w, c.cc->inv_h, grad);
    }

    /// value and gradient at once
    static inline void
    value_and_gradient(const Cell &c, const Field &f, const Eval &e, double (&val)[dim], double (&grad)[dim][dim])
    {
      gradient(c, f, e, grad);
      interpolate(f, e, val);
    }

    /// The nodes one point touches, for matrix assembly (transfer/matrix_ops.h):
    /// stencil slot, value and real-space gradient of each (Q1: the cell's 2^dim
    /// vertices, slot = vertex).
    static constexpr unsigned int n_point_nodes = n_nodes;
    static inline void
    point_stencil(const Cell &c, const dealii::Point<dim> &xi, unsigned int (&slot)[n_point_nodes],
                  double (&N)[n_point_nodes], double (&G)[n_point_nodes][dim])
    {
      Q1<dim>::values_and_gradients(xi, c.cc->inv_h, N, G);
      for (unsigned int v = 0; v < n_point_nodes; ++v)
        slot[v] = v;
    }

    /// Lumped mass (Eq. 4.32) and internal force (Eq. 4.41) of a cell's points
    /// in pair-moment form; gravity (Eq. 4.34) is m_v g per node.
    struct MassForce
    {
      double lm[n_nodes]            = {};
      double T[dim][F::npairs][dim] = {};
      /// zero the sums (a new cell)
      inline void
      clear()
      {
        *this = MassForce();
      }
      /// one point: mass m, t = -V sigma
      inline void
      add(const Eval &e, const double m, const double (&t)[dim][dim])
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          lm[v] += m * e.N[v];
        F::add_moments(t, e.w, T);
      }
      inline void
      scatter(const Cell &c, const dealii::Tensor<1, dim> &g, double *M, double *Fv) const
      {
        double f[n_nodes][dim];
        for (unsigned int v = 0; v < n_nodes; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            f[v][d] = lm[v] * g[d];
        F::expand_moments(T, c.cc->inv_h, f);
        for (unsigned int v = 0; v < n_nodes; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              const unsigned int i = c.dofs[v * dim + d];
              M[i] += lm[v];
              Fv[i] += f[v][d];
            }
      }
    };

    /// Mass and force of one point (a point moved into another cell).
    static inline void
    scatter_point(const Cell &c, const Eval &e, const double m, const double (&t)[dim][dim],
                  const dealii::Tensor<1, dim> &g, double *M, double *Fv)
    {
      MassForce sums;
      sums.add(e, m, t);
      sums.scatter(c, g, M, Fv);
    }

    /// sum_p m_p N_v(x_p) v_p of a cell's points (Eq. 4.47)
    struct Momentum
    {
      double lp[n_nodes][dim] = {};
      inline void
      clear()
      {
        *this = Momentum();
      }
      template <class E>
      inline void
      add(const E &e, const double m, const double *vel)
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            lp[v][d] += m * e.N[v] * vel[d];
      }
      inline void
      scatter(const Cell &c, double *P) const
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            P[c.dofs[v * dim + d]] += lp[v][d];
      }
    };
  };
} // namespace talus::shape
