// talus — stability of one explicit MPM step on a uniform 1D grid (see the header
// and docs/stability-analysis.md).
#include <talus/analysis/scheme_stability.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <vector>

namespace talus::analysis
{
  namespace
  {
    // Linear map of the point state x = [v_p, sigma_p] over one step, h = c = E = rho = 1:
    //   a_i      = -(1/m_i) sum_p V_p sigma_p N'_i(x_p)              (Eq. 4.45, f_ext = 0)
    //   v_p'     = v_p + dt sum_i N_i(x_p) a_i                       (4.46)
    //   v_i      = (1/m_i) sum_p m_p N_i(x_p) v_p'                    (4.47-4.48)
    //   sigma_p' = sigma_p + dt E sum_i N'_i(x_p) v_i                (4.49-4.50)
    // with m_p = V_p = h / n, m_i = sum_p m_p N_i(x_p) (lumped), fixed nodes v_i = a_i = 0.
    dealii::LAPACKFullMatrix<double>
    amplification(const unsigned int n, const unsigned int n_cells, const bool periodic, const double dt)
    {
      const unsigned int         n_nodes = periodic ? n_cells : n_cells + 1;
      const unsigned int         np      = n * n_cells;
      dealii::FullMatrix<double> S(np, n_nodes), B(np, n_nodes); // N_i(x_p), N'_i(x_p)
      for (unsigned int e = 0; e < n_cells; ++e)
        for (unsigned int k = 0; k < n; ++k)
          {
            const unsigned int p  = e * n + k;
            const double       xi = (k + 0.5) / n;
            const unsigned int i0 = e, i1 = periodic ? (e + 1) % n_cells : e + 1;
            S(p, i0) += 1 - xi;
            S(p, i1) += xi;
            B(p, i0) -= 1;
            B(p, i1) += 1;
          }
      const double        mp = 1.0 / n;
      std::vector<double> m(n_nodes, 0.0);
      for (unsigned int p = 0; p < np; ++p)
        for (unsigned int i = 0; i < n_nodes; ++i)
          m[i] += mp * S(p, i);
      // fixed node: x = 0 of the bar (zero acceleration and velocity)
      std::vector<double> inv_m(n_nodes);
      for (unsigned int i = 0; i < n_nodes; ++i)
        inv_m[i] = (!periodic && i == 0) ? 0.0 : 1.0 / m[i];

      // A = S M^-1 B^T V (point velocity change per unit dt and stress, sign -)
      // C = B M^-1 S^T m (point strain rate from the point velocities)
      dealii::FullMatrix<double> A(np, np), C(np, np);
      for (unsigned int p = 0; p < np; ++p)
        for (unsigned int q = 0; q < np; ++q)
          {
            double a = 0, c = 0;
            for (unsigned int i = 0; i < n_nodes; ++i)
              {
                a += S(p, i) * inv_m[i] * B(q, i) * mp;
                c += B(p, i) * inv_m[i] * S(q, i) * mp;
              }
            A(p, q) = a;
            C(p, q) = c;
          }
      // v' = v - dt A sigma;  sigma' = sigma + dt C v' = dt C v + (I - dt^2 C A) sigma
      dealii::LAPACKFullMatrix<double> G(2 * np, 2 * np);
      for (unsigned int p = 0; p < np; ++p)
        {
          G(p, p) += 1;
          G(np + p, np + p) += 1;
          for (unsigned int q = 0; q < np; ++q)
            {
              G(p, np + q) = -dt * A(p, q);
              G(np + p, q) = dt * C(p, q);
              double ca    = 0;
              for (unsigned int r = 0; r < np; ++r)
                ca += C(p, r) * A(r, q);
              G(np + p, np + q) -= dt * dt * ca;
            }
        }
      return G;
    }
    // One step at arbitrary point positions x (h = c = E = rho = 1) on a periodic grid.
    dealii::FullMatrix<double>
    step_at(const std::vector<double> &x, const unsigned int n_cells, const unsigned int n, const double dt)
    {
      const unsigned int         np = x.size();
      dealii::FullMatrix<double> S(np, n_cells), B(np, n_cells);
      for (unsigned int p = 0; p < np; ++p)
        {
          double y = std::fmod(x[p], double(n_cells));
          if (y < 0)
            y += n_cells;
          const unsigned int e  = std::min(n_cells - 1, static_cast<unsigned int>(std::floor(y)));
          const double       xi = y - e;
          const unsigned int e1 = (e + 1) % n_cells;
          S(p, e) += 1 - xi;
          S(p, e1) += xi;
          B(p, e) -= 1;
          B(p, e1) += 1;
        }
      const double        mp = 1.0 / n;
      std::vector<double> m(n_cells, 0.0);
      for (unsigned int p = 0; p < np; ++p)
        for (unsigned int i = 0; i < n_cells; ++i)
          m[i] += mp * S(p, i);
      dealii::FullMatrix<double> A(np, np), C(np, np), G(2 * np, 2 * np);
      for (unsigned int p = 0; p < np; ++p)
        for (unsigned int q = 0; q < np; ++q)
          for (unsigned int i = 0; i < n_cells; ++i)
            {
              A(p, q) += S(p, i) / m[i] * B(q, i) * mp;
              C(p, q) += B(p, i) / m[i] * S(q, i) * mp;
            }
      for (unsigned int p = 0; p < np; ++p)
        {
          G(p, p) += 1;
          G(np + p, np + p) += 1;
          for (unsigned int q = 0; q < np; ++q)
            {
              G(p, np + q) = -dt * A(p, q);
              G(np + p, q) = dt * C(p, q);
              double ca    = 0;
              for (unsigned int r = 0; r < np; ++r)
                ca += C(p, r) * A(r, q);
              G(np + p, np + q) -= dt * dt * ca;
            }
        }
      return G;
    }
  } // namespace

