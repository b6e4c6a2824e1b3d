// talus — checkpoint/restart of the explicit solver.
//
// A checkpoint is one HDF5 file (io/hdf5.h) with the complete state:
//  - attributes: format, version, dimension, ranks, step, time, time step,
//    stage, output counters, energies and counters of the run;
//  - scene/grid, scene/sizes: what the .prm of a restart must match;
//  - particles/{id, location, reference, cell, properties}: every material
//    point with all its properties (history variables included), per rank in
//    the storage order of its ParticleHandler;
//  - ranks/{n_particles, n_dofs, moves}: per-rank counts;
//  - nodal/{mass, force}: the raw local (owned + ghost) nodal sums the fused
//    update pass accumulated for the next step;
//  - output/{pvd, grid_pvd}: times of the VTU series written so far;
//  - probes/ids.
// Restarting on the same number of ranks re-inserts every rank's points in
// the same order into the same cells and restores the nodal sums, so the
// continuation is bitwise identical to the uninterrupted run. On another
// number of ranks the points are redistributed by deal.II
// (insert_global_particles) and the nodal sums are recomputed: the
// continuation then agrees to round-off.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/io/hdf5.h>

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <array>
#include <map>
#include <tuple>
#include <filesystem>
#include <sstream>

namespace talus::explicit_mpm
{
  namespace
  {
    const char *const format_name    = "talus-explicit-checkpoint";
    const int         format_version = 1;

    /// The numbers a restart's .prm must reproduce.
    template <int dim>
    std::vector<double> scene_signature(const Parameters<dim> &prm, const PropertyLayout<dim> &layout)
    {
      std::vector<double> s;
      for (unsigned int d = 0; d < dim; ++d)
        s.push_back(prm.grid_lower[d]);
      for (unsigned int d = 0; d < dim; ++d)
        s.push_back(prm.grid_upper[d]);
      for (unsigned int d = 0; d < dim; ++d)
        s.push_back(prm.grid_cells[d]);
      s.push_back(layout.n_properties());
      s.push_back(prm.materials.size());
      s.push_back(prm.bodies.size());
      return s;
    }

