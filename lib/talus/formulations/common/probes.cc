#include <talus/base/errors.h>
#include <talus/formulations/common/probes.h>
#include <talus/io/hdf5.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <limits>
#include <utility>

namespace talus
{
  template <int dim>
  void
  PointProbes<dim>::select(const MaterialPointSet<dim> &set, const std::vector<dealii::Point<dim>> &at, MPI_Comm comm)
  {
    ids.clear();
    for (const auto &q : at)
      {
        std::pair<double, dealii::types::particle_index> best{std::numeric_limits<double>::max(), 0};
        for (const auto &pt : set.handler)
          best = std::min(best, std::make_pair(pt.get_location().distance(q), pt.get_id()));
        const auto all     = dealii::Utilities::MPI::all_gather(comm, best);
        const auto nearest = *std::min_element(all.begin(), all.end());
        require(nearest.first < std::numeric_limits<double>::max(), "output/probes",
                "the point set '" + set.name() + "' has no points to track; remove the entry");
        ids.push_back(nearest.second);
      }
    resize();
  }

  template <int dim>
  void
  PointProbes<dim>::resize()
  {
    values.assign(ids.size() * 2 * dim, 0.0);
    stress.assign(ids.size() * L::n_stress, 0.0);
  }

  template <int dim>
  void
  PointProbes<dim>::clear_values()
  {
    std::fill(values.begin(), values.end(), 0.0);
    std::fill(stress.begin(), stress.end(), 0.0);
  }

  template <int dim>
  void
  PointProbes<dim>::sample(const MaterialPointSet<dim> &set)
  {
    clear_values();
    if (ids.empty())
      return;
    for (const auto &pt : set.handler)
      record(pt.get_id(), pt.get_properties());
  }

  template <int dim>
  void
  PointProbes<dim>::add_columns(std::vector<std::string> &c, const PropertyLayout<dim> &layout) const
  {
    const char *ax[] = {"x", "y", "z"};
    for (unsigned int k = 0; k < ids.size(); ++k)
      {
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back("probe" + std::to_string(k) + "_u" + ax[d]);
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back("probe" + std::to_string(k) + "_v" + ax[d]);
      }
    // the stresses after all displacement/velocity columns
    const auto names = layout.names();
    for (unsigned int k = 0; k < ids.size(); ++k)
      for (unsigned int q = 0; q < L::n_stress; ++q)
        c.push_back("probe" + std::to_string(k) + "_" + names[L::stress + q]);
  }

  template <int dim>
  void
  PointProbes<dim>::add_values(std::vector<double> &r, MPI_Comm comm) const
  {
    if (values.empty())
      return;
    std::vector<double> v(values.size()), s(stress.size());
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(values), comm, dealii::ArrayView<double>(v));
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(stress), comm, dealii::ArrayView<double>(s));
    r.insert(r.end(), v.begin(), v.end());
    r.insert(r.end(), s.begin(), s.end());
  }

  template <int dim>
  void
  PointProbes<dim>::write_ids(io::H5File &f, const std::string &name) const
  {
    const std::vector<double> d(ids.begin(), ids.end());
    f.write_global(name, d, 1);
  }

  template <int dim>
  void
  PointProbes<dim>::read_ids(const io::H5File &f, const std::string &where, const std::string &name)
  {
    require(f.exists(name), where,
            "has no '" + name +
              "' (the ids of the tracked points of 'output/probes'); allowed: a checkpoint of the "
              "same scene");
    ids.clear();
    for (const double id : f.read_all(name))
      ids.push_back(static_cast<dealii::types::particle_index>(id));
    resize();
  }

  template struct PointProbes<2>;
  template struct PointProbes<3>;
} // namespace talus