  double
  scheme_critical_factor_moved(const unsigned int n)
  {
    // beta(sigma) = 1/6 + 1/(12 n^2) - sigma^2 / n^2 for a shift sigma in [-1/2, 1/2] of the
    // point spacing; gamma = 4 beta is smallest at |sigma| = 1/2. lambda(s) = (4 c^2/h^2)
    // s^2 (1 - gamma s^2) is largest at s^2 = 1 (gamma <= 1/2) or 1 / (2 gamma).
    const double gamma = 2.0 / 3.0 - 2.0 / (3.0 * n * n);
    return gamma <= 0.5 ? 1.0 / std::sqrt(1 - gamma) : 2 * std::sqrt(gamma);
  }

  double
  shifted_spectral_radius(const unsigned int n, const unsigned int n_cells, const double shift, const double factor)
  {
    std::vector<double> x(n * n_cells);
    for (unsigned int e = 0; e < n_cells; ++e)
      for (unsigned int k = 0; k < n; ++k)
        x[e * n + k] = e + (k + 0.5) / n + shift;
    const auto                       G = step_at(x, n_cells, n, factor);
    dealii::LAPACKFullMatrix<double> L(G.m(), G.n());
    L = G;
    L.compute_eigenvalues(false, false);
    double r = 0;
    for (unsigned int i = 0; i < L.m(); ++i)
      r = std::max(r, std::abs(L.eigenvalue(i)));
    return r;
  }

  double
  crossing_growth_per_step(const unsigned int n, const double courant, const double v_over_c,
                           const unsigned int n_cells, double *v_over_c_used)
  {
    const double dt = courant;
    // distance per step r = v dt / h, rounded to the nearest fraction a / b with b <= 200:
    // after S = b N / gcd(a, N) steps the points have moved a whole number of grid lengths
    // and the configuration repeats exactly
    const double  d = std::max(v_over_c, 0.0) * dt;
    unsigned long a = 0, b = 1;
    double        best = std::numeric_limits<double>::max();
    for (unsigned long q = 1; q <= 200 && d > 0; ++q)
      {
        const unsigned long p = std::lround(d * q);
        if (p > 0 && std::abs(double(p) / q - d) < best - 1e-15)
          {
            best = std::abs(double(p) / q - d);
            a    = p;
            b    = q;
          }
      }
    const double v = a > 0 ? double(a) / b / dt : 0.0;
    if (v_over_c_used)
      *v_over_c_used = v;
    const unsigned int  np    = n * n_cells;
    const unsigned int  steps = a > 0 ? b * n_cells / std::gcd(a, static_cast<unsigned long>(n_cells)) : 1;
    std::vector<double> x(np);
    for (unsigned int e = 0; e < n_cells; ++e)
      for (unsigned int k = 0; k < n; ++k)
        x[e * n + k] = e + (k + 0.5) / n;
    dealii::FullMatrix<double> P(2 * np, 2 * np), T(2 * np, 2 * np);
    for (unsigned int i = 0; i < 2 * np; ++i)
      P(i, i) = 1;
    double log_scale = 0; // P is renormalised to keep it finite
    for (unsigned int s = 0; s < steps; ++s)
      {
        const auto G = step_at(x, n_cells, n, dt);
        G.mmult(T, P);
        P                 = T;
        const double norm = P.linfty_norm();
        if (norm > 1e50)
          {
            P *= 1.0 / norm;
            log_scale += std::log(norm);
          }
        for (auto &y : x)
          y += v * dt;
      }
    dealii::LAPACKFullMatrix<double> L(2 * np, 2 * np);
    L = P;
    L.compute_eigenvalues(false, false);
    double r = 0;
    for (unsigned int i = 0; i < L.m(); ++i)
      r = std::max(r, std::abs(L.eigenvalue(i)));
    return std::exp((std::log(r) + log_scale) / steps);
  }

  double
  scheme_spectral_radius(const unsigned int n, const unsigned int n_cells, const bool periodic, const double factor)
  {
    auto G = amplification(n, n_cells, periodic, factor);
    G.compute_eigenvalues(false, false);
    double r = 0;
    for (unsigned int i = 0; i < G.m(); ++i)
      r = std::max(r, std::abs(G.eigenvalue(i)));
    return r;
  }

  double
  scheme_critical_factor_closed_form(const unsigned int n)
  {
    // lambda(theta) = (4 c^2 / h^2) s^2 (1 - gamma s^2), s = sin(theta / 2), gamma = 4 beta,
    // beta = (1/n) sum_k xi_k (1 - xi_k) = 1/6 + 1/(12 n^2) > 1/8: the maximum is at
    // s^2 = 1 / (2 gamma), lambda_max = c^2 / (gamma h^2), dt = 2 / sqrt(lambda_max).
    const double gamma = 2.0 / 3.0 + 1.0 / (3.0 * n * n);
    return 2 * std::sqrt(gamma);
  }

  double
  scheme_critical_factor(const unsigned int n, const unsigned int n_cells, const bool periodic)
  {
    // |lambda| = 1 for the undamped modes and the (defective) null modes of the point
    // velocities: allow 1e-7 round-off; past the limit |lambda| grows like sqrt(f - f_cr).
    const auto stable = [&](const double f) { return scheme_spectral_radius(n, n_cells, periodic, f) <= 1 + 1e-7; };
    double     lo = 0.1, hi = 4.0;
    if (stable(hi))
      return hi;
    while (hi - lo > 1e-6 * lo)
      {
        const double mid        = 0.5 * (lo + hi);
        (stable(mid) ? lo : hi) = mid;
      }
    return lo;
  }
} // namespace talus::analysis
