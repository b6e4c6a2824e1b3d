// talus — load balancing by material points, the one implementation every
// formulation family uses (issue 15; docs/scaling.md).
//
// A cell weighs 'cell weight' + 'point weight' x (points of ALL the family's
// point sets in the cell); p4est cuts its space-filling curve into pieces of
// equal weight. The imbalance is the largest number of points (all sets) on a
// rank over the mean. A rebalance packs the points of every set with their
// cells, repartitions, unpacks them, and then calls the family's
// `grid_changed` so that it rebuilds everything that depends on the partition
// (DoF numbering, nodal vectors, flags, matrices). The weights of the last
// rebalance go into checkpoints (`balance/weights`: CellId words and weight of
// the cells with points); a restart on as many ranks repartitions with them
// before it inserts the points, which recreates the saved partition and
// numbering exactly (the grid must be built with mesh reconstruction after
// repartitioning: BackgroundGrid(comm, true)).
#pragma once

#include <talus/formulations/common/scene_parameters.h>
#include <talus/grid/background_grid.h>
#include <talus/io/hdf5.h>
#include <talus/particles/material_point_set.h>

#include <functional>
#include <string>
#include <vector>

namespace talus
{
  template <int dim>
  class LoadBalance
  {
  public:
    using Settings = typename RunParameters<dim>::Balance;

    /// `sets`: every point set on the grid (their points are counted together
    /// and all move with their cells). `grid_changed`: the family's rebuild of
    /// its partition-dependent data, called after every repartition.
    LoadBalance(BackgroundGrid<dim> &grid, const Settings &settings, std::vector<MaterialPointSet<dim> *> sets,
                std::function<void()> grid_changed);

    /// 'load balancing/interval' > 0
    bool
    enabled() const
    {
      return settings.enabled();
    }
    /// enabled and more than one rank
    bool active() const;

    /// Largest over mean number of material points (all sets) per rank. Collective.
    double imbalance() const;
    /// Repartition by the weights of the current points, move the points of
    /// every set with their cells, call grid_changed. Collective.
    void rebalance();
    /// At the end of a family's setup: partition by points (unless a restart
    /// recreated the saved partition); logs the imbalance before and after.
    /// Returns whether it rebalanced (grid_changed was called). Collective.
    bool initial();
    /// After step `step_number`: at every 'interval'-th step, rebalance if the
    /// imbalance exceeds the threshold (logged when `progress`). Returns
    /// whether it rebalanced. Collective.
    bool after_step(unsigned int step_number, bool progress);

    /// The weights of the last rebalance into the checkpoint (when enabled).
    void write(io::H5File &f) const;
    /// Before the points are read: on as many ranks as the checkpoint's and
    /// with saved weights, recreate the saved partition (grid_changed is
    /// called; the point sets must be empty). Returns whether it did. Collective.
    bool restore(const io::H5File &f);

    /// The series.csv column (when enabled) and its value.
    void add_series_column(std::vector<std::string> &columns) const;
    void add_series_value(std::vector<double> &values) const;
    /// ", rebalances N" for the summary line (empty when disabled).
    std::string summary() const;

    unsigned int n_rebalances = 0;

  private:
    /// Repartition with given (CellId words, weight) rows (the cells absent
    /// from them weigh 'cell weight').
    void repartition_with(const std::vector<double> &rows);

    BackgroundGrid<dim>                 &grid;
    const Settings                      &settings;
    std::vector<MaterialPointSet<dim> *> sets;
    std::function<void()>                grid_changed;
    /// (CellId words, weight) of this rank's cells with points at the last
    /// rebalance (a restart keeps all rows on rank 0).
    std::vector<double> weights;
    bool                restored_partition = false;
  };
} // namespace talus
