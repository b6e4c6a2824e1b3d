#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/point_forces.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <limits>

namespace talus::loads
{
  template <int dim>
  void
  PointForces<dim>::extend_layout(PropertyLayout<dim> &layout, const unsigned int n_slots)
  {
    slots = n_slots;
    for (unsigned int j = 0; j < n_slots; ++j)
      {
        const unsigned int o = layout.add_extra("point_force_" + std::to_string(j), dim, true);
        if (j == 0)
          force_offset = o;
      }
  }

  template <int dim>
  void
  PointForces<dim>::assign(const std::vector<Traction<dim>> &tractions, MaterialPointSet<dim> &points,
                           const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                           MPI_Comm comm)
  {
    // Each point gets the share A_p of the loaded area proportional to V_p /
    // spacing normal to the face (regular seeding: the area of its sub-cell
    // face); for a body face the shares are normalised to the face area of the
    // box, so the total force is exactly traction x area (seed 000 Eq. 4.29:
    // f_p = tau S_e / n_ebMP). With Traction::total the shares are normalised
    // to the selected points' area instead, so the total is the given force.
    using L                = PropertyLayout<dim>;
    const unsigned int off = force_offset;
    for (auto &pt : points.handler)
      {
        auto P = pt.get_properties();
        for (unsigned int i = 0; i < slots * dim; ++i)
          P[off + i] = 0.0;
      }
    have_tractions = !tractions.empty();
    for (unsigned int j = 0; j < tractions.size(); ++j)
      {
        const auto &t = tractions[j];
        if (t.target == Traction<dim>::Target::boundary) // grid nodal forces: no point carries it
          continue;
        const auto initial = [&](const auto &pt) {
          auto X = pt.get_location();
          for (unsigned int d = 0; d < dim; ++d)
            X[d] -= pt.get_properties()[L::displacement + d];
          return X;
        };
        const auto spacing = [&](const auto &pt) {
          const auto        &cc = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
          const unsigned int b  = static_cast<unsigned int>(pt.get_properties()[L::body]);
          return cc.h[t.axis] / bodies[b].particles_per_direction;
        };
        double extreme = -std::numeric_limits<double>::max();
        if (t.target == Traction<dim>::Target::body_face)
          {
            for (const auto &pt : points.handler)
              if (static_cast<unsigned int>(pt.get_properties()[L::body]) == t.body)
                extreme = std::max(extreme, t.side * initial(pt)[t.axis]);
            extreme = dealii::Utilities::MPI::max(extreme, comm);
          }
        const auto selected = [&](const auto &pt) {
          const auto X = initial(pt);
          if (t.target == Traction<dim>::Target::body_face)
            return static_cast<unsigned int>(pt.get_properties()[L::body]) == t.body &&
                   t.side * X[t.axis] > extreme - 0.5 * spacing(pt);
          for (unsigned int d = 0; d < dim; ++d)
            if (X[d] < t.lower[d] || X[d] > t.upper[d])
              return false;
          return true;
        };
        double       area_sum = 0;
        unsigned int n_sel    = 0;
        for (const auto &pt : points.handler)
          if (selected(pt))
            {
              area_sum += pt.get_properties()[L::volume] / spacing(pt);
              ++n_sel;
            }
        area_sum         = dealii::Utilities::MPI::sum(area_sum, comm);
        const auto n_all = dealii::Utilities::MPI::sum(n_sel, comm);
        require(n_all > 0, t.where, "selects no material point (check the body/face or the region)");
        double scale = 1.0;
        if (t.total) // the resultant spread by area share: traction = force / loaded area
          scale = 1.0 / area_sum;
        else if (t.target == Traction<dim>::Target::body_face)
          {
            const auto &b    = bodies[t.body];
            double      area = 1.0;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != t.axis)
                area *= b.upper[d] - b.lower[d];
            scale = area / area_sum;
          }
        for (auto &pt : points.handler)
          if (selected(pt))
            {
              auto         P  = pt.get_properties();
              const double Ap = scale * P[L::volume] / spacing(pt);
              for (unsigned int d = 0; d < dim; ++d)
                P[off + j * dim + d] = t.traction[d] * Ap;
            }
        log() << "  " << t.where << ": " << n_all << " boundary material points, loaded area "
              << (t.total ? area_sum : area_sum * scale) << (dim == 2 ? " m (per unit thickness)" : " m^2")
              << (t.total ? " (total force given)" : "") << ", f(t) = " << t.function.text() << std::endl;
      }
  }

  template <int dim>
  void
  PointForces<dim>::update_factors(const std::vector<Traction<dim>> &tractions, const unsigned int n_global,
                                   const double t, const double stage_t0)
  {
    const unsigned int nt = tractions.size();
    factor.resize(nt);
    for (unsigned int j = 0; j < nt; ++j)
      factor[j] = tractions[j].function.value(j < n_global ? t : t - stage_t0);
  }

  template class PointForces<2>;
  template class PointForces<3>;
} // namespace talus::loads
