// talus — the material-point file that talus-mesh writes and the solvers read:
// one HDF5 file (io/hdf5.h) with the tables
//   position     N x dim   [m]
//   volume       N x 1     [m^3] (area in 2D)
//   material_id  N x 1     (uint64)
//   body_id      N x 1     (uint64)
//   stress       N x 4|6   optional initial Cauchy stress, tension positive [Pa]
//                          (2D xx,yy,zz,xy; 3D xx,yy,zz,xy,yz,xz)
// and the root attributes format = "talus particles", version = 1, dimension.
// Row i is material point i (the solvers give it id = its row, offset by the
// points seeded from .prm shapes).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

namespace talus::io
{
  struct ParticleTable
  {
    unsigned int               dim = 2;
    std::vector<double>        position; ///< dim per point
    std::vector<double>        volume;
    std::vector<std::uint64_t> material, body;
    std::vector<double>        stress; ///< empty or n_stress per point
    std::size_t
    size() const
    {
      return volume.size();
    }
    unsigned int
    n_stress() const
    {
      return dim == 2 ? 4 : 6;
    }
  };

  /// Collective: rank 0 passes the complete table, the other ranks an empty one
  /// (or every rank its own rows). Written as path + ".part", then renamed.
  void write_particle_file(const std::string &path, const ParticleTable &local, MPI_Comm comm);

  /// Summary of a particle file without the data (collective): dimension, rows,
  /// whether it has stresses, and the number of rows per body id.
  struct ParticleFileInfo
  {
    unsigned int               dim        = 0;
    std::uint64_t              n          = 0;
    bool                       has_stress = false;
    std::vector<std::uint64_t> rows_per_body;
    std::uint64_t              max_material = 0;
    /// per body id: the distinct material ids of its rows, ascending
    std::vector<std::vector<std::uint64_t>> materials_per_body;
  };
  /// InputError naming the file (and `where`, the .prm entry) if it is not a
  /// talus particle file of dimension dim.
  ParticleFileInfo particle_file_info(const std::string &path, unsigned int dim, MPI_Comm comm,
                                      const std::string &where);

  /// The complete table on every rank (collective).
  ParticleTable read_particle_file(const std::string &path, unsigned int dim, MPI_Comm comm, const std::string &where);
} // namespace talus::io
