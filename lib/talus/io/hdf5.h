// talus — a thin parallel HDF5 file (the MPI-IO build of HDF5 that deal.II
// links). Every member is collective over the communicator: all ranks call it
// in the same order. Datasets are 2D tables of rows x cols; each rank writes
// its own rows, stored contiguously in rank order, so a file written on N
// ranks can be read back on any number of ranks (read_rows with any range).
//
// Files are written to "<path>.part" and renamed into place by commit(); a
// file destroyed without commit() removes its temporary (no truncated result).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace talus::io
{
  class H5File
  {
  public:
    enum class Mode
    {
      create, ///< new file at path + ".part"; commit() renames it to path
      read
    };

    H5File(const std::string &path, Mode mode, MPI_Comm comm);
    ~H5File();
    H5File(const H5File &)            = delete;
    H5File &operator=(const H5File &) = delete;

    /// Close and (create mode) rename into place. Collective.
    void commit();

    const std::string &
    path() const
    {
      return file_path;
    }

    /// Dataset `name` ("a/b/c": groups created as needed) of shape
    /// (sum over ranks of local rows) x cols.
    void write_rows(const std::string &name, const std::vector<double> &local, unsigned int cols);
    void write_rows(const std::string &name, const std::vector<std::uint64_t> &local, unsigned int cols);
    /// The same table on every rank, written once (by rank 0).
    void write_global(const std::string &name, const std::vector<double> &data, unsigned int cols);

    bool exists(const std::string &name) const;
    /// (rows, cols); throws InputError naming the file and dataset if missing.
    std::pair<std::uint64_t, unsigned int> shape(const std::string &name) const;
    /// Rows [begin, end) of a dataset, row-major.
    std::vector<double>        read_rows(const std::string &name, std::uint64_t begin, std::uint64_t end) const;
    std::vector<std::uint64_t> read_rows_u64(const std::string &name, std::uint64_t begin, std::uint64_t end) const;
    std::vector<double>        read_all(const std::string &name) const;

    /// Attributes of the root group (all ranks pass the same value).
    void         set_attribute(const std::string &name, double value);
    void         set_attribute(const std::string &name, std::int64_t value);
    void         set_attribute(const std::string &name, const std::string &value);
    bool         has_attribute(const std::string &name) const;
    double       get_double(const std::string &name) const;
    std::int64_t get_int(const std::string &name) const;
    std::string  get_string(const std::string &name) const;

  private:
    std::string  file_path, tmp_path;
    MPI_Comm     comm;
    std::int64_t file    = -1; // hid_t
    bool         writing = false;
    void         close();
    void         fail(const std::string &what) const;
  };

  /// Rows [begin, end) that rank `rank` of `n_ranks` reads of a table of n rows
  /// (contiguous blocks, as even as possible).
  std::pair<std::uint64_t, std::uint64_t> block_range(std::uint64_t n, unsigned int rank, unsigned int n_ranks);
} // namespace talus::io
