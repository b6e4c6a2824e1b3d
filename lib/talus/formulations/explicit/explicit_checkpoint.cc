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
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/load_control.h>
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
    const int         format_version = 2; // 2: the points through formulations/common/point_checkpoint

    /// Partition-independent key of every locally owned DoF: vertex
    /// coordinates and component (the vertices of the box grid are computed
    /// identically on any number of ranks). Index: local DoF index.
    template <int dim>
    std::vector<std::array<double, dim + 1>>
    owned_dof_keys(const BackgroundGrid<dim> &grid, const unsigned int n_owned)
    {
      std::vector<std::array<double, dim + 1>> keys(n_owned);
      std::vector<unsigned char>               seen(n_owned, 0);
      for (unsigned int c = 0; c < grid.cells.size(); ++c)
        {
          if (grid.cell_iterator(c) == grid.tria.end()) // artificial: not cached
            continue;
          for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
            for (unsigned int d = 0; d < dim; ++d)
              {
                const unsigned int i = grid.cells[c].dofs[v * dim + d];
                if (i >= n_owned || seen[i])
                  continue;
                seen[i]      = 1;
                const auto x = grid.cell_iterator(c)->vertex(v);
                for (unsigned int e = 0; e < dim; ++e)
                  keys[i][e] = x[e];
                keys[i][dim] = d;
              }
        }
      return keys;
    }

    /// Raw local elements (owned + ghost) of a distributed vector.
    std::vector<double>
    local_elements(const Vector &v)
    {
      const unsigned int n = v.locally_owned_size() + v.get_partitioner()->n_ghost_indices();
      return std::vector<double>(v.begin(), v.begin() + n);
    }
  } // namespace


  template <int dim>
  std::string
  Solver<dim>::checkpoint_directory() const
  {
    return checkpoint_directory_of(prm);
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::list_checkpoints() const
  {
    return list_checkpoint_files(checkpoint_directory(), comm);
  }

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    const std::string dir  = checkpoint_directory();
    const std::string name = prepare_checkpoint_file(dir, step_number, comm);

    io::H5File f(name, io::H5File::Mode::create, comm);
    write_checkpoint_header(f, format_name, format_version, dim, comm);
    write_run_state(f, *this);
    f.set_attribute("p2g ready", std::int64_t(p2g_ready ? 1 : 0));
    f.set_attribute("external work", external_work);
    f.set_attribute("energy scale", energy_scale);
    f.set_attribute("initial kinetic", initial_energies.kinetic);
    f.set_attribute("initial strain", initial_energies.strain);
    f.set_attribute("initial potential", initial_energies.gravity_potential);
    f.set_attribute("initial external work", initial_energies.external_work);
    f.write_global("scene/signature", scene_signature(prm, points.layout.n_properties()), 1);
    write_points(f, points);

    const auto mass = local_elements(nodal_mass), force = local_elements(nodal_a);
    f.write_rows("ranks/n_dofs", std::vector<std::uint64_t>{mass.size()}, 1);
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

    write_pvd_times(f, "output/pvd", pvd_records);
    write_pvd_times(f, "output/grid_pvd", grid_pvd_records);
    probes.write_ids(f);
    if (!prm.rigid_plates.empty()) // the plates' state (the same on every rank)
      f.write_global("plates/state", control->rigid_plate_state(), loads::LoadControl<dim>::rigid_plate_state_size);
    balance.write(f); // the partition of the last rebalance
    f.commit();

    prune_checkpoint_files(dir, prm.checkpoint_keep, comm); // keep the newest `keep`
    return name;
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    const auto rank    = dealii::Utilities::MPI::this_mpi_process(comm);
    const auto fp      = open_newest_checkpoint<dim>(list_checkpoints(), format_name, format_version,
                                                scene_signature(prm, points.layout.n_properties()), comm);
    if (!fp)
      return false;
    const io::H5File &f     = *fp;
    const std::string file  = f.path();
    const std::string where = "checkpoint " + file;
    read_run_state(f, *this, prm.checkpoint_interval);
    external_work    = f.get_double("external work");
    energy_scale     = f.get_double("energy scale");
    initial_energies = {f.get_double("initial kinetic"), f.get_double("initial strain"),
                        f.get_double("initial potential"), f.get_double("initial external work")};
    const bool same  = f.get_int("ranks") == static_cast<std::int64_t>(n_ranks);
    balance.restore(f); // same ranks: the saved partition (grid_changed() called)
    if (same)
      {
        read_points(f, points, grid, where);
        // the nodal sums of the next step, exactly as the run left them
        const auto    ndofs     = f.read_rows_u64("ranks/n_dofs", 0, n_ranks);
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
      }
    else
      {
        read_points(f, points, grid, where); // redistributed by deal.II

        // the next step's nodal sums, by vertex and component
        p2g_ready = false;
        if (f.exists("nodal/by_vertex") && f.get_int("p2g ready"))
          {
            const auto                                                       table = f.read_all("nodal/by_vertex");
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
      }

    pvd_records      = read_pvd_records(f, "output/pvd", "particles");
    grid_pvd_records = read_pvd_records(f, "output/grid_pvd", "grid");
    probes.read_ids(f, "checkpoint " + f.path());
    if (!prm.rigid_plates.empty())
      {
        require(f.exists("plates/state"), where,
                "has no rigid plate state ('plates/state'), but the scene has rigid plates");
        control->restore_rigid_plate_state(f.read_all("plates/state"));
      }
    restored_from = file;
    return true;
  }

  template std::string              Solver<2>::write_checkpoint();
  template std::string              Solver<3>::write_checkpoint();
  template bool                     Solver<2>::restore_checkpoint();
  template bool                     Solver<3>::restore_checkpoint();
  template std::vector<std::string> Solver<2>::list_checkpoints() const;
  template std::vector<std::string> Solver<3>::list_checkpoints() const;
  template std::string              Solver<2>::checkpoint_directory() const;
  template std::string              Solver<3>::checkpoint_directory() const;
} // namespace talus::explicit_mpm
