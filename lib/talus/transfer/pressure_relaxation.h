// talus — the relaxation of point pore pressures towards their node map-remap:
// the rule for the share of the smoothed value per step and the blend, shared by
// the semi-implicit family ('semi implicit/pressure smoothing fraction',
// docs/semi-implicit.md "The smoothing at low k") and the explicit 2-phase step
// on quadratic B-splines ('two phase/pressure relaxation', docs/shape-functions.md
// "2-phase on B-splines"). A family makes its own nodal map (its nodal vectors,
// fused into its own passes) and chooses the modulus of its consolidation
// coefficient; the rule and the blend live here only.
#pragma once

#include <algorithm>

namespace talus::transfer
{
  /// The consolidation coefficient c_v = k M / (rho_w g) [m^2/s] of a skeleton of
  /// hydraulic conductivity k [m/s] and modulus M [Pa] (the constrained modulus
  /// E_c, or a storage modulus with the liquid's compressibility) in a liquid of
  /// density rho_w under g.
  inline double
  consolidation_coefficient(const double k, const double M, const double rho_w, const double g)
  {
    return k * M / (rho_w * g);
  }

  /// The share of the smoothed pore pressure in a step dt: min(1, C c_v dt / h^2),
  /// C times the fraction of a grid cell's own diffusion time h^2 / c_v that the
  /// step is: a pattern of the grid scale that only the smoothing sees decays at
  /// the rate Darcy flow would dissipate it (C = 1: the semi-implicit 'automatic').
  inline double
  pressure_smoothing_fraction(const double c_v, const double dt, const double h, const double C = 1.0)
  {
    return std::min(1.0, C * c_v * dt / (h * h));
  }

  /// A point's pore pressure p blended towards its smoothed value p_s (the
  /// map-remap through the nodes, interpolated at the point) with share beta:
  /// (1 - beta) p + beta p_s; beta = 1 replaces it (seed 002 Eq. 77).
  inline double
  blend_pressure(const double p, const double p_s, const double beta)
  {
    return beta == 1.0 ? p_s : (1 - beta) * p + beta * p_s;
  }
} // namespace talus::transfer
