#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/point_forces.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace talus::loads
{
  namespace
  {
    /// angle of x about the centre of a pressure traction, from the start of its arc, in [0, 2 pi)
    template <int dim>
    double
    arc_angle(const Traction<dim> &t, const dealii::Point<dim> &x)
    {
      double phi = std::atan2(x[1] - t.centre[1], x[0] - t.centre[0]) - t.arc_start;
      while (phi < 0)
        phi += 2.0 * M_PI;
      while (phi >= 2.0 * M_PI)
        phi -= 2.0 * M_PI;
      return phi;
    }
  } // namespace

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
    // a point load already on a point (a later stage, a restart) stays there
    std::vector<dealii::types::particle_index> kept(tractions.size(), invalid_particle);
    for (unsigned int j = 0; j < tractions.size(); ++j)
      if (tractions[j].target == Traction<dim>::Target::point)
        kept[j] = carrier(tractions[j], j, points, comm);
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
        if (t.target == Traction<dim>::Target::point)
          {
            assign_point_load(t, j, kept[j], points, comm);
            continue;
          }
        const auto initial = [&](const auto &pt) {
          auto X = pt.get_location();
          for (unsigned int d = 0; d < dim; ++d)
            X[d] -= pt.get_properties()[L::displacement + d];
          return X;
        };
        const auto spacing = [&](const auto &pt) {
          const auto        &cc = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
          const unsigned int b  = static_cast<unsigned int>(pt.get_properties()[L::body]);
          if (t.radial) // a pressure on a circle: the smallest point spacing
            {
              double h = cc.h[0];
              for (unsigned int d = 1; d < dim; ++d)
                h = std::min(h, cc.h[d]);
              return h / bodies[b].particles_per_direction;
            }
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
          if (t.radial) // the points within one spacing of the circle: one layer along a surface
            return std::abs(X.distance(t.centre) - t.radius) < spacing(pt);
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
        // a pressure on a circle: each loaded point's share of the arc is the
        // angular interval between the mid-angles to its neighbours (sorted by
        // angle over all ranks; the arc's ends close the first and last
        // interval, the whole circle wraps), so the shares follow the points'
        // spacing along the arc and add up to the arc inside the region box
        std::vector<double> sorted_angles, shares;
        if (t.radial)
          {
            std::vector<double> mine;
            for (const auto &pt : points.handler)
              if (selected(pt))
                mine.push_back(arc_angle(t, initial(pt)));
            for (const auto &v : dealii::Utilities::MPI::all_gather(comm, mine))
              sorted_angles.insert(sorted_angles.end(), v.begin(), v.end());
            std::sort(sorted_angles.begin(), sorted_angles.end());
            const std::size_t m    = sorted_angles.size();
            const bool        full = t.arc_span >= 2.0 * M_PI * (1 - 1e-12);
            shares.resize(m);
            for (std::size_t k = 0; k < m; ++k)
              {
                const double lo = k > 0  ? 0.5 * (sorted_angles[k - 1] + sorted_angles[k])
                                  : full ? 0.5 * (sorted_angles[m - 1] - 2.0 * M_PI + sorted_angles[0])
                                         : std::min(0.0, sorted_angles[0]);
                const double hi = k + 1 < m ? 0.5 * (sorted_angles[k] + sorted_angles[k + 1])
                                  : full    ? 0.5 * (sorted_angles[m - 1] + 2.0 * M_PI + sorted_angles[0])
                                            : std::max(t.arc_span, sorted_angles[m - 1]);
                shares[k]       = t.radius * (hi - lo);
              }
          }
        // the share of a point at angle phi: the mean over the points at exactly that angle
        const auto arc_share = [&](const double phi) {
          const auto lo  = std::lower_bound(sorted_angles.begin(), sorted_angles.end(), phi);
          const auto hi  = std::upper_bound(sorted_angles.begin(), sorted_angles.end(), phi);
          double     sum = 0;
          for (auto it = lo; it != hi; ++it)
            sum += shares[it - sorted_angles.begin()];
          return sum / std::max<std::ptrdiff_t>(1, hi - lo);
        };
        double scale = 1.0; // (a pressure on a circle: the arc shares above)
        if (t.total)        // the resultant spread by area share: traction = force / loaded area
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
              if (t.radial)
                {
                  const dealii::Tensor<1, dim> r     = initial(pt) - t.centre;
                  const double                 share = arc_share(arc_angle(t, initial(pt)));
                  for (unsigned int d = 0; d < dim; ++d)
                    P[off + j * dim + d] = t.pressure * share * r[d] / r.norm();
                }
              else
                for (unsigned int d = 0; d < dim; ++d)
                  P[off + j * dim + d] = t.traction[d] * Ap;
            }
        if (t.radial)
          log() << "  " << t.where << ": pressure " << t.pressure << " Pa on the circle about " << t.centre
                << ", radius " << t.radius << ": " << n_all << " material points, arc length " << t.radius * t.arc_span
                << " m inside the region, f(t) = " << t.function.text() << std::endl;
        else
          log() << "  " << t.where << ": " << n_all << " boundary material points, loaded area "
                << (t.total ? area_sum : area_sum * scale) << (dim == 2 ? " m (per unit thickness)" : " m^2")
                << (t.total ? " (total force given)" : "") << ", f(t) = " << t.function.text() << std::endl;
      }
  }

  template <int dim>
  dealii::types::particle_index
  PointForces<dim>::carrier(const Traction<dim> &t, const unsigned int j, const MaterialPointSet<dim> &points,
                            MPI_Comm comm) const
  {
    // the marker: exactly one point of all ranks carries the force in slot j
    unsigned long long            mine = 0;
    dealii::types::particle_index id   = 0;
    if (t.traction.norm() > 0)
      for (const auto &pt : points.handler)
        {
          const auto P     = pt.get_properties();
          bool       equal = true;
          for (unsigned int d = 0; d < dim; ++d)
            equal = equal && P[force_offset + j * dim + d] == t.traction[d];
          if (equal)
            {
              ++mine;
              id = pt.get_id();
            }
        }
    if (dealii::Utilities::MPI::sum(mine, comm) != 1)
      return invalid_particle;
    return dealii::Utilities::MPI::max(mine > 0 ? id : dealii::types::particle_index(0), comm);
  }

  template <int dim>
  void
  PointForces<dim>::assign_point_load(const Traction<dim> &t, const unsigned int j,
                                      const dealii::types::particle_index kept, MaterialPointSet<dim> &points,
                                      MPI_Comm comm)
  {
    using L = PropertyLayout<dim>;
    // candidates by initial position X = x - u; per rank the nearest as
    // (distance, X, id), then the smallest over all ranks. Ties go to the
    // smaller X (x, then y, then z), which no partition changes (particle ids
    // follow the seeding order of the ranks' cells), then to the smaller id.
    constexpr unsigned int n = 2 + dim;
    const auto less = [](const double *a, const double *b) { return std::lexicographical_compare(a, a + n, b, b + n); };
    std::vector<double> mine(n, std::numeric_limits<double>::max()), cand(n);
    for (const auto &pt : points.handler)
      {
        const auto         P    = pt.get_properties();
        const unsigned int body = static_cast<unsigned int>(P[L::body]);
        if (kept != invalid_particle ? pt.get_id() != kept : t.body != Traction<dim>::any_body && body != t.body)
          continue;
        auto X = pt.get_location();
        for (unsigned int d = 0; d < dim; ++d)
          X[d] -= P[L::displacement + d];
        cand[0] = X.distance(t.position);
        for (unsigned int d = 0; d < dim; ++d)
          cand[1 + d] = X[d];
        cand[1 + dim] = static_cast<double>(pt.get_id());
        if (less(cand.data(), mine.data()))
          mine = cand;
      }
    int n_ranks = 1;
    MPI_Comm_size(comm, &n_ranks);
    std::vector<double> all(n_ranks * n);
    MPI_Allgather(mine.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, comm);
    const double *b = all.data();
    for (int r = 1; r < n_ranks; ++r)
      if (less(&all[r * n], b))
        b = &all[r * n];
    require(b[0] < std::numeric_limits<double>::max(), t.body == Traction<dim>::any_body ? t.where : t.where + "/body",
            t.body == Traction<dim>::any_body
              ? std::string("no material point exists to carry the point load (the scene has none here)")
              : "body " + std::to_string(t.body) +
                  " has no material point to carry the point load; allowed: a body that holds points, or any");
    const auto chosen = static_cast<dealii::types::particle_index>(b[1 + dim]);
    for (auto &pt : points.handler)
      if (pt.get_id() == chosen)
        {
          auto P = pt.get_properties();
          for (unsigned int d = 0; d < dim; ++d)
            P[force_offset + j * dim + d] = t.traction[d];
        }
    std::ostringstream x, f;
    for (unsigned int d = 0; d < dim; ++d)
      {
        x << (d ? ", " : "") << b[1 + d];
        f << (d ? ", " : "") << t.traction[d];
      }
    log() << "  " << t.where << ": " << (kept != invalid_particle ? "kept on" : "on") << " the material point "
          << chosen << " at (" << x.str() << ") (initial position), " << b[0] << " m from the position, force ("
          << f.str() << (dim == 2 ? ") N (per unit thickness)" : ") N") << ", f(t) = " << t.function.text()
          << std::endl;
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
