// talus — consistency checks of a talus-explicit .prm that need no grid and no
// particles: they run at the end of parse_parameters(), so every tool reading
// the scene (talus-explicit, talus-critical-dt, --check) refuses a broken scene
// with one message naming the entry or entity BEFORE the grid is built, the
// points are seeded or any output is written.
#pragma once

#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/explicit/explicit_solver.h>

namespace talus::explicit_mpm
{
  /// check_scene_consistency (formulations/common/scene_checks.h), then the
  /// explicit family's own: tractions on box bodies only, mass scaling >= 1
  /// with coupled 2-phase materials. The scene check throws InputError for:
  /// boundary ids that a box grid does not have (allowed 0..2 dim-1); a grid
  /// with too many cells; a body lying entirely outside the grid or, for a box
  /// body, between the seeding positions (no material point); too many material
  /// points; a fixed 'time step' above the critical time step of Eq. 4.120
  /// without 'force time step'. (Ranges of single entries, material ids and
  /// numbers are checked while parsing.)
  template <int dim>
  void check_consistency(const Parameters<dim> &p);

  /// Critical time step of Eq. 4.120 from the parameters alone (smallest cell
  /// edge of the box grid over the fastest material's wave speed).
  template <int dim>
  double critical_time_step_of(const Parameters<dim> &p);

  /// The talus-explicit check: parse_parameters() (with check_consistency) for
  /// the file's dimension, and the output directory must be creatable/writable.
  void check_scene(dealii::ParameterHandler &prm, const std::string &prm_file);
} // namespace talus::explicit_mpm
