// talus — FEM / UL-FEM integration in the explicit solver (see fem.h).
#include <talus/base/errors.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/fem.h>
#include <talus/shape/q1_iso.h>
#include <talus/transfer/cell_walk.h>

#include <deal.II/base/mpi.h>

#include <cmath>

namespace talus::explicit_mpm
{
  template <int dim>
  FemIntegration<dim>::FemIntegration(Solver<dim> &solver, const bool updated_lagrangian)
      : s(solver)
      , ul(updated_lagrangian)
  {
    collect_vertices();
    if (ul)
      s.grid.reinit_vector(nodal_u);
  }

  template <int dim>
  void
  FemIntegration<dim>::collect_vertices()
  {
    const auto &grid = s.grid;
    vertices.assign(grid.cells.size() * nv * dim, 0.0);
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cell_iterator(c) != grid.tria.end())
        for (unsigned int v = 0; v < nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            vertices[(c * nv + v) * dim + d] = grid.cell_iterator(c)->vertex(v)[d];
  }

  template <int dim>
  void
  FemIntegration<dim>::grid_changed()
  {
    Assert(!ul, dealii::ExcMessage("ul-fem keeps its mesh displacement on the grid: no repartition"));
    collect_vertices();
    moving_dofs.clear();
  }

  template <int dim>
  void
  FemIntegration<dim>::current_vertices(const unsigned int c, double (&X)[nv][dim]) const
  {
    const double *X0 = vertices.data() + c * nv * dim;
    for (unsigned int v = 0; v < nv; ++v)
      for (unsigned int d = 0; d < dim; ++d)
        X[v][d] = X0[v * dim + d];
    if (ul)
      {
        const auto   &cc = s.grid.cells[c];
        const double *U  = nodal_u.begin();
        for (unsigned int v = 0; v < nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            X[v][d] += U[cc.dofs[v * dim + d]];
      }
  }

  template <int dim>
  SeedingResult
  FemIntegration<dim>::seed(const std::vector<double> &density_of_material)
  {
    using L             = PropertyLayout<dim>;
    const auto  &grid   = s.grid;
    const auto  &bodies = s.prm.bodies;
    const double gauss  = 0.5 / std::sqrt(3.0);
    const double weight = 1.0 / nv; // Gauss weights on the unit cell
    struct NewPoint
    {
      dealii::Point<dim> x, xi;
      unsigned int       cell, body, material;
      double             volume;
    };
    std::vector<NewPoint> points;
    SeedingResult         result;
    result.volume_per_body.assign(bodies.size(), 0.0);
    // cells covered by a body: those holding its points in the MPM seeding
    std::vector<int> body_of_cell(grid.cells.size(), -1), material_of_cell(grid.cells.size(), -1);
    for (const auto &pt : s.points.handler)
      {
        const unsigned int c = pt.get_surrounding_cell()->active_cell_index();
        const int          b = static_cast<int>(pt.get_properties()[L::body]);
        if (body_of_cell[c] < 0 || b < body_of_cell[c])
          {
            body_of_cell[c]     = b;
            material_of_cell[c] = static_cast<int>(pt.get_properties()[L::material]);
          }
      }
    s.points.handler.clear_particles();
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      {
        if (!grid.cells[c].locally_owned || body_of_cell[c] < 0)
          continue;
        typename Kernel::Cell cell;
        current_vertices(c, cell.X);
        const unsigned int b = body_of_cell[c];
        for (unsigned int q = 0; q < nv; ++q)
          {
            dealii::Point<dim> xi, x;
            for (unsigned int d = 0; d < dim; ++d)
              xi[d] = 0.5 + (((q >> d) & 1u) ? gauss : -gauss);
            typename Kernel::Eval e;
            Kernel::evaluate(cell, xi, e);
            const double det = e.det;
            if (!(det > 0))
              throw InputError("grid: cell " + grid.cell_iterator(c)->id().to_string() +
                               " is inverted or degenerate (det J = " + std::to_string(det) +
                               " at a Gauss point); numerics/integration = fem | ul-fem needs valid cells");
            Kernel::position(cell, e, x);
            points.push_back({x, xi, c, b, static_cast<unsigned int>(material_of_cell[c]), det * weight});
          }
      }

    const unsigned long long n_local = points.size();
    unsigned long long       offset  = 0;
    MPI_Exscan(&n_local, &offset, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, grid.comm);
    if (dealii::Utilities::MPI::this_mpi_process(grid.comm) == 0)
      offset = 0;
    s.points.handler.reserve(points.size());
    std::vector<double> props(s.points.layout.n_properties(), 0.0);
    for (std::size_t i = 0; i < points.size(); ++i)
      {
        const auto &p    = points[i];
        const auto &body = bodies[p.body];
        std::fill(props.begin(), props.end(), 0.0);
        props[L::mass]                 = density_of_material[p.material] * p.volume;
        props[L::volume]               = p.volume;
        props[L::material]             = p.material;
        props[L::body]                 = p.body;
        const dealii::Tensor<1, dim> v = body.velocity_field ? body.velocity_field(p.x) : body.initial_velocity;
        for (unsigned int d = 0; d < dim; ++d)
          props[L::velocity + d] = v[d];
        result.volume_per_body[p.body] += p.volume;
        s.points.handler.insert_particle(p.x, p.xi, offset + i, grid.cell_iterator(p.cell),
                                         dealii::ArrayView<const double>(props.data(), props.size()));
      }
    s.points.handler.update_cached_numbers();
    result.n_particles = dealii::Utilities::MPI::sum(n_local, grid.comm);
    for (auto &v : result.volume_per_body)
      v = dealii::Utilities::MPI::sum(v, grid.comm);
    return result;
  }

  template <int dim>
  void
  FemIntegration<dim>::collect_moving_dofs()
  {
    const unsigned int         n = s.nodal_mass.locally_owned_size() + s.grid.partitioner->n_ghost_indices();
    std::vector<unsigned char> mark(n, 0);
    moving_dofs.clear();
    for (const auto &ac : s.points.active_cells())
      for (const unsigned int i : s.grid.cells[ac.cell].dofs)
        if (!mark[i])
          {
            mark[i] = 1;
            moving_dofs.push_back(i);
          }
  }

  template <int dim>
  void
  FemIntegration<dim>::p2g_mass_and_force()
  {
    using L         = PropertyLayout<dim>;
    double *const M = s.nodal_mass.begin();
    double *const F = s.nodal_a.begin();
    const auto    g = s.gravity;
    s.zero_on_active(s.nodal_mass);
    s.zero_on_active(s.nodal_a);
    typename Kernel::Cell      cell;
    typename Kernel::MassForce sums;
    const auto                 begin_cell = [&](const unsigned int c) {
      current_vertices(c, cell.X);
      cell.dofs = s.grid.cells[c].dofs;
      sums.clear();
    };
    const auto at_point = [&](const unsigned int, auto &pt) {
      const double         *P = pt->get_properties().data();
      typename Kernel::Eval e;
      Kernel::evaluate(cell, pt->get_reference_location(), e);
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      sums.add(e, P[L::mass], t);
    };
    transfer::for_each_active_cell(s.points, begin_cell, at_point,
                                   [&](const unsigned int) { sums.scatter(cell, g, M, F); });
  }

  template <int dim>
  void
  FemIntegration<dim>::update(const double h)
  {
    using L                        = PropertyLayout<dim>;
    const double *const         Vn = s.nodal_p.begin();
    const auto                  g  = s.gravity;
    double *const               M  = s.nodal_mass.begin();
    double *const               F  = s.nodal_a.begin();
    diagnostics::PointSums<dim> point_sums;
    bool                        bad          = false;
    const bool                  track_probes = !s.probes.ids.empty();
    s.probes.clear_values();
    s.zero_on_active(s.nodal_mass);
    s.zero_on_active(s.nodal_a);
    // the cell's vertices at the start and end of the step, the nodal
    // displacement increments, and the next step's mass and force sums
    typename Kernel::Cell      cell;        // at the start of the step
    double                     X1[nv][dim]; // its vertices at the end
    typename Kernel::Field     du;
    typename Kernel::MassForce sums;
    const auto                 begin_cell = [&](const unsigned int c) {
      current_vertices(c, cell.X);
      cell.dofs = s.grid.cells[c].dofs;
      Kernel::gather(cell, Vn, h, du); // seed 000 Eq. 4.49
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          X1[v][d] = cell.X[v][d] + (ul ? du.u[v][d] : 0.0);
      sums.clear();
    };
    const auto at_point = [&](const unsigned int, auto &pt) {
      double               *P = pt->get_properties().data();
      typename Kernel::Eval at;
      Kernel::evaluate(cell, pt->get_reference_location(), at);
      const double det0 = at.det;
      double       gu[dim][dim], dx[dim];
      Kernel::value_and_gradient(du, at, dx, gu);
      materials::Strain d_eps;
      materials::Spin   d_omega; // zero for small strain (fem)
      for (unsigned int a = 0; a < dim; ++a)
        for (unsigned int b = 0; b < dim; ++b)
          {
            if (b >= a)
              d_eps[a][b] = 0.5 * (gu[a][b] + gu[b][a]);
            if (ul)
              d_omega[a][b] = 0.5 * (gu[a][b] - gu[b][a]);
          }
      const unsigned int         mat   = static_cast<unsigned int>(P[L::material]);
      const materials::Material &m     = *s.prm.materials[mat];
      auto                       sigma = L::get_stress(P);
      m.update_stress(d_eps, d_omega, h, sigma, dealii::ArrayView<double>(P + s.points.layout.history, m.n_history()));
      L::set_stress(sigma, P);

      dealii::Point<dim> x = pt->get_location();
      for (unsigned int d = 0; d < dim; ++d)
        P[L::displacement + d] += dx[d];
      double det1 = det0;
      if (ul)
        {
          // the point follows its cell: x_p = sum N_i x_i, V_p = det J w
          det1 = Kernel::move_vertices(X1, at);
          P[L::volume] *= det1 / det0;
          for (unsigned int d = 0; d < dim; ++d)
            x[d] += dx[d];
          pt->set_location(x);
        }
      const double       mass = P[L::mass];
      dealii::Point<dim> xp   = x; // fem: the current position is the Gauss point plus the displacement
      if (!ul)
        for (unsigned int d = 0; d < dim; ++d)
          xp[d] += P[L::displacement + d];
      const double v2 = point_sums.add(mass, P + L::velocity, xp, g);
      if (s.need_strain_energy)
        point_sums.add_strain(P[L::volume] * m.elastic_energy_density(sigma));
      if (!std::isfinite(sigma[0][0] + sigma[1][1] + sigma[0][1] + x[0] + x[1] + v2 + P[L::volume]) ||
          !(P[L::volume] > 0) || !(det1 > 0))
        bad = true;
      if (track_probes)
        s.probes.record(pt->get_id(), P);

      // next step's mass and internal force at the updated state
      double t[dim][dim];
      minus_V_sigma<dim>(P, P[L::volume], t);
      sums.add(at, mass, t);
    };
    transfer::for_each_active_cell(s.points, begin_cell, at_point,
                                   [&](const unsigned int) { sums.scatter(cell, g, M, F); });
    if (ul)
      {
        // move the nodes of the cells with points (owned and ghost entries:
        // the ghost velocities are current, so no exchange is needed)
        if (moving_dofs.empty())
          collect_moving_dofs();
        double *U = nodal_u.begin();
        for (const unsigned int i : moving_dofs)
          U[i] += h * Vn[i];
      }
    s.local_sums = point_sums;
    s.local_bad  = bad;
  }

  template class FemIntegration<2>;
  template class FemIntegration<3>;
} // namespace talus::explicit_mpm
