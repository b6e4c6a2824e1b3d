// talus — isoparametric Q1 on a general (possibly deformed) quad/hex: values,
// reference derivatives and real-space gradients for given vertex coordinates.
// Q1Iso is its kernel policy (the interface of q1_box.h, as far as the FEM /
// UL-FEM integration of formulations/explicit/fem.cc uses it), where cells need
// not be axis-aligned boxes (ul-fem deforms them); the MPM loops use the cheaper
// box kernel Q1Box.
#pragma once

#include <deal.II/base/point.h>

namespace talus::shape
{
  /// Isoparametric Q1 on a general (possibly deformed) quad/hex: values and
  /// reference derivatives at xi, and real-space gradients for given vertex
  /// coordinates. Vertex numbering as deal.II (bit d of v = coordinate d).
  template <int dim>
  struct IsoQ1
  {
    static constexpr unsigned int nv = 1u << dim;

    static inline void
    shape(const dealii::Point<dim> &xi, double (&N)[nv], double (&dN)[nv][dim])
    {
      double f[dim][2];
      for (unsigned int d = 0; d < dim; ++d)
        {
          f[d][0] = 1.0 - xi[d];
          f[d][1] = xi[d];
        }
      for (unsigned int v = 0; v < nv; ++v)
        {
          double n = 1.0;
          for (unsigned int d = 0; d < dim; ++d)
            n *= f[d][(v >> d) & 1u];
          N[v] = n;
          for (unsigned int e = 0; e < dim; ++e)
            {
              double g = ((v >> e) & 1u) ? 1.0 : -1.0;
              for (unsigned int d = 0; d < dim; ++d)
                if (d != e)
                  g *= f[d][(v >> d) & 1u];
              dN[v][e] = g;
            }
        }
    }

