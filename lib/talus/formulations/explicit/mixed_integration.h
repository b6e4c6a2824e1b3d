// talus — MPM-MIXED integration of the internal force of one filled cell
// (seed 000 §6.6, extended for Q1 quads/hexes).
//
// The manual's MPM-MIXED integrates a filled cell with the volume-averaged stress
// of its points (Eq. 6.32) at one Gauss point. That is exact on linear tetrahedra
// but on a Q1 box cell a constant stress does not resist the hourglass modes
// (strains linear in the other coordinates), while the points' stresses, updated
// from their own strains, still see them: measured unstable on the elastic
// column with 4 points per direction. Here the cell stress is linear instead:
//
//   sigma(xi) = sigma_bar + B (xi - xi_bar)
//
// fitted to the points' stresses by volume-weighted least squares (sigma_bar is
// then Eq. 6.32 exactly), and integrated at the 2^dim Gauss points of the cell
// with the cell volume, which is exact for the Q1 force of a linear stress field.
// Directions in which the points are not spread (weighted variance of xi_k below
// `min_variance`) get no slope; too few points or nearly collinear positions fall
// back to the constant stress. A limiter keeps the field at the Gauss points
// within the points' range widened by half of it on each side (per stress
// component), so a cluster of points in a corner of the cell is never
// extrapolated far.
//
// Stress components in the order of PropertyLayout: xx, yy, zz, xy (, yz, xz).
#pragma once

#include <talus/shape/q1.h>

#include <deal.II/base/point.h>

#include <algorithm>
#include <cmath>

namespace talus::explicit_mpm
{
  template <int dim>
  struct CellStressFit
  {
    using F                                        = shape::Q1Factorised<dim>;
    static constexpr unsigned int nst              = dim == 2 ? 4 : 6;
    static constexpr double       min_variance     = 1.0 / 144.0; ///< (1/12 of the cell width)^2
    static constexpr double       limiter_widening = 0.5;

    unsigned int n  = 0;
    double       sV = 0, sVx[dim], sVxx[dim][dim], sVs[nst], sVsx[nst][dim], smin[nst], smax[nst];

    void
    clear()
    {
      n  = 0;
      sV = 0;
      std::fill(&sVx[0], &sVx[0] + dim, 0.0);
      std::fill(&sVxx[0][0], &sVxx[0][0] + dim * dim, 0.0);
      std::fill(&sVs[0], &sVs[0] + nst, 0.0);
      std::fill(&sVsx[0][0], &sVsx[0][0] + nst * dim, 0.0);
      std::fill(&smin[0], &smin[0] + nst, 1e300);
      std::fill(&smax[0], &smax[0] + nst, -1e300);
    }

    CellStressFit() { clear(); }

    /// One point: reference coordinates, volume, stress components s[nst].
    void
    add(const dealii::Point<dim> &xi, const double V, const double *s)
    {
      ++n;
      sV += V;
      for (unsigned int k = 0; k < dim; ++k)
        {
          sVx[k] += V * xi[k];
          for (unsigned int l = 0; l < dim; ++l)
            sVxx[k][l] += V * xi[k] * xi[l];
        }
      for (unsigned int q = 0; q < nst; ++q)
        {
          sVs[q] += V * s[q];
          for (unsigned int k = 0; k < dim; ++k)
            sVsx[q][k] += V * s[q] * xi[k];
          smin[q] = std::min(smin[q], s[q]);
          smax[q] = std::max(smax[q], s[q]);
        }
    }

    /// The fitted field: mean (Eq. 6.32), slopes d sigma_q / d xi_k (before the
    /// limiter) and the weighted centre xi_bar. Returns the number of
    /// directions with a slope (0: constant stress).
    unsigned int
    fit(double (&mean)[nst], double (&slope)[nst][dim], double (&centre)[dim]) const
    {
      for (unsigned int k = 0; k < dim; ++k)
        centre[k] = sVx[k] / sV;
      for (unsigned int q = 0; q < nst; ++q)
        {
          mean[q] = sVs[q] / sV;
          for (unsigned int k = 0; k < dim; ++k)
            slope[q][k] = 0;
        }
      // weighted covariance of the positions and of position and stress
      double       C[dim][dim];
      unsigned int active[dim], na = 0;
      for (unsigned int k = 0; k < dim; ++k)
        for (unsigned int l = 0; l < dim; ++l)
          C[k][l] = sVxx[k][l] / sV - centre[k] * centre[l];
      for (unsigned int k = 0; k < dim; ++k)
        if (C[k][k] > min_variance)
          active[na++] = k;
      if (na == 0 || n < na + 1)
        return 0;
      // reduced system A b = r for the active directions (Gauss elimination)
      double A[dim][dim], diag = 1.0;
      for (unsigned int a = 0; a < na; ++a)
        {
          for (unsigned int b = 0; b < na; ++b)
            A[a][b] = C[active[a]][active[b]];
          diag *= A[a][a];
        }
      double       inv[dim][dim];
      const double det = invert(A, na, inv);
      if (!(det > 1e-2 * diag)) // nearly collinear positions: constant stress
        return 0;
      for (unsigned int q = 0; q < nst; ++q)
        {
          double r[dim];
          for (unsigned int a = 0; a < na; ++a)
            r[a] = sVsx[q][active[a]] / sV - mean[q] * centre[active[a]];
          for (unsigned int a = 0; a < na; ++a)
            {
              double b = 0;
              for (unsigned int c = 0; c < na; ++c)
                b += inv[a][c] * r[c];
              slope[q][active[a]] = b;
            }
        }
      return na;
    }

