// talus — the pieces of a checkpoint every formulation family shares: the
// checkpoint-<step>.h5 files of a directory, the run state of the time loop,
// the scene signature a restart must match, and the material points of a
// MaterialPointSet with everything they carry.
//
// Points are written per rank in the storage order of the ParticleHandler,
// with their cell. A restart on as many ranks re-inserts every rank's points
// into the same cells in the same order (MaterialPointSet::insert_in_order),
// so the walks of the continuation visit them exactly as the saved run did: a
// bitwise restart. On another number of ranks deal.II redistributes the
// points (insert_global_particles) and each cell gets its points back in the
// saved order: the continuation agrees to round-off.
//
// What a family keeps beyond the points (nodal sums, partition weights,
// energies) it writes and reads itself, in the same file.
#pragma once

#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/io/hdf5.h>
#include <talus/particles/material_point_set.h>

#include <mpi.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace talus
{
  /// checkpoint-<step>.h5 files in `dir`, newest first, the same list on every
  /// rank (rank 0 looks). Collective.
  std::vector<std::string> list_checkpoint_files(const std::string &dir, MPI_Comm comm);
  /// Create `dir`, remove the ".part" files a killed run left; returns the name
  /// of the checkpoint of `step`. Collective.
  std::string prepare_checkpoint_file(const std::string &dir, unsigned int step, MPI_Comm comm);
  /// Keep the newest `keep` checkpoints of `dir`. Collective.
  void prune_checkpoint_files(const std::string &dir, unsigned int keep, MPI_Comm comm);

  /// Format name, version, dimension and rank count as attributes.
  void write_checkpoint_header(io::H5File &f, const std::string &format, int version, unsigned int dim, MPI_Comm comm);
  /// The newest of `files` that opens and carries `format` at `version` (the
  /// others are skipped with a warning in the log); nullptr if none. A file of
  /// another dimension or scene (`signature`) is an InputError. Collective.
  template <int dim>
  std::unique_ptr<io::H5File> open_newest_checkpoint(const std::vector<std::string> &files, const std::string &format,
                                                     int version, const std::vector<double> &signature, MPI_Comm comm);

  /// The time loop's state (step, time, step size, stage, output cadence) as
  /// attributes; read_run_state moves the next checkpoint time past `time` by
  /// `checkpoint_interval` if it lies behind (the interval of the restart's .prm).
  void write_run_state(io::H5File &f, const RunState &s);
  void read_run_state(const io::H5File &f, RunState &s, double checkpoint_interval);

  /// The numbers a restart's .prm must reproduce (grid, properties per point,
  /// materials, bodies), and their description for the error message.
  template <int dim>
  std::vector<double> scene_signature(const SceneParameters<dim> &scene, unsigned int n_properties);
  template <int dim>
  std::string describe_scene_signature(const std::vector<double> &signature);

  /// Every point of the set (id, cell, location, reference location, all
  /// properties) in storage order, the per-rank counts and the relocation
  /// counters; datasets under `group` ("particles" for the first set).
  template <int dim>
  void write_points(io::H5File &f, const MaterialPointSet<dim> &points, const std::string &group = "particles");
  /// Into the empty set: exactly as saved on the same number of ranks, else
  /// redistributed by deal.II (see the top). `where` names the file in errors.
  template <int dim>
  void read_points(const io::H5File &f, MaterialPointSet<dim> &points, const BackgroundGrid<dim> &grid,
                   const std::string &where, const std::string &group = "particles");

  /// Times of the VTU records written so far (the records are named
  /// <prefix>_<counter>.pvtu), to rewrite a PVD file after a restart.
  void write_pvd_times(io::H5File &f, const std::string &name, const std::vector<std::pair<double, std::string>> &records);
  std::vector<std::pair<double, std::string>> read_pvd_records(const io::H5File &f, const std::string &name,
                                                               const std::string &prefix);
} // namespace talus
