// talus — VTU output of every formulation, one piece per rank plus the PVTU
// record, each written under a temporary name and renamed when complete, so a
// killed run never leaves a truncated VTU/PVTU:
//  * point sets (every family's material points): talus's own writer, VTK XML
//    UnstructuredGrid with the data in one raw appended binary block (header
//    type UInt64), one vertex cell per point, one write per array
//    (docs/scaling.md, "Snapshot output");
//  * grid fields (talus-explicit's `output/write grid`): deal.II's DataOut.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace dealii
{
  template <int dim, int spacedim>
  class DataOutInterface;
}

namespace talus::io
{
  /// Write `out` as <directory>/<base>_<counter>.<rank>.vtu and the record
  /// <base>_<counter>.pvtu (same names as deal.II's
  /// write_vtu_with_pvtu_record). Collective. Returns the PVTU file name.
  template <int patch_dim, int spacedim>
  std::string write_vtu_atomic(const dealii::DataOutInterface<patch_dim, spacedim> &out, const std::string &directory,
                               const std::string &base, const unsigned int counter, MPI_Comm comm);

  /// One point-data array of a piece: n_points x n_components values, Float32
  /// (f32) or, if `integer`, UInt64 (u64).
  struct VtuPointArray
  {
    std::string                name;
    unsigned int               n_components = 1;
    bool                       integer      = false;
    std::vector<float>         f32;
    std::vector<std::uint64_t> u64;
  };

  /// Fills the buffers of one chunk of points: fill(first, count, points,
  /// arrays) writes the coordinates (3 per point) of points first ...
  /// first + count - 1 into `points` (3 x count floats) and their values into
  /// the arrays (count x n_components each, f32 or u64 as declared). Called for
  /// consecutive chunks in point order.
  using VtuChunkFill = std::function<void(std::uint64_t first, std::uint64_t count, std::vector<float> &points,
                                          std::vector<VtuPointArray> &arrays)>;

  /// This rank's n points (3 coordinates per point, Float32) and the arrays
  /// declared by `arrays` (name, components, type; their data are ignored),
  /// written as <directory>/<base>_<counter>.<rank>.vtu (raw appended data, the
  /// time as FieldData TIME) and, by rank 0, the record <base>_<counter>.pvtu.
  /// The values come from `fill`, `chunk` points at a time, each chunk written
  /// to its place in every array's block: the memory held is one chunk
  /// (~93 bytes per 3D point), not the whole snapshot. Every rank passes the
  /// same array names, components and types; a rank without points writes a
  /// valid empty piece. Collective (every rank must call it; no data is
  /// exchanged). Returns the PVTU file name.
  std::string write_points_vtu(std::uint64_t n, const std::vector<VtuPointArray> &arrays, const VtuChunkFill &fill,
                               double time, const std::string &directory, const std::string &base, unsigned int counter,
                               MPI_Comm comm, std::uint64_t chunk = 65536);
} // namespace talus::io
