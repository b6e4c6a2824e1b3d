// talus — the HDF5 results file of every family (output/results file): the
// series (read back from series.csv), the probes over time, the final fields
// of a point set and those fields mapped to the grid nodes. Read by
// talus-compare (lib/talus/io/results.h). Layout in docs/fem.md, "Results
// file".
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/particles/material_point_set.h>

#include <deal.II/base/types.h>

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace talus
{
  namespace io
  {
    class H5File;
  }

  /// What a results file says about its run besides the points.
  struct ResultsFileInfo
  {
    std::string  path;        ///< output/results file (complete path)
    std::string  integration; ///< the attribute 'integration' (mpm, fem, implicit, ...)
    double       time  = 0;
    std::int64_t steps = 0;
    /// The points stay at their origin (FEM Gauss points): position = location
    /// + u, initial position = location; otherwise initial position = location - u.
    bool position_is_origin = false;
  };

  /// Write the results file of `points` (the set the particles/, probes/ and
  /// grid/ groups describe): series/ from the complete `series_csv`, probes/
  /// from its probe columns (ids: the tracked points of `points`), particles/,
  /// grid/ (lumped Q1 projection on `grid`). `extra(file)` may add datasets
  /// before the file is committed (another point set's group). Collective.
  template <int dim>
  void write_results_file(const ResultsFileInfo &info, const BackgroundGrid<dim> &grid,
                          const MaterialPointSet<dim>                      &points,
                          const std::vector<dealii::types::particle_index> &probe_ids, const std::string &series_csv,
                          MPI_Comm comm, const std::function<void(io::H5File &)> &extra = {});

  /// The final point table of `set` under `group` (id, position,
  /// initial_position, displacement, velocity, stress, volume, mass,
  /// material_id, body_id), each rank its rows. Collective.
  template <int dim>
  void write_point_table(io::H5File &out, const std::string &group, const MaterialPointSet<dim> &set,
                         bool position_is_origin = false);
} // namespace talus
