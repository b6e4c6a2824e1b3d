#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/semi_implicit/boundary_loads.h>
#include <talus/loads/kinematics.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>

namespace talus::semi_implicit
{
  namespace
  {
    const char *const axes = "xyz";

    template <int dim>
    bool
    region_meets_grid(const dealii::Point<dim> &lower, const dealii::Point<dim> &upper, const Parameters<dim> &p)
    {
      for (unsigned int d = 0; d < dim; ++d)
        if (lower[d] > p.grid_upper[d] || upper[d] < p.grid_lower[d])
          return false;
      return true;
    }
    template <int dim>
    std::string
    grid_extent(const Parameters<dim> &p)
    {
      std::string s;
      for (unsigned int d = 0; d < dim; ++d)
        s += std::string(d ? ", " : "") + axes[d] + " " + std::to_string(p.grid_lower[d]) + " .. " +
             std::to_string(p.grid_upper[d]);
      return "(grid extent " + s + ")";
    }
    template <int dim>
    double
    cell_size(const Parameters<dim> &p, const unsigned int d)
    {
      return (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d];
    }
  } // namespace

  void
  declare_boundary_load_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, const unsigned int dim)
  {
    loads::declare_traction_parameters(prm, prm_file, dim, /*with_velocities=*/true);
    prm.enter_subsection("boundary conditions");
    loads::declare_drainage_parameters(prm, dim, loads::peek_drainage(prm_file));
    prm.leave_subsection();
    prm.enter_subsection("semi implicit");
    prm.declare_entry("traction acts at", "body surface", dealii::Patterns::Selection("body surface|load points"),
                      "Where the force of a soil point carrying a traction ('loads/traction k', apply to = body face "
                      "or region) enters the grid. body surface: at the point's share of the loaded face, the point "
                      "position plus half its sub-cell spacing towards the face, a vector carried by the point's dF "
                      "(the weak form's face integral: the top points carry the full load). load points: at the "
                      "point itself (the top layer then carries only part of the load and is too stiff; kept for "
                      "comparison; docs/semi-implicit.md).");
    prm.leave_subsection();
  }

  template <int dim>
  void
  parse_boundary_load_parameters(dealii::ParameterHandler &prm, Parameters<dim> &p)
  {
    p.tractions = loads::parse_traction_parameters<dim>(prm, p.bodies, p.grid_lower, p.grid_upper, &p.velocities);
    prm.enter_subsection("boundary conditions");
    for (const auto &c : loads::parse_drainage_parameters<dim>(prm, /*box_grid=*/true))
      p.drainage.push_back(c); // after the alias 'semi implicit/drained boundaries': the later wins
    prm.leave_subsection();
    prm.enter_subsection("semi implicit");
    p.traction_at_surface = prm.get("traction acts at") == "body surface";
    prm.leave_subsection();
    const std::string rigid = "'semi implicit/rigid skeleton = true' holds every soil node at rest";
    for (const auto &t : p.tractions)
      {
        require(!t.radial, t.where + "/pressure centre",
                "a pressure on a circle is not available in talus-semi-implicit (allowed: talus-explicit, "
                "talus-implicit in plane strain; here 'traction' on a face)");
        require(!p.rigid_skeleton, t.where,
                "talus-semi-implicit cannot honour a traction here: " + rigid +
                  ", so no load can move the soil (allowed: rigid skeleton = false, or no traction)");
        if (t.target == loads::Traction<dim>::Target::body_face)
          require(p.phase_of_body[t.body] != Phase::water, t.where + "/body",
                  "body " + std::to_string(t.body) +
                    " has phase = water; a traction is carried by soil points (allowed: a body with phase "
                    "saturated or soil, or apply to = boundary)");
        if (t.target == loads::Traction<dim>::Target::point && t.body != loads::Traction<dim>::any_body)
          require(p.phase_of_body[t.body] != Phase::water, t.where + "/body",
                  "body " + std::to_string(t.body) +
                    " has phase = water; a point load is carried by soil points (allowed: a body with phase "
                    "saturated or soil, or any)");
        if (t.target == loads::Traction<dim>::Target::region)
          require(region_meets_grid(t.lower, t.upper, p), t.where + "/region lower corner",
                  "the region lies outside the grid " + grid_extent(p));
      }
    for (const auto &v : p.velocities)
      {
        require(v.target != loads::PrescribedVelocity<dim>::Target::body, v.where + "/apply to",
                "is 'body': talus-semi-implicit cannot honour a prescribed velocity of material points (its "
                "velocities are solved on the grid nodes of two point sets); allowed: boundary or region");
        require(!p.rigid_skeleton, v.where,
                "talus-semi-implicit cannot honour a prescribed velocity here: " + rigid +
                  " (allowed: rigid skeleton = false, or no velocity condition)");
        if (v.target == loads::PrescribedVelocity<dim>::Target::region)
          {
            require(region_meets_grid(v.lower, v.upper, p), v.where + "/region lower corner",
                    "the region lies outside the grid " + grid_extent(p));
            // a node of the box grid inside the region (so that --check finds it)
            bool any = true;
            for (unsigned int d = 0; d < dim; ++d)
              {
                const double h = cell_size(p, d), tol = 1e-9 * h;
                const double i0 = std::max(0.0, std::ceil((v.lower[d] - tol - p.grid_lower[d]) / h));
                const double i1 =
                  std::min<double>(p.grid_cells[d], std::floor((v.upper[d] + tol - p.grid_lower[d]) / h));
                any = any && i0 <= i1;
              }
            require(any, v.where,
                    "holds no grid node: no node of the grid lies inside its region (allowed: a region that "
                    "contains at least one grid node)");
          }
      }
    for (const auto &c : p.drainage)
      if (c.target == loads::Drainage<dim>::Target::region)
        require(region_meets_grid(c.lower, c.upper, p), c.where + "/region lower corner",
                "the region lies outside the grid " + grid_extent(p));
  }

  template <int dim>
  BoundaryLoads<dim>::BoundaryLoads(const Parameters<dim> &prm, const BackgroundGrid<dim> &grid, MPI_Comm comm)
      : prm(prm)
      , grid(grid)
      , comm(comm)
      , at_surface(prm.traction_at_surface)
  {
  }

  template <int dim>
  void
  BoundaryLoads<dim>::extend_layout(PropertyLayout<dim> &layout, const unsigned int offset)
  {
    offset_field = offset;
    bool any     = false;
    for (const auto &t : prm.tractions)
      any = any || t.target != loads::Traction<dim>::Target::boundary;
    // one slot per traction (a boundary traction's stays 0); none without a point traction
    point_forces.extend_layout(layout, any ? prm.tractions.size() : 0);
  }

  template <int dim>
  void
  BoundaryLoads<dim>::assign(MaterialPointSet<dim> &soil, const std::vector<BodyDescription<dim>> &bodies)
  {
    using L = PropertyLayout<dim>;
    if (point_forces.n_slots() > 0)
      {
        point_forces.assign(prm.tractions, soil, grid, bodies, comm);
        // each loaded point's offset to its share of the face: half its
        // sub-cell spacing towards the face of its first traction
        const unsigned int off = point_forces.offset();
        for (auto &pt : soil.handler)
          {
            auto P = pt.get_properties();
            for (unsigned int d = 0; d < dim; ++d)
              P[offset_field + d] = 0;
            if (!at_surface)
              continue;
            for (unsigned int j = 0; j < prm.tractions.size(); ++j)
              {
                bool loaded_by_j = false;
                for (unsigned int d = 0; d < dim; ++d)
                  loaded_by_j = loaded_by_j || P[off + j * dim + d] != 0.0;
                const auto &t = prm.tractions[j];
                if (!loaded_by_j || t.target == loads::Traction<dim>::Target::point) // a point load: at the point
                  continue;
                const auto        &cc    = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
                const unsigned int b     = static_cast<unsigned int>(P[L::body]);
                P[offset_field + t.axis] = t.side * 0.5 * cc.h[t.axis] / bodies[b].particles_per_direction;
                break;
              }
          }
      }
    // a boundary traction acts where soil touches its face: some soil point
    // within one cell of it
    for (const auto &t : prm.tractions)
      if (t.target == loads::Traction<dim>::Target::boundary)
        {
          const double face = t.side > 0 ? prm.grid_upper[t.axis] : prm.grid_lower[t.axis];
          unsigned int near = 0;
          for (const auto &pt : soil.handler)
            near += std::abs(pt.get_location()[t.axis] - face) < cell_size(prm, t.axis) ? 1 : 0;
          near = dealii::Utilities::MPI::sum(near, comm);
          require(near > 0, t.where + "/boundary id",
                  "no soil point lies within a cell of the grid face with boundary id " + std::to_string(t.boundary) +
                    ": the traction would load nothing (allowed: a face the soil touches)");
          double area = 1;
          for (unsigned int d = 0; d < dim; ++d)
            if (d != t.axis)
              area *= prm.grid_upper[d] - prm.grid_lower[d];
          log() << "  " << t.where << ": grid boundary id " << t.boundary << ", nodal forces on its nodes that "
                << "carry soil, face area " << area << (dim == 2 ? " m (per unit thickness)" : " m^2")
                << (t.total ? " (total force given)" : "") << ", f(t) = " << t.function.text() << std::endl;
        }
  }

  template <int dim>
  void
  BoundaryLoads<dim>::grid_changed(const std::vector<unsigned int>       &node_of,
                                   const std::vector<unsigned char>      &component,
                                   const std::vector<dealii::Point<dim>> &node_x,
                                   std::vector<unsigned char>            &water_constrained)
  {
    const unsigned int nl = node_of.size();
    dof_component         = component;
    velocity_of.assign(nl, none);
    velocity_value.assign(nl, 0.0);
    water_free.assign(nl, 0);
    drain_all.assign(nl, none);
    drain_surface.assign(nl, none);
    grid.reinit_vector(loaded);
    // drainage: per node the last condition that holds it; a draining boundary
    // (drained or pressure) frees the water's component normal to it
    for (unsigned int i = 0; i < nl; ++i)
      for (unsigned int c = 0; c < prm.drainage.size(); ++c)
        {
          const auto &dc = prm.drainage[c];
          if (!dc.holds(node_x[i], prm.grid_lower, prm.grid_upper))
            continue;
          if (dc.target == loads::Drainage<dim>::Target::region)
            drain_surface[node_of[i]] = c;
          else
            {
              drain_all[node_of[i]] = c;
              const bool drains     = dc.kind != loads::Drainage<dim>::Kind::impermeable;
              if (component[i] == dc.boundary / 2)
                {
                  water_free[i] = drains;
                  if (drains)
                    water_constrained[i] = 0;
                }
            }
        }
    // prescribed velocities (a DoF of two conditions: the later)
    std::vector<unsigned long long> count(prm.velocities.size(), 0);
    const unsigned int              owned = grid.partitioner->locally_owned_size();
    for (const auto &e : loads::prescribed_node_dofs(grid, prm.velocities, /*owned_only=*/false))
      {
        velocity_of[e.dof] = e.condition;
        if (e.dof < owned)
          ++count[e.condition];
      }
    if (!nodes_checked && !count.empty())
      {
        MPI_Allreduce(MPI_IN_PLACE, count.data(), static_cast<int>(count.size()), MPI_UNSIGNED_LONG_LONG, MPI_SUM,
                      comm);
        for (unsigned int k = 0; k < count.size(); ++k)
          require(count[k] > 0, prm.velocities[k].where,
                  "holds no grid node: no node of the grid lies inside its region (allowed: a region that "
                  "contains at least one grid node)");
      }
    nodes_checked = true;
    // boundary tractions: every DoF of the face's nodes with the node's share
    // of the face (the product of its cells' widths along the face, halved at
    // the face's edges)
    nodal_tractions.clear();
    for (unsigned int j = 0; j < prm.tractions.size(); ++j)
      {
        const auto &t = prm.tractions[j];
        if (t.target != loads::Traction<dim>::Target::boundary)
          continue;
        double face_area = 1;
        for (unsigned int d = 0; d < dim; ++d)
          if (d != t.axis)
            face_area *= prm.grid_upper[d] - prm.grid_lower[d];
        const double face = t.side > 0 ? prm.grid_upper[t.axis] : prm.grid_lower[t.axis];
        for (unsigned int i = 0; i < nl; ++i)
          {
            const double tol = 1e-9 * (prm.grid_upper[t.axis] - prm.grid_lower[t.axis]);
            if (std::abs(node_x[i][t.axis] - face) > tol)
              continue;
            double area = 1;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != t.axis)
                {
                  const double h   = cell_size(prm, d);
                  const bool   end = std::abs(node_x[i][d] - prm.grid_lower[d]) < 1e-9 * h ||
                                   std::abs(node_x[i][d] - prm.grid_upper[d]) < 1e-9 * h;
                  area *= end ? 0.5 * h : h;
                }
            nodal_tractions.push_back(
              {i, node_of[i], j, t.traction[component[i]] * area / (t.total ? face_area : 1.0)});
          }
      }
    reaction.assign(prm.velocities.size() * dim, 0.0);
  }

  template <int dim>
  void
  BoundaryLoads<dim>::describe(std::ostream &out) const
  {
    for (const auto &v : prm.velocities)
      {
        std::string comps;
        for (unsigned int d = 0; d < dim; ++d)
          if (v.component[d])
            comps += std::string(comps.empty() ? "" : ", ") + axes[d];
        out << "  " << v.where << ": "
            << (v.target == loads::PrescribedVelocity<dim>::Target::boundary
                  ? "boundary id " + std::to_string(v.boundary)
                  : std::string("region"))
            << ", prescribed soil velocity (" << comps << ") x f(t) = " << v.function.text()
            << "; the water moves with it unless the node drains" << std::endl;
      }
    for (const auto &c : prm.drainage)
      out << "  " << c.where << ": "
          << (c.target == loads::Drainage<dim>::Target::boundary ? "boundary id " + std::to_string(c.boundary)
                                                                 : std::string("the free surface inside a region"))
          << ", "
          << (c.kind == loads::Drainage<dim>::Kind::drained ? "drained (p = 0)"
              : c.kind == loads::Drainage<dim>::Kind::impermeable
                ? "impermeable"
                : "pore pressure " + std::to_string(c.pressure) + " Pa x f(t) = " + c.function.text())
          << std::endl;
  }

  template <int dim>
  void
  BoundaryLoads<dim>::begin_step(const double t, const double h)
  {
    time_end = t + h;
    traction_factor.resize(prm.tractions.size());
    for (unsigned int j = 0; j < prm.tractions.size(); ++j) // the mean over the step of a ramp
      traction_factor[j] = prm.tractions[j].function.value(t + 0.5 * h);
    if (point_forces.n_slots() > 0)
      point_forces.set_factors(traction_factor);
    for (unsigned int i = 0; i < velocity_of.size(); ++i)
      if (velocity_of[i] != none)
        {
          const auto &v     = prm.velocities[velocity_of[i]];
          velocity_value[i] = v.velocity[dof_component[i]] * v.function.value(t + h);
        }
    loaded       = 0;
    n_water_rows = 0;
  }

  template <int dim>
  void
  BoundaryLoads<dim>::add_boundary_tractions(Vector &Fs, const Vector &Ms, const double ms_cut)
  {
    loaded.compress(dealii::VectorOperation::add);
    loaded.update_ghost_values();
    for (const auto &n : nodal_tractions)
      if (Ms.local_element(n.node) > ms_cut)
        {
          Fs.local_element(n.dof) += traction_factor[n.traction] * n.force;
          loaded.local_element(n.node) = 1; // (owned and ghost alike)
        }
  }

  template <int dim>
  void
  BoundaryLoads<dim>::reactions(const std::function<double(unsigned int)> &residual)
  {
    if (prm.velocities.empty())
      return;
    std::fill(reaction.begin(), reaction.end(), 0.0);
    const unsigned int owned = grid.partitioner->locally_owned_size();
    for (unsigned int i = 0; i < owned; ++i)
      if (velocity_of[i] != none)
        reaction[velocity_of[i] * dim + dof_component[i]] += residual(i);
    MPI_Allreduce(MPI_IN_PLACE, reaction.data(), static_cast<int>(reaction.size()), MPI_DOUBLE, MPI_SUM, comm);
  }

  template <int dim>
  std::pair<bool, double>
  BoundaryLoads<dim>::pressure_row(const unsigned int i, const bool has_water, const bool plate_drained,
                                   const bool plate_sealed, const double wet, const double dry, const double near_wet,
                                   const double p)
  {
    const Row row = decide_row(i, has_water, plate_drained, plate_sealed, wet, dry, near_wet, p);
    // the references of the pressure: its Dirichlet rows at water, and the
    // sealed surface's rows at a dry cell (the surface term fixes the
    // pressure's level; a candidate inside the water is none)
    if ((row.dirichlet || (row.sealed && dry > 0)) && has_water)
      ++n_water_rows;
    return {row.dirichlet, row.dp};
  }

  template <int dim>
  bool
  BoundaryLoads<dim>::sealed_surface(const unsigned int i, const bool has_water, const bool plate_drained,
                                     const bool plate_sealed, const double wet, const double dry,
                                     const double near_wet) const
  {
    return decide_row(i, has_water, plate_drained, plate_sealed, wet, dry, near_wet, 0.0).sealed;
  }

  template <int dim>
  bool
  BoundaryLoads<dim>::may_seal_surface() const
  {
    if (!prm.tractions.empty())
      return true;
    for (const auto &c : prm.drainage)
      if (c.target == loads::Drainage<dim>::Target::region && c.kind == loads::Drainage<dim>::Kind::impermeable)
        return true;
    return false;
  }

  template <int dim>
  typename BoundaryLoads<dim>::Row
  BoundaryLoads<dim>::decide_row(const unsigned int i, const bool has_water, const bool plate_drained,
                                 const bool plate_sealed, const double wet, const double dry, const double near_wet,
                                 const double p) const
  {
    using Kind = typename loads::Drainage<dim>::Kind;
    if (!has_water) // no water: Delta p = 0 (A2, A4)
      return {true, 0.0, false};
    if (plate_drained) // a permeable plate: p^{t+1} = 0
      return {true, -p, false};
    // under an impermeable plate: solved, also where the plate's edge lies on
    // a draining face (the plate covers the surface over its node's support:
    // p = 0 there drained the plate's edge cell, Mandel's problem 14 % too
    // fast; docs/semi-implicit.md 'Mandel's problem')
    if (plate_sealed)
      return {false, 0.0, false};
    // a boundary condition holds every water node of its face
    const unsigned int a = drain_all[i];
    if (a != none && prm.drainage[a].kind == Kind::drained)
      return {true, -p, false};
    if (a != none && prm.drainage[a].kind == Kind::pressure)
      return {true, prm.drainage[a].pressure_at(time_end) - p, false};
    // the surface's kind: a region's condition; else (at a vertex of a wet and
    // a dry cell) a boundary's impermeable one; else sealed where a load acts
    // (a loaded face drains only where the user says so), drained elsewhere (A6)
    const unsigned int r      = drain_surface[i];
    const bool         load   = loaded.local_element(i) > 0;
    const bool         region = r != none;
    if (!(dry > 0)) // inside the water: solved; a candidate of the seal under a sealed surface (sealed_surface)
      return {false, 0.0, region ? prm.drainage[r].kind == Kind::impermeable : load};
    if (wet > 0)
      {
        const Kind kind = region      ? prm.drainage[r].kind
                          : a != none ? Kind::impermeable
                          : load      ? Kind::impermeable
                                      : Kind::drained;
        if (kind == Kind::impermeable) // solved; a sealed surface node of a region or a load
          return {false, 0.0, region || (a == none && load)};
        if (kind == Kind::pressure)
          return {true, prm.drainage[r].pressure_at(time_end) - p, false};
        return {true, -p, false};
      }
    // all-dry nodes touched by water (A6): those next to a wet cell keep the
    // mapped p^t (Delta p = 0), the others p^{t+1} = 0; next to a wet cell
    // under a sealed surface (a region's impermeable condition or a load)
    // they are solved with the surface's force (docs/semi-implicit.md 'A
    // sealed surface')
    const bool keep = near_wet > 0;
    if (keep && (region ? prm.drainage[r].kind == Kind::impermeable : load))
      return {false, 0.0, true};
    return {true, keep ? 0.0 : -p, false};
  }

  template <int dim>
  void
  BoundaryLoads<dim>::check_pressure_reference() const
  {
    if (dealii::Utilities::MPI::sum(n_water_rows, comm) > 0)
      return;
    std::string who;
    if (!prm.tractions.empty())
      who = prm.tractions.front().where;
    else if (!prm.velocities.empty())
      who = prm.velocities.front().where;
    else
      for (const auto &c : prm.drainage)
        if (who.empty() && c.kind == loads::Drainage<dim>::Kind::impermeable)
          who = c.where;
    require(who.empty(), who,
            "the pore water has no pressure reference: no free surface drains, no boundary is drained or has a "
            "prescribed pressure, no plate is permeable (a closed, sealed box: a loaded face or a moving wall is "
            "impermeable unless a drainage condition says otherwise); allowed: 'boundary conditions/drainage k' "
            "with condition = drained or pressure on a boundary id or on the loaded surface's region");
  }

  template <int dim>
  std::vector<std::string>
  BoundaryLoads<dim>::series_columns() const
  {
    std::vector<std::string> c;
    for (unsigned int k = 0; k < prm.velocities.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        if (prm.velocities[k].component[d])
          c.push_back("velocity_" + std::to_string(k) + "_reaction_" + axes[d]);
    return c;
  }

  template <int dim>
  void
  BoundaryLoads<dim>::series_values(std::vector<double> &v) const
  {
    for (unsigned int k = 0; k < prm.velocities.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        if (prm.velocities[k].component[d])
          v.push_back(reaction[k * dim + d]);
  }

  template <int dim>
  void
  BoundaryLoads<dim>::settlement_weights(const double *P, double &force_dot_u, double &force) const
  {
    force_dot_u = force       = 0;
    const unsigned int off    = point_forces.offset();
    double             f[dim] = {};
    for (unsigned int j = 0; j < point_forces.n_slots(); ++j)
      for (unsigned int d = 0; d < dim; ++d)
        f[d] += P[off + j * dim + d];
    double f2 = 0;
    for (unsigned int d = 0; d < dim; ++d)
      {
        force_dot_u += f[d] * P[PropertyLayout<dim>::displacement + d];
        f2 += f[d] * f[d];
      }
    force = std::sqrt(f2);
  }

  template void parse_boundary_load_parameters<2>(dealii::ParameterHandler &, Parameters<2> &);
  template void parse_boundary_load_parameters<3>(dealii::ParameterHandler &, Parameters<3> &);
  template class BoundaryLoads<2>;
  template class BoundaryLoads<3>;
} // namespace talus::semi_implicit
