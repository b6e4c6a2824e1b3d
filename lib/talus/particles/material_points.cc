#include <talus/base/errors.h>
#include <talus/io/particle_file.h>
#include <talus/particles/material_points.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

namespace talus
{
  // ------------------------------------------------------------ layout
  template <int dim>
  std::vector<std::string>
  PropertyLayout<dim>::names() const
  {
    std::vector<std::string> n = {"mass", "volume", "material_id", "body_id"};
    for (unsigned int d = 0; d < dim; ++d)
      n.emplace_back("velocity");
    for (unsigned int d = 0; d < dim; ++d)
      n.emplace_back("displacement");
    const char *s2[] = {"stress_xx", "stress_yy", "stress_zz", "stress_xy"};
    const char *s3[] = {"stress_xx", "stress_yy", "stress_zz", "stress_xy", "stress_yz", "stress_xz"};
    for (unsigned int i = 0; i < n_stress; ++i)
      n.emplace_back(dim == 2 ? s2[i] : s3[i]);
    for (unsigned int i = 0; i < n_history; ++i)
      n.emplace_back("history_" + std::to_string(i));
    for (const auto &e : extras)
      for (unsigned int i = 0; i < e.size; ++i)
        n.emplace_back(e.vector || e.size == 1 ? e.name : e.name + "_" + std::to_string(i));
    return n;
  }

  template <int dim>
  std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation>
  PropertyLayout<dim>::interpretations() const
  {
    using namespace dealii::DataComponentInterpretation;
    std::vector<DataComponentInterpretation> r(n_properties(), component_is_scalar);
    for (unsigned int d = 0; d < dim; ++d)
      {
        r[velocity + d]     = component_is_part_of_vector;
        r[displacement + d] = component_is_part_of_vector;
      }
    for (const auto &e : extras)
      if (e.vector)
        for (unsigned int i = 0; i < e.size; ++i)
          r[e.offset + i] = component_is_part_of_vector;
    return r;
  }

  // ------------------------------------------------------------ bodies
  template <int dim>
  bool
  BodyDescription<dim>::contains(const dealii::Point<dim> &x) const
  {
    switch (shape)
      {
        case Shape::box:
          for (unsigned int d = 0; d < dim; ++d)
            if (x[d] < lower[d] || x[d] > upper[d])
              return false;
          return true;
        case Shape::ball:
          return x.distance_square(center) <= radius * radius;
        case Shape::polygon:
          {
            // even-odd rule in the x-y plane (2D bodies only)
            bool              inside = false;
            const std::size_t n      = polygon.size();
            for (std::size_t i = 0, j = n - 1; i < n; j = i++)
              {
                const auto &a = polygon[i], &b = polygon[j];
                if (((a[1] > x[1]) != (b[1] > x[1])) && (x[0] < (b[0] - a[0]) * (x[1] - a[1]) / (b[1] - a[1]) + a[0]))
                  inside = !inside;
              }
            return inside;
          }
        case Shape::file:
          return false; // not seeded by seed_bodies()
      }
    return false;
  }

  template <int dim>
  void
  BodyDescription<dim>::bounding_box(dealii::Point<dim> &lo, dealii::Point<dim> &hi) const
  {
    switch (shape)
      {
        case Shape::box:
          lo = lower, hi = upper;
          return;
        case Shape::ball:
          for (unsigned int d = 0; d < dim; ++d)
            lo[d] = center[d] - radius, hi[d] = center[d] + radius;
          return;
        case Shape::polygon:
          for (unsigned int d = 0; d < dim; ++d)
            lo[d] = std::numeric_limits<double>::max(), hi[d] = -lo[d];
          for (const auto &v : polygon)
            for (unsigned int d = 0; d < dim && d < 2; ++d)
              lo[d] = std::min(lo[d], v[d]), hi[d] = std::max(hi[d], v[d]);
          return;
        case Shape::file:
          lo = hi = dealii::Point<dim>();
          return;
      }
  }

