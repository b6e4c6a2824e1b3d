#include <talus/io/output.h>
#include <talus/io/vtu.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
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

  // grid fields in 2D and 3D
  template std::string write_vtu_atomic<2, 2>(const dealii::DataOutInterface<2, 2> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);
  template std::string write_vtu_atomic<3, 3>(const dealii::DataOutInterface<3, 3> &, const std::string &,
                                              const std::string &, const unsigned int, MPI_Comm);

  namespace
  {
    bool
    host_is_little_endian()
    {
      const std::uint16_t one = 1;
      unsigned char       first;
      std::memcpy(&first, &one, 1);
      return first == 1;
    }

    /// A block of the appended data: its XML attributes and its bytes.
    struct Block
    {
      std::string   attributes; ///< type, Name, NumberOfComponents
      const char   *data;
      std::uint64_t bytes;
    };

    template <typename T>
    Block
    block_of(const std::string &attributes, const std::vector<T> &v)
    {
      return {attributes, reinterpret_cast<const char *>(v.data()), std::uint64_t(v.size() * sizeof(T))};
    }
  } // namespace

  std::string
  write_points_vtu(const std::vector<float> &points, const std::vector<VtuPointArray> &arrays, const double time,
                   const std::string &directory, const std::string &base, const unsigned int counter, MPI_Comm comm)
  {
    const unsigned int  rank   = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int  n_rank = dealii::Utilities::MPI::n_mpi_processes(comm);
    const std::string   stem   = base + "_" + dealii::Utilities::int_to_string(counter, 4);
    const std::uint64_t n      = points.size() / 3;
    if (points.size() != 3 * n)
      throw std::logic_error("write_points_vtu: the coordinates are not 3 per point");
    const auto type_of = [](const VtuPointArray &a) { return a.integer ? "UInt64" : "Float32"; };
    for (const auto &a : arrays)
      if ((a.integer ? a.u64.size() : a.f32.size()) != n * a.n_components)
        throw std::logic_error("write_points_vtu: array '" + a.name + "' does not hold " +
                               std::to_string(a.n_components) + " values per point");

    // one vertex cell per point: connectivity i, offsets i + 1, type 1 (VTK_VERTEX);
    // Int32 unless a piece has 2^31 points or more
    const bool                small = n < std::uint64_t(std::numeric_limits<std::int32_t>::max());
    std::vector<std::int32_t> conn32, off32;
    std::vector<std::int64_t> conn64, off64;
    if (small)
      {
        conn32.resize(n);
        off32.resize(n);
        for (std::uint64_t i = 0; i < n; ++i)
          {
            conn32[i] = std::int32_t(i);
            off32[i]  = std::int32_t(i + 1);
          }
      }
    else
      {
        conn64.resize(n);
        off64.resize(n);
        for (std::uint64_t i = 0; i < n; ++i)
          {
            conn64[i] = std::int64_t(i);
            off64[i]  = std::int64_t(i + 1);
          }
      }
    const std::vector<std::uint8_t> types(n, 1);

    std::vector<Block> point_data;
    for (const auto &a : arrays)
      {
        const std::string attr = std::string("type=\"") + type_of(a) + "\" Name=\"" + a.name +
                                 "\" NumberOfComponents=\"" + std::to_string(a.n_components) + "\"";
        point_data.push_back(a.integer ? block_of(attr, a.u64) : block_of(attr, a.f32));
      }
    const Block pts  = block_of("type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\"", points);
    const Block conn = small ? block_of("type=\"Int32\" Name=\"connectivity\"", conn32)
                             : block_of("type=\"Int64\" Name=\"connectivity\"", conn64);
    const Block off =
      small ? block_of("type=\"Int32\" Name=\"offsets\"", off32) : block_of("type=\"Int64\" Name=\"offsets\"", off64);
    const Block typ = block_of("type=\"UInt8\" Name=\"types\"", types);

    const char *const  order = host_is_little_endian() ? "LittleEndian" : "BigEndian";
    std::ostringstream xml;
    std::uint64_t      offset = 0;
    std::vector<Block> all;
    const auto         entry = [&](const Block &b) {
      xml << "        <DataArray " << b.attributes << " format=\"appended\" offset=\"" << offset << "\"/>\n";
      offset += sizeof(std::uint64_t) + b.bytes;
      all.push_back(b);
    };
    xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"" << order
        << "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <FieldData>\n"
        << "      <DataArray type=\"Float64\" Name=\"TIME\" NumberOfTuples=\"1\" format=\"ascii\">"
        << std::setprecision(17) << time << "</DataArray>\n    </FieldData>\n"
        << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n      <PointData>\n";
    for (const auto &b : point_data)
      entry(b);
    xml << "      </PointData>\n      <Points>\n";
    entry(pts);
    xml << "      </Points>\n      <Cells>\n";
    entry(conn);
    entry(off);
    entry(typ);
    xml << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n_";
    {
      AtomicFile f(directory + "/" + stem + "." + std::to_string(rank) + ".vtu");
      auto      &s    = f.stream();
      const auto head = xml.str();
      s.write(head.data(), std::streamsize(head.size()));
      // each block: its byte count, then its bytes in one write
      for (const auto &b : all)
        {
          s.write(reinterpret_cast<const char *>(&b.bytes), sizeof(b.bytes));
          s.write(b.data, std::streamsize(b.bytes));
        }
      s << "\n  </AppendedData>\n</VTKFile>\n";
      f.commit();
    }
    if (rank == 0)
      {
        AtomicFile f(directory + "/" + stem + ".pvtu");
        auto      &s = f.stream();
        s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"" << order
          << "\" header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n";
        for (const auto &b : point_data)
          s << "      <PDataArray " << b.attributes << "/>\n";
        s << "    </PPointData>\n    <PPoints>\n      <PDataArray type=\"Float32\" NumberOfComponents=\"3\"/>\n"
          << "    </PPoints>\n";
        for (unsigned int r = 0; r < n_rank; ++r)
          s << "    <Piece Source=\"" << stem << "." << r << ".vtu\"/>\n";
        s << "  </PUnstructuredGrid>\n</VTKFile>\n";
        f.commit();
      }
    return stem + ".pvtu";
  }
} // namespace talus::io
