// talus — the top-level 'damping' section of every family (issue 37: one
// vocabulary): declared and parsed here, honoured by the families that can and
// refused (exit 2, the entry and the reason) by the others
// (docs/boundary-conditions.md, "Damping").
//   local damping      alpha of seed 000 §6.3: f = -alpha |f| sign(v)   talus-explicit
//   viscous damping    alpha_v [1/s], C = alpha_v M (mass-proportional
//                      Rayleigh damping): f = -alpha_v m v              talus-explicit, talus-implicit (dynamic)
//   stiffness damping  beta [s], C += beta K (stiffness-proportional
//                      Rayleigh damping)                                talus-implicit (dynamic, irreducible)
// The 'damping' of a 'stage k' (talus-explicit's stages) has the first two,
// -1 meaning "as the top level".
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>

namespace talus::loads
{
  /// The values of one 'damping' section (0: off).
  struct Damping
  {
    double local     = 0; ///< 'local damping' alpha in [0, 1)
    double viscous   = 0; ///< 'viscous damping' alpha_v [1/s]
    double stiffness = 0; ///< 'stiffness damping' beta [s] (top level only)
  };

  /// Declares the subsection 'damping' at the current level of `prm`. `stage`:
  /// the section of a 'stage k' (defaults -1 = inherit, no 'stiffness damping').
  void declare_damping(dealii::ParameterHandler &prm, bool stage = false);

  /// Reads the subsection 'damping' at the current level; `path` is the
  /// prefix of the entries in messages ("" or "stage 1"); `base` (a stage's):
  /// the values an entry of -1 inherits. Checks the ranges (InputError).
  Damping parse_damping(dealii::ParameterHandler &prm, const std::string &path = "", const Damping *base = nullptr);

  /// InputError naming 'damping/<entry>' when `value` is not 0: the family
  /// `tool` cannot honour it, for `reason` (which should say what is allowed).
  void refuse_damping(double value, const std::string &entry, const std::string &tool, const std::string &reason);
} // namespace talus::loads
