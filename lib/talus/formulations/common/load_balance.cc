#include <talus/base/tool.h>
#include <talus/formulations/common/load_balance.h>

#include <deal.II/base/mpi.h>

#include <iomanip>
#include <map>

namespace talus
{
  template <int dim>
  LoadBalance<dim>::LoadBalance(BackgroundGrid<dim> &grid_, const Settings &settings_,
                                std::vector<MaterialPointSet<dim> *> sets_, std::function<void()> grid_changed_)
      : grid(grid_)
      , settings(settings_)
      , sets(std::move(sets_))
      , grid_changed(std::move(grid_changed_))
  {
  }

  template <int dim>
  bool
  LoadBalance<dim>::active() const
  {
    return enabled() && dealii::Utilities::MPI::n_mpi_processes(grid.comm) > 1;
  }

  template <int dim>
  double
  LoadBalance<dim>::imbalance() const
  {
    double n = 0;
    for (const auto *s : sets)
      n += s->handler.n_locally_owned_particles();
    const double       mx  = dealii::Utilities::MPI::max(n, grid.comm);
    const double       sum = dealii::Utilities::MPI::sum(n, grid.comm);
    const unsigned int nr  = dealii::Utilities::MPI::n_mpi_processes(grid.comm);
    return sum > 0 ? mx * nr / sum : 1.0;
  }

  template <int dim>
  void
  LoadBalance<dim>::repartition_with(const std::vector<double> &rows)
  {
    // rows: the 4 words of CellId::to_binary and the weight
    std::map<dealii::CellId::binary_type, unsigned int> weight_of;
    for (std::size_t r = 0; r + 5 <= rows.size(); r += 5)
      {
        dealii::CellId::binary_type key;
        for (unsigned int k = 0; k < 4; ++k)
          key[k] = static_cast<unsigned int>(rows[r + k]);
        weight_of[key] = static_cast<unsigned int>(rows[r + 4]);
      }
    grid.repartition([&](const typename dealii::Triangulation<dim>::cell_iterator &cell) {
      const auto it = weight_of.find(cell->id().template to_binary<dim>());
      return it == weight_of.end() ? settings.cell_weight : it->second;
    });
  }

  template <int dim>
  void
  LoadBalance<dim>::rebalance()
  {
    // the weights of the cells with points of any set (the others weigh 'cell
    // weight'), kept for checkpoints: a bitwise restart recreates the
    // partition from them, and the repartition itself uses the same rows
    weights.clear();
    for (const auto &cell : grid.tria.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          unsigned int n = 0;
          for (const auto *s : sets)
            n += s->handler.n_particles_in_cell(cell);
          if (n == 0)
            continue;
          for (const unsigned int w : cell->id().template to_binary<dim>())
            weights.push_back(w);
          weights.push_back(settings.cell_weight + settings.point_weight * n);
        }
    // an empty handler follows the triangulation's signals by itself; one with
    // points is packed and unpacked around the repartition
    std::vector<unsigned char> packed(sets.size(), 0);
    for (unsigned int k = 0; k < sets.size(); ++k)
      if (sets[k]->handler.n_global_particles() > 0)
        {
          sets[k]->handler.prepare_for_coarsening_and_refinement();
          packed[k] = 1;
        }
    repartition_with(weights);
    for (unsigned int k = 0; k < sets.size(); ++k)
      if (packed[k])
        sets[k]->handler.unpack_after_coarsening_and_refinement();
    grid_changed();
    ++n_rebalances;
  }

  template <int dim>
  bool
  LoadBalance<dim>::initial()
  {
    if (!active() || restored_partition)
      return false;
    const double before = imbalance();
    rebalance();
    log() << "  load balancing: points per rank max/mean " << std::setprecision(4) << before << " -> " << imbalance()
          << std::endl;
    return true;
  }

  template <int dim>
  bool
  LoadBalance<dim>::after_step(const unsigned int step_number, const bool progress)
  {
    if (!active() || step_number % settings.interval != 0)
      return false;
    const double before = imbalance();
    if (before <= settings.threshold)
      return false;
    rebalance();
    const double after = imbalance();
    if (progress)
      log() << "  step " << step_number << ": rebalanced, points per rank max/mean " << std::setprecision(4) << before
            << " -> " << after << std::endl;
    return true;
  }

  template <int dim>
  void
  LoadBalance<dim>::write(io::H5File &f) const
  {
    if (enabled()) // the partition of the last rebalance (CellId words, weight)
      f.write_rows("balance/weights", weights, 5);
  }

  template <int dim>
  bool
  LoadBalance<dim>::restore(const io::H5File &f)
  {
    const bool same =
      f.get_int("ranks") == static_cast<std::int64_t>(dealii::Utilities::MPI::n_mpi_processes(grid.comm));
    if (!same || !f.exists("balance/weights"))
      return false;
    // the partition of the saved run: the same weights give the same cells per rank
    const auto rows = f.read_all("balance/weights");
    repartition_with(rows);
    grid_changed();
    restored_partition = true;
    weights.clear();
    if (dealii::Utilities::MPI::this_mpi_process(grid.comm) == 0)
      weights = rows;
    return true;
  }

  template <int dim>
  void
  LoadBalance<dim>::add_series_column(std::vector<std::string> &columns) const
  {
    if (enabled())
      columns.push_back("imbalance");
  }

  template <int dim>
  void
  LoadBalance<dim>::add_series_value(std::vector<double> &values) const
  {
    if (enabled())
      values.push_back(imbalance());
  }

  template <int dim>
  std::string
  LoadBalance<dim>::summary() const
  {
    return enabled() ? ", rebalances " + std::to_string(n_rebalances) : std::string();
  }

  template class LoadBalance<2>;
  template class LoadBalance<3>;
} // namespace talus
