// talus — VTU output of every formulation: one piece per rank plus the PVTU
// record, each written under a temporary name and renamed when complete, so a
// killed run never leaves a truncated VTU/PVTU.
#pragma once

#include <mpi.h>

#include <string>

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
} // namespace talus::io
