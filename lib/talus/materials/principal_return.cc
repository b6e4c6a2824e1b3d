#include <talus/materials/principal_return.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace talus::materials::internal
{
  namespace
  {
    // All subsets of up to 6 candidates with at most 3 members, ordered by size
    // (faces, then edges, then corners) and, within one size, lexicographically.
    const std::vector<unsigned int> &
    subsets_by_size()
    {
      static const std::vector<unsigned int> list = [] {
        std::vector<unsigned int> l;
        for (unsigned int size = 1; size <= 3; ++size)
          for (unsigned int m = 1; m < 64; ++m)
            if (static_cast<unsigned int>(__builtin_popcount(m)) == size)
              l.push_back(m);
        return l;
      }();
      return list;
    }

    // Solve the m x m system A x = r (m <= 3) by Gaussian elimination with partial
    // pivoting; false when (numerically) singular.
    bool
    solve_small(double A[3][3], double r[3], const unsigned int m, double x[3])
    {
      double scale = 0;
      for (unsigned int i = 0; i < m; ++i)
        for (unsigned int j = 0; j < m; ++j)
          scale = std::max(scale, std::abs(A[i][j]));
      if (scale == 0)
        return false;
      for (unsigned int c = 0; c < m; ++c)
        {
          unsigned int p = c;
          for (unsigned int i = c + 1; i < m; ++i)
            if (std::abs(A[i][c]) > std::abs(A[p][c]))
              p = i;
          if (std::abs(A[p][c]) < 1e-10 * scale)
            return false;
          if (p != c)
            {
              for (unsigned int j = 0; j < m; ++j)
                std::swap(A[p][j], A[c][j]);
              std::swap(r[p], r[c]);
            }
          for (unsigned int i = c + 1; i < m; ++i)
            {
              const double f = A[i][c] / A[c][c];
              for (unsigned int j = c; j < m; ++j)
                A[i][j] -= f * A[c][j];
              r[i] -= f * r[c];
            }
        }
      for (int i = static_cast<int>(m) - 1; i >= 0; --i)
        {
          double v = r[i];
          for (unsigned int j = i + 1; j < m; ++j)
            v -= A[i][j] * x[j];
          x[i] = v / A[i][i];
        }
      return true;
    }

    inline double
    dot(const Vec3 &a, const Vec3 &b)
    {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    }

    // D b for isotropic elasticity in principal space: 2G b + lambda tr(b) 1.
    inline Vec3
    elastic(const Vec3 &b, const double lambda, const double G)
    {
      const double t = lambda * (b[0] + b[1] + b[2]);
      return {{2 * G * b[0] + t, 2 * G * b[1] + t, 2 * G * b[2] + t}};
    }
  } // namespace

  PrincipalReturnResult
  return_to_planar_surfaces(const Vec3 &trial, const double lambda, const double G, const PlanarSurface *cand,
                            const unsigned int n_cand, const PlanarSurface *check, const unsigned int n_check,
                            const double tol)
  {
    PrincipalReturnResult res;
    Vec3                  Db[6];
    double                f_trial[6];
    for (unsigned int k = 0; k < n_cand; ++k)
      {
        Db[k]      = elastic(cand[k].b, lambda, G);
        f_trial[k] = dot(cand[k].a, trial) - cand[k].k;
      }
    double fmax = -1;
    for (unsigned int k = 0; k < n_cand; ++k)
      fmax = std::max(fmax, f_trial[k]);
    if (fmax <= tol)
      {
        res.converged = true;
        res.sigma     = trial;
        return res;
      }
    const unsigned int all = (1u << n_cand) - 1;
    for (const unsigned int mask : subsets_by_size())
      {
        if ((mask & ~all) != 0)
          continue;
        unsigned int idx[3], m = 0;
        for (unsigned int k = 0; k < n_cand; ++k)
          if (mask & (1u << k))
            idx[m++] = k;
        // only surfaces violated by the trial state can start an active set
        bool any_violated = false;
        for (unsigned int i = 0; i < m; ++i)
          any_violated |= (f_trial[idx[i]] > tol);
        if (!any_violated)
          continue;
        double A[3][3], r[3], x[3];
        for (unsigned int i = 0; i < m; ++i)
          {
            for (unsigned int j = 0; j < m; ++j)
              A[i][j] = dot(cand[idx[i]].a, Db[idx[j]]);
            r[i] = f_trial[idx[i]];
          }
        if (!solve_small(A, r, m, x))
          continue;
        double xmax = 0;
        for (unsigned int i = 0; i < m; ++i)
          xmax = std::max(xmax, std::abs(x[i]));
        bool ok = true;
        for (unsigned int i = 0; i < m; ++i)
          ok &= (x[i] >= -1e-12 * xmax);
        if (!ok)
          continue;
        Vec3 s = trial, dep{{0, 0, 0}};
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int d = 0; d < 3; ++d)
            {
              s[d] -= x[i] * Db[idx[i]][d];
              dep[d] += x[i] * cand[idx[i]].b[d];
            }
        for (unsigned int j = 0; j < n_check && ok; ++j)
          ok = (dot(check[j].a, s) - check[j].k <= tol);
        if (!ok)
          continue;
        res.converged   = true;
        res.sigma       = s;
        res.dep         = dep;
        res.active_mask = mask;
        res.n_active    = m;
        return res;
      }
    return res;
  }

  Spectral
  spectral_decomposition(const dealii::SymmetricTensor<2, 3> &s)
  {
    const auto ev = dealii::eigenvectors(s, dealii::SymmetricTensorEigenvectorMethod::ql_implicit_shifts);
    Spectral   sd;
    for (unsigned int i = 0; i < 3; ++i)
      {
        sd.values[i]  = ev[i].first;
        sd.vectors[i] = ev[i].second;
      }
    return sd;
  }

  dealii::SymmetricTensor<2, 3>
  compose(const Vec3 &v, const Spectral &sd)
  {
    dealii::SymmetricTensor<2, 3> r;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = i; j < 3; ++j)
          r[i][j] += v[k] * sd.vectors[k][i] * sd.vectors[k][j];
    return r;
  }

  Vec3
  principal_values(const dealii::SymmetricTensor<2, 3> &s)
  {
    const auto e = dealii::eigenvalues(s);
    return {{e[0], e[1], e[2]}};
  }
} // namespace talus::materials::internal
