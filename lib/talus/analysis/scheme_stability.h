// talus — von Neumann / eigenvalue stability analysis of the explicit MPM step
// actually implemented (seed 000 §4.3.7: lumped mass, USL-type update with the
// momentum re-projection of Eqs. 4.47-4.48), on a uniform 1D grid of linear
// elements with n equally spaced material points per cell (at (k + 1/2) / n).
// See docs/stability-analysis.md for the derivation.
#pragma once

namespace talus::analysis
{
  /// Spectral radius of the amplification matrix of one step of size
  /// dt = factor * h / c (c = sqrt(E / rho)), for n_points points per cell on
  /// n_cells cells: periodic (Bloch waves theta = 2 pi k / n_cells) or a bar
  /// fixed at x = 0 and free at x = n_cells h.
  double scheme_spectral_radius(unsigned int n_points, unsigned int n_cells, bool periodic, double factor);

  /// Closed form of the limit on an infinite uniform grid (Bloch analysis of the
  /// reduced nodal recurrence, docs/stability-analysis.md):
  /// dt_scheme = 2 sqrt(2/3 + 1/(3 n^2)) h / c (n = 1: 2, n = 2: sqrt(3), n -> oo: sqrt(8/3)).
  double scheme_critical_factor_closed_form(unsigned int n_points);

  /// The same limit when the points have moved: all points of every cell shifted by the
  /// same distance (a uniform translation) on an infinite uniform grid; the smallest limit
  /// over the shifts, reached when points sit on the nodes:
  /// gamma_min = 2/3 - 2/(3 n^2); dt = h / (c sqrt(1 - gamma_min)) if gamma_min <= 1/2, else
  /// 2 sqrt(gamma_min) h / c (n = 1: 1, n = 2: sqrt(2), n = 3: 1.540, n = 4: 1.581).
  double scheme_critical_factor_moved(unsigned int n_points);

  /// Spectral radius of one step with the points of every cell shifted by `shift` (in cell
  /// sizes) from the regular positions, periodic grid of n_cells cells, dt = factor h / c.
  double shifted_spectral_radius(unsigned int n_points, unsigned int n_cells, double shift, double factor);

  /// Largest factor f (dt = f h / c) for which the spectral radius stays <= 1
  /// (to 1e-7 in |lambda|): bisection on f in [0.1, 4], to relative 1e-6.
  double scheme_critical_factor(unsigned int n_points, unsigned int n_cells = 32, bool periodic = true);
  /// Points crossing cells: growth factor per step of a perturbation of a uniformly
  /// translating state (velocity v, points at (k + 1/2)/n + v t of every cell) on a periodic
  /// grid of n_cells cells, for dt = courant h / c (Floquet analysis: the product of the
  /// step matrices at the moving point positions over the time the points need to travel
  /// the whole grid, after which the configuration repeats exactly;
  /// docs/stability-analysis.md, "Cell crossing"). v dt / h is rounded to the nearest
  /// fraction a / b with b <= 200 (exact periodicity); `v_over_c_used` returns the value used.
  /// 1 for v = 0 below the limit; > 1 means the crossing makes the step unstable.
  double crossing_growth_per_step(unsigned int n_points, double courant, double v_over_c, unsigned int n_cells,
                                  double *v_over_c_used = nullptr);
} // namespace talus::analysis
