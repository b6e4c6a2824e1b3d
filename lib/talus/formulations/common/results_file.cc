#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/results_file.h>
#include <talus/io/hdf5.h>
#include <talus/io/results.h>
#include <talus/shape/q1.h>
#include <talus/transfer/cell_walk.h>

#include <deal.II/base/mpi.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace talus
{
  namespace
  {
    /// The columns of series.csv (complete, also after a restart): rank 0
    /// reads the file, every rank gets the names and the values.
    struct SeriesColumns
    {
      std::vector<std::string>         names;
      std::vector<std::vector<double>> columns;
    };

    SeriesColumns
    read_series(const std::string &series_csv, MPI_Comm comm)
    {
      const bool  root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
      std::string text;
      if (root)
        {
          std::ifstream     in(series_csv);
          std::stringstream ss;
          ss << in.rdbuf();
          text = ss.str();
        }
      text = dealii::Utilities::MPI::broadcast(comm, text, 0);
      SeriesColumns      series;
      auto              &names   = series.names;
      auto              &columns = series.columns;
      std::istringstream is(text);
      std::string        line;
      if (std::getline(is, line))
        names = dealii::Utilities::split_string_list(line, ',');
      columns.assign(names.size(), {});
      while (std::getline(is, line))
        {
          const auto f = dealii::Utilities::split_string_list(line, ',');
          if (f.size() != names.size())
            break;
          for (std::size_t k = 0; k < f.size(); ++k)
            columns[k].push_back(std::stod(f[k]));
        }
      return series;
    }

    /// probes/: time x (probe, component) tables from the series columns, and
    /// the tracked points' initial positions. Collective.
    template <int dim>
    void
    write_probe_tables(io::H5File &out, const SeriesColumns &series, const MaterialPointSet<dim> &points,
                       const std::vector<dealii::types::particle_index> &probe_ids, const bool position_is_origin,
                       MPI_Comm comm)
    {
      using L                         = PropertyLayout<dim>;
      constexpr unsigned int nst      = L::n_stress;
      const auto            &names    = series.names;
      const auto            &columns  = series.columns;
      const unsigned int     n_probes = probe_ids.size();
      out.set_attribute("probes", std::int64_t(n_probes));
      if (n_probes > 0)
        {
          const char *ax[]   = {"x", "y", "z"};
          const auto  pnames = points.layout.names();
          const auto  column = [&](const std::string &n) -> const std::vector<double>  &{
            for (std::size_t k = 0; k < names.size(); ++k)
              if (names[k] == n)
                return columns[k];
            throw std::runtime_error("results: series.csv has no column '" + n + "'");
          };
          const std::size_t n_rows = names.empty() ? 0 : columns[0].size();
          const auto        table  = [&](const std::vector<std::string> &cols) {
            std::vector<double> t(n_rows * cols.size());
            for (std::size_t c = 0; c < cols.size(); ++c)
              {
                const auto &v = column(cols[c]);
                for (std::size_t r = 0; r < n_rows; ++r)
                  t[r * cols.size() + c] = v[r];
              }
            return t;
          };
          std::vector<std::string> u, v, sg;
          for (unsigned int k = 0; k < n_probes; ++k)
            {
              for (unsigned int d = 0; d < dim; ++d)
                {
                  u.push_back("probe" + std::to_string(k) + "_u" + ax[d]);
                  v.push_back("probe" + std::to_string(k) + "_v" + ax[d]);
                }
              for (unsigned int q = 0; q < nst; ++q)
                sg.push_back("probe" + std::to_string(k) + "_" + pnames[L::stress + q]);
            }
          out.write_global("probes/time", column("time"), 1);
          out.write_global("probes/displacement", table(u), n_probes * dim);
          out.write_global("probes/velocity", table(v), n_probes * dim);
          out.write_global("probes/stress", table(sg), n_probes * nst);
          // initial positions X = x - u of the tracked points
          std::vector<double> X(n_probes * dim, 0.0);
          for (const auto &pt : points.handler)
            for (unsigned int k = 0; k < n_probes; ++k)
              if (pt.get_id() == probe_ids[k])
                for (unsigned int d = 0; d < dim; ++d)
                  X[k * dim + d] = position_is_origin ? pt.get_location()[d]
                                                      : pt.get_location()[d] - pt.get_properties()[L::displacement + d];
          std::vector<double> Xs(X.size());
          dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(X), comm, dealii::ArrayView<double>(Xs));
          out.write_global("probes/initial_position", Xs, dim);
        }
    }

    /// grid/: the final fields mapped to the grid nodes by a lumped projection,
    ///   m_i = sum m_p N_i, u_i = sum m_p N_i u_p / m_i, v_i likewise,
    ///   sigma_i = sum V_p N_i sigma_p / sum V_p N_i
    /// (each rank its owned nodes). Collective.
    template <int dim>
    void
    write_grid_projection(io::H5File &out, const BackgroundGrid<dim> &grid, const MaterialPointSet<dim> &points)
    {
      using L                    = PropertyLayout<dim>;
      using Vector               = talus::Vector;
      constexpr unsigned int nst = L::n_stress;
      constexpr unsigned int nv  = shape::Q1<dim>::n_vertices;
      {
        constexpr unsigned int n_sv = (nst + dim - 1) / dim; // stress components over dim-vectors
        std::vector<Vector>    w(3 + n_sv);                  // weights (m, V), u, v, stress blocks
        for (auto &vec : w)
          grid.reinit_vector(vec);
        // (linear hats whatever the run's shape function: a post-processing projection)
        const CellCache<dim> *cell     = nullptr;
        const auto            at_point = [&](const unsigned int, auto &pt) {
          const auto &cc = *cell;
          const auto  P  = pt->get_properties();
          double      N[nv];
          shape::Q1<dim>::values(pt->get_reference_location(), N);
          for (unsigned int v = 0; v < nv; ++v)
            {
              const double mN = P[L::mass] * N[v], VN = P[L::volume] * N[v];
              w[0].local_element(cc.dofs[v * dim + 0]) += mN;
              w[0].local_element(cc.dofs[v * dim + 1]) += VN;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  w[1].local_element(cc.dofs[v * dim + d]) += mN * P[L::displacement + d];
                  w[2].local_element(cc.dofs[v * dim + d]) += mN * P[L::velocity + d];
                }
              for (unsigned int q = 0; q < nst; ++q)
                w[3 + q / dim].local_element(cc.dofs[v * dim + q % dim]) += VN * P[L::stress + q];
            }
        };
        // the walk takes a mutable set (it hands out particle iterators); this one only reads
        transfer::for_each_active_cell(
          const_cast<MaterialPointSet<dim> &>(points), [&](const unsigned int c) { cell = &grid.cells[c]; }, at_point,
          [](const unsigned int) {});
        for (auto &vec : w)
          vec.compress(dealii::VectorOperation::add);
        const unsigned int         n_owned = w[0].locally_owned_size();
        std::vector<unsigned char> done(n_owned, 0);
        std::vector<double>        X, m, u, vel, sig;
        for (unsigned int c = 0; c < grid.cells.size(); ++c)
          {
            if (grid.cell_iterator(c) == grid.tria.end())
              continue;
            const auto &cc = grid.cells[c];
            for (unsigned int v = 0; v < nv; ++v)
              {
                const unsigned int i0 = cc.dofs[v * dim + 0];
                if (i0 >= n_owned || done[i0])
                  continue;
                done[i0]        = 1;
                const double mi = w[0].local_element(i0), Vi = w[0].local_element(cc.dofs[v * dim + 1]);
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    X.push_back(grid.cell_iterator(c)->vertex(v)[d]);
                    const unsigned int i = cc.dofs[v * dim + d];
                    u.push_back(mi > 0 ? w[1].local_element(i) / mi : 0.0);
                    vel.push_back(mi > 0 ? w[2].local_element(i) / mi : 0.0);
                  }
                for (unsigned int q = 0; q < nst; ++q)
                  sig.push_back(Vi > 0 ? w[3 + q / dim].local_element(cc.dofs[v * dim + q % dim]) / Vi : 0.0);
                m.push_back(mi);
              }
          }
        out.write_rows("grid/vertices", X, dim);
        out.write_rows("grid/mass", m, 1);
        out.write_rows("grid/displacement", u, dim);
        out.write_rows("grid/velocity", vel, dim);
        out.write_rows("grid/stress", sig, nst);
      }
    }
  } // namespace

  template <int dim>
  void
  write_point_table(io::H5File &out, const std::string &group, const MaterialPointSet<dim> &set,
                    const bool position_is_origin)
  {
    using L                        = PropertyLayout<dim>;
    constexpr unsigned int     nst = L::n_stress;
    std::vector<std::uint64_t> id;
    std::vector<double>        x, X, u, vel, sig, vol, mass, mat, body;
    for (const auto &pt : set.handler)
      {
        const auto P   = pt.get_properties();
        const bool fix = position_is_origin; // fem: the point stays at its Gauss point
        id.push_back(pt.get_id());
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double loc = pt.get_location()[d], ud = P[L::displacement + d];
            x.push_back(fix ? loc + ud : loc);
            X.push_back(fix ? loc : loc - ud);
            u.push_back(ud);
            vel.push_back(P[L::velocity + d]);
          }
        for (unsigned int q = 0; q < nst; ++q)
          sig.push_back(P[L::stress + q]);
        vol.push_back(P[L::volume]);
        mass.push_back(P[L::mass]);
        mat.push_back(P[L::material]);
        body.push_back(P[L::body]);
      }
    out.write_rows(group + "/id", id, 1);
    out.write_rows(group + "/position", x, dim);
    out.write_rows(group + "/initial_position", X, dim);
    out.write_rows(group + "/displacement", u, dim);
    out.write_rows(group + "/velocity", vel, dim);
    out.write_rows(group + "/stress", sig, nst);
    out.write_rows(group + "/volume", vol, 1);
    out.write_rows(group + "/mass", mass, 1);
    out.write_rows(group + "/material_id", mat, 1);
    out.write_rows(group + "/body_id", body, 1);
  }

  template <int dim>
  void
  write_results_file(const ResultsFileInfo &info, const BackgroundGrid<dim> &grid, const MaterialPointSet<dim> &points,
                     const std::vector<dealii::types::particle_index> &probe_ids, const std::string &series_csv,
                     MPI_Comm comm, const std::function<void(io::H5File &)> &extra)
  {
    const SeriesColumns series = read_series(series_csv, comm);
    io::H5File          out(info.path, io::H5File::Mode::create, comm);
    out.set_attribute("format", std::string(io::results_format));
    out.set_attribute("version", std::int64_t(io::results_version));
    out.set_attribute("dimension", std::int64_t(dim));
    out.set_attribute("integration", info.integration);
    out.set_attribute("ranks", std::int64_t(dealii::Utilities::MPI::n_mpi_processes(comm)));
    out.set_attribute("time", info.time);
    out.set_attribute("steps", info.steps);
    out.set_attribute("material points", std::int64_t(points.handler.n_global_particles()));
    std::string joined;
    for (const auto &n : series.names)
      joined += (joined.empty() ? "" : ",") + n;
    out.set_attribute("series columns", joined);
    for (std::size_t k = 0; k < series.names.size(); ++k)
      out.write_global("series/" + series.names[k], series.columns[k], 1);

    write_probe_tables(out, series, points, probe_ids, info.position_is_origin, comm);
    write_point_table(out, "particles", points, info.position_is_origin); // each rank its rows
    write_grid_projection(out, grid, points);
    if (extra)
      extra(out);
    out.commit();
    log() << "  results: " << info.path << std::endl;
  }

  template void write_point_table<2>(io::H5File &, const std::string &, const MaterialPointSet<2> &, bool);
  template void write_point_table<3>(io::H5File &, const std::string &, const MaterialPointSet<3> &, bool);
  template void write_results_file<2>(const ResultsFileInfo &, const BackgroundGrid<2> &, const MaterialPointSet<2> &,
                                      const std::vector<dealii::types::particle_index> &, const std::string &, MPI_Comm,
                                      const std::function<void(io::H5File &)> &);
  template void write_results_file<3>(const ResultsFileInfo &, const BackgroundGrid<3> &, const MaterialPointSet<3> &,
                                      const std::vector<dealii::types::particle_index> &, const std::string &, MPI_Comm,
                                      const std::function<void(io::H5File &)> &);
} // namespace talus
