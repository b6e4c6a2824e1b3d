#include <talus/formulations/common/diagnostics.h>
#include <talus/materials/material.h>
#include <talus/particles/material_point_set.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace talus::diagnostics
{
  template <int dim>
  void
  PointSums<dim>::sum_over_ranks(MPI_Comm comm)
  {
    diagnostics::sum_over_ranks<dim>({this}, comm);
  }

  template <int dim>
  void
  sum_over_ranks(const std::vector<PointSums<dim> *> &sums, MPI_Comm comm)
  {
    constexpr unsigned int per = 6 + 2 * dim; // the fields of one PointSums
    std::vector<double>    v;
    v.reserve(per * sums.size());
    for (const auto *s : sums)
      {
        for (const double x : {s->mass, s->second_mass, s->kinetic, s->strain, s->gravity_potential, s->n_points})
          v.push_back(x);
        for (unsigned int d = 0; d < dim; ++d)
          {
            v.push_back(s->momentum[d]);
            v.push_back(s->mass_moment[d]);
          }
      }
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v), comm, dealii::ArrayView<double>(v));
    unsigned int k = 0;
    for (auto *s : sums)
      {
        for (double *x : {&s->mass, &s->second_mass, &s->kinetic, &s->strain, &s->gravity_potential, &s->n_points})
          *x = v[k++];
        for (unsigned int d = 0; d < dim; ++d)
          {
            s->momentum[d]    = v[k++];
            s->mass_moment[d] = v[k++];
          }
      }
  }

  template <int dim>
  PointSums<dim>
  sum_points(const MaterialPointSet<dim> &set, const SumOptions<dim> &o)
  {
    using L = PropertyLayout<dim>;
    PointSums<dim> s;
    for (const auto &pt : set.handler)
      {
        const auto         props = pt.get_properties();
        const double      *P     = props.data();
        dealii::Point<dim> x     = pt.get_location();
        if (o.add_displacement)
          for (unsigned int d = 0; d < dim; ++d)
            x[d] += P[L::displacement + d];
        const double *vL = nullptr;
        const double  mL = o.second_phase ? o.second_phase(P, vL) : 0.0;
        if (mL != 0)
          s.add(P[L::mass], P + L::velocity, mL, vL, x, o.gravity);
        else
          s.add(P[L::mass], P + L::velocity, x, o.gravity);
        if (o.materials)
          s.add_strain(P[L::volume] * (*o.materials)[static_cast<unsigned int>(P[L::material])]->elastic_energy_density(
                                        L::get_stress(P)));
        if (o.extra_strain)
          s.add_strain(o.extra_strain(P));
      }
    return s;
  }

  template <int dim>
  std::string
  find_invalid_point(const MaterialPointSet<dim> &set, MPI_Comm comm, const unsigned int n_checked,
                     const bool positive_volume)
  {
    using L              = PropertyLayout<dim>;
    const unsigned int n = std::min(n_checked, set.layout.n_properties());
    std::string        found;
    for (const auto &pt : set.handler)
      {
        const auto   P = pt.get_properties();
        const auto   x = pt.get_location();
        unsigned int k = 0; // the first non-finite property
        while (k < n && std::isfinite(P[k]))
          ++k;
        bool finite_x = true;
        for (unsigned int d = 0; d < dim; ++d)
          finite_x = finite_x && std::isfinite(x[d]);
        const bool bad_volume = positive_volume && !(P[L::volume] > 0);
        if (k == n && finite_x && !bad_volume)
          continue;
        std::ostringstream os;
        os << "point " << pt.get_id() << " of '" << set.name() << "' at (";
        for (unsigned int d = 0; d < dim; ++d)
          os << (d ? ", " : "") << x[d];
        os << ")";
        if (!finite_x)
          os << ": its position is not finite";
        else if (k < n)
          {
            os << ": " << set.layout.names()[k];
            if (k >= L::velocity && k < L::stress) // a vector component
              os << "_" << char('x' + (k - L::velocity) % dim);
            os << " = " << P[k];
          }
        else
          os << ": volume = " << P[L::volume] << " (must be > 0)";
        found = os.str();
        break;
      }
    // the lowest rank with an invalid point tells the others
    const unsigned int rank = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int first =
      dealii::Utilities::MPI::min(found.empty() ? std::numeric_limits<unsigned int>::max() : rank, comm);
    if (first == std::numeric_limits<unsigned int>::max())
      return {};
    return dealii::Utilities::MPI::broadcast(comm, found, first);
  }

  template struct PointSums<2>;
  template struct PointSums<3>;
  template void         sum_over_ranks(const std::vector<PointSums<2> *> &, MPI_Comm);
  template void         sum_over_ranks(const std::vector<PointSums<3> *> &, MPI_Comm);
  template PointSums<2> sum_points(const MaterialPointSet<2> &, const SumOptions<2> &);
  template PointSums<3> sum_points(const MaterialPointSet<3> &, const SumOptions<3> &);
  template std::string  find_invalid_point(const MaterialPointSet<2> &, MPI_Comm, unsigned int, bool);
  template std::string  find_invalid_point(const MaterialPointSet<3> &, MPI_Comm, unsigned int, bool);
} // namespace talus::diagnostics
