// talus — output of a material-point set that every family writes the same
// way: the VTU/PVTU set of one output time (with its PVD record) and the final
// particle table (particles_final.csv).
#pragma once

#include <talus/particles/material_point_set.h>

#include <mpi.h>

#include <string>
#include <utility>
#include <vector>

namespace talus
{
  /// Write <directory>/<name>-<counter> (.vtu per rank, .pvtu) with every
  /// property of the set, add (time, file) to `records` and rewrite
  /// <directory>/<name>.pvd. Collective.
  template <int dim>
  void write_point_vtu(const MaterialPointSet<dim> &set, const std::string &directory, const std::string &name,
                       unsigned int counter, double time, std::vector<std::pair<double, std::string>> &records,
                       MPI_Comm comm);

  /// Write <directory>/particles_final.csv (rank 0, atomically): per point id,
  /// position, displacement, velocity, stress, volume and the extra blocks,
  /// sorted by id. `position_is_origin`: the stored location is the point's
  /// origin (FEM Gauss points) and the position written is location + u.
  /// Collective.
  template <int dim>
  void write_final_points_csv(const MaterialPointSet<dim> &set, const std::string &directory, MPI_Comm comm,
                              bool position_is_origin = false);
} // namespace talus