    /// G[v][k] = dN_v/dx_k for vertex coordinates X; returns det J.
    static inline double
    gradients(const double (&X)[nv][dim], const double (&dN)[nv][dim], double (&G)[nv][dim])
    {
      double J[dim][dim] = {};
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          for (unsigned int e = 0; e < dim; ++e)
            J[d][e] += X[v][d] * dN[v][e];
      double Ji[dim][dim], det;
      if constexpr (dim == 2)
        {
          det            = J[0][0] * J[1][1] - J[0][1] * J[1][0];
          const double r = 1.0 / det;
          Ji[0][0]       = J[1][1] * r;
          Ji[0][1]       = -J[0][1] * r;
          Ji[1][0]       = -J[1][0] * r;
          Ji[1][1]       = J[0][0] * r;
        }
      else
        {
          const double c00 = J[1][1] * J[2][2] - J[1][2] * J[2][1];
          const double c01 = J[1][2] * J[2][0] - J[1][0] * J[2][2];
          const double c02 = J[1][0] * J[2][1] - J[1][1] * J[2][0];
          det              = J[0][0] * c00 + J[0][1] * c01 + J[0][2] * c02;
          const double r   = 1.0 / det;
          Ji[0][0]         = c00 * r;
          Ji[1][0]         = c01 * r;
          Ji[2][0]         = c02 * r;
          Ji[0][1]         = (J[0][2] * J[2][1] - J[0][1] * J[2][2]) * r;
          Ji[1][1]         = (J[0][0] * J[2][2] - J[0][2] * J[2][0]) * r;
          Ji[2][1]         = (J[0][1] * J[2][0] - J[0][0] * J[2][1]) * r;
          Ji[0][2]         = (J[0][1] * J[1][2] - J[0][2] * J[1][1]) * r;
          Ji[1][2]         = (J[0][2] * J[1][0] - J[0][0] * J[1][2]) * r;
          Ji[2][2]         = (J[0][0] * J[1][1] - J[0][1] * J[1][0]) * r;
        }
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int k = 0; k < dim; ++k)
          {
            double g = 0;
            for (unsigned int e = 0; e < dim; ++e)
              g += dN[v][e] * Ji[e][k];
            G[v][k] = g;
          }
      return det;
    }
  };

  /// The isoparametric Q1 kernel policy: a cell is its (current) vertex
  /// coordinates and the local DoF indices of its vertices (component d of
  /// vertex v at dofs[v * dim + d], as the grid's cell cache).
  template <int dim>
  struct Q1Iso
  {
    using Iso                             = IsoQ1<dim>;
    static constexpr unsigned int n_nodes = Iso::nv;

    struct Cell
    {
      double              X[n_nodes][dim];
      const unsigned int *dofs = nullptr;
    };

    /// values, reference derivatives, real-space gradients and det J at a point
    struct Eval
    {
      double N[n_nodes], dN[n_nodes][dim], G[n_nodes][dim];
      double det = 0;
    };
    static inline void
    evaluate(const Cell &cell, const dealii::Point<dim> &xi, Eval &e)
    {
      Iso::shape(xi, e.N, e.dN);
      e.det = Iso::gradients(cell.X, e.dN, e.G);
    }
    /// The gradients at the same reference point for other vertex positions
    /// (a cell deformed over the step); returns the new det J.
    static inline double
    move_vertices(const double (&X)[n_nodes][dim], Eval &e)
    {
      e.det = Iso::gradients(X, e.dN, e.G);
      return e.det;
    }

    /// scale x the nodal vector V on the cell's vertices
    struct Field
    {
      double u[n_nodes][dim];
    };
    static inline void
    gather(const Cell &cell, const double *V, const double scale, Field &f)
    {
      for (unsigned int v = 0; v < n_nodes; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          f.u[v][d] = scale * V[cell.dofs[v * dim + d]];
    }
    /// value u(x_p) and gradient g[a][b] = du_a/dx_b of a field at a point
    static inline void
    value_and_gradient(const Field &f, const Eval &e, double (&u)[dim], double (&g)[dim][dim])
    {
      for (unsigned int a = 0; a < dim; ++a)
        {
          u[a] = 0;
          for (unsigned int b = 0; b < dim; ++b)
            g[a][b] = 0;
        }
      for (unsigned int v = 0; v < n_nodes; ++v)
        for (unsigned int a = 0; a < dim; ++a)
          {
            u[a] += e.N[v] * f.u[v][a];
            for (unsigned int b = 0; b < dim; ++b)
              g[a][b] += f.u[v][a] * e.G[v][b];
          }
    }
    /// the position sum_v N_v X_v of a point
    static inline void
    position(const Cell &cell, const Eval &e, dealii::Point<dim> &x)
    {
      for (unsigned int v = 0; v < n_nodes; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          x[d] += e.N[v] * cell.X[v][d];
    }

    /// A cell's lumped mass sum_p m_p N_v and internal force sum_p t_p grad N_v
    /// (t = -V sigma), scattered once per cell with gravity m g added.
    struct MassForce
    {
      double m[n_nodes], f[n_nodes][dim];
      inline void
      clear()
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          {
            m[v] = 0;
            for (unsigned int d = 0; d < dim; ++d)
              f[v][d] = 0;
          }
      }
      inline void
      add(const Eval &e, const double mass, const double (&t)[dim][dim])
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          {
            m[v] += mass * e.N[v];
            for (unsigned int a = 0; a < dim; ++a)
              for (unsigned int b = 0; b < dim; ++b)
                f[v][a] += t[a][b] * e.G[v][b];
          }
      }
      template <class Gravity>
      inline void
      scatter(const Cell &cell, const Gravity &g, double *M, double *F) const
      {
        for (unsigned int v = 0; v < n_nodes; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              const unsigned int i = cell.dofs[v * dim + d];
              M[i] += m[v];
              F[i] += f[v][d] + m[v] * g[d];
            }
      }
    };
  };
} // namespace talus::shape
