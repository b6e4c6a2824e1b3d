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

  /// This rank's points (3 coordinates per point, Float32) and arrays, written
  /// as <directory>/<base>_<counter>.<rank>.vtu (raw appended data, the time as
  /// FieldData TIME) and, by rank 0, the record <base>_<counter>.pvtu. Every
  /// rank passes the same array names, components and types; a rank without
  /// points writes a valid empty piece. Collective (every rank must call it;
  /// no data is exchanged). Returns the PVTU file name.
  std::string write_points_vtu(const std::vector<float> &points, const std::vector<VtuPointArray> &arrays, double time,
                               const std::string &directory, const std::string &base, unsigned int counter,
                               MPI_Comm comm);
} // namespace talus::io
