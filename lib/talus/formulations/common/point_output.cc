#include <talus/formulations/common/point_output.h>
#include <talus/io/output.h>
#include <talus/io/vtu.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <iomanip>

namespace talus
{
  template <int dim>
  void
  write_point_vtu(const MaterialPointSet<dim> &set, const std::string &directory, const std::string &name,
                  const unsigned int counter, const double time, std::vector<std::pair<double, std::string>> &records,
                  MPI_Comm comm)
  {
    using namespace dealii::DataComponentInterpretation;
    // the arrays: "id", then the properties in layout order, a run of vector
    // components of one name as one 3-component array (zero z in 2D)
    const auto                     names  = set.layout.names();
    const auto                     interp = set.layout.interpretations();
    const auto                     n      = set.handler.n_locally_owned_particles();
    std::vector<io::VtuPointArray> arrays(1);
    arrays[0].name    = "id";
    arrays[0].integer = true;
    std::vector<std::pair<unsigned int, unsigned int>> slot(names.size()); // property -> (array, component)
    for (unsigned int k = 0; k < names.size();)
      {
        unsigned int size = 1;
        if (interp[k] == component_is_part_of_vector)
          while (k + size < names.size() && interp[k + size] == component_is_part_of_vector &&
                 names[k + size] == names[k] && size < dim)
            ++size;
        io::VtuPointArray a;
        a.name         = names[k];
        a.n_components = interp[k] == component_is_part_of_vector ? 3 : 1;
        for (unsigned int c = 0; c < size; ++c)
          slot[k + c] = {static_cast<unsigned int>(arrays.size()), c};
        arrays.push_back(std::move(a));
        k += size;
      }
    // one pass over the points, a chunk at a time (the writer holds one chunk,
    // not the whole snapshot: docs/scaling.md, "Peak memory")
    auto                      it = set.handler.begin();
    std::vector<float *>      first(slot.size());
    std::vector<unsigned int> stride(slot.size());
    const auto                fill = [&](const std::uint64_t, const std::uint64_t count, std::vector<float> &points,
                          std::vector<io::VtuPointArray> &buffers) {
      // property k of point i goes to first[k][i * stride[k]]
      for (unsigned int k = 0; k < slot.size(); ++k)
        {
          auto &a   = buffers[slot[k].first];
          first[k]  = a.f32.data() + slot[k].second;
          stride[k] = a.n_components;
        }
      auto &ids = buffers[0].u64;
      for (std::uint64_t i = 0; i < count; ++i, ++it)
        {
          ids[i]       = it->get_id();
          const auto x = it->get_location();
          for (unsigned int d = 0; d < dim; ++d)
            points[3 * i + d] = static_cast<float>(x[d]);
          const auto P = it->get_properties();
          for (unsigned int k = 0; k < first.size(); ++k)
            first[k][i * stride[k]] = static_cast<float>(P[k]);
        }
    };
    const std::string file = io::write_points_vtu(n, arrays, fill, time, directory, name, counter, comm);
    records.emplace_back(time, file);
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      io::write_pvd(directory + "/" + name + ".pvd", records);
  }

  template <int dim>
  void
  write_final_points_csv(const MaterialPointSet<dim> &set, const std::string &directory, MPI_Comm comm,
                         const bool position_is_origin)
  {
    using L = PropertyLayout<dim>;
    std::vector<std::vector<double>> rows;
    for (const auto &pt : set.handler)
      {
        std::vector<double> r = {static_cast<double>(pt.get_id())};
        const auto          P = pt.get_properties();
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(pt.get_location()[d] + (position_is_origin ? P[L::displacement + d] : 0.0));
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(P[L::displacement + d]);
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(P[L::velocity + d]);
        for (unsigned int k = 0; k < L::n_stress; ++k)
          r.push_back(P[L::stress + k]);
        r.push_back(P[L::volume]);
        for (const auto &e : set.layout.extras)
          for (unsigned int i = 0; i < e.size; ++i)
            r.push_back(P[e.offset + i]);
        rows.push_back(r);
      }
    const auto all = dealii::Utilities::MPI::gather(comm, rows, 0);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::vector<std::vector<double>> merged;
    for (const auto &r : all)
      merged.insert(merged.end(), r.begin(), r.end());
    std::sort(merged.begin(), merged.end());
    std::vector<std::string> header = {"id"};
    const char              *ax[]   = {"x", "y", "z"};
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("pos_") + ax[d]);
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("u_") + ax[d]);
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("v_") + ax[d]);
    const auto names = set.layout.names();
    for (unsigned int k = 0; k < L::n_stress; ++k)
      header.push_back(names[L::stress + k]);
    header.push_back("volume");
    for (const auto &e : set.layout.extras)
      for (unsigned int i = 0; i < e.size; ++i)
        header.push_back(e.size == 1           ? e.name
                         : e.size == dim * dim ? e.name + "_" + ax[i / dim] + ax[i % dim]
                                               : // a matrix (APIC C_p)
                           e.name + "_" + std::string(ax[i < 3 ? i : 0]));
    io::AtomicFile f(directory + "/particles_final.csv");
    for (unsigned int k = 0; k < header.size(); ++k)
      f.stream() << (k ? "," : "") << header[k];
    f.stream() << "\n" << std::setprecision(17);
    for (const auto &r : merged)
      {
        f.stream() << static_cast<unsigned long long>(r[0]);
        for (unsigned int k = 1; k < r.size(); ++k)
          f.stream() << "," << r[k];
        f.stream() << "\n";
      }
    f.commit();
  }

  template void write_point_vtu(const MaterialPointSet<2> &, const std::string &, const std::string &, unsigned int,
                                double, std::vector<std::pair<double, std::string>> &, MPI_Comm);
  template void write_point_vtu(const MaterialPointSet<3> &, const std::string &, const std::string &, unsigned int,
                                double, std::vector<std::pair<double, std::string>> &, MPI_Comm);
  template void write_final_points_csv(const MaterialPointSet<2> &, const std::string &, MPI_Comm, bool);
  template void write_final_points_csv(const MaterialPointSet<3> &, const std::string &, MPI_Comm, bool);
} // namespace talus