    /// Reference coordinate of the Gauss points along one axis (index 0 or 1).
    static double
    gauss(const unsigned int i)
    {
      return 0.5 + (i ? 0.5 : -0.5) / std::sqrt(3.0);
    }

    /// The field integrated: the fit with the limiter applied (linear), or the
    /// mean alone (linear = false, slopes 0).
    void
    field(const bool linear, double (&mean)[nst], double (&slope)[nst][dim], double (&centre)[dim]) const
    {
      fit(mean, slope, centre);
      if (!linear)
        {
          std::fill(&slope[0][0], &slope[0][0] + nst * dim, 0.0);
          return;
        }
      // limiter per component over the Gauss points
      for (unsigned int q = 0; q < nst; ++q)
        {
          const double range = smax[q] - smin[q];
          const double hi = smax[q] + limiter_widening * range, lo = smin[q] - limiter_widening * range;
          double       phi = 1.0;
          for (unsigned int gp = 0; gp < F::nv; ++gp)
            {
              double d = 0;
              for (unsigned int k = 0; k < dim; ++k)
                d += slope[q][k] * (gauss((gp >> k) & 1u) - centre[k]);
              const double v = mean[q] + d;
              if (v > hi && d > 0)
                phi = std::min(phi, (hi - mean[q]) / d);
              else if (v < lo && d < 0)
                phi = std::min(phi, (lo - mean[q]) / d);
            }
          phi = std::max(phi, 0.0);
          for (unsigned int k = 0; k < dim; ++k)
            slope[q][k] *= phi;
        }
    }

    /// Pair moments (Q1Factorised::add_moments convention) of -int sigma grad N
    /// over a cell of volume `cell_volume`, 2^dim Gauss points, with field().
    /// T is overwritten.
    void
    moments(const double cell_volume, const bool linear, double (&T)[dim][F::npairs][dim]) const
    {
      double mean[nst], slope[nst][dim], centre[dim];
      field(linear, mean, slope, centre);
      std::fill(&T[0][0][0], &T[0][0][0] + dim * F::npairs * dim, 0.0);
      const double wq = cell_volume / F::nv;
      for (unsigned int gp = 0; gp < F::nv; ++gp)
        {
          dealii::Point<dim> xi;
          for (unsigned int k = 0; k < dim; ++k)
            xi[k] = gauss((gp >> k) & 1u);
          double s[nst];
          for (unsigned int q = 0; q < nst; ++q)
            {
              s[q] = mean[q];
              for (unsigned int k = 0; k < dim; ++k)
                s[q] += slope[q][k] * (xi[k] - centre[k]);
            }
          double t[dim][dim];
          t[0][0] = -wq * s[0];
          t[1][1] = -wq * s[1];
          t[0][1] = t[1][0] = -wq * s[3];
          if constexpr (dim == 3)
            {
              t[2][2] = -wq * s[2];
              t[1][2] = t[2][1] = -wq * s[4];
              t[0][2] = t[2][0] = -wq * s[5];
            }
          double N[F::nv], w[dim][F::npairs];
          F::weights(xi, N, w);
          F::add_moments(t, w, T);
        }
    }

  private:
    /// inverse of the leading n x n block (n <= 3); returns the determinant
    static double
    invert(const double (&A)[dim][dim], const unsigned int n, double (&inv)[dim][dim])
    {
      if (n == 1)
        {
          inv[0][0] = 1.0 / A[0][0];
          return A[0][0];
        }
      if (n == 2)
        {
          const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
          inv[0][0]        = A[1][1] / det;
          inv[1][1]        = A[0][0] / det;
          inv[0][1]        = -A[0][1] / det;
          inv[1][0]        = -A[1][0] / det;
          return det;
        }
      if constexpr (dim == 3)
        {
          const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                             A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                             A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              {
                // cofactor of A[j][i]
                const unsigned int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
                inv[i][j] = (A[r0][c0] * A[r1][c1] - A[r0][c1] * A[r1][c0]) / det;
              }
          return det;
        }
      return 0;
    }
  };
} // namespace talus::explicit_mpm