    template <int dim>
    std::string describe_signature(const std::vector<double> &s)
    {
      std::ostringstream os;
      os << "grid (";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? "," : "") << s[d];
      os << ") to (";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? "," : "") << s[dim + d];
      os << "), cells ";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? "x" : "") << s[2 * dim + d];
      os << ", " << s[3 * dim] << " properties per point, " << s[3 * dim + 1] << " materials, " << s[3 * dim + 2]
         << " bodies";
      return os.str();
    }

    bool is_root(MPI_Comm comm) { return dealii::Utilities::MPI::this_mpi_process(comm) == 0; }

    /// checkpoint-<step>.h5 files in dir, newest first (names carry the
    /// zero-padded step: lexicographic order is chronological).
    std::vector<std::string> sorted_checkpoints(const std::string &dir)
    {
      std::vector<std::string> files;
      if (std::filesystem::is_directory(dir))
        for (const auto &e : std::filesystem::directory_iterator(dir))
          {
            const std::string n = e.path().filename().string();
            if (n.rfind("checkpoint-", 0) == 0 && e.path().extension() == ".h5")
              files.push_back(e.path().string());
          }
      std::sort(files.rbegin(), files.rend());
      return files;
    }

    /// Partition-independent key of every locally owned DoF: vertex
    /// coordinates and component (the vertices of the box grid are computed
    /// identically on any number of ranks). Index: local DoF index.
    template <int dim>
    std::vector<std::array<double, dim + 1>> owned_dof_keys(const BackgroundGrid<dim> &grid, const unsigned int n_owned)
    {
      std::vector<std::array<double, dim + 1>> keys(n_owned);
      std::vector<unsigned char>               seen(n_owned, 0);
      for (unsigned int c = 0; c < grid.cells.size(); ++c)
        {
          if (grid.cell_iterators[c] == grid.tria.end()) // artificial: not cached
            continue;
          for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
            for (unsigned int d = 0; d < dim; ++d)
              {
                const unsigned int i = grid.cells[c].dofs[v * dim + d];
                if (i >= n_owned || seen[i])
                  continue;
                seen[i] = 1;
                const auto x = grid.cell_iterators[c]->vertex(v);
                for (unsigned int e = 0; e < dim; ++e)
                  keys[i][e] = x[e];
                keys[i][dim] = d;
              }
        }
      return keys;
    }

    /// Raw local elements (owned + ghost) of a distributed vector.
    std::vector<double> local_elements(const Vector &v)
    {
      const unsigned int n = v.locally_owned_size() + v.get_partitioner()->n_ghost_indices();
      return std::vector<double>(v.begin(), v.begin() + n);
    }
  } // namespace


  template <int dim>
  std::string
  Solver<dim>::checkpoint_directory() const
  {
    return prm.checkpoint_directory.empty() ? prm.output_directory + "/checkpoints" : prm.checkpoint_directory;
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::list_checkpoints() const
  {
    std::vector<std::string> files;
    if (is_root(comm))
      files = sorted_checkpoints(checkpoint_directory());
    return dealii::Utilities::MPI::broadcast(comm, files, 0);
  }

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    const std::string dir = checkpoint_directory();
    if (is_root(comm))
      {
        std::filesystem::create_directories(dir);
        for (const auto &e : std::filesystem::directory_iterator(dir))
          if (e.path().extension() == ".part") // left by a killed run
            std::filesystem::remove(e.path());
      }
    MPI_Barrier(comm);
    const std::string name = dir + "/checkpoint-" + dealii::Utilities::int_to_string(step_number, 10) + ".h5";

    io::H5File f(name, io::H5File::Mode::create, comm);
    f.set_attribute("format", std::string(format_name));
    f.set_attribute("version", std::int64_t(format_version));
    f.set_attribute("dimension", std::int64_t(dim));
    f.set_attribute("ranks", std::int64_t(dealii::Utilities::MPI::n_mpi_processes(comm)));
    f.set_attribute("step", std::int64_t(step_number));
    f.set_attribute("stage", std::int64_t(current_stage));
    f.set_attribute("stage start time", stage_start_time);
    f.set_attribute("time", time);
    f.set_attribute("time step", dt);
    f.set_attribute("vtu counter", std::int64_t(counters.vtu_counter));
    f.set_attribute("next series", counters.next_series);
    f.set_attribute("next vtu", counters.next_vtu);
    f.set_attribute("next checkpoint", counters.next_checkpoint);
    f.set_attribute("lost reported", std::int64_t(counters.lost_reported));
    f.set_attribute("p2g ready", std::int64_t(p2g_ready ? 1 : 0));
    f.set_attribute("external work", external_work);
    f.set_attribute("energy scale", energy_scale);
    f.set_attribute("initial kinetic", initial_energies.kinetic);
    f.set_attribute("initial strain", initial_energies.strain);
    f.set_attribute("initial potential", initial_energies.gravity_potential);
    f.set_attribute("initial external work", initial_energies.external_work);
    f.set_attribute("moved locally", std::int64_t(points.relocation_stats.moved_locally));
    f.set_attribute("global sorts", std::int64_t(points.relocation_stats.global_sorts));
    f.set_attribute("storage sorts", std::int64_t(points.relocation_stats.storage_sorts));
    f.set_attribute("lost", std::int64_t(points.relocation_stats.lost));
    f.write_global("scene/signature", scene_signature(prm, points.layout), 1);

    // particles in storage order
    const unsigned int         n_props = points.layout.n_properties();
    const std::size_t          n_local = points.handler.n_locally_owned_particles();
    std::vector<std::uint64_t> ids, cells;
    std::vector<double>        loc, ref, props;
    ids.reserve(n_local);
    cells.reserve(n_local);
    loc.reserve(n_local * dim);
    ref.reserve(n_local * dim);
    props.reserve(n_local * n_props);
    for (const auto &pt : points.handler)
      {
        ids.push_back(pt.get_id());
        cells.push_back(pt.get_surrounding_cell()->active_cell_index());
        const auto x = pt.get_location(), xi = pt.get_reference_location();
        for (unsigned int d = 0; d < dim; ++d)
          loc.push_back(x[d]);
        for (unsigned int d = 0; d < dim; ++d)
          ref.push_back(xi[d]);
        const auto P = pt.get_properties();
        props.insert(props.end(), P.begin(), P.end());
      }
    f.write_rows("particles/id", ids, 1);
    f.write_rows("particles/cell", cells, 1);
    f.write_rows("particles/location", loc, dim);
    f.write_rows("particles/reference", ref, dim);
    f.write_rows("particles/properties", props, n_props);

    const auto mass = local_elements(nodal_mass), force = local_elements(nodal_a);
    f.write_rows("ranks/n_particles", std::vector<std::uint64_t>{ids.size()}, 1);
    f.write_rows("ranks/n_dofs", std::vector<std::uint64_t>{mass.size()}, 1);
    f.write_rows("ranks/moves", std::vector<std::uint64_t>{points.relocator().moves_since_sort()}, 1);
    f.write_rows("nodal/mass", mass, 1);
    f.write_rows("nodal/force", force, 1);
    {
      // the same sums after the ghost contributions are added to their owners
      // (what the next step's compress() will produce), keyed by vertex and
      // component: a restart on another number of ranks starts from them
      Vector m, F;
      grid.reinit_vector(m);
      grid.reinit_vector(F);
      std::copy(mass.begin(), mass.end(), m.begin());
      std::copy(force.begin(), force.end(), F.begin());
      m.compress(dealii::VectorOperation::add);
      F.compress(dealii::VectorOperation::add);
      const unsigned int  n_owned = m.locally_owned_size();
      const auto          keys    = owned_dof_keys(grid, n_owned);
      std::vector<double> table;
      table.reserve(n_owned * (dim + 3));
      for (unsigned int i = 0; i < n_owned; ++i)
        {
          table.insert(table.end(), keys[i].begin(), keys[i].end());
          table.push_back(m.local_element(i));
          table.push_back(F.local_element(i));
        }
      f.write_rows("nodal/by_vertex", table, dim + 3);
    }

    std::vector<double> pvd, grid_pvd;
    for (const auto &r : pvd_records)
      pvd.push_back(r.first);
    for (const auto &r : grid_pvd_records)
      grid_pvd.push_back(r.first);
    f.write_global("output/pvd", pvd, 1);
    f.write_global("output/grid_pvd", grid_pvd, 1);
    std::vector<double> probes(probe_ids.begin(), probe_ids.end());
    f.write_global("probes/ids", probes, 1);
    if (prm.balance.enabled()) // the partition of the last rebalance (CellId words, weight)
      f.write_rows("balance/weights", balance_weights, 5);
    f.commit();

    // keep the newest `keep`
    if (is_root(comm))
      {
        const auto files = sorted_checkpoints(dir);
        for (std::size_t k = prm.checkpoint_keep; k < files.size(); ++k)
          std::filesystem::remove(files[k]);
      }
    return name;
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto   files   = list_checkpoints();
    const auto   n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    const auto   rank    = dealii::Utilities::MPI::this_mpi_process(comm);
    const auto   own_sig = scene_signature(prm, points.layout);
    for (const auto &file : files)
      {
        // a file that cannot be read is skipped (the older one is tried);
        // a readable one of another scene is an input error
        std::unique_ptr<io::H5File> fp;
        std::string                 problem;
        try
          {
            fp = std::make_unique<io::H5File>(file, io::H5File::Mode::read, comm);
            if (fp->get_string("format") != format_name || fp->get_int("version") != format_version)
              problem = "not a talus-explicit checkpoint of version " + std::to_string(format_version);
          }
        catch (const std::exception &e)
          {
            problem = e.what();
          }
        // every rank must agree on skipping
        const int bad = dealii::Utilities::MPI::max(problem.empty() ? 0 : 1, comm);
        if (bad)
          {
            log() << "  warning: skipping checkpoint " << file << ": "
                  << (problem.empty() ? "unreadable on another rank" : problem) << std::endl;
            continue;
          }
        io::H5File &f = *fp;
        const std::string where = "checkpoint " + file;
        if (f.get_int("dimension") != dim)
          throw InputError(where + ": written by a " + std::to_string(f.get_int("dimension")) +
                           "D run, this .prm is " + std::to_string(dim) + "D");
        const auto sig = f.read_all("scene/signature");
        if (sig != own_sig)
          throw InputError(where + ": written for another scene (" + describe_signature<dim>(sig) +
                           "); this .prm has " + describe_signature<dim>(own_sig));

        step_number   = f.get_int("step");
        current_stage = f.get_int("stage");
        stage_start_time = f.has_attribute("stage start time") ? f.get_double("stage start time") : 0.0;
        time          = f.get_double("time");
        dt            = f.get_double("time step");
        counters.vtu_counter     = f.get_int("vtu counter");
        counters.next_series     = f.get_double("next series");
        counters.next_vtu        = f.get_double("next vtu");
        counters.next_checkpoint = f.get_double("next checkpoint");
        counters.lost_reported   = f.get_int("lost reported");
        external_work            = f.get_double("external work");
        energy_scale             = f.get_double("energy scale");
        initial_energies         = {f.get_double("initial kinetic"), f.get_double("initial strain"),
                            f.get_double("initial potential"), f.get_double("initial external work")};
        points.relocation_stats.moved_locally = f.get_int("moved locally");
        points.relocation_stats.global_sorts  = f.get_int("global sorts");
        points.relocation_stats.storage_sorts = f.get_int("storage sorts");
        points.relocation_stats.lost          = f.get_int("lost");
        // the next interval-driven checkpoint follows the current settings
        if (prm.checkpoint_interval > 0 && counters.next_checkpoint <= time)
          counters.next_checkpoint = time + prm.checkpoint_interval;

        const unsigned int n_props   = points.layout.n_properties();
        const bool         same      = f.get_int("ranks") == static_cast<std::int64_t>(n_ranks);
        if (same && f.exists("balance/weights"))
          {
            // the partition of the saved run: the same weights give the same cells per rank
            const auto rows = f.read_all("balance/weights");
            repartition_with(rows);
            grid_changed();
            restored_partition = true;
            if (rank == 0)
              balance_weights = rows;
          }
        if (same)
          {
            // my rows: the counts of the ranks before me
            const auto counts = f.read_rows_u64("ranks/n_particles", 0, n_ranks);
            std::uint64_t begin = 0;
            for (unsigned int r = 0; r < rank; ++r)
              begin += counts[r];
            const std::uint64_t end   = begin + counts[rank];
            const auto          ids   = f.read_rows_u64("particles/id", begin, end);
            const auto          cells = f.read_rows_u64("particles/cell", begin, end);
            const auto          loc   = f.read_rows("particles/location", begin, end);
            const auto          ref   = f.read_rows("particles/reference", begin, end);
            const auto          props = f.read_rows("particles/properties", begin, end);
            // the points cell group by cell group, in the saved storage order
            std::vector<unsigned int>                                             cell_order;
            std::vector<std::vector<typename MaterialPointSet<dim>::SavedPoint>> groups;
            for (std::size_t i = 0; i < ids.size(); ++i)
              {
                if (cells[i] >= grid.cell_iterators.size() || !grid.cell_iterators[cells[i]]->is_locally_owned())
                  throw InputError(where + ": particle " + std::to_string(ids[i]) +
                                   " refers to a cell this rank does not own (grid partition differs)");
                if (i == 0 || cells[i] != cells[i - 1])
                  {
                    cell_order.push_back(cells[i]);
                    groups.emplace_back();
                  }
                typename MaterialPointSet<dim>::SavedPoint q;
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    q.x[d]  = loc[i * dim + d];
                    q.xi[d] = ref[i * dim + d];
                  }
                q.id         = ids[i];
                q.properties = props.data() + i * n_props;
                groups.back().push_back(q);
              }
            points.handler.reserve(ids.size());
            points.insert_in_order(cell_order, groups);
            // the nodal sums of the next step, exactly as the run left them
            const auto ndofs = f.read_rows_u64("ranks/n_dofs", 0, n_ranks);
            std::uint64_t dof_begin = 0;
            for (unsigned int r = 0; r < rank; ++r)
              dof_begin += ndofs[r];
            const auto mass  = f.read_rows("nodal/mass", dof_begin, dof_begin + ndofs[rank]);
            const auto force = f.read_rows("nodal/force", dof_begin, dof_begin + ndofs[rank]);
            const bool dofs_match =
              mass.size() == nodal_mass.locally_owned_size() + nodal_mass.get_partitioner()->n_ghost_indices();
            const bool all_match = dealii::Utilities::MPI::min(dofs_match ? 1 : 0, comm) == 1;
            if (all_match && f.get_int("p2g ready"))
              {
                std::copy(mass.begin(), mass.end(), nodal_mass.begin());
                std::copy(force.begin(), force.end(), nodal_a.begin());
                p2g_ready = true;
              }
            else
              p2g_ready = false;
            points.relocator().moves_since_sort() = f.read_rows_u64("ranks/moves", rank, rank + 1)[0];
          }
        else
          {
            // another rank count: read a block, let deal.II send every point
            // to the rank owning its cell. The row index travels as the id;
            // then every cell's points are re-inserted in the saved order with
            // their saved ids and reference coordinates, cells in the order of
            // their first saved row (the storage order of the run, as far as a
            // new partition allows).
            const std::uint64_t n   = f.shape("particles/id").first;
            const auto [b, e]       = io::block_range(n, rank, n_ranks);
            const auto          loc = f.read_rows("particles/location", b, e);
            const auto          pr  = f.read_rows("particles/properties", b, e);
            std::vector<dealii::Point<dim>>            x(e - b);
            std::vector<std::vector<double>>           props(e - b);
            std::vector<dealii::types::particle_index> row(e - b);
            for (std::size_t i = 0; i < x.size(); ++i)
              {
                for (unsigned int d = 0; d < dim; ++d)
                  x[i][d] = loc[i * dim + d];
                props[i].assign(pr.begin() + i * n_props, pr.begin() + (i + 1) * n_props);
                row[i] = b + i;
              }
            const auto boxes = dealii::GridTools::compute_mesh_predicate_bounding_box(
              grid.tria, dealii::IteratorFilters::LocallyOwnedCell());
            const auto global_boxes = dealii::Utilities::MPI::all_gather(comm, boxes);
            points.handler.insert_global_particles(x, global_boxes, props, row);
            if (points.handler.n_global_particles() != n)
              throw InputError(where + ": " + std::to_string(n) + " points in the file, " +
                               std::to_string(points.handler.n_global_particles()) + " placed in the grid");

            const auto all_ids = f.read_rows_u64("particles/id", 0, n);
            const auto all_ref = f.read_rows("particles/reference", 0, n);
            struct Local
            {
              std::uint64_t       row;
              unsigned int        cell;
              dealii::Point<dim>  x;
              std::vector<double> props;
            };
            std::vector<Local> local;
            local.reserve(points.handler.n_locally_owned_particles());
            for (const auto &pt : points.handler)
              {
                const auto P = pt.get_properties();
                local.push_back({pt.get_id(), pt.get_surrounding_cell()->active_cell_index(), pt.get_location(),
                                 std::vector<double>(P.begin(), P.end())});
              }
            std::sort(local.begin(), local.end(), [](const Local &a, const Local &c) { return a.row < c.row; });
            std::vector<unsigned int> cell_order;
            std::vector<std::vector<unsigned int>> in_cell_rows(grid.cells.size());
            for (unsigned int k = 0; k < local.size(); ++k)
              {
                if (in_cell_rows[local[k].cell].empty())
                  cell_order.push_back(local[k].cell);
                in_cell_rows[local[k].cell].push_back(k);
              }
            points.handler.clear_particles();
            std::vector<std::vector<typename MaterialPointSet<dim>::SavedPoint>> groups(cell_order.size());
            for (std::size_t g = 0; g < cell_order.size(); ++g)
              {
                const unsigned int c = cell_order[g];
                for (const unsigned int k : in_cell_rows[c])
                  {
                    const auto &       q  = local[k];
                    dealii::Point<dim> xi = grid.reference_point(c, q.x), saved;
                    double             dist = 0;
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        saved[d] = all_ref[q.row * dim + d];
                        dist     = std::max(dist, std::abs(saved[d] - xi[d]));
                      }
                    // the saved coordinates unless deal.II put the point into
                    // the neighbour of its old cell (a point on a face)
                    groups[g].push_back({q.x, dist < 1e-10 ? saved : xi,
                                         static_cast<dealii::types::particle_index>(all_ids[q.row]), q.props.data()});
                  }
              }
            points.insert_in_order(cell_order, groups);

            // the next step's nodal sums, by vertex and component
            p2g_ready = false;
            if (f.exists("nodal/by_vertex") && f.get_int("p2g ready"))
              {
                const auto  table = f.read_all("nodal/by_vertex");
                std::map<std::array<double, dim + 1>, std::pair<double, double>> sums;
                for (std::size_t r = 0; r + dim + 3 <= table.size(); r += dim + 3)
                  {
                    std::array<double, dim + 1> key;
                    std::copy(table.begin() + r, table.begin() + r + dim + 1, key.begin());
                    sums[key] = {table[r + dim + 1], table[r + dim + 2]};
                  }
                const unsigned int n_owned = nodal_mass.locally_owned_size();
                const auto         keys    = owned_dof_keys(grid, n_owned);
                nodal_mass                 = 0;
                nodal_a                    = 0;
                bool all_found             = true;
                for (unsigned int i = 0; i < n_owned; ++i)
                  {
                    const auto it = sums.find(keys[i]);
                    if (it == sums.end())
                      all_found = false;
                    else
                      {
                        nodal_mass.local_element(i) = it->second.first;
                        nodal_a.local_element(i)    = it->second.second;
                      }
                  }
                // ghosts stay zero: the compress of the next step adds nothing
                p2g_ready = dealii::Utilities::MPI::min(all_found ? 1 : 0, comm) == 1;
              }
            // the memory-order sort counter: this rank's share
            std::uint64_t moves = 0;
            for (const auto m : f.read_all("ranks/moves"))
              moves += static_cast<std::uint64_t>(m);
            points.relocator().moves_since_sort() = moves / n_ranks;
          }

        pvd_records.clear();
        grid_pvd_records.clear();
        {
          const auto   t = f.read_all("output/pvd");
          unsigned int k = 0;
          for (const double tt : t)
            pvd_records.emplace_back(tt, "particles_" + dealii::Utilities::int_to_string(k++, 4) + ".pvtu");
          const auto tg = f.read_all("output/grid_pvd");
          k             = 0;
          for (const double tt : tg)
            grid_pvd_records.emplace_back(tt, "grid_" + dealii::Utilities::int_to_string(k++, 4) + ".pvtu");
        }
        probe_ids.clear();
        for (const double id : f.read_all("probes/ids"))
          probe_ids.push_back(static_cast<dealii::types::particle_index>(id));
        probe_values.assign(probe_ids.size() * 2 * dim, 0.0);
        probe_stress.assign(probe_ids.size() * PropertyLayout<dim>::n_stress, 0.0);
        restored_from = file;
        return true;
      }
    return false;
  }

  template std::string Solver<2>::write_checkpoint();
  template std::string Solver<3>::write_checkpoint();
  template bool        Solver<2>::restore_checkpoint();
  template bool        Solver<3>::restore_checkpoint();
  template std::vector<std::string> Solver<2>::list_checkpoints() const;
  template std::vector<std::string> Solver<3>::list_checkpoints() const;
  template std::string              Solver<2>::checkpoint_directory() const;
  template std::string              Solver<3>::checkpoint_directory() const;
} // namespace talus::explicit_mpm
