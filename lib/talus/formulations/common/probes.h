// talus — the tracked points of 'output/probes', for every family: which point
// a probe follows (the nearest point of a set at t = 0, ties: the lowest id;
// after a restart the saved ids), its displacement, velocity and stress as
// series.csv columns, and the ids in a checkpoint. Layout of the columns:
// probe<k>_u<x>, probe<k>_v<x> for every probe, then probe<k>_stress_<ij> for
// every probe (docs/fem.md, "Results file").
#pragma once

#include <talus/particles/material_point_set.h>

#include <deal.II/base/point.h>
#include <deal.II/base/types.h>

#include <mpi.h>

#include <string>
#include <vector>

namespace talus
{
  namespace io
  {
    class H5File;
  }

  template <int dim>
  struct PointProbes
  {
    using L = PropertyLayout<dim>;

    /// The ids of the tracked points, one per probe.
    std::vector<dealii::types::particle_index> ids;
    /// This rank's values: (u, v) per probe (2 dim each), and n_stress per
    /// probe; zero where the rank does not hold the point.
    std::vector<double> values, stress;

    /// The point of `set` nearest to each of `at` (by its current location:
    /// call at t = 0; ties: the lowest id). Collective.
    void select(const MaterialPointSet<dim> &set, const std::vector<dealii::Point<dim>> &at, MPI_Comm comm);

    /// Size the value tables to the ids (after select or restore).
    void resize();

    /// Zero this rank's values (before a pass that records).
    void clear_values();

    /// Record the point `id` with properties P if it is tracked (hot passes).
    template <typename Properties>
    void
    record(const dealii::types::particle_index id, const Properties &P)
    {
      for (unsigned int k = 0; k < ids.size(); ++k)
        if (id == ids[k])
          {
            for (unsigned int d = 0; d < dim; ++d)
              {
                values[k * 2 * dim + d]       = P[L::displacement + d];
                values[k * 2 * dim + dim + d] = P[L::velocity + d];
              }
            for (unsigned int q = 0; q < L::n_stress; ++q)
              stress[k * L::n_stress + q] = P[L::stress + q];
          }
    }

    /// clear_values and record every point of `set`.
    void sample(const MaterialPointSet<dim> &set);

    /// Append the series.csv column names (`layout`: for the stress names).
    void add_columns(std::vector<std::string> &columns, const PropertyLayout<dim> &layout) const;

    /// Append the values of those columns, summed over the ranks. Collective.
    void add_values(std::vector<double> &row, MPI_Comm comm) const;

    /// The ids as the dataset `name` of a checkpoint / read them back (an
    /// InputError naming `where` if the file has no such dataset).
    void write_ids(io::H5File &f, const std::string &name = "probes/ids") const;
    void read_ids(const io::H5File &f, const std::string &where, const std::string &name = "probes/ids");
  };
} // namespace talus
