// talus — seeding a scene's bodies into a point set and initialising the
// points' history, once for every family: shape bodies on the sub-cell
// lattice and file bodies from their particle files, a body that holds no
// point refused (naming it), what 'clip to grid' left out logged, then each
// point's model history from its initial stress. The family decides what goes
// into which set (the semi-implicit family seeds soil and water sets from the
// bodies of their phases) and what it sets on the points afterwards.
#pragma once

#include <talus/formulations/common/scene_parameters.h>
#include <talus/particles/material_point_set.h>

#include <memory>
#include <string>
#include <vector>

namespace talus
{
  /// Seed `bodies` (a selection of the scene's, or all of them) into `set`:
  /// shape bodies, then file bodies with ids after them; point masses are
  /// density_of_material x volume. Unless `allow_empty`, a body that holds no
  /// point is an InputError naming 'body k' (`body_index[k]`, or k when empty)
  /// and `what` ("material point", "soil point", ...). With `scene`, what
  /// 'clip to grid' left out of each body is logged. Returns the volumes per
  /// body (shape + file) and the counts. Collective.
  template <int dim>
  SeedingResult seed_scene_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                                  const std::vector<double> &density_of_material, MaterialPointSet<dim> &set,
                                  const std::string &what, const SceneParameters<dim> *scene = nullptr,
                                  const std::vector<unsigned int> &body_index = {}, bool allow_empty = false);

  /// The density of every material of the scene (the point masses of seeding).
  template <int dim>
  std::vector<double> material_densities(const SceneParameters<dim> &scene);

  /// InputError naming 'body k' unless every body holds volume in
  /// `volume_per_body` (after a family re-seeded, e.g. FEM Gauss points).
  template <int dim>
  void require_seeded(const std::vector<BodyDescription<dim>> &bodies, const std::vector<double> &volume_per_body,
                      const std::string &what, const std::vector<unsigned int> &body_index = {});

  /// Each locally owned point's model history from its material (property
  /// `material`) and its current stress; the history sits at `history_offset`.
  template <int dim>
  void initialize_point_histories(const std::vector<std::shared_ptr<const materials::Material>> &materials,
                                  MaterialPointSet<dim> &set, unsigned int history_offset);

  /// Log what 'clip to grid' left out of each body with clipping: the seeding
  /// positions outside a box grid (counted), the rows of a file body outside
  /// the grid, or for a shape body on a grid file the shape's volume minus the
  /// seeded volume.
  template <int dim>
  void log_clipping(const SceneParameters<dim> &p, const std::vector<BodyDescription<dim>> &bodies,
                    const SeedingResult &seeded, const SeedingResult &filed,
                    const std::vector<unsigned int> &body_index = {});
} // namespace talus
