// talus — validation of the shared scene sections (grid, boundary conditions,
// bodies) before any heavy work, for every family's --check and run: boundary
// ids that exist, a grid that fits the memory and the cell limit, bodies
// inside the grid that hold material points. InputError names the entry.
#pragma once

#include <talus/formulations/common/scene_parameters.h>

#include <cstdint>
#include <string>
#include <vector>

namespace talus
{
  /// Largest box grid (cells in total) and number of material points a scene
  /// may ask for: beyond these the run would not fit any machine talus targets;
  /// the limit turns a typo (an extra zero in 'cells') into an error instead of
  /// an out-of-memory kill.
  inline constexpr double max_grid_cells      = 1e8;
  inline constexpr double max_material_points = 2e9;

  /// What a family changes in the shared scene checks.
  struct SceneCheckOptions
  {
    /// Material point sets each body seeds, by body (bodies without an entry:
    /// 1); the semi-implicit family's saturated bodies seed two, soil and water.
    std::vector<unsigned int> point_sets_of_body;
    /// Memory per cell as a multiple of the explicit family's measured figure
    /// (the semi-implicit family's pressure space, its matrix and its two-phase
    /// nodal vectors: 2).
    double cell_memory_factor = 1;
  };

  /// The scene checks every family runs before any heavy work: boundary ids
  /// that exist (box grid or grid file), rigid plate regions that meet the
  /// grid, the memory the grid and the points need on this node, the cell and
  /// point limits, every body inside the grid (or clipped to it) holding at
  /// least one seeding position, file bodies whose rows exist. InputError
  /// naming the entry and what is allowed.
  template <int dim>
  void check_scene_consistency(const SceneParameters<dim> &p, const SceneCheckOptions &options = {});

  /// What a file body takes from its particle file (known before seeding).
  struct FileBodyRows
  {
    std::uint64_t             rows = 0;  ///< its material points
    std::vector<unsigned int> materials; ///< the distinct material ids of its rows, ascending
  };

  /// Body k has shape = file: its particle file holds rows of its body id, their
  /// material ids exist, and no earlier body takes the same rows. Reads only the
  /// file's body and material id columns. InputError naming the entry. Collective.
  template <int dim>
  FileBodyRows check_file_body(const SceneParameters<dim> &p, unsigned int k);

  /// Smallest cell edge of the scene's grid (grid file or box) [m]: the L of
  /// the critical time step (seed 000 Eq. 4.120), known before any setup.
  template <int dim>
  double smallest_cell_edge(const SceneParameters<dim> &p);

  /// Where checkpoints go: checkpoint/directory, or <output>/checkpoints.
  template <int dim>
  std::string
  checkpoint_directory_of(const RunParameters<dim> &p)
  {
    return p.checkpoint_directory.empty() ? p.output_directory + "/checkpoints" : p.checkpoint_directory;
  }

  /// The files of a run (for --check and before the run): the output
  /// directory and, with checkpoints, their directory can be created; with
  /// 'restart = true' a checkpoint exists to restart from.
  template <int dim>
  void check_run_files(const RunParameters<dim> &p);

  /// Estimated peak memory of one node [bytes] for a scene of n_cells and
  /// n_points run on ranks_on_node ranks (measured figures, docs/reliability.md);
  /// `cell_factor` scales the memory per cell (SceneCheckOptions::cell_memory_factor).
  double estimated_memory_bytes(double n_cells, double n_points, unsigned int dim, unsigned int ranks_on_node,
                                double cell_factor = 1);
} // namespace talus
