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
// energies, a second point set under its own group) it writes and reads
// itself, in the same file: write_checkpoint_file hands it the open file,
// open_checkpoint_to_restore the file of the restart.
#pragma once

#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/scene_checks.h>
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
  void                                        write_pvd_times(io::H5File &f, const std::string &name,
                                                              const std::vector<std::pair<double, std::string>> &records);
  std::vector<std::pair<double, std::string>> read_pvd_records(const io::H5File &f, const std::string &name,
                                                               const std::string &prefix);

  /// The checkpoint of the state `s` in the run's checkpoint directory: the
  /// header, the run state and the scene signature, then `body(file)` writes
  /// the family's part (points, sums, records); committed, then the directory
  /// pruned to 'checkpoint/keep'. Returns the file's name. Collective.
  template <int dim, class Body>
  std::string
  write_checkpoint_file(const RunParameters<dim> &p, const RunState &s, const std::string &format, const int version,
                        const std::vector<double> &signature, MPI_Comm comm, Body &&body)
  {
    const std::string dir  = checkpoint_directory_of(p);
    const std::string name = prepare_checkpoint_file(dir, s.step_number, comm);
    {
      io::H5File f(name, io::H5File::Mode::create, comm);
      write_checkpoint_header(f, format, version, dim, comm);
      write_run_state(f, s);
      f.write_global("scene/signature", signature, 1);
      body(f);
      f.commit();
    }
    prune_checkpoint_files(dir, p.checkpoint_keep, comm);
    return name;
  }

  /// The newest valid checkpoint of the run's directory with its run state read
  /// into `s` (restored_from set); nullptr if there is none. Collective.
  template <int dim>
  std::unique_ptr<io::H5File>
  open_checkpoint_to_restore(const RunParameters<dim> &p, RunState &s, const std::string &format, const int version,
                             const std::vector<double> &signature, MPI_Comm comm)
  {
    auto fp = open_newest_checkpoint<dim>(list_checkpoint_files(checkpoint_directory_of(p), comm), format, version,
                                          signature, comm);
    if (fp)
      {
        read_run_state(*fp, s, p.checkpoint_interval);
        s.restored_from = fp->path();
      }
    return fp;
  }

  /// 'checkpoint/restart': unless false, `restore()` (returns false when there
  /// is no valid checkpoint) brings the state back; `true` without one is an
  /// InputError naming the entry, `if available` starts at t = 0. Returns
  /// whether the state was restored. Collective.
  template <int dim, class Restore>
  bool
  restore_if_asked(const RunParameters<dim> &p, Restore &&restore)
  {
    if (p.restart == RunParameters<dim>::Restart::no)
      return false;
    const bool restored = restore();
    if (!restored && p.restart == RunParameters<dim>::Restart::yes)
      throw InputError("checkpoint/restart: no valid checkpoint (checkpoint-<step>.h5) in '" +
                       checkpoint_directory_of(p) + "'");
    if (!restored)
      log() << "  no checkpoint in " << checkpoint_directory_of(p) << ": starting at t = 0" << std::endl;
    return restored;
  }
} // namespace talus
