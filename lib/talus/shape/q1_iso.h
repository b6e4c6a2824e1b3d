// talus — isoparametric Q1 on a general (possibly deformed) quad/hex: values,
// reference derivatives and real-space gradients for given vertex coordinates.
// Used by the FEM / UL-FEM integration (formulations/explicit/fem.cc), where
// cells need not be axis-aligned boxes (ul-fem deforms them); the MPM loops use
// the cheaper box kernel of q1.h.
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
          det      = J[0][0] * J[1][1] - J[0][1] * J[1][0];
          const double r = 1.0 / det;
          Ji[0][0] = J[1][1] * r;
          Ji[0][1] = -J[0][1] * r;
          Ji[1][0] = -J[1][0] * r;
          Ji[1][1] = J[0][0] * r;
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

} // namespace talus::shape
