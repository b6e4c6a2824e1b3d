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
#include <type_traits>
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

    /// A block of the appended data: its XML attributes, the bytes per point
    /// and its offset in the appended data (its byte count, then its bytes).
    struct Block
    {
      std::string   attributes; ///< type, Name, NumberOfComponents
      std::uint64_t bytes_per_point;
      std::uint64_t offset = 0;
    };
  } // namespace

  std::string
  write_points_vtu(const std::uint64_t n, const std::vector<VtuPointArray> &arrays, const VtuChunkFill &fill,
                   const double time, const std::string &directory, const std::string &base, const unsigned int counter,
                   MPI_Comm comm, const std::uint64_t chunk)
  {
    const unsigned int rank   = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int n_rank = dealii::Utilities::MPI::n_mpi_processes(comm);
    const std::string  stem   = base + "_" + dealii::Utilities::int_to_string(counter, 4);
    if (chunk == 0)
      throw std::logic_error("write_points_vtu: chunk of zero points");
    const auto type_of = [](const VtuPointArray &a) { return a.integer ? "UInt64" : "Float32"; };

    // one vertex cell per point: connectivity i, offsets i + 1, type 1 (VTK_VERTEX);
    // Int32 unless a piece has 2^31 points or more
    const bool small = n < std::uint64_t(std::numeric_limits<std::int32_t>::max());

    // the blocks in file order: the point data, the points, the cells
    std::vector<Block> blocks;
    for (const auto &a : arrays)
      blocks.push_back({std::string("type=\"") + type_of(a) + "\" Name=\"" + a.name + "\" NumberOfComponents=\"" +
                          std::to_string(a.n_components) + "\"",
                        a.n_components * (a.integer ? sizeof(std::uint64_t) : sizeof(float))});
    const std::size_t pts = blocks.size();
    blocks.push_back({"type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\"", 3 * sizeof(float)});
    const std::size_t conn = blocks.size();
    blocks.push_back({small ? "type=\"Int32\" Name=\"connectivity\"" : "type=\"Int64\" Name=\"connectivity\"",
                      small ? sizeof(std::int32_t) : sizeof(std::int64_t)});
    blocks.push_back({small ? "type=\"Int32\" Name=\"offsets\"" : "type=\"Int64\" Name=\"offsets\"",
                      small ? sizeof(std::int32_t) : sizeof(std::int64_t)});
    blocks.push_back({"type=\"UInt8\" Name=\"types\"", sizeof(std::uint8_t)});

    const char *const  order = host_is_little_endian() ? "LittleEndian" : "BigEndian";
    std::ostringstream xml;
    std::uint64_t      offset = 0;
    const auto         entry  = [&](Block &b) {
      xml << "        <DataArray " << b.attributes << " format=\"appended\" offset=\"" << offset << "\"/>\n";
      b.offset = offset;
      offset += sizeof(std::uint64_t) + n * b.bytes_per_point;
    };
    xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"" << order
        << "\" header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <FieldData>\n"
        << "      <DataArray type=\"Float64\" Name=\"TIME\" NumberOfTuples=\"1\" format=\"ascii\">"
        << std::setprecision(17) << time << "</DataArray>\n    </FieldData>\n"
        << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n      <PointData>\n";
    for (std::size_t k = 0; k < pts; ++k)
      entry(blocks[k]);
    xml << "      </PointData>\n      <Points>\n";
    entry(blocks[pts]);
    xml << "      </Points>\n      <Cells>\n";
    for (std::size_t k = conn; k < blocks.size(); ++k)
      entry(blocks[k]);
    xml << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n_";
    {
      AtomicFile f(directory + "/" + stem + "." + std::to_string(rank) + ".vtu");
      auto      &s    = f.stream();
      const auto head = xml.str();
      s.write(head.data(), std::streamsize(head.size()));
      const std::streamoff data_start = std::streamoff(head.size());
      // each block: its byte count, then its bytes, written chunk by chunk at their place
      for (const Block &b : blocks)
        {
          const std::uint64_t bytes = n * b.bytes_per_point;
          s.seekp(data_start + std::streamoff(b.offset));
          s.write(reinterpret_cast<const char *>(&bytes), sizeof(bytes));
        }
      std::vector<VtuPointArray> buffers(arrays.size());
      for (std::size_t k = 0; k < arrays.size(); ++k)
        {
          buffers[k].name         = arrays[k].name;
          buffers[k].n_components = arrays[k].n_components;
          buffers[k].integer      = arrays[k].integer;
        }
      std::vector<float>        points;
      std::vector<std::int32_t> i32;
      std::vector<std::int64_t> i64;
      std::vector<std::uint8_t> types;
      const auto put = [&](const Block &b, const std::uint64_t first, const void *data, const std::uint64_t count) {
        s.seekp(data_start + std::streamoff(b.offset + sizeof(std::uint64_t) + first * b.bytes_per_point));
        s.write(static_cast<const char *>(data), std::streamsize(count * b.bytes_per_point));
      };
      for (std::uint64_t first = 0; first < n; first += chunk)
        {
          const std::uint64_t count = std::min(chunk, n - first);
          points.assign(3 * count, 0.0f);
          for (auto &a : buffers)
            {
              if (a.integer)
                a.u64.assign(count * a.n_components, 0);
              else
                a.f32.assign(count * a.n_components, 0.0f);
            }
          fill(first, count, points, buffers);
          for (std::size_t k = 0; k < buffers.size(); ++k)
            {
              const auto &a = buffers[k];
              if ((a.integer ? a.u64.size() : a.f32.size()) != count * a.n_components)
                throw std::logic_error("write_points_vtu: array '" + a.name + "' does not hold " +
                                       std::to_string(a.n_components) + " values per point");
              put(blocks[k], first, a.integer ? static_cast<const void *>(a.u64.data()) : a.f32.data(), count);
            }
          if (points.size() != 3 * count)
            throw std::logic_error("write_points_vtu: the coordinates are not 3 per point");
          put(blocks[pts], first, points.data(), count);
          // connectivity (point k is vertex k) and offsets (k + 1), in the file's integer width
          const auto put_ids = [&](auto &ids) {
            using Id = typename std::decay_t<decltype(ids)>::value_type;
            ids.resize(count);
            for (const unsigned int shift : {0u, 1u})
              {
                for (std::uint64_t i = 0; i < count; ++i)
                  ids[i] = Id(first + i + shift);
                put(blocks[conn + shift], first, ids.data(), count);
              }
          };
          if (small)
            put_ids(i32);
          else
            put_ids(i64);
          types.assign(count, 1);
          put(blocks[conn + 2], first, types.data(), count);
        }
      s.seekp(data_start + std::streamoff(offset));
      s << "\n  </AppendedData>\n</VTKFile>\n";
      f.commit();
    }
    if (rank == 0)
      {
        AtomicFile f(directory + "/" + stem + ".pvtu");
        auto      &s = f.stream();
        s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"" << order
          << "\" header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n";
        for (std::size_t k = 0; k < pts; ++k)
          s << "      <PDataArray " << blocks[k].attributes << "/>\n";
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
