// talus — the Simulation base of every family's solver (simulation.h).
#include <talus/formulations/common/point_output.h>
#include <talus/formulations/common/simulation.h>
#include <talus/io/output.h>

#include <deal.II/base/mpi.h>

namespace talus
{
  template <int dim>
  std::vector<MaterialPointSet<dim> *>
  Simulation<dim>::set_pointers(const std::vector<std::unique_ptr<MaterialPointSet<dim>>> &sets)
  {
    std::vector<MaterialPointSet<dim> *> out;
    for (const auto &s : sets)
      out.push_back(s.get());
    return out;
  }

  namespace
  {
    template <int dim>
    std::vector<std::unique_ptr<MaterialPointSet<dim>>>
    make_sets(const BackgroundGrid<dim> &grid, const std::vector<std::string> &names)
    {
      std::vector<std::unique_ptr<MaterialPointSet<dim>>> sets;
      for (const auto &n : names)
        sets.push_back(std::make_unique<MaterialPointSet<dim>>(grid, n));
      return sets;
    }
  } // namespace

  template <int dim>
  Simulation<dim>::Simulation(const SceneParameters<dim> &scene_, const RunParameters<dim> &run_, MPI_Comm c,
                              const std::vector<std::string> &set_names)
      : comm(c)
      , grid(c, run_.balance.enabled())
      , point_sets(make_sets(grid, set_names))
      , balance(grid, run_.balance, set_pointers(point_sets), [this] { grid_changed(); })
      , point_set_records(set_names.size())
      , scene(scene_)
      , run(run_)
  {
  }

  template <int dim>
  Simulation<dim>::~Simulation() = default;

  template <int dim>
  void
  Simulation<dim>::make_grid()
  {
    if (scene.grid_mesh)
      grid.make_from_mesh(*scene.grid_mesh);
    else
      grid.make_box(scene.grid_lower, scene.grid_upper, scene.grid_cells);
    grid.setup();
    if (scene.bspline())
      grid.setup_bspline_patches(); // the 4^dim node patch of every owned cell
  }

  template <int dim>
  void
  Simulation<dim>::after_step()
  {
    balance.after_step(step_number, run.progress);
  }

  template <int dim>
  unsigned long long
  Simulation<dim>::lost_points() const
  {
    unsigned long long lost = 0;
    for (const auto &s : point_sets)
      lost += s->relocation_stats.lost;
    return lost;
  }

  template <int dim>
  std::string
  Simulation<dim>::point_set_output_name(const unsigned int k) const
  {
    return point_sets.size() == 1 ? std::string("particles") : point_sets[k]->name();
  }

  template <int dim>
  void
  Simulation<dim>::write_point_sets(const unsigned int counter)
  {
    for (unsigned int k = 0; k < point_sets.size(); ++k)
      write_point_vtu(*point_sets[k], run.output_directory, point_set_output_name(k), counter, time,
                      point_set_records[k], comm);
  }

  template <int dim>
  void
  Simulation<dim>::rewrite_point_set_records() const
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    for (unsigned int k = 0; k < point_sets.size(); ++k)
      io::write_pvd(run.output_directory + "/" + point_set_output_name(k) + ".pvd", point_set_records[k]);
  }

  template class Simulation<2>;
  template class Simulation<3>;
} // namespace talus
