#include <talus/io/output.h>
#include <talus/io/vtu.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <vector>

namespace talus::io
{
  template <int patch_dim, int spacedim>
  std::string
  write_vtu_atomic(const dealii::DataOutInterface<patch_dim, spacedim> &out, const std::string &directory,
                   const std::string &base, const unsigned int counter, MPI_Comm comm)
  {
    const unsigned int rank   = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int n_rank = dealii::Utilities::MPI::n_mpi_processes(comm);
    const std::string  stem   = base + "_" + dealii::Utilities::int_to_string(counter, 4);
    {
      AtomicFile f(directory + "/" + stem + "." + std::to_string(rank) + ".vtu");
      out.write_vtu(f.stream());
      f.commit();
    }
    if (rank == 0)
      {
        std::vector<std::string> pieces;
        for (unsigned int r = 0; r < n_rank; ++r)
          pieces.push_back(stem + "." + std::to_string(r) + ".vtu");
        AtomicFile f(directory + "/" + stem + ".pvtu");
        out.write_pvtu_record(f.stream(), pieces);
        f.commit();
      }
    return stem + ".pvtu";
  }

  // particles (patch dimension 0) and grid fields, in 2D and 3D
  template std::string write_vtu_atomic<0, 2>(const dealii::DataOutInterface<0, 2> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);
  template std::string write_vtu_atomic<0, 3>(const dealii::DataOutInterface<0, 3> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);
  template std::string write_vtu_atomic<2, 2>(const dealii::DataOutInterface<2, 2> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);
  template std::string write_vtu_atomic<3, 3>(const dealii::DataOutInterface<3, 3> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);
} // namespace talus::io
