// talus — parallel HDF5 tables (see hdf5.h).
#include <talus/base/errors.h>
#include <talus/base/startup.h>
#include <talus/io/hdf5.h>

#include <hdf5.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace talus::io
{
  namespace
  {
    std::vector<std::string>
    split_path(const std::string &name)
    {
      std::vector<std::string> parts;
      std::string              cur;
      for (const char c : name)
        if (c == '/')
          {
            if (!cur.empty())
              parts.push_back(cur);
            cur.clear();
          }
        else
          cur += c;
      if (!cur.empty())
        parts.push_back(cur);
      return parts;
    }

    int
    rank_of(MPI_Comm c)
    {
      int r = 0;
      if (mpi_started())
        MPI_Comm_rank(c, &r);
      return r;
    }
  } // namespace

  std::pair<std::uint64_t, std::uint64_t>
  block_range(const std::uint64_t n, const unsigned int rank, const unsigned int n_ranks)
  {
    const std::uint64_t q = n / n_ranks, r = n % n_ranks;
    const std::uint64_t begin = rank * q + std::min<std::uint64_t>(rank, r);
    return {begin, begin + q + (rank < r ? 1 : 0)};
  }

  void
  H5File::fail(const std::string &what) const
  {
    throw InputError("HDF5 file '" + file_path + "': " + what);
  }

  H5File::H5File(const std::string &path, const Mode mode, MPI_Comm comm_)
      : file_path(path)
      , tmp_path(path + ".part")
      , comm(comm_)
      , writing(mode == Mode::create)
  {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); // errors are reported by us
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (mpi_started())
      H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
    hid_t f;
    if (writing)
      f = H5Fcreate(tmp_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    else
      f = H5Fopen(file_path.c_str(), H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    if (f < 0)
      {
        if (writing)
          throw std::runtime_error("cannot create HDF5 file '" + tmp_path + "'");
        fail(std::filesystem::exists(file_path) ? "not a readable HDF5 file" : "no such file");
      }
    file = f;
  }

  void
  H5File::close()
  {
    if (file >= 0)
      H5Fclose(static_cast<hid_t>(file));
    file = -1;
  }

  H5File::~H5File()
  {
    const bool was_writing = writing && file >= 0;
    close();
    if (was_writing && rank_of(comm) == 0)
      std::remove(tmp_path.c_str());
  }

  void
  H5File::commit()
  {
    if (!writing)
      return;
    H5Fflush(static_cast<hid_t>(file), H5F_SCOPE_GLOBAL);
    close();
    MPI_Barrier(comm);
    if (rank_of(comm) == 0)
      {
        std::error_code ec;
        std::filesystem::rename(tmp_path, file_path, ec);
        if (ec)
          throw std::runtime_error("cannot rename '" + tmp_path + "' to '" + file_path + "': " + ec.message());
      }
    MPI_Barrier(comm);
    writing = false;
  }

  namespace
  {
    /// Open or create the groups of `name` and return (parent group, leaf).
    std::pair<hid_t, std::string>
    parent_group(hid_t file, const std::string &name, const bool create)
    {
      const auto parts = split_path(name);
      hid_t      g     = H5Gopen2(file, "/", H5P_DEFAULT);
      for (std::size_t i = 0; i + 1 < parts.size(); ++i)
        {
          hid_t next;
          if (H5Lexists(g, parts[i].c_str(), H5P_DEFAULT) > 0)
            next = H5Gopen2(g, parts[i].c_str(), H5P_DEFAULT);
          else if (create)
            next = H5Gcreate2(g, parts[i].c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
          else
            next = -1;
          H5Gclose(g);
          if (next < 0)
            return {-1, ""};
          g = next;
        }
      return {g, parts.empty() ? std::string() : parts.back()};
    }

    template <typename T>
    hid_t h5_type();
    template <>
    hid_t
    h5_type<double>()
    {
      return H5T_NATIVE_DOUBLE;
    }
    template <>
    hid_t
    h5_type<std::uint64_t>()
    {
      return H5T_NATIVE_UINT64;
    }

    template <typename T>
    void
    write_table(hid_t file, MPI_Comm comm, const std::string &name, const std::vector<T> &local,
                const unsigned int cols, const bool only_root)
    {
      const std::uint64_t my_rows = cols == 0 ? 0 : local.size() / cols;
      std::uint64_t       offset = 0, total = 0;
      MPI_Exscan(&my_rows, &offset, 1, MPI_UINT64_T, MPI_SUM, comm);
      if (rank_of(comm) == 0)
        offset = 0;
      MPI_Allreduce(&my_rows, &total, 1, MPI_UINT64_T, MPI_SUM, comm);

      auto [group, leaf]  = parent_group(file, name, true);
      hsize_t     dims[2] = {total, cols};
      const hid_t space   = H5Screate_simple(2, dims, nullptr);
      const hid_t dset    = H5Dcreate2(group, leaf.c_str(), h5_type<T>(), space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      if (dset < 0)
        throw std::runtime_error("HDF5: cannot create dataset '" + name + "'");
      const hid_t xfer = H5Pcreate(H5P_DATASET_XFER);
      H5Pset_dxpl_mpio(xfer, H5FD_MPIO_COLLECTIVE);
      hsize_t start[2] = {offset, 0}, count[2] = {my_rows, cols};
      hid_t   mem;
      if (my_rows == 0 || cols == 0)
        {
          // ranks without rows still take part in the collective write
          H5Sselect_none(space);
          mem = H5Screate(H5S_NULL);
          H5Sselect_none(mem);
        }
      else
        {
          H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
          mem = H5Screate_simple(2, count, nullptr);
        }
      (void)only_root;
      // an empty table is created but not written (HDF5 refuses an empty write)
      const herr_t st =
        total * cols == 0 ? 0 : H5Dwrite(dset, h5_type<T>(), mem, space, xfer, local.empty() ? nullptr : local.data());
      H5Sclose(mem);
      H5Pclose(xfer);
      H5Sclose(space);
      H5Dclose(dset);
      H5Gclose(group);
      if (st < 0)
        throw std::runtime_error("HDF5: cannot write dataset '" + name + "'");
    }

    template <typename T>
    std::vector<T>
    read_table(hid_t file, const std::string &path, const std::string &name, std::uint64_t begin, std::uint64_t end)
    {
      auto [group, leaf] = parent_group(file, name, false);
      if (group < 0 || H5Lexists(group, leaf.c_str(), H5P_DEFAULT) <= 0)
        {
          if (group >= 0)
            H5Gclose(group);
          throw InputError("HDF5 file '" + path + "': no dataset '" + name + "'");
        }
      const hid_t dset    = H5Dopen2(group, leaf.c_str(), H5P_DEFAULT);
      const hid_t space   = H5Dget_space(dset);
      hsize_t     dims[2] = {0, 0};
      H5Sget_simple_extent_dims(space, dims, nullptr);
      if (end > dims[0] || begin > end)
        throw InputError("HDF5 file '" + path + "': dataset '" + name + "' has " + std::to_string(dims[0]) +
                         " rows, asked for rows " + std::to_string(begin) + ".." + std::to_string(end));
      std::vector<T> out((end - begin) * dims[1]);
      hsize_t        start[2] = {begin, 0}, count[2] = {end - begin, dims[1]};
      hid_t          mem;
      if (out.empty())
        {
          H5Sselect_none(space);
          mem = H5Screate(H5S_NULL);
        }
      else
        {
          H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
          mem = H5Screate_simple(2, count, nullptr);
        }
      const herr_t st = dims[0] * dims[1] == 0
                          ? 0
                          : H5Dread(dset, h5_type<T>(), mem, space, H5P_DEFAULT, out.empty() ? nullptr : out.data());
      H5Sclose(mem);
      H5Sclose(space);
      H5Dclose(dset);
      H5Gclose(group);
      if (st < 0)
        throw InputError("HDF5 file '" + path + "': cannot read dataset '" + name + "' (wrong type?)");
      return out;
    }
  } // namespace

  void
  H5File::write_rows(const std::string &name, const std::vector<double> &local, const unsigned int cols)
  {
    write_table(file, comm, name, local, cols, false);
  }
  void
  H5File::write_rows(const std::string &name, const std::vector<std::uint64_t> &local, const unsigned int cols)
  {
    write_table(file, comm, name, local, cols, false);
  }
  void
  H5File::write_global(const std::string &name, const std::vector<double> &data, const unsigned int cols)
  {
    static const std::vector<double> none;
    write_table(file, comm, name, rank_of(comm) == 0 ? data : none, cols, true);
  }

  bool
  H5File::exists(const std::string &name) const
  {
    auto [group, leaf] = parent_group(file, name, false);
    if (group < 0)
      return false;
    const bool e = H5Lexists(group, leaf.c_str(), H5P_DEFAULT) > 0;
    H5Gclose(group);
    return e;
  }

  std::pair<std::uint64_t, unsigned int>
  H5File::shape(const std::string &name) const
  {
    if (!exists(name))
      fail("no dataset '" + name + "'");
    auto [group, leaf]  = parent_group(file, name, false);
    const hid_t dset    = H5Dopen2(group, leaf.c_str(), H5P_DEFAULT);
    const hid_t space   = H5Dget_space(dset);
    hsize_t     dims[2] = {0, 1};
    const int   nd      = H5Sget_simple_extent_ndims(space);
    H5Sget_simple_extent_dims(space, dims, nullptr);
    H5Sclose(space);
    H5Dclose(dset);
    H5Gclose(group);
    if (nd != 2)
      fail("dataset '" + name + "' is not a table (rank " + std::to_string(nd) + ")");
    return {dims[0], static_cast<unsigned int>(dims[1])};
  }

  std::vector<double>
  H5File::read_rows(const std::string &name, std::uint64_t begin, std::uint64_t end) const
  {
    return read_table<double>(file, file_path, name, begin, end);
  }
  std::vector<std::uint64_t>
  H5File::read_rows_u64(const std::string &name, std::uint64_t begin, std::uint64_t end) const
  {
    return read_table<std::uint64_t>(file, file_path, name, begin, end);
  }
  std::vector<double>
  H5File::read_all(const std::string &name) const
  {
    return read_rows(name, 0, shape(name).first);
  }

  namespace
  {
    void
    put_attribute(hid_t file, const std::string &name, hid_t type, const void *value)
    {
      const hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
      if (H5Aexists(root, name.c_str()) > 0)
        H5Adelete(root, name.c_str());
      const hid_t  space = H5Screate(H5S_SCALAR);
      const hid_t  attr  = H5Acreate2(root, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
      const herr_t st    = H5Awrite(attr, type, value);
      H5Aclose(attr);
      H5Sclose(space);
      H5Gclose(root);
      if (st < 0)
        throw std::runtime_error("HDF5: cannot write attribute '" + name + "'");
    }
    hid_t
    open_attribute(hid_t file, const std::string &path, const std::string &name)
    {
      const hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
      const hid_t attr = H5Aexists(root, name.c_str()) > 0 ? H5Aopen(root, name.c_str(), H5P_DEFAULT) : -1;
      H5Gclose(root);
      if (attr < 0)
        throw InputError("HDF5 file '" + path + "': no attribute '" + name + "'");
      return attr;
    }
  } // namespace

  void
  H5File::set_attribute(const std::string &name, const double value)
  {
    put_attribute(file, name, H5T_NATIVE_DOUBLE, &value);
  }
  void
  H5File::set_attribute(const std::string &name, const std::int64_t value)
  {
    put_attribute(file, name, H5T_NATIVE_INT64, &value);
  }
  void
  H5File::set_attribute(const std::string &name, const std::string &value)
  {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, value.size() + 1);
    put_attribute(file, name, type, value.c_str());
    H5Tclose(type);
  }
  bool
  H5File::has_attribute(const std::string &name) const
  {
    const hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
    const bool  e    = H5Aexists(root, name.c_str()) > 0;
    H5Gclose(root);
    return e;
  }
  double
  H5File::get_double(const std::string &name) const
  {
    const hid_t  attr = open_attribute(file, file_path, name);
    double       v    = 0;
    const herr_t st   = H5Aread(attr, H5T_NATIVE_DOUBLE, &v);
    H5Aclose(attr);
    if (st < 0)
      fail("attribute '" + name + "' is not a number");
    return v;
  }
  std::int64_t
  H5File::get_int(const std::string &name) const
  {
    const hid_t  attr = open_attribute(file, file_path, name);
    std::int64_t v    = 0;
    const herr_t st   = H5Aread(attr, H5T_NATIVE_INT64, &v);
    H5Aclose(attr);
    if (st < 0)
      fail("attribute '" + name + "' is not an integer");
    return v;
  }
  std::string
  H5File::get_string(const std::string &name) const
  {
    const hid_t attr      = open_attribute(file, file_path, name);
    const hid_t type      = H5Aget_type(attr);
    const bool  is_string = H5Tget_class(type) == H5T_STRING;
    std::string v;
    if (is_string)
      {
        const std::size_t n = H5Tget_size(type);
        std::vector<char> buf(n + 1, '\0');
        const hid_t       mem = H5Tcopy(H5T_C_S1);
        H5Tset_size(mem, n);
        H5Aread(attr, mem, buf.data());
        H5Tclose(mem);
        v = buf.data();
      }
    H5Tclose(type);
    H5Aclose(attr);
    if (!is_string)
      fail("attribute '" + name + "' is not a string");
    return v;
  }
} // namespace talus::io