  template <int dim>
  double
  BodyDescription<dim>::volume() const
  {
    double v = 0;
    switch (shape)
      {
        case Shape::box:
          v = 1;
          for (unsigned int d = 0; d < dim; ++d)
            v *= upper[d] - lower[d];
          break;
        case Shape::ball:
          v = dim == 2 ? M_PI * radius * radius : 4.0 / 3.0 * M_PI * radius * radius * radius;
          break;
        case Shape::polygon:
          for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++)
            v += 0.5 * (polygon[j][0] * polygon[i][1] - polygon[i][0] * polygon[j][1]);
          v = std::abs(v);
          break;
        case Shape::file:
          break;
      }
    return v;
  }

  template <int dim>
  std::string
  outside_extent(const BodyDescription<dim> &b, const dealii::Point<dim> &lo, const dealii::Point<dim> &hi)
  {
    using S = typename BodyDescription<dim>::Shape;
    if (b.shape == S::file)
      return "";
    dealii::Point<dim> blo, bhi;
    b.bounding_box(blo, bhi);
    const char *axis = "xyz";
    for (unsigned int d = 0; d < dim; ++d)
      for (const bool upper : {false, true})
        {
          const double tol = 1e-12 * (hi[d] - lo[d]);
          const double x   = upper ? bhi[d] : blo[d];
          if (upper ? x <= hi[d] + tol : x >= lo[d] - tol)
            continue;
          std::ostringstream os;
          os << (b.shape == S::box    ? (upper ? "upper corner" : "lower corner")
                 : b.shape == S::ball ? (upper ? "center + radius" : "center - radius")
                                      : (upper ? "vertices (largest)" : "vertices (smallest)"))
             << ": " << axis[d] << " = " << x << " lies outside the grid (" << axis[d] << " from " << lo[d] << " to "
             << hi[d] << ")";
          return os.str();
        }
    return "";
  }

  template <int dim>
  ClipCount
  clipped_by_box_grid(const BodyDescription<dim> &b, const dealii::Point<dim> &lo, const dealii::Point<dim> &hi,
                      const std::vector<unsigned int> &cells)
  {
    using S = typename BodyDescription<dim>::Shape;
    ClipCount          r;
    const unsigned int n = b.particles_per_direction;
    dealii::Point<dim> blo, bhi;
    b.bounding_box(blo, bhi);
    // lattice x_k = lo + (k + 1/2) s, k integer (also < 0 and beyond the grid)
    double    s[dim], sub_volume = 1, n_all = 1, n_in = 1, visits = 1;
    long long k0[dim], k1[dim];
    for (unsigned int d = 0; d < dim; ++d)
      {
        s[d] = (hi[d] - lo[d]) / (double(cells[d]) * n);
        sub_volume *= s[d];
        k0[d]            = static_cast<long long>(std::ceil((blo[d] - lo[d]) / s[d] - 0.5 - 1e-12));
        k1[d]            = static_cast<long long>(std::floor((bhi[d] - lo[d]) / s[d] - 0.5 + 1e-12));
        const double all = std::max(0.0, double(k1[d] - k0[d] + 1));
        const double in  = std::max(
           0.0, double(std::min<long long>(k1[d], (long long)cells[d] * n - 1) - std::max<long long>(k0[d], 0) + 1));
        n_all *= all, n_in *= in, visits *= all;
      }
    if (b.shape == S::box)
      r.points = n_all - n_in;
    else if (visits > 5e7)
      {
        r.counted = false;
        return r;
      }
    else
      {
        long long       k[3] = {0, 0, 0};
        const long long nk   = static_cast<long long>(visits);
        for (long long i = 0; i < nk; ++i)
          {
            long long          rem     = i;
            bool               in_grid = true;
            dealii::Point<dim> x;
            for (unsigned int d = 0; d < dim; ++d)
              {
                const long long len = k1[d] - k0[d] + 1;
                k[d]                = k0[d] + rem % len;
                rem /= len;
                x[d]    = lo[d] + (k[d] + 0.5) * s[d];
                in_grid = in_grid && k[d] >= 0 && k[d] < (long long)cells[d] * n;
              }
            if (!in_grid && b.contains(x))
              r.points += 1;
          }
      }
    r.volume = r.points * sub_volume;
    return r;
  }

  template <int dim>
  SeedingResult
  seed_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
              const std::vector<double> &density_of_material, const PropertyLayout<dim> &layout,
              dealii::Particles::ParticleHandler<dim> &particles)
  {
    struct NewPoint
    {
      dealii::Point<dim> x, xi;
      unsigned int       cell, body;
      double             volume;
    };
    std::vector<NewPoint> points;
    SeedingResult         result;
    result.volume_per_body.assign(bodies.size(), 0.0);

    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      {
        struct
        {
          double lower[dim], h[dim];
        } cc;
        if (!grid.owned_cell_box(c, cc.lower, cc.h))
          continue;
        double cell_volume = 1.0;
        for (unsigned int d = 0; d < dim; ++d)
          cell_volume *= cc.h[d];
        for (unsigned int b = 0; b < bodies.size(); ++b)
          {
            const unsigned int n     = bodies[b].particles_per_direction;
            unsigned int       total = 1;
            for (unsigned int d = 0; d < dim; ++d)
              total *= n;
            for (unsigned int k = 0; k < total; ++k)
              {
                dealii::Point<dim> xi, x;
                unsigned int       r = k;
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    xi[d] = (r % n + 0.5) / n;
                    r /= n;
                    x[d] = cc.lower[d] + xi[d] * cc.h[d];
                  }
                if (!bodies[b].contains(x))
                  continue;
                // first body wins: skip if an earlier body claims this point
                bool claimed = false;
                for (unsigned int e = 0; e < b && !claimed; ++e)
                  claimed = bodies[e].contains(x);
                if (claimed)
                  continue;
                points.push_back({x, xi, c, b, cell_volume / total});
              }
          }
      }

    const unsigned long long n_local = points.size();
    unsigned long long       offset  = 0;
    MPI_Exscan(&n_local, &offset, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, grid.comm);
    if (dealii::Utilities::MPI::this_mpi_process(grid.comm) == 0)
      offset = 0;

    particles.reserve(points.size());
    std::vector<double> props(layout.n_properties(), 0.0);
    for (std::size_t i = 0; i < points.size(); ++i)
      {
        const auto &p    = points[i];
        const auto &body = bodies[p.body];
        std::fill(props.begin(), props.end(), 0.0);
        props[layout.mass]             = density_of_material[body.material_id] * p.volume;
        props[layout.volume]           = p.volume;
        props[layout.material]         = body.material_id;
        props[layout.body]             = p.body;
        const dealii::Tensor<1, dim> v = body.velocity_field ? body.velocity_field(p.x) : body.initial_velocity;
        for (unsigned int d = 0; d < dim; ++d)
          props[layout.velocity + d] = v[d];
        result.volume_per_body[p.body] += p.volume;
        particles.insert_particle(p.x, p.xi, offset + i, grid.cell_iterator(p.cell),
                                  dealii::ArrayView<const double>(props.data(), props.size()));
      }
    particles.update_cached_numbers();
    result.n_particles = dealii::Utilities::MPI::sum(n_local, grid.comm);
    for (auto &v : result.volume_per_body)
      v = dealii::Utilities::MPI::sum(v, grid.comm);
    return result;
  }

  template <int dim>
  SeedingResult
  insert_file_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                     const std::vector<double> &density_of_material, const PropertyLayout<dim> &layout,
                     dealii::Particles::ParticleHandler<dim> &particles, const unsigned long long first_id)
  {
    SeedingResult result;
    result.volume_per_body.assign(bodies.size(), 0.0);
    std::map<std::string, io::ParticleTable> tables;
    for (const auto &b : bodies)
      if (b.shape == BodyDescription<dim>::Shape::file && !tables.count(b.particle_file))
        tables[b.particle_file] = io::read_particle_file(b.particle_file, dim, grid.comm, "body '" + b.name + "'");
    if (tables.empty())
      return result;

    // bucket grid over the locally owned cells (boxes) for the point location
    double       lo[dim], hi[dim], h_sum = 0;
    unsigned int n_owned = 0;
    for (unsigned int d = 0; d < dim; ++d)
      lo[d] = std::numeric_limits<double>::max(), hi[d] = -lo[d];
    for (const auto &cc : grid.cells)
      if (cc.locally_owned)
        {
          ++n_owned;
          for (unsigned int d = 0; d < dim; ++d)
            {
              lo[d] = std::min(lo[d], cc.lower[d]);
              hi[d] = std::max(hi[d], cc.lower[d] + cc.h[d]);
              h_sum += cc.h[d];
            }
        }
    const double bucket = n_owned ? h_sum / (dim * n_owned) : 1.0;
    unsigned int nb[dim];
    std::size_t  n_buckets = 1;
    for (unsigned int d = 0; d < dim; ++d)
      {
        nb[d] =
          n_owned ? std::max(1u, static_cast<unsigned int>(std::min(1e6, std::ceil((hi[d] - lo[d]) / bucket)))) : 1;
        n_buckets *= nb[d];
      }
    const auto bucket_of = [&](const double x, const unsigned int d) {
      const double r = std::floor((x - lo[d]) / bucket);
      return static_cast<int>(std::max(-1.0, std::min(double(nb[d]), r)));
    };
    std::vector<std::vector<unsigned int>> buckets(n_owned ? n_buckets : 0);
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cells[c].locally_owned)
        {
          const auto &cc = grid.cells[c];
          int         b0[dim], b1[dim];
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double tol = 1e-10 * cc.h[d];
              b0[d]            = std::max(0, bucket_of(cc.lower[d] - tol, d));
              b1[d]            = std::min(int(nb[d]) - 1, bucket_of(cc.lower[d] + cc.h[d] + tol, d));
            }
          for (int k = (dim == 3 ? b0[dim - 1] : 0); k <= (dim == 3 ? b1[dim - 1] : 0); ++k)
            for (int j = b0[1]; j <= b1[1]; ++j)
              for (int i = b0[0]; i <= b1[0]; ++i)
                buckets[i + nb[0] * (j + std::size_t(nb[1]) * k)].push_back(c);
        }
    const auto locate = [&](const dealii::Point<dim> &x) -> unsigned int {
      if (buckets.empty())
        return dealii::numbers::invalid_unsigned_int;
      std::size_t idx = 0, stride = 1;
      for (unsigned int d = 0; d < dim; ++d)
        {
          const int b = bucket_of(x[d], d);
          if (b < 0 || b >= int(nb[d]))
            return dealii::numbers::invalid_unsigned_int;
          idx += b * stride;
          stride *= nb[d];
        }
      for (const unsigned int c : buckets[idx])
        {
          const auto &cc = grid.cells[c];
          bool        in = true;
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double r = (x[d] - cc.lower[d]) * cc.inv_h[d];
              in             = in && r >= -1e-12 && r <= 1 + 1e-12;
            }
          if (in)
            return c;
        }
      return dealii::numbers::invalid_unsigned_int;
    };

    // all points of the file bodies, in body then row order
    struct Row
    {
      const io::ParticleTable *table;
      std::size_t              row;
      unsigned int             body;
    };
    std::vector<Row> rows;
    for (unsigned int b = 0; b < bodies.size(); ++b)
      if (bodies[b].shape == BodyDescription<dim>::Shape::file)
        {
          const auto &t = tables[bodies[b].particle_file];
          for (std::size_t i = 0; i < t.size(); ++i)
            if (t.body[i] == bodies[b].file_body_id)
              rows.push_back({&t, i, b});
        }
    const int                 rank = dealii::Utilities::MPI::this_mpi_process(grid.comm);
    std::vector<int>          owner(rows.size(), INT_MAX);
    std::vector<unsigned int> cell_of(rows.size(), dealii::numbers::invalid_unsigned_int);
    for (std::size_t k = 0; k < rows.size(); ++k)
      {
        dealii::Point<dim> x;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = rows[k].table->position[rows[k].row * dim + d];
        cell_of[k] = locate(x);
        if (cell_of[k] != dealii::numbers::invalid_unsigned_int)
          owner[k] = rank;
      }
    if (!owner.empty())
      MPI_Allreduce(MPI_IN_PLACE, owner.data(), owner.size(), MPI_INT, MPI_MIN, grid.comm);
    result.dropped_points.assign(bodies.size(), 0.0);
    result.dropped_volume.assign(bodies.size(), 0.0);
    for (std::size_t k = 0; k < rows.size(); ++k)
      if (owner[k] == INT_MAX && bodies[rows[k].body].clip_to_grid)
        {
          result.dropped_points[rows[k].body] += 1;
          result.dropped_volume[rows[k].body] += rows[k].table->volume[rows[k].row];
        }
      else if (owner[k] == INT_MAX)
        {
          // the grid's extent for the message (all ranks reach this point together)
          double glo[dim], ghi[dim];
          for (unsigned int d = 0; d < dim; ++d)
            glo[d] = -lo[d], ghi[d] = hi[d];
          MPI_Allreduce(MPI_IN_PLACE, glo, dim, MPI_DOUBLE, MPI_MAX, grid.comm);
          MPI_Allreduce(MPI_IN_PLACE, ghi, dim, MPI_DOUBLE, MPI_MAX, grid.comm);
          std::ostringstream os;
          os << "body " << rows[k].body << " ('" << bodies[rows[k].body].name << "'): material point " << rows[k].row
             << " of particle file '" << bodies[rows[k].body].particle_file << "' at (";
          for (unsigned int d = 0; d < dim; ++d)
            os << (d ? ", " : "") << rows[k].table->position[rows[k].row * dim + d];
          os << ") lies outside the grid (";
          for (unsigned int d = 0; d < dim; ++d)
            os << (d ? ", " : "") << "xyz"[d] << " from " << -glo[d] << " to " << ghi[d];
          os << "; was the file made for another grid? 'clip to grid = true' in the body drops such points)";
          throw InputError(os.str());
        }

    std::vector<double> props(layout.n_properties(), 0.0);
    unsigned long long  n_local = 0;
    for (std::size_t k = 0; k < rows.size(); ++k)
      {
        const auto &t    = *rows[k].table;
        const auto  i    = rows[k].row;
        const auto &body = bodies[rows[k].body];
        result.volume_per_body[rows[k].body] += owner[k] == rank ? t.volume[i] : 0.0;
        if (owner[k] != rank)
          continue;
        ++n_local;
        dealii::Point<dim> x;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = t.position[i * dim + d];
        dealii::Point<dim> xi = grid.reference_point(cell_of[k], x);
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = std::min(1.0, std::max(0.0, xi[d]));
        std::fill(props.begin(), props.end(), 0.0);
        const unsigned int m           = static_cast<unsigned int>(t.material[i]);
        props[layout.mass]             = density_of_material[m] * t.volume[i];
        props[layout.volume]           = t.volume[i];
        props[layout.material]         = m;
        props[layout.body]             = rows[k].body;
        const dealii::Tensor<1, dim> v = body.velocity_field ? body.velocity_field(x) : body.initial_velocity;
        for (unsigned int d = 0; d < dim; ++d)
          props[layout.velocity + d] = v[d];
        if (!t.stress.empty())
          for (unsigned int s = 0; s < t.n_stress(); ++s)
            props[layout.stress + s] = t.stress[i * t.n_stress() + s];
        particles.insert_particle(x, xi, first_id + k, grid.cell_iterator(cell_of[k]),
                                  dealii::ArrayView<const double>(props.data(), props.size()));
      }
    particles.update_cached_numbers();
    result.n_particles = dealii::Utilities::MPI::sum(n_local, grid.comm);
    for (auto &v : result.volume_per_body)
      v = dealii::Utilities::MPI::sum(v, grid.comm);
    return result;
  }

  // ------------------------------------------------------------ relocation
  template <int dim>
  Relocator<dim>::Relocator(const BackgroundGrid<dim> &g, dealii::Particles::ParticleHandler<dim> &p)
      : grid(g)
      , particles(p)
  {
    particles.signals.particle_lost.connect(
      [this](const typename dealii::Particles::ParticleIterator<dim> &,
             const typename dealii::Triangulation<dim>::active_cell_iterator &) { ++lost_counter; });
  }

  template <int dim>
  void
  Relocator<dim>::finish(RelocationStats                                                                     &stats,
                         const std::function<void(unsigned int, const dealii::Point<dim> &, const double *)> &moved)
  {
    const auto t0 = std::chrono::steady_clock::now();
    moves.clear();
    props.clear();
    cell_changes.clear();
    sorted_last                  = false;
    reordered_last               = false;
    const unsigned int n_props   = particles.n_properties_per_particle();
    bool               need_sort = false;
    const bool         parallel  = dealii::Utilities::MPI::n_mpi_processes(grid.comm) > 1;
    // per destination rank: the points that entered one of its cells (CellId
    // words, id, x, xi, properties per point); only ranks that get points have an entry
    std::map<unsigned int, std::vector<double>> outgoing;
    unsigned long long                          n_sent = 0, n_local_moves = 0;
    props.resize(n_props);
    // backwards: pending is in ascending order within each cell, and deal.II
    // removes by moving the cell's last particle into the hole (an insertion
    // appends to its cell, so the iterators still pending stay valid)
    for (std::size_t k = pending.size(); k-- > 0;)
      {
        const auto        &it = pending[k].it;
        const auto        &xi = pending[k].xi;
        const auto         x  = it->get_location();
        const unsigned int n  = pending[k].entered; // looked up by the walk
        if (n == dealii::numbers::invalid_unsigned_int)
          {
            need_sort = true; // jumped past the neighbours or left the grid
            continue;
          }
        const auto p = it->get_properties();
        if (grid.cells[n].locally_owned) // (checked: fills the entry of a cell that gets a point)
          {
            // remove, then insert at once: the pool gives the freed slot back
            const auto id = it->get_id();
            std::copy(p.begin(), p.end(), props.begin());
            particles.remove_particle(it);
            cell_changes.push_back({pending[k].cell, false});
            if (moved && !pending[k].added)
              moved(n, xi, props.data());
            particles.insert_particle(x, xi, id, grid.cell_iterator(n),
                                      dealii::ArrayView<const double>(props.data(), n_props));
            cell_changes.push_back({n, true});
            ++n_local_moves;
            continue;
          }
        // a neighbour cell of another rank: send the point to its owner
        // (point to point, no collective sort)
        const auto &cell = grid.cell_iterator(n);
        auto       &buf  = outgoing[cell->subdomain_id()];
        for (const unsigned int w : cell->id().template to_binary<dim>())
          buf.push_back(w);
        buf.push_back(static_cast<double>(it->get_id()));
        for (unsigned int d = 0; d < dim; ++d)
          buf.push_back(x[d]);
        for (unsigned int d = 0; d < dim; ++d)
          buf.push_back(xi[d]);
        buf.insert(buf.end(), p.begin(), p.end());
        ++n_sent;
        particles.remove_particle(it);
        cell_changes.push_back({pending[k].cell, false});
      }
    // the points other ranks sent into my cells, in rank order (deterministic)
    props.clear();
    if (parallel)
      {
        const auto         received = dealii::Utilities::MPI::some_to_some(grid.comm, outgoing);
        const unsigned int stride   = 4 + 1 + 2 * dim + n_props;
        for (const auto &from : received)
          for (std::size_t o = 0; o + stride <= from.second.size(); o += stride)
            {
              const double               *q = from.second.data() + o;
              dealii::CellId::binary_type key;
              for (unsigned int w = 0; w < 4; ++w)
                key[w] = static_cast<unsigned int>(q[w]);
              const auto cell = grid.tria.create_cell_iterator(dealii::CellId(key));
              AssertThrow(cell->is_active() && cell->is_locally_owned(),
                          dealii::ExcMessage("a material point was sent to a rank that does not own its cell"));
              Move m{{},
                     {},
                     static_cast<dealii::types::particle_index>(q[4]),
                     cell->active_cell_index(),
                     static_cast<unsigned int>(props.size())};
              for (unsigned int d = 0; d < dim; ++d)
                {
                  m.x[d]  = q[5 + d];
                  m.xi[d] = q[5 + dim + d];
                }
              moves.push_back(m);
              props.insert(props.end(), q + 5 + 2 * dim, q + stride);
            }
      }
    for (const auto &m : moves)
      {
        grid.cells.ensure_filled(m.cell); // a cell with points: read unchecked from now on
        if (moved)
          moved(m.cell, m.xi, props.data() + m.prop_offset);
        cell_changes.push_back({m.cell, true});
        particles.insert_particle(m.x, m.xi, m.id, grid.cell_iterator(m.cell),
                                  dealii::ArrayView<const double>(props.data() + m.prop_offset, n_props));
      }
    stats.moved_locally += n_local_moves + n_sent;
    stats.sent_to_ranks += n_sent;
    moved_since_sort += n_local_moves + moves.size(); // local and received
    pending.clear();

    // one reduction decides both: a needed sort and a memory-order sort
    double flags[3] = {need_sort ? 1.0 : 0.0, double(moved_since_sort), double(particles.n_locally_owned_particles())};
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(flags, 3), grid.comm,
                                dealii::ArrayView<double>(flags, 3));
    const bool reorder = flags[1] > resort_fraction * flags[2];
    const auto t1      = std::chrono::steady_clock::now();
    stats.seconds_moves += std::chrono::duration<double>(t1 - t0).count();
    if (flags[0] > 0)
      {
        // deal.II's sort also restores the memory order
        const unsigned long long lost_before = lost_counter;
        particles.sort_particles_into_subdomains_and_cells();
        ++stats.global_sorts;
        sorted_last = true;
        stats.lost += dealii::Utilities::MPI::sum(lost_counter - lost_before, grid.comm);
      }
    else if (reorder)
      {
        restore_memory_order();
        ++stats.storage_sorts;
        reordered_last = true;
      }
    if (sorted_last || reordered_last)
      {
        moved_since_sort = 0;
        stats.seconds_sorts += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      }
  }

  template <int dim>
  void
  Relocator<dim>::restore_memory_order()
  {
    // Why not deal.II's sort: sort_particles_into_subdomains_and_cells() locates
    // every point again through the mapping and walks all active cells; it cost
    // about 400 ns per point on the 3D bench. Why not a copy of all points,
    // clear_particles() and insertion in order (the rebuild until 2026-12-07): the
    // copy (184 bytes per 3D point) sat beside deal.II's pool and set the peak
    // memory of the bench.
    //
    // In place instead: deal.II 9.4's pool hands the slot freed last to the next
    // insertion (PropertyPool::register_particle takes the back of its free list),
    // so removing the points that hold slots a, b (in that order) and inserting
    // two points at once gives the first one b and the second a. Going through
    // the cell groups in active-cell order, each group's target slots are the next
    // n occupied slots; the group's points and the points of other cells that
    // hold those slots are copied out (a few points), removed (the holders of the
    // targets from the last to the first, then the group's points outside the
    // targets), and inserted again: the others first (they take the slots the
    // group leaves), then the group in its old order (they take the targets in
    // increasing order). The set of occupied slots never changes, so a pool
    // with free slots (points sent away or lost) keeps them as gaps.
    //
    // The bookkeeping runs on plain arrays: one pass over the points, the
    // group's own removals through a mirror of its handle vector (no search),
    // the copies through one scratch buffer (docs/scaling.md, "in-place rebuild").
    using Handle               = typename dealii::Particles::PropertyPool<dim>::Handle;
    auto              &pool    = particles.get_property_pool();
    const unsigned int n_props = particles.n_properties_per_particle();
    const unsigned int invalid = dealii::numbers::invalid_unsigned_int;
    const std::size_t  n_slots = pool.n_slots();

    // per slot: the cell of its point (invalid: a free slot) and the slot the
    // point goes to; the cell groups in walk order. Filled in one pass: first
    // the point's group and its place in the group, then (below) turned into
    // the group's cell and the target.
    std::vector<unsigned int> cell_of(n_slots, invalid);
    std::vector<Handle>       dest(n_slots, invalid);
    struct Group
    {
      unsigned int cell, count;
      std::size_t  offset; ///< index of its first target among the occupied slots
    };
    std::vector<Group> groups;
    std::size_t        n_particles = 0;
    for (auto it = particles.begin(); it != particles.end(); ++it)
      {
        const unsigned int c = it->get_surrounding_cell()->active_cell_index();
        if (groups.empty() || groups.back().cell != c)
          groups.push_back({c, 0, 0});
        const Handle s = it->get_local_index();
        cell_of[s]     = static_cast<unsigned int>(groups.size() - 1);
        dest[s]        = groups.back().count++;
        ++n_particles;
      }
    // the occupied slots in increasing order (without free slots: 0, 1, 2, ...)
    std::vector<Handle> occupied;
    if (n_particles != n_slots)
      for (std::size_t s = 0; s < n_slots; ++s)
        if (cell_of[s] != invalid)
          occupied.push_back(s);
    const auto target = [&](const std::size_t k) -> Handle { return occupied.empty() ? Handle(k) : occupied[k]; };
    // deal.II's update_cached_numbers() keeps the cell groups in active-cell
    // order, so the targets go to the groups in that order
    std::vector<unsigned int> order(groups.size());
    for (unsigned int g = 0; g < groups.size(); ++g)
      order[g] = g;
    std::sort(order.begin(), order.end(),
              [&](const unsigned int a, const unsigned int b) { return groups[a].cell < groups[b].cell; });
    {
      std::size_t k = 0;
      for (const unsigned int g : order)
        {
          groups[g].offset = k;
          k += groups[g].count;
        }
    }
    for (std::size_t s = 0; s < n_slots; ++s)
      if (cell_of[s] != invalid)
        {
          const Group &g = groups[cell_of[s]];
          cell_of[s]     = g.cell;
          dest[s]        = target(g.offset + dest[s]);
        }

    // scratch for the points of one group and the others that hold its targets
    struct Held
    {
      Handle                        slot, dest;
      unsigned int                  cell;
      dealii::Point<dim>            x, xi;
      dealii::types::particle_index id;
    };
    std::vector<Held>   mine, others;
    std::vector<double> mine_p, others_p;
    std::vector<Handle> mirror; // the group's handle vector, as deal.II holds it
    const auto          copy_data = [&](Held &h, std::vector<double> &to_p, const std::size_t i) {
      const Handle s = h.slot;
      h.x            = pool.get_location(s);
      h.xi           = pool.get_reference_location(s);
      h.id           = pool.get_id(s);
      const auto P   = pool.get_properties(s);
      std::copy(P.begin(), P.end(), to_p.begin() + i * n_props);
    };
    // a point of another cell: found by its slot among the cell's points
    const auto remove_other = [&](const unsigned int c, const Handle s) {
      const auto range = particles.particles_in_cell(grid.cell_iterator(c));
      for (auto it = range.begin(); it != range.end(); ++it)
        if (it->get_local_index() == s)
          {
            particles.remove_particle(it);
            return;
          }
      throw std::logic_error("Relocator::restore_memory_order: slot not found in its cell");
    };
    const auto insert = [&](const Held &h, const double *P) {
      const auto   it = particles.insert_particle(h.x, h.xi, h.id, grid.cell_iterator(h.cell),
                                                  dealii::ArrayView<const double>(P, n_props));
      const Handle s  = it->get_local_index();
      cell_of[s]      = h.cell;
      dest[s]         = h.dest;
      return s;
    };

    for (const unsigned int g : order)
      {
        const Group &G     = groups[g];
        const Handle first = target(G.offset), last = target(G.offset + G.count - 1);
        // the group's points by target (their old order in the cell)
        mine.clear();
        mirror.clear();
        bool       in_place = true;
        const auto range    = particles.particles_in_cell(grid.cell_iterator(G.cell));
        const auto begin    = range.begin(); // stays valid while the cell has points
        {
          unsigned int j = 0;
          for (auto it = begin; it != range.end(); ++it, ++j)
            {
              const Handle s = it->get_local_index();
              in_place       = in_place && s == target(G.offset + j) && dest[s] == s;
              mine.push_back({s, dest[s], G.cell, {}, {}, 0});
              mirror.push_back(s);
            }
        }
        if (in_place)
          continue;
        if (!std::is_sorted(mine.begin(), mine.end(), [](const Held &a, const Held &b) { return a.dest < b.dest; }))
          std::sort(mine.begin(), mine.end(), [](const Held &a, const Held &b) { return a.dest < b.dest; });
        mine_p.resize(mine.size() * n_props);
        for (std::size_t i = 0; i < mine.size(); ++i)
          copy_data(mine[i], mine_p, i);
        // the points of other cells on the targets
        others.clear();
        for (unsigned int j = 0; j < G.count; ++j)
          {
            const Handle t = target(G.offset + j);
            if (cell_of[t] != G.cell)
              others.push_back({t, dest[t], cell_of[t], {}, {}, 0});
          }
        others_p.resize(others.size() * n_props);
        for (std::size_t i = 0; i < others.size(); ++i)
          copy_data(others[i], others_p, i);
        // removals: the holders of the targets from the last one to the first,
        // then the group's points outside the targets (the group's own through
        // the mirror: deal.II moves a cell's last handle into the hole)
        const auto remove_mine = [&](const Handle s) {
          const std::size_t pos = std::find(mirror.begin(), mirror.end(), s) - mirror.begin();
          AssertThrow(pos < mirror.size(), dealii::ExcInternalError());
          auto it = begin;
          for (std::size_t i = 0; i < pos; ++i)
            ++it;
          particles.remove_particle(it);
          mirror[pos] = mirror.back();
          mirror.pop_back();
        };
        for (unsigned int j = G.count; j-- > 0;)
          {
            const Handle t = target(G.offset + j);
            if (cell_of[t] == G.cell)
              remove_mine(t);
            else
              remove_other(cell_of[t], t);
          }
        for (const Held &h : mine)
          if (h.slot < first || h.slot > last)
            remove_mine(h.slot);
        // insertions: the others take the slots the group left, the group its targets
        for (std::size_t i = 0; i < others.size(); ++i)
          insert(others[i], others_p.data() + i * n_props);
        // (a lone group with free slots: removing all its points emptied the pool,
        // which then starts again at slot 0: memory order too)
        for (std::size_t j = 0; j < mine.size(); ++j)
          if (insert(mine[j], mine_p.data() + j * n_props) != mine[j].dest && groups.size() > 1)
            throw std::logic_error("Relocator::restore_memory_order: deal.II's pool did not hand out the freed slot");
      }
    particles.update_cached_numbers();
  }

  template struct PropertyLayout<2>;
  template struct PropertyLayout<3>;
  template struct BodyDescription<2>;
  template struct BodyDescription<3>;
  template class Relocator<2>;
  template std::string outside_extent(const BodyDescription<2> &, const dealii::Point<2> &, const dealii::Point<2> &);
  template std::string outside_extent(const BodyDescription<3> &, const dealii::Point<3> &, const dealii::Point<3> &);
  template ClipCount clipped_by_box_grid(const BodyDescription<2> &, const dealii::Point<2> &, const dealii::Point<2> &,
                                         const std::vector<unsigned int> &);
  template ClipCount clipped_by_box_grid(const BodyDescription<3> &, const dealii::Point<3> &, const dealii::Point<3> &,
                                         const std::vector<unsigned int> &);
  template class Relocator<3>;
  template SeedingResult seed_bodies(const BackgroundGrid<2> &, const std::vector<BodyDescription<2>> &,
                                     const std::vector<double> &, const PropertyLayout<2> &,
                                     dealii::Particles::ParticleHandler<2> &);
  template SeedingResult insert_file_bodies(const BackgroundGrid<2> &, const std::vector<BodyDescription<2>> &,
                                            const std::vector<double> &, const PropertyLayout<2> &,
                                            dealii::Particles::ParticleHandler<2> &, unsigned long long);
  template SeedingResult insert_file_bodies(const BackgroundGrid<3> &, const std::vector<BodyDescription<3>> &,
                                            const std::vector<double> &, const PropertyLayout<3> &,
                                            dealii::Particles::ParticleHandler<3> &, unsigned long long);
  template SeedingResult seed_bodies(const BackgroundGrid<3> &, const std::vector<BodyDescription<3>> &,
                                     const std::vector<double> &, const PropertyLayout<3> &,
                                     dealii::Particles::ParticleHandler<3> &);
} // namespace talus
