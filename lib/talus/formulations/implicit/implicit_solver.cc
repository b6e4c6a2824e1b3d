#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/diagnostics.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/point_output.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/formulations/implicit/updated_lagrangian_ops.h>
#include <talus/io/output.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/loads/kinematics.h>
#include <talus/shape/with_kernel.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>

#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

namespace talus::implicit_mpm
{
  namespace
  {
    /// The consistent inertia of one point on the displacement components
    /// (`with_matrix`, `with_vector` as the walk's integrand flags):
    /// b_ic += m_p N_i sum_j N_j w_jc (w: the nodal a + alpha_R v, the walk's
    /// field) and A_ic,jc += coef m_p N_i N_j. Summed over the points this is
    /// M w and coef M with M_ij = sum_p m_p N_i N_j (its row sums are the lumped
    /// masses); a pressure component (mixed u-p) carries no mass.
    template <int dim, bool with_matrix, bool with_vector>
    struct ConsistentInertia
    {
      double                coef   = 0;
      static constexpr bool matrix = with_matrix, vector = with_vector;
      template <int d_, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc >= dim && d_ == dim, "ConsistentInertia: the displacement components come first");
        const double m = P[PropertyLayout<dim>::mass];
        if constexpr (with_vector)
          {
            double w[dim] = {};
            for (unsigned int j = 0; j < p.n; ++j)
              for (unsigned int c = 0; c < dim; ++c)
                w[c] += p.N[j] * ls.u[p.local[j] * nc + c];
            for (unsigned int i = 0; i < p.n; ++i)
              for (unsigned int c = 0; c < dim; ++c)
                ls.b[p.local[i] * nc + c] += m * p.N[i] * w[c];
          }
        if constexpr (with_matrix)
          for (unsigned int i = 0; i < p.n; ++i)
            for (unsigned int j = 0; j < p.n; ++j)
              {
                const double v = coef * m * p.N[i] * p.N[j];
                for (unsigned int c = 0; c < dim; ++c)
                  ls.a(p.local[i] * nc + c, p.local[j] * nc + c) += v;
              }
      }
    };
  } // namespace

  // ================================================================ solver
  template <int dim>
  template <class F>
  void
  Solver<dim>::with_kernel(F &&f) const
  {
    shape::with_kernel<dim>(prm.bspline(), std::forward<F>(f));
  }

  template <int dim>
  Solver<dim>::Solver(const Parameters<dim> &p, MPI_Comm c)
      : Simulation<dim>(p, p, c, {"points"})
      , prm(p)
      , points(*this->point_sets[0])
      , space(grid, p.mixed_up ? dim + 1 : dim)
      , active(space)
      , newmark(p.gamma, p.beta)
      , pvd_records(this->point_set_records[0])
  {
  }

  template <int dim>
  Solver<dim>::~Solver() = default;

  template <int dim>
  void
  Solver<dim>::setup()
  {
    this->make_grid();
    space.setup();

    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    points.layout.n_history = n_history;
    acceleration_offset     = points.layout.add_extra("acceleration", dim, true);
    point_forces.extend_layout(points.layout, prm.tractions.size());
    if (prm.axisymmetric)
      radius_offset = points.layout.add_extra("radius", 1);
    if (prm.contact_on_points || prm.footing.enabled)
      {
        // the contact walls as planes (box faces: id = 2 axis + (0 lower | 1 upper))
        std::vector<ContactPlane> planes;
        const auto                cell_size = [&](const unsigned int axis) {
          return (prm.grid_upper[axis] - prm.grid_lower[axis]) / prm.grid_cells[axis];
        };
        for (const auto id : prm.contact_on_points ? prm.contact_ids : std::vector<dealii::types::boundary_id>())
          {
            ContactPlane c;
            c.axis     = id / 2;
            c.sign     = id % 2 ? 1 : -1;
            c.wall     = c.sign < 0 ? prm.grid_lower[c.axis] : prm.grid_upper[c.axis];
            c.cell     = cell_size(c.axis);
            c.penalty  = prm.contact_penalty;
            c.friction = prm.contact_mu;
            planes.push_back(c);
          }
        if (prm.footing.enabled)
          {
            const auto  &f = prm.footing;
            ContactPlane c;
            c.axis   = f.axis;
            c.sign   = f.sign;
            c.wall_0 = f.level;
            c.wall = c.wall_n = f.level; // set_time moves it every step
            c.velocity        = f.velocity;
            c.cell            = cell_size(c.axis);
            c.penalty         = f.penalty;
            c.friction        = f.friction;
            c.footing         = true;
            for (unsigned int k = 0; k + 1 < dim; ++k)
              {
                c.lower[k] = f.lower[k];
                c.upper[k] = f.upper[k];
              }
            planes.push_back(c);
          }
        point_contact = std::make_unique<PointContact<dim>>(planes, prm.materials, prm.axisymmetric, prm.bspline());
        point_contact->extend_layout(points.layout);
      }
    if (prm.mixed_up)
      {
        pressure_offset = points.layout.add_extra("pressure", 1);
        for (const auto &m : prm.materials)
          split_models.push_back(m.get());
      }
    points.initialize();

    const unsigned int n_plates = prm.rigid_plates.size();
    plate_displacement.assign(n_plates, 0.0);
    plate_step.assign(n_plates, 0.0);
    plate_c.assign(n_plates, 0.0);
    plate_target.assign(n_plates, 0.0);
    plate_sum.assign(n_plates, 0.0);
    plate_reaction.assign(n_plates, dealii::Tensor<1, dim>());
    plate_owned.assign(n_plates, {});
    idle_plates.assign(n_plates, 0);
    const bool restored = restore_if_asked(prm, [this] { return restore_checkpoint(); });
    if (!restored)
      {
        seed_scene_bodies(grid, prm.bodies, material_densities(prm), points, "material point", &prm);
        using L = PropertyLayout<dim>;
        if (any_initial_stress(prm.initial_stress)) // the K0 procedure (formulations/common/initial_stress.h)
          {
            GeostaticState<dim> geo(prm.initial_stress, prm.gravity);
            geo.find_body_tops({&points}, grid, prm.bodies, comm);
            for (auto &pt : points.handler)
              {
                auto               P = pt.get_properties();
                const unsigned int b = static_cast<unsigned int>(P[L::body]);
                if (geo.applies(b))
                  L::set_stress(geo.one_phase_stress(b, pt.get_location(), P[L::mass] / P[L::volume]), P.data());
              }
          }
        initialize_point_histories(prm.materials, points, L::history);
        for (auto &pt : points.handler)
          {
            auto P = pt.get_properties();
            for (unsigned int d = 0; d < dim; ++d)
              P[acceleration_offset + d] = 0.0;
            if (prm.mixed_up) // the mean of the initial stress
              P[pressure_offset] = dealii::trace(L::get_stress(P.data())) / 3.0;
          }
        if (point_contact)
          point_contact->initialize_points(points);
        dt = prm.stage_time_steps[0];
      }
    require(current_stage < prm.stages.size(), "checkpoint/restart",
            "the checkpoint is in stage " + std::to_string(current_stage) + " but the .prm has " +
              std::to_string(prm.stages.size()) + " stage(s)");
    enter_stage(current_stage);
    check_plates();
    points.collect_active_cells();
    if (!prm.tractions.empty())
      point_forces.assign(prm.tractions, points, grid, prm.bodies, comm);
    if (prm.axisymmetric && !restored)
      {
        // The ring measure (docs/implicit.md, "Axisymmetry"): the seeded V_p is
        // the point's area in the r-z plane; its volume and mass become those
        // of the ring it stands for, 2 pi r_p V_p and 2 pi r_p m_p, so that every
        // integral of the step (internal force, m_p g, the lumped mass, V_{n+1} =
        // det(dF) V_n with the hoop stretch in dF) is the plane one with the
        // ring's measure. The traction forces were assigned on the areas (per
        // unit length of the face in the r-z plane); they get the ring weight of
        // the loaded surface: 2 pi x the face's radius for a body face normal to
        // x (r = the body's lower/upper x), 2 pi r_p otherwise.
        using L                = PropertyLayout<dim>;
        const double two_pi    = 2 * dealii::numbers::PI;
        double       totals[2] = {0, 0};
        // a point on or across the axis (only a particle file can put one there:
        // seeded points sit at sub-cell centres of a grid with x >= 0)
        double r_min = std::numeric_limits<double>::max();
        for (const auto &pt : points.handler)
          r_min = std::min(r_min, pt.get_location()[0]);
        r_min = dealii::Utilities::MPI::min(r_min, comm);
        require(r_min > 0, "implicit/geometry",
                "'axisymmetric': a material point lies at x = " + std::to_string(r_min) +
                  " <= 0, on or across the axis (x is the radius; points must have x > 0)");
        for (auto &pt : points.handler)
          {
            auto         P = pt.get_properties();
            const double r = pt.get_location()[0];
            for (unsigned int j = 0; j < prm.tractions.size(); ++j)
              {
                const auto &t      = prm.tractions[j];
                double      r_face = r;
                if (t.target == loads::Traction<dim>::Target::body_face && t.axis == 0)
                  r_face = t.side < 0 ? prm.bodies[t.body].lower[0] : prm.bodies[t.body].upper[0];
                for (unsigned int d = 0; d < dim; ++d)
                  P[point_forces.offset() + j * dim + d] *= two_pi * r_face;
              }
            P[L::volume] *= two_pi * r;
            P[L::mass] *= two_pi * r;
            totals[0] += P[L::volume];
            totals[1] += P[L::mass];
          }
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(totals, 2), comm,
                                    dealii::ArrayView<double>(totals, 2));
        log() << "  axisymmetric: points carry their rings (2 pi r x area): volume " << totals[0] << " m^3, mass "
              << totals[1] << " kg" << std::endl;
        if (prm.grid_lower[0] == 0)
          for (const auto &bc : prm.boundary_conditions)
            if (bc.id == 0)
              log() << "  axisymmetric: the x-min wall is the axis, u_r = 0 there ("
                    << (bc.kind == BoundaryCondition::Kind::roller ? "roller" : "fixed") << ")" << std::endl;
      }
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap})
      space.reinit_vector(*v);
    // every contact node starts in contact (released in the first step where
    // the wall would pull on it); a restart starts so too
    contact_state = 1.0;
    contact_state.update_ghost_values();
    // load balancing: partition by points from the start (a restart on as many
    // ranks has recreated its saved partition instead)
    balance.initial();
  }

  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    space.setup();
    if (current_stage < prm.stages.size())
      stage_nodes(current_stage);
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap})
      space.reinit_vector(*v);
    contact_state = 1.0; // (load balancing is refused with contact walls on the nodes)
    contact_state.update_ghost_values();
    points.collect_active_cells();
  }

  template <int dim>
  double
  Solver<dim>::load_factor(const double t) const
  {
    if (dynamic() || !prm.ramp_loads)
      return 1.0;
    if (!prm.staged)
      return std::min(1.0, t / prm.end_time);
    return std::min(1.0, (t - stage_start_time) / prm.stages[current_stage].duration);
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::apply_loads_at(const double t)
  {
    const double r = load_factor(t);
    if (!prm.staged) // the ramp scales gravity and every traction alike
      {
        point_forces.update_factors(prm.tractions, prm.tractions.size(), t, 0.0);
        point_force_scale = r;
        return r * prm.gravity;
      }
    // global tractions (absolute time) ramp in with stage 0 and stay on; a
    // stage's own (stage time) ramp in over it and are off in other stages
    const unsigned int  k = current_stage;
    std::vector<double> f(prm.tractions.size(), 0.0);
    for (unsigned int j = 0; j < prm.tractions.size(); ++j)
      if (prm.traction_stage[j] < 0)
        f[j] = prm.tractions[j].function.value(t) * (k == 0 ? r : 1.0);
      else if (static_cast<unsigned int>(prm.traction_stage[j]) == k)
        f[j] = prm.tractions[j].function.value(t - stage_start_time) * r;
    point_forces.set_factors(std::move(f));
    point_force_scale               = 1;
    const dealii::Tensor<1, dim> &g = prm.stages[k].gravity;
    if (r == 1.0)
      return g;
    const dealii::Tensor<1, dim> g_before = k > 0 ? prm.stages[k - 1].gravity : dealii::Tensor<1, dim>();
    return g_before + r * (g - g_before);
  }

  template <int dim>
  void
  Solver<dim>::enter_stage(const unsigned int k)
  {
    stage_nodes(k);
    idle_conditions.assign(prm.stages[k].velocities.size() + prm.rigid_plates.size(), 0);
    region_shift.assign(prm.stages[k].velocities.size(), dealii::Tensor<1, dim>());
  }

  template <int dim>
  void
  Solver<dim>::stage_nodes(const unsigned int k)
  {
    const auto &st = prm.stages[k];
    boundary_flags = loads::wall_dof_flags(grid, st.boundary_conditions);
    contact_nodes  = prm.contact_on_points ? std::vector<loads::ContactNode>()
                                           : loads::contact_wall_nodes(grid, prm.contact_ids, boundary_flags);
    node_contact.assign(boundary_flags.size(), -1);
    for (std::size_t k = 0; k < contact_nodes.size(); ++k)
      node_contact[contact_nodes[k].node] = int(k);
    // the grid nodes of the stage's 'velocity k' (owned and ghost: constraints
    // of a distributed assembly must be known where a rank assembles)
    prescribed_dofs = loads::prescribed_node_dofs(grid, st.velocities, false);
    // the plates' nodes (their walls are those of the stage)
    plate_nodes = loads::rigid_plate_node_dofs(grid, prm.rigid_plates, false);
    append_plate_dofs();
  }

  template <int dim>
  void
  Solver<dim>::append_plate_dofs()
  {
    // a component a fixed/roller wall holds stays the wall's (wall_constraints
    // would let a prescribed line win); the axis component of a force plate is
    // no prescribed DoF but the plate's unknown
    const unsigned int n_vel = n_velocities();
    for (const auto &p : plate_nodes)
      {
        const auto &plate = prm.rigid_plates[p.condition];
        if (boundary_flags[p.dof] || (force_plate(p.condition) && p.component == plate.axis))
          continue;
        prescribed_dofs.push_back({p.dof, p.node, n_vel + p.condition, p.component});
      }
  }

  template <int dim>
  void
  Solver<dim>::check_plates()
  {
    // the shared node checks (exit 2 naming the plate) of every stage's walls
    std::vector<std::vector<BoundaryCondition>> walls;
    std::vector<std::string>                    names;
    for (const auto &st : prm.stages)
      walls.push_back(st.boundary_conditions), names.push_back(st.name);
    const auto counts = loads::check_rigid_plate_nodes(grid, prm.rigid_plates, walls, names, comm);
    for (unsigned int k = 0; k < counts.size(); ++k)
      log() << loads::rigid_plate_log_line(prm.rigid_plates[k], k, counts[k]) << std::endl;
  }

  template <int dim>
  void
  Solver<dim>::find_plate_dofs()
  {
    // the axis DoFs of each force plate that the step leaves free (not held by
    // a wall, a prescribed line, contact, the inactive pins or the negligible
    // mass rule, which includes the prescribed lines of displacement plates;
    // plates share no node: check_plates)
    const auto                                  &owned = space.locally_owned_dofs();
    std::vector<dealii::types::global_dof_index> mine;
    for (auto &v : plate_owned)
      v.clear();
    for (const auto &p : plate_nodes)
      {
        const auto &plate = prm.rigid_plates[p.condition];
        if (!force_plate(p.condition) || p.component != plate.axis)
          continue;
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || constraints.is_constrained(i))
          continue;
        plate_owned[p.condition].push_back(i);
        mine.push_back(i);
      }
    plate_all.clear();
    for (const auto &v : dealii::Utilities::MPI::all_gather(comm, mine))
      plate_all.insert(plate_all.end(), v.begin(), v.end());
    std::sort(plate_all.begin(), plate_all.end());
  }

  template <int dim>
  void
  Solver<dim>::prepare_step()
  {
    if (prm.axisymmetric) // r_n of every point, read by the residual and the convective phase
      for (auto &pt : points.handler)
        pt.get_properties()[radius_offset] = pt.get_location()[0];
    if (prm.moving_velocity_regions)
      {
        // the regions shifted by what their conditions have prescribed so far
        auto velocities = prm.stages[current_stage].velocities;
        for (unsigned int k = 0; k < velocities.size(); ++k)
          if (velocities[k].target == loads::PrescribedVelocity<dim>::Target::region)
            {
              velocities[k].lower += region_shift[k];
              velocities[k].upper += region_shift[k];
            }
        prescribed_dofs = loads::prescribed_node_dofs(grid, velocities, false);
        append_plate_dofs();
      }
    // the cell terms (PPP cell means, F-bar's cell mean) couple all the nodes a cell's points touch
    const auto reach = prm.mixed_up || prm.fbar ? ActiveSet<dim>::Reach::cell : ActiveSet<dim>::Reach::point;
    with_kernel(
      [&](auto k) { active.template reinit<decltype(k)>({&points}, ActiveSet<dim>::Couplings::skip, reach); });
    active.reinit_matrix(tangent);
    project_to_grid();
    find_negligible_nodes();
    // the walls' fixed and roller DoFs as homogeneous constraints on the
    // increment, merged with the pins of the inactive DoFs
    contact_changes.assign(contact_nodes.size(), 0);
    if (!prm.contact_ids.empty() && !point_contact)
      measure_contact_gaps();
    if (point_contact) // x_n of the points, read by the contact terms of the step
      point_contact->start_step(points);
    constraints = step_constraints();
    if (any_force_plate())
      find_plate_dofs();
  }

  template <int dim>
  void
  Solver<dim>::measure_contact_gaps()
  {
    using L          = PropertyLayout<dim>;
    const double far = std::numeric_limits<double>::max();
    contact_gap      = far;
    contact_gap.update_ghost_values();
    contact_gap.set_ghost_state(false); // ghost entries written below and sent to the owners (compress)
    for (const auto &pt : points.handler)
      {
        const auto &cc = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
        const auto &x  = pt.get_location();
        const auto  P  = pt.get_properties();
        double      V  = P[L::volume];
        if (prm.axisymmetric)
          V /= 2 * M_PI * std::max(x[0], 1e-300);
        const double half = 0.5 * std::pow(V, 1.0 / dim);
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            const int k = node_contact[cc.dofs[v * dim]];
            if (k < 0)
              continue;
            const auto  &c   = contact_nodes[k];
            const auto   in  = space.node_dof(c.node, c.axis);
            const double gap = c.sign * (c.wall - x[c.axis]) - half;
            contact_gap(in)  = std::min(contact_gap(in), gap);
          }
      }
    contact_gap.compress(dealii::VectorOperation::min);
    contact_gap.update_ghost_values();
    // the material has left the wall at a node in contact: released
    const auto  &owned = space.locally_owned_dofs();
    unsigned int left  = 0;
    for (const auto &c : contact_nodes)
      {
        const auto in = space.node_dof(c.node, c.axis);
        if (owned.is_element(in) && contact_state(in) != 0.0 && contact_gap(in) > contact_gap_tolerance(c))
          {
            contact_state(in) = 0.0;
            ++left;
          }
      }
    contact_state.update_ghost_values();
    gap_releases += dealii::Utilities::MPI::sum(left, comm);
  }

  template <int dim>
  dealii::AffineConstraints<double>
  Solver<dim>::step_constraints(const std::vector<double> *values, const bool with_contact, const bool with_prescribed,
                                const bool hold_plates) const
  {
    // the contact nodes now in contact: their normal DoF, with no slip all
    std::vector<dealii::types::global_dof_index> held;
    if (with_contact)
      for (const auto &c : contact_nodes)
        {
          const auto in = space.node_dof(c.node, c.axis);
          if (contact_state(in) == 0.0)
            continue;
          for (unsigned int d = 0; d < dim; ++d)
            if (d == c.axis || prm.contact_no_slip)
              held.push_back(space.node_dof(c.node, d));
        }
    held.insert(held.end(), negligible_dofs.begin(), negligible_dofs.end());
    if (hold_plates) // the force plates' axis DoFs at zero increment (the predictor)
      for (const auto &p : plate_nodes)
        if (force_plate(p.condition) && p.component == prm.rigid_plates[p.condition].axis)
          held.push_back(space.node_dof(p.node, p.component));
    return active.constraints_with(loads::wall_constraints(
      grid, space, boundary_flags, with_prescribed ? &prescribed_dofs : nullptr, values, &held));
  }

  template <int dim>
  void
  Solver<dim>::find_negligible_nodes()
  {
    // A node touched only by the far corner of a point's support (a point
    // heaving into an empty cell row) has a tiny mass and a stiffness from
    // that one point only; with a perfectly plastic model it has none in the
    // flow direction and Newton breaks down. Such nodes' DoFs are held at zero
    // increment for the step (the reading notes' choice, §7: the thesis is
    // silent); a prescribed or wall DoF keeps its own line.
    negligible_dofs.clear();
    if (!(prm.negligible_mass > 0))
      return;
    double m_max = 0;
    for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
      if (space.component(k) < dim)
        m_max = std::max(m_max, mass.local_element(k));
    m_max              = dealii::Utilities::MPI::max(m_max, comm);
    const double limit = prm.negligible_mass * m_max;
    // every component of such a node is held, in u-p its pressure too: the
    // pressure row scales with the node's tiny point volume (V N / K and the
    // stabilisation) and left free it kept the system near-singular (h = 0.1 m
    // footing: increments of 1e5 .. 1e7 in converged steps, breakdown at
    // s = 0.084 m; held: docs/implicit.md, "Rigid strip footing")
    const unsigned int n_held = space.n_components();
    mass.update_ghost_values();
    std::vector<unsigned char> seen(mass.locally_owned_size() + mass.get_partitioner()->n_ghost_indices(), 0);
    for (const auto &cell : grid.tria.active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            const unsigned int node = grid.cells[cell->active_cell_index()].dofs[v * dim];
            const auto         i0   = space.node_dof(node, 0);
            const auto         j    = mass.get_partitioner()->global_to_local(i0);
            if (seen[j] || !active.is_active(i0))
              continue;
            seen[j] = 1;
            if (mass(i0) < limit)
              for (unsigned int k = 0; k < n_held; ++k)
                negligible_dofs.push_back(space.node_dof(node, k));
          }
    mass.zero_out_ghost_values();
  }

  template <int dim>
  std::pair<unsigned int, unsigned int>
  Solver<dim>::update_contact(const dealii::Tensor<1, dim> &g, const double force_scale)
  {
    // the residual assembled without the contact constraints: at a contact
    // DoF it is the force the wall must exert on the node, r = f_int + m a -
    // f_ext (the residual of the other DoFs is kept)
    Vector kept(residual);
    auto   free_contact = step_constraints(nullptr, false);
    std::swap(constraints, free_contact);
    try
      {
        assemble(false, g);
      }
    catch (...)
      {
        std::swap(constraints, free_contact);
        residual = kept;
        throw;
      }
    std::swap(constraints, free_contact);
    const auto  &owned  = space.locally_owned_dofs();
    const auto  &pins   = active.constraints();
    const double du_max = du.linfty_norm();
    // a pull below 1e-8 of the load scale and a penetration below 1e-8 of the
    // largest increment are round-off of the Newton solve, not a change
    const double tol_pull = 1e-8 * force_scale, tol_in = 1e-8 * du_max;
    unsigned int released = 0, added = 0;
    for (std::size_t k = 0; k < contact_nodes.size(); ++k)
      {
        const auto &c  = contact_nodes[k];
        const auto  in = space.node_dof(c.node, c.axis);
        if (!owned.is_element(in) || pins.is_constrained(in) || free_contact.is_constrained(in) || mass(in) == 0)
          continue;
        if (contact_changes[k] >= 2) // changed twice in this step: held
          continue;
        if (contact_state(in) != 0.0)
          {
            // compressive: the wall pushes the node into the domain, r . n_out < 0
            if (residual(in) * c.sign > tol_pull)
              {
                contact_state(in) = 0.0;
                ++contact_changes[k];
                ++released;
              }
          }
        else if (du(in) * c.sign > tol_in && contact_gap(in) <= contact_gap_tolerance(c))
          {
            contact_state(in) = 1.0;
            ++contact_changes[k];
            ++added;
          }
      }
    residual = kept;
    contact_state.update_ghost_values();
    return {dealii::Utilities::MPI::sum(released, comm), dealii::Utilities::MPI::sum(added, comm)};
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::condition_increment(const unsigned int k, const double h) const
  {
    // v f integrated over [t, t + h] by the trapezoidal rule (exact for constant
    // and piecewise-linear time functions whose kinks fall on step ends)
    const auto  &st = prm.stages[current_stage];
    const auto  &pv = st.velocities[k];
    const double t0 = k < st.n_global_velocities ? 0.0 : stage_start_time; // stage loads: stage time
    return pv.velocity * (0.5 * (pv.function.value(time - t0) + pv.function.value(time + h - t0)) * h);
  }

  template <int dim>
  double
  Solver<dim>::prescribed_increment(const loads::PrescribedNodeDof &p, const double h) const
  {
    const unsigned int n_vel = n_velocities();
    if (p.condition < n_vel)
      return condition_increment(p.condition, h)[p.component];
    // a plate: its displacement history along its axis (absolute time; the
    // static ramp does not scale it), zero tangential increments (rough)
    const auto &plate = prm.rigid_plates[p.condition - n_vel];
    if (plate.control != loads::RigidPlate<dim>::Control::displacement || p.component != plate.axis)
      return 0.0;
    return plate.displacement_at(time + h) - plate.displacement_at(time);
  }

  template <int dim>
  void
  Solver<dim>::prescribed_reaction(const dealii::Tensor<1, dim> &g)
  {
    // the residual r = f_int - f_ext assembled without the prescribed lines: at
    // a prescribed DoF it is the force the node exerts on the material (the
    // same device as the contact reactions); the other DoFs keep theirs
    Vector kept(residual);
    auto   free_prescribed = step_constraints(nullptr, true, false);
    std::swap(constraints, free_prescribed);
    try
      {
        assemble(false, g);
      }
    catch (...)
      {
        std::swap(constraints, free_prescribed);
        residual = kept;
        throw;
      }
    std::swap(constraints, free_prescribed);
    const auto &owned = space.locally_owned_dofs();
    const auto &pins  = active.constraints();
    // the velocity conditions' sum per component, then each plate's per component
    const unsigned int                           n_vel = n_velocities();
    std::vector<double>                          f(dim * (1 + prm.rigid_plates.size()), 0.0);
    std::vector<dealii::types::global_dof_index> seen; // a node of two conditions counts once
    for (const auto &p : prescribed_dofs)
      {
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || pins.is_constrained(i) || free_prescribed.is_constrained(i) ||
            std::find(seen.begin(), seen.end(), i) != seen.end())
          continue;
        seen.push_back(i);
        const unsigned int slot = p.condition < n_vel ? 0 : 1 + p.condition - n_vel;
        f[slot * dim + p.component] += residual(i);
      }
    dealii::Utilities::MPI::sum(f, comm, f);
    for (unsigned int d = 0; d < dim; ++d)
      last.prescribed_force[d] = f[d];
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        plate_reaction[k][d] = f[(1 + k) * dim + d];
    residual = kept;
  }

  namespace
  {
    /// A singular tangent (a body free to move as a rigid body in a static
    /// analysis, a point set cut loose) gives a direct solve without error but
    /// a solution that does not solve the system: a failed step.
    void
    require_solved(const LinearSolveInfo &info)
    {
      if (!(info.relative_residual <= 1e-6))
        {
          std::ostringstream os;
          os << "the linear system is singular or nearly so (|b - A x| / |b| = " << info.relative_residual
             << " after the " << info.method
             << " solve): are rigid-body motions of every body prevented by boundary conditions?";
          throw NewtonFailure(os.str());
        }
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta()
  {
    return solve_for_delta(residual);
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta(const Vector &r)
  {
    const auto start = Clock::now();
    Vector     rhs(r);
    rhs *= -1.0;
    delta = 0;
    LinearSolveInfo info;
    try
      {
        info = solve_linear(tangent, delta, rhs, prm.linear, space.constant_modes());
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    ++n_solves;
    require_solved(info);
    return info;
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_several(std::vector<Vector> &r)
  {
    // iterative methods: one solve_for_delta per right-hand side
    if (prm.linear.method != LinearSolverOptions::Method::direct)
      {
        LinearSolveInfo info;
        for (auto &x : r)
          {
            // a zero right-hand side (the first iteration of a step whose only
            // load is a plate's force: the free rows are in balance) has the
            // solution 0; a Krylov solver would stop with a breakdown on it
            if (x.linfty_norm() == 0)
              continue;
            const auto one = solve_for_delta(x);
            info.method    = one.method;
            info.iterations += one.iterations;
            info.relative_residual = std::max(info.relative_residual, one.relative_residual);
            x                      = delta;
          }
        return info;
      }
    // direct: one factorisation for all of them (solvers/linear_solver.h)
    const auto      start = Clock::now();
    LinearSolveInfo info;
    try
      {
        std::vector<Vector> b(r.size()), x;
        for (unsigned int k = 0; k < r.size(); ++k)
          {
            b[k].reinit(r[k], true);
            b[k] = r[k];
            b[k] *= -1.0;
          }
        info = solve_direct(tangent, x, b, prm.linear.direct_package);
        for (unsigned int k = 0; k < r.size(); ++k)
          r[k].copy_locally_owned_data_from(x[k]);
        info.method = "direct (" + prm.linear.direct_package + ", one factorisation for " + std::to_string(r.size()) +
                      " right-hand sides)";
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    n_solves += r.size();
    require_solved(info);
    return info;
  }

  template <int dim>
  void
  Solver<dim>::predict_prescribed(const double h, const dealii::Tensor<1, dim> &g)
  {
    // The first iterate of a step with prescribed DoFs: one linear solve at
    // Du = 0 with the prescribed increments as inhomogeneous constraints (the
    // lifting: rhs_F = -r_F - K_FP Du_P), so the free nodes follow the
    // prescribed ones at once instead of a cell next to them being crushed by
    // a predictor that moves only the prescribed nodes. The assembly moves
    // -A_ij g_j to the vector it builds, which here is the residual, whose
    // negative is the right-hand side: hence g = -Du_P.
    std::vector<double> minus_increment(prescribed_dofs.size());
    for (std::size_t k = 0; k < prescribed_dofs.size(); ++k)
      minus_increment[k] = -prescribed_increment(prescribed_dofs[k], h);
    // a force plate's DoFs are held here (Newton moves them as one from this iterate on)
    auto lifted = step_constraints(&minus_increment, true, true, true);
    std::swap(constraints, lifted);
    plates_held = true;
    try
      {
        // the out-of-balance force the prescribed increment creates: the scale
        // Newton's residual test measures against (after this solve the
        // residual is small, so its own first value is no scale)
        lifted_residual = assemble(true, g);
        solve_for_delta();
      }
    catch (...)
      {
        std::swap(constraints, lifted);
        plates_held = false;
        throw;
      }
    std::swap(constraints, lifted);
    plates_held = false;
    for (const auto &dofs : plate_owned)
      for (const auto i : dofs)
        delta[i] = 0.0;

    // Du: the solve's free values, the prescribed increments at the prescribed
    // DoFs of active nodes, 0 at the other constrained DoFs
    constraints.set_zero(delta);
    const auto         &pins       = active.constraints(); // inactive nodes: no mass, pinned to 0
    const auto         &owned      = space.locally_owned_dofs();
    const auto         &velocities = prm.stages[current_stage].velocities;
    std::vector<double> n_active(velocities.size() + prm.rigid_plates.size(), 0.0);
    for (const auto &p : prescribed_dofs)
      {
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || pins.is_constrained(i))
          continue;
        delta[i] = prescribed_increment(p, h);
        n_active[p.condition] += 1;
      }
    delta.compress(dealii::VectorOperation::insert);
    du = delta;
    du.update_ghost_values();
    // the nodes of a condition are fixed in space: once the material has left
    // their cells they carry no mass and the condition acts on nothing; say so
    // (once per condition) instead of letting a displacement control go slack
    dealii::Utilities::MPI::sum(n_active, comm, n_active);
    for (unsigned int k = 0; k < n_active.size(); ++k)
      if (n_active[k] == 0 && !idle_conditions[k] && (k < velocities.size() || !force_plate(k - velocities.size())))
        {
          idle_conditions[k] = 1;
          log() << "  WARNING: "
                << (k < velocities.size() ? velocities[k].where : prm.rigid_plates[k - velocities.size()].where)
                << " reaches no grid node next to material at t = " << time
                << " s (the prescribed nodes are fixed in space and the material has left their cells): "
                << "the condition has no effect from here on" << std::endl;
        }
  }

  template <int dim>
  void
  Solver<dim>::project_to_grid()
  {
    using L                                   = PropertyLayout<dim>;
    std::vector<MaterialPointSet<dim> *> sets = {&points};
    const auto                          &pins = active.constraints(); // inactive DoFs only: walls keep their mass
    mass                                      = 0;
    with_kernel([&](auto k) {
      with_components([&](auto nc) {
        transfer::assemble<dim, decltype(k), decltype(nc)::value>(sets, active, pins, transfer::NodalProjection<dim>{},
                                                                  nullptr, &mass);
      });
    });
    if (!dynamic())
      return;
    v_n = 0;
    a_n = 0;
    // mixed u-p: onto the displacement components of the u-p space (the
    // pressure components get no mass, hence no inertia)
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{L::velocity}, nullptr, &v_n);
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{acceleration_offset}, nullptr,
                                      &a_n);
      });
    });
    for (unsigned int i = 0; i < mass.locally_owned_size(); ++i)
      {
        const double m       = mass.local_element(i);
        v_n.local_element(i) = m > 0 ? v_n.local_element(i) / m : 0.0;
        a_n.local_element(i) = m > 0 ? a_n.local_element(i) / m : 0.0;
      }
  }

  template <int dim>
  void
  Solver<dim>::compute_cell_jbar()
  {
    cell_jbar.assign(grid.tria.n_active_cells(), 1.0);
    transfer::CellMeanJacobian<dim, shape::Q1Box<dim>> mean{grid, space, du, cell_jbar};
    transfer::for_each_active_cell(points, mean);
  }

  template <int dim>
  double
  Solver<dim>::assemble(const bool with_tangent, const dealii::Tensor<1, dim> &g)
  {
    const auto                            start = Clock::now();
    transfer::PointFailure                failure;
    transfer::UpdatedLagrangianForce<dim> force;
    force.materials      = &prm.materials;
    force.history_offset = PropertyLayout<dim>::history;
    force.gravity        = g;
    force.point_forces   = &point_forces;
    force.load_scale     = point_force_scale; // set with g by apply_loads_at
    force.tangent        = with_tangent;
    force.failure        = &failure;
    force.radius_offset  = radius_offset;
    if (prm.fbar)
      {
        compute_cell_jbar();
        force.jbar = &cell_jbar;
      }
    residual = 0;
    if (with_tangent)
      tangent = 0;
    if (prm.mixed_up)
      {
        transfer::MixedUpForce<dim> up;
        up.models         = &split_models;
        up.history_offset = force.history_offset;
        up.gravity        = g;
        up.point_forces   = &point_forces;
        up.load_scale     = force.load_scale;
        up.alpha          = prm.stabilisation;
        up.tangent        = with_tangent;
        up.failure        = &failure;
        with_kernel([&](auto k) {
          transfer::assemble<dim, decltype(k), dim + 1>({&points}, active, constraints, up,
                                                        with_tangent ? &tangent : nullptr, &residual, &du);
        });
      }
    else
      with_kernel([&](auto k) {
        transfer::assemble<dim, decltype(k), dim>({&points}, active, constraints, force,
                                                  with_tangent ? &tangent : nullptr, &residual, &du);
      });
    const bool any_failed = dealii::Utilities::MPI::max(failure.failed ? 1 : 0, comm) > 0;
    if (any_failed)
      throw NewtonFailure(failure.failed ? failure.what : "a material point on another rank failed");
    if (assembling_damping)
      return 0.0;
    if (dynamic() && prm.rayleigh_beta > 0)
      {
        // stiffness-proportional damping: r += beta_R K_n v^{n+1}(du) on the free DoFs and
        // tangent += beta_R gamma/(beta h) K_n (K_n held for the step: the tangent is exact)
        Vector v, Kv;
        space.reinit_vector(v);
        space.reinit_vector(Kv);
        const auto &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          v.local_element(k) = constraints.is_constrained(owned.nth_index_in_set(k))
                                 ? 0.0
                                 : newmark.velocity(du.local_element(k), v_n.local_element(k), a_n.local_element(k));
        damping_stiffness.vmult(Kv, v);
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          if (!constraints.is_constrained(owned.nth_index_in_set(k)))
            residual.local_element(k) += prm.rayleigh_beta * Kv.local_element(k);
        if (with_tangent)
          tangent.add(prm.rayleigh_beta * newmark.damping_coefficient(), damping_stiffness);
      }
    if (point_contact) // the penalty walls on the points (point_contact.h)
      point_contact->assemble(points, active, constraints, du, with_tangent ? &tangent : nullptr, residual);
    if (dynamic() && prm.consistent_mass)
      add_consistent_inertia(with_tangent);
    else if (dynamic())
      {
        // lumped inertia and mass-proportional damping at the nodes:
        // r_i += m_i (a_i + alpha v_i), tangent_ii += m_i (1/(beta h^2) + alpha gamma/(beta h))
        const double coef  = newmark.tangent_factors(prm.rayleigh_alpha, 0).mass;
        const auto  &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
          {
            const auto   i = owned.nth_index_in_set(k);
            const double m = mass.local_element(k);
            if (m == 0 || constraints.is_constrained(i))
              continue;
            const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
            residual.local_element(k) +=
              m * (newmark.acceleration(u, v, a) + prm.rayleigh_alpha * newmark.velocity(u, v, a));
            if (with_tangent)
              tangent.add(i, i, m * coef);
          }
        if (with_tangent)
          tangent.compress(dealii::VectorOperation::add);
      }
    seconds_assembly += seconds_since(start);
    ++n_assemblies;
    if (!any_force_plate() || plates_held)
      return residual.l2_norm();
    // force plates: their DoFs' equations are the plates' balances, one per
    // plate: sum_{i in P_k} r_i = F_k (the force the plate exerts on the
    // material). The sums are kept and the rows zeroed (the solve's right-hand
    // side there is 0); the norm Newton tests is that of the free rows and the
    // plates' out-of-balance forces.
    const unsigned int  n = prm.rigid_plates.size();
    std::vector<double> sums(n, 0.0);
    for (unsigned int k = 0; k < n; ++k)
      for (const auto i : plate_owned[k])
        {
          sums[k] += residual(i);
          residual(i) = 0.0;
        }
    dealii::Utilities::MPI::sum(sums, comm, sums);
    double norm2 = residual.norm_sqr();
    for (unsigned int k = 0; k < n; ++k)
      if (force_plate(k))
        {
          plate_sum[k] = sums[k];
          norm2 += (sums[k] - plate_target[k]) * (sums[k] - plate_target[k]);
        }
    return std::sqrt(norm2);
  }

  namespace
  {
    /// Zero the rows and columns of the global DoFs `dofs` (sorted, the same
    /// list on every rank) of a filled Trilinos matrix, keeping each row's
    /// diagonal: the matrix of the system with those DoFs prescribed
    /// (symmetric if A is). In place on Epetra's values (the pattern is kept).
    void
    zero_rows_and_columns(dealii::TrilinosWrappers::SparseMatrix             &A,
                          const std::vector<dealii::types::global_dof_index> &dofs)
    {
      auto                      &E    = const_cast<Epetra_CrsMatrix &>(A.trilinos_matrix());
      const Epetra_Map          &rows = E.RowMap(), &cols = E.ColMap();
      std::vector<unsigned char> col_hit(E.NumMyCols(), 0);
      for (const auto g : dofs)
        {
          const int l = cols.LID(static_cast<int>(g));
          if (l >= 0)
            col_hit[l] = 1;
        }
      for (int r = 0; r < E.NumMyRows(); ++r)
        {
          int     n       = 0;
          double *values  = nullptr;
          int    *indices = nullptr;
          E.ExtractMyRowView(r, n, values, indices);
          const int  gid = rows.GID(r);
          const bool hit = std::binary_search(dofs.begin(), dofs.end(), dealii::types::global_dof_index(gid));
          for (int j = 0; j < n; ++j)
            if ((hit && cols.GID(indices[j]) != gid) || (!hit && col_hit[indices[j]]))
              values[j] = 0.0;
        }
      // values changed behind Epetra's back: drop its cached norms
      E.SumIntoMyValues(0, 0, nullptr, nullptr);
    }

    /// Solve the small dense system M c = b (n x n, row-major) by Gaussian
    /// elimination with partial pivoting; the same arithmetic on every rank.
    std::vector<double>
    solve_dense(std::vector<double> M, std::vector<double> b)
    {
      const unsigned int n = b.size();
      for (unsigned int k = 0; k < n; ++k)
        {
          unsigned int p = k;
          for (unsigned int i = k + 1; i < n; ++i)
            if (std::abs(M[i * n + k]) > std::abs(M[p * n + k]))
              p = i;
          for (unsigned int j = 0; j < n; ++j)
            std::swap(M[k * n + j], M[p * n + j]);
          std::swap(b[k], b[p]);
          for (unsigned int i = k + 1; i < n; ++i)
            {
              const double f = M[i * n + k] / M[k * n + k];
              for (unsigned int j = k; j < n; ++j)
                M[i * n + j] -= f * M[k * n + j];
              b[i] -= f * b[k];
            }
        }
      std::vector<double> c(n, 0.0);
      for (unsigned int k = n; k-- > 0;)
        {
          double s = b[k];
          for (unsigned int j = k + 1; j < n; ++j)
            s -= M[k * n + j] * c[j];
          c[k] = s / M[k * n + k];
        }
      return c;
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_with_plates()
  {
    // The plates' DoFs condensed by superposition (docs/implicit.md, "Rigid
    // plate"): exact, the same solution as a master-slave line u_i = u_m per
    // plate node, without couplings of the master in the sparsity or the
    // master as a ghost on every rank.
    const auto                start = Clock::now();
    const unsigned int        n_all = prm.rigid_plates.size();
    std::vector<unsigned int> ks; // the force plates
    for (unsigned int k = 0; k < n_all; ++k)
      if (force_plate(k))
        ks.push_back(k);
    const unsigned int  n = ks.size();
    std::vector<Vector> e(n), v(n), w(n), z(n);
    std::vector<double> size(n, 0.0);
    for (unsigned int a = 0; a < n; ++a)
      {
        for (Vector *x : {&e[a], &v[a], &w[a], &z[a]})
          space.reinit_vector(*x);
        for (const auto i : plate_owned[ks[a]])
          e[a][i] = 1.0;
        size[a] = plate_owned[ks[a]].size();
        tangent.vmult(v[a], e[a]);  // K e: the plate's column sum (K_FP 1 in the free rows)
        tangent.Tvmult(w[a], e[a]); // K^T e: its row sum, sum_{i in P} K_ij
      }
    dealii::Utilities::MPI::sum(size, comm, size);
    zero_rows_and_columns(tangent, plate_all);
    const auto zero_plate_entries = [&](Vector &x) {
      for (const auto &dofs : plate_owned)
        for (const auto i : dofs)
          x[i] = 0.0;
    };
    // z_0 (the plates held) and z_a (the response to a unit displacement of
    // plate a), from one factorisation with the direct solver
    std::vector<Vector> x(1 + n);
    x[0] = residual; // its plate rows are 0 (assemble)
    for (unsigned int a = 0; a < n; ++a)
      {
        x[1 + a] = v[a];
        zero_plate_entries(x[1 + a]);
      }
    seconds_plates += seconds_since(start);
    const auto      start_solve = Clock::now();
    LinearSolveInfo info        = solve_several(x);
    const double    t_solve     = seconds_since(start_solve);
    const auto      start2      = Clock::now();
    Vector          z0(x[0]);
    zero_plate_entries(z0);
    for (unsigned int a = 0; a < n; ++a)
      {
        z[a] = x[1 + a];
        zero_plate_entries(z[a]);
      }
    seconds_plates_solve += t_solve;
    // the linearised balance of plate a: sum_{i in P_a} (r + K delta)_i = F_a,
    // delta = z_0 + sum_b c_b (z_b + e_b): sum_b (w_a . z_b + e_a . v_b) c_b = F_a - R_a - w_a . z_0
    std::vector<double> M(n * n), b(n);
    for (unsigned int a = 0; a < n; ++a)
      {
        const auto k = ks[a];
        if (size[a] == 0)
          {
            // the plate acts on no free node next to material: its force has
            // nothing to act on (said once), its increment is 0
            for (unsigned int c = 0; c < n; ++c)
              M[a * n + c] = c == a ? 1.0 : 0.0;
            b[a] = 0;
            if (!idle_plates[k])
              {
                idle_plates[k] = 1;
                log() << "  WARNING: " << prm.rigid_plates[k].where
                      << " reaches no free grid node next to material at t = " << time
                      << " s: its force acts on nothing from here on" << std::endl;
              }
            continue;
          }
        for (unsigned int c = 0; c < n; ++c)
          M[a * n + c] = (w[a] * z[c]) + (e[a] * v[c]);
        b[a] = plate_target[k] - plate_sum[k] - (w[a] * z0);
      }
    const std::vector<double> c = solve_dense(M, b);
    delta                       = z0;
    for (unsigned int a = 0; a < n; ++a)
      {
        delta.add(c[a], z[a]);
        plate_c[ks[a]] = c[a];
        for (const auto i : plate_owned[ks[a]])
          delta[i] = c[a]; // exactly c: the plate's nodes move as one
      }
    seconds_plates += seconds_since(start2);
    return info;
  }

  template <int dim>
  void
  Solver<dim>::add_consistent_inertia(const bool with_tangent)
  {
    // The inertia and damping with the consistent mass: r += M (a + alpha_R v),
    // tangent += (1/(beta h^2) + alpha_R gamma/(beta h)) M. As with the lumped
    // mass, only the free DoFs carry inertia: w = 0 at every DoF constrained in
    // this assembly (walls, held contact nodes, prescribed and inactive nodes),
    // so a constrained node neither feels nor exerts an inertial force.
    const auto  &owned = space.locally_owned_dofs();
    const double alpha = prm.rayleigh_alpha;
    for (unsigned int k = 0; k < inertia_field.locally_owned_size(); ++k)
      {
        const auto i = owned.nth_index_in_set(k);
        if (mass.local_element(k) == 0 || constraints.is_constrained(i))
          {
            inertia_field.local_element(k) = 0.0;
            continue;
          }
        const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
        inertia_field.local_element(k) = newmark.acceleration(u, v, a) + alpha * newmark.velocity(u, v, a);
      }
    inertia_field.update_ghost_values();
    const double coef = newmark.tangent_factors(alpha, 0).mass;
    // The matrix and the vector go through the constraints in one call unless
    // the constraints are inhomogeneous (the lifted predictor of prescribed
    // nodes): there the combined call would move -coef M_ij g_j to the residual,
    // an inertia of the prescribed nodes that the residual (w = 0 there) does not have.
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        if (with_tangent && !constraints.has_inhomogeneities())
          transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, true>{coef},
                                        &tangent, &residual, &inertia_field);
        else
          {
            if (with_tangent)
              transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, false>{coef},
                                            &tangent, nullptr);
            transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, false, true>{coef},
                                          nullptr, &residual, &inertia_field);
          }
      });
    });
  }

  template <int dim>
  void
  Solver<dim>::predict_pressure()
  {
    // Eq. 5.20: p_i = sum_p N_i m_p p_p / sum_p N_i m_p (residual and delta as scratch)
    const auto &pins = active.constraints();
    residual         = 0;
    delta            = 0;
    with_kernel([&](auto k) {
      using K = decltype(k);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, true}, nullptr, &residual);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, false}, nullptr, &delta);
    });
    for (unsigned int k = 0; k < du.locally_owned_size(); ++k)
      if (space.component(k) == dim && delta.local_element(k) > 0)
        du.local_element(k) = residual.local_element(k) / delta.local_element(k);
    du.update_ghost_values();
    delta = 0;
  }

  template <int dim>
  void
  Solver<dim>::nodal_acceleration(Vector &a) const
  {
    for (unsigned int k = 0; k < a.locally_owned_size(); ++k)
      a.local_element(k) = mass.local_element(k) > 0
                             ? newmark.acceleration(du.local_element(k), v_n.local_element(k), a_n.local_element(k))
                             : 0.0;
    a.update_ghost_values();
  }

  template <int dim>
  void
  Solver<dim>::assemble_damping_stiffness(const dealii::Tensor<1, dim> &g)
  {
    const Vector saved(du);
    du = 0;
    du.update_ghost_values();
    assembling_damping = true;
    try
      {
        assemble(true, g);
      }
    catch (...)
      {
        assembling_damping = false;
        throw;
      }
    assembling_damping = false;
    damping_stiffness.copy_from(tangent);
    du = saved;
    du.update_ghost_values();
  }

  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    newmark.set_time_step(h);
    if (point_contact) // a footing's base to where it is at the step's start and end
      point_contact->set_time(time, time + h);
    prepare_step();
    const dealii::Tensor<1, dim> g = apply_loads_at(time + h);
    if (dynamic() && prm.rayleigh_beta > 0)
      assemble_damping_stiffness(g);
    // the external force scale |f_ext| (lumped nodal masses times g)
    double f2 = 0;
    for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
      {
        const unsigned int c = space.component(k);
        if (c < dim)
          f2 += std::pow(mass.local_element(k) * g[c], 2);
      }
    double f_ext = std::sqrt(dealii::Utilities::MPI::sum(f2, comm));
    if (point_forces.any())
      {
        // the scale of gravity plus tractions: |sum_p N_i (m_p g + lambda f_p)|
        transfer::ExternalForce<dim> load{g, &point_forces, point_force_scale};
        residual = 0;
        with_kernel([&](auto k) {
          with_components([&](auto nc) {
            transfer::assemble<dim, decltype(k), decltype(nc)::value>({&points}, active, active.constraints(), load,
                                                                      nullptr, &residual);
          });
        });
        f_ext = residual.l2_norm();
      }
    // the plates' forces at t + h (their own time functions) join the scale
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        plate_target[k] = force_plate(k) ? prm.rigid_plates[k].force_at(time + h) : 0.0;
        plate_step[k]   = 0.0;
        plate_c[k]      = 0.0;
        f_ext           = std::sqrt(f_ext * f_ext + plate_target[k] * plate_target[k]);
      }

    du = 0;
    du.update_ghost_values();
    lifted_residual = 0;
    // collective: the predictor assembles and solves on every rank, also on a
    // rank none of whose nodes is prescribed (else the ranks part ways and the
    // run hangs in the next collective)
    if (dealii::Utilities::MPI::logical_or(!prescribed_dofs.empty(), comm))
      {
        try
          {
            predict_prescribed(h, g);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the prescribed-displacement predictor failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
      }
    if (prm.mixed_up)
      predict_pressure();
    unsigned int  linear_iterations     = 0;
    double        worst_linear_residual = 0;
    NewtonProblem problem;
    problem.assemble = [&](const bool with_tangent) { return assemble(with_tangent, g); };
    problem.solve    = [&]() {
      const LinearSolveInfo info = any_force_plate() ? solve_with_plates() : solve_for_delta();
      linear_iterations += info.iterations;
      worst_linear_residual = std::max(worst_linear_residual, info.relative_residual);
      constraints.set_zero(delta);
      delta.update_ghost_values();
      return delta.l2_norm();
    };
    problem.apply = [&](const double alpha) {
      du.add(alpha, delta);
      du.update_ghost_values();
      for (unsigned int k = 0; k < plate_step.size(); ++k)
        plate_step[k] += alpha * plate_c[k];
    };
    problem.step_increment_norm = [&]() { return du.l2_norm(); };
    problem.residual_reference  = [&]() { return std::max(f_ext, lifted_residual); };
    // Newton, then (contact walls) the active set from the converged state's
    // reactions and penetrations; a change re-solves from there
    NewtonResult       result;
    unsigned int       iterations = 0, passes = 0, released = 0, added = 0;
    std::ostringstream pass_log;
    const bool         any_contact = dealii::Utilities::MPI::sum(contact_nodes.size(), comm) > 0;
    for (;;)
      {
        result = NewtonSolver(prm.newton).solve(problem);
        iterations += result.iterations;
        ++passes;
        if (!result.converged || !any_contact)
          break;
        std::pair<unsigned int, unsigned int> changed;
        try
          {
            changed = update_contact(g, f_ext);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the contact reactions failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
        released += changed.first;
        added += changed.second;
        if (changed.first + changed.second == 0)
          break;
        pass_log << " [pass " << passes << ": " << changed.first << " released, " << changed.second << " in contact]";
        if (passes >= prm.contact_passes)
          {
            // the last solution keeps the previous set; the new one starts the next step
            log() << "  WARNING: step " << step_number + 1 << " (t = " << time + h
                  << "): the contact active set still changed after " << passes
                  << " passes (contact passes); the step keeps the last solve" << std::endl;
            break;
          }
        constraints = step_constraints();
        if (any_force_plate())
          find_plate_dofs();
        constraints.set_zero(du);
        du.update_ghost_values();
      }
    result.iterations = iterations;

    last                   = StepReport();
    last.iterations        = result.iterations;
    last.contact_passes    = passes;
    last.contact_released  = released;
    last.contact_added     = added;
    last.linear_iterations = linear_iterations;
    last.observed_order    = result.observed_order;
    {
      // the order seen in the increments |du_k| (the error of iterate k-1): the
      // residual norm of a stiff structure mixes stiff and soft modes and hits
      // its round-off floor first (docs/implicit.md); increments at round-off
      // level (below 1e-13 |Du|) are left out
      std::vector<double> inc;
      for (unsigned int k = 1; k < result.history.size(); ++k)
        if (result.history[k].increment > 1e-13 * du.l2_norm())
          inc.push_back(result.history[k].increment);
      last.increment_order = observed_order(inc);
    }
    if (!result.history.empty())
      {
        last.residual_first = result.history.front().residual;
        last.residual_last  = result.history.back().residual;
      }
    std::ostringstream hist;
    hist << std::setprecision(3);
    for (unsigned int k = 0; k < result.history.size(); ++k)
      hist << (k ? " " : "") << result.history[k].residual;
    hist << "; |du|";
    for (unsigned int k = 1; k < result.history.size(); ++k)
      hist << " " << result.history[k].increment;
    last.history = hist.str();
    total_iterations += result.iterations;
    total_linear_iterations += linear_iterations;
    total_contact_passes += passes;
    total_contact_released += released;
    total_contact_added += added;
    if (any_contact)
      {
        unsigned int n = 0;
        for (const auto &c : contact_nodes)
          {
            const auto in = space.node_dof(c.node, c.axis);
            if (space.locally_owned_dofs().is_element(in) && contact_state(in) != 0.0 && mass(in) > 0 &&
                !active.constraints().is_constrained(in))
              ++n;
          }
        last.contact_nodes = dealii::Utilities::MPI::sum(n, comm);
      }
    if (!result.converged)
      {
        log() << "  step " << step_number + 1 << " (t = " << time + h << "): Newton " << to_string(result.status)
              << " after " << result.iterations << " iterations (|r|: " << last.history << "); " << result.message
              << std::endl;
        return StepOutcome::cut_back;
      }

    if (any_velocity_condition() || any_plate_reaction()) // collective: the same on every rank
      {
        try
          {
            prescribed_reaction(g);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the reactions of the prescribed nodes failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
      }
    for (unsigned int k = 0; k < region_shift.size(); ++k)
      region_shift[k] += condition_increment(k, h);
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &plate = prm.rigid_plates[k];
        plate_displacement[k] +=
          force_plate(k) ? plate_step[k] : plate.displacement_at(time + h) - plate.displacement_at(time);
      }

    if (point_contact)
      {
        // the stick anchors and contact flags of the converged increment
        last.point_contact = point_contact->commit(points, space, du);
        total_point_contacts += last.point_contact.new_contacts;
        total_point_releases += last.point_contact.released;
        total_point_slip_steps += last.point_contact.slipping;
        worst_penetration_ratio = std::max(worst_penetration_ratio, last.point_contact.max_penetration_ratio);
      }
    // convective phase
    const auto start = Clock::now();
    if (dynamic())
      nodal_acceleration(a_new);
    transfer::PointFailure failure;
    if (prm.fbar)
      compute_cell_jbar(); // of the converged du
    with_kernel([&](auto k) {
      transfer::CommitUpdatedLagrangian<dim, decltype(k)> commit(points, space, du, dynamic() ? &a_new : nullptr,
                                                                 prm.materials, acceleration_offset, h, newmark.gamma(),
                                                                 failure, pressure_offset, radius_offset);
      if (prm.fbar)
        commit.jbar = &cell_jbar;
      transfer::for_each_active_cell(points, commit);
    });
    if (dealii::Utilities::MPI::max(failure.failed ? 1 : 0, comm) > 0)
      throw InstabilityError("the constitutive update of the converged step failed: " +
                             (failure.failed ? failure.what : std::string("on another rank")));
    points.relocate();
    seconds_commit += seconds_since(start);
    log() << "  step " << step_number + 1 << " t = " << std::setprecision(6) << time + h << ": " << result.iterations
          << " Newton iterations, |r| " << last.history << ", order (|r|) " << std::setprecision(3)
          << result.observed_order << ", (|du|) " << last.increment_order << ", " << linear_iterations
          << " linear iterations (largest |b - A x|/|b| " << worst_linear_residual << ")";
    if (point_contact)
      log() << "; contact (points): " << last.point_contact.in_contact << " in contact (" << last.point_contact.slipping
            << " slipping, " << last.point_contact.new_contacts << " new, " << last.point_contact.released
            << " released), normal force " << last.point_contact.normal_force << ", largest penetration / r_p "
            << last.point_contact.max_penetration_ratio;
    if (prm.footing.enabled)
      log() << "; footing force " << last.point_contact.footing_force;
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      log() << "; plate " << k << " displacement " << std::setprecision(8) << plate_displacement[k] << ", force "
            << (force_plate(k) ? plate_sum[k] : plate_reaction[k][prm.rigid_plates[k].axis]) << std::setprecision(6);
    if (any_contact)
      log() << "; contact: " << passes << " pass(es), " << released << " released, " << added << " in contact again, "
            << last.contact_nodes << " nodes in contact" << pass_log.str();
    log() << std::endl;
    return StepOutcome::done;
  }

  template <int dim>
  double
  Solver<dim>::tangent_error(const double h, const double scale, const double eps, const double pressure_scale)
  {
    newmark.set_time_step(h);
    prepare_step();
    const dealii::Tensor<1, dim> g = apply_loads_at(time + h);
    if (dynamic() && prm.rayleigh_beta > 0)
      assemble_damping_stiffness(g);
    const auto &owned = space.locally_owned_dofs();
    Vector      v;
    space.reinit_vector(v);
    for (unsigned int k = 0; k < du.locally_owned_size(); ++k)
      {
        const auto i = owned.nth_index_in_set(k);
        // deterministic, rank-independent values from the global index
        du.local_element(k) =
          (space.component(k) == dim ? pressure_scale : 1.0) * scale * std::sin(1.3 * double(i) + 0.7);
        v.local_element(k) = std::cos(2.1 * double(i) + 0.3);
      }
    constraints.set_zero(du);
    constraints.set_zero(v);
    const Vector u0(du);
    du.update_ghost_values();
    assemble(true, g);
    Vector Kv;
    space.reinit_vector(Kv);
    tangent.vmult(Kv, v);
    Vector r_plus, fd;
    space.reinit_vector(r_plus);
    space.reinit_vector(fd);
    du = u0;
    du.add(eps, v);
    du.update_ghost_values();
    assemble(false, g);
    r_plus = residual;
    du     = u0;
    du.add(-eps, v);
    du.update_ghost_values();
    assemble(false, g);
    fd = r_plus;
    fd.add(-1.0, residual);
    fd *= 1.0 / (2 * eps);
    fd.add(-1.0, Kv);
    constraints.set_zero(fd); // constrained rows hold the matrix's diagonal, not the residual's derivative
    Vector Kv_free(Kv);
    constraints.set_zero(Kv_free);
    du = 0;
    // per block (displacement rows, pressure rows): the pressure rows of u-p
    // are divided by K and are orders of magnitude smaller than the force rows,
    // so one norm over both would hide an error in them
    double sums[4] = {0, 0, 0, 0}; // |error|^2, |Kv|^2 of u rows; of p rows
    for (unsigned int k = 0; k < fd.locally_owned_size(); ++k)
      {
        const unsigned int b = space.component(k) < dim ? 0 : 2;
        sums[b] += fd.local_element(k) * fd.local_element(k);
        sums[b + 1] += Kv_free.local_element(k) * Kv_free.local_element(k);
      }
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums, 4), comm, dealii::ArrayView<double>(sums, 4));
    double error = std::sqrt(sums[0] / sums[1]);
    if (prm.mixed_up)
      error = std::max(error, std::sqrt(sums[2] / sums[3]));
    return error;
  }

  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    // the fields up to the stress (the history may hold infinities)
    const std::string which = diagnostics::find_invalid_point(points, comm, PropertyLayout<dim>::history, false);
    if (!which.empty())
      throw InstabilityError("a material point holds a non-finite value after step " + std::to_string(step_number) +
                             ": " + which);
  }

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    out << "  grid: " << grid.tria.n_global_active_cells() << " cells; " << n_points() << " material points"
        << std::endl;
    out << "  analysis: " << (dynamic() ? "dynamic (Newmark gamma = " : "static (")
        << (dynamic() ? std::to_string(prm.gamma) + ", beta = " + std::to_string(prm.beta) +
                          (prm.consistent_mass ? ", consistent mass" : ", lumped mass") +
                          (prm.rayleigh_alpha > 0 ? ", Rayleigh alpha = " + std::to_string(prm.rayleigh_alpha) : "") +
                          (prm.rayleigh_beta > 0 ? ", Rayleigh beta = " + std::to_string(prm.rayleigh_beta) : "")
                      : std::string(prm.ramp_loads ? "loads ramped over the end time" : "full loads"))
        << "), time step " << dt << std::endl;
    out << "  formulation: "
        << (prm.mixed_up ? std::string(prm.bspline() ? "mixed u-p (equal-order B-splines" : "mixed u-p (Q1-Q1") +
                             ", PPP stabilisation alpha = " + std::to_string(prm.stabilisation) + ")"
                         : std::string("irreducible (displacement)"))
        << (prm.bspline() ? ", quadratic B-splines" : ", linear shape functions")
        << (prm.tractions.empty() ? "" : ", " + std::to_string(prm.tractions.size()) + " traction(s) (dead loads)")
        << (prm.velocities.empty()
              ? ""
              : ", " + std::to_string(prm.velocities.size()) + " prescribed nodal velocity condition(s)")
        << (dim == 3           ? std::string()
            : prm.axisymmetric ? ", axisymmetric (x = radius)"
                               : ", plane strain")
        << std::endl;
    if (!prm.contact_ids.empty())
      {
        out << "  contact walls (unilateral, "
            << (prm.contact_no_slip   ? std::string("no slip")
                : prm.contact_mu == 0 ? std::string("frictionless")
                                      : "Coulomb mu = " + std::to_string(prm.contact_mu))
            << "): boundary";
        for (const auto id : prm.contact_ids)
          out << " " << id;
        if (point_contact)
          out << "; on the material points: penalty k = " << prm.contact_penalty
              << " x M V_p / h^2, point extent V_p^(1/dim)/2" << std::endl;
        else
          out << "; at most " << prm.contact_passes << " active-set passes per step" << std::endl;
      }
    if (prm.footing.enabled)
      {
        const auto &f    = prm.footing;
        const char *ax[] = {"x", "y", "z"};
        out << "  rigid footing on the points: base " << ax[f.axis] << " = " << f.level << " + " << f.velocity
            << " t, span";
        for (unsigned int k = 0; k + 1 < dim; ++k)
          out << " [" << f.lower[k] << ", " << f.upper[k] << "]";
        out << ", " << (std::isinf(f.friction) ? "rough (no slip)" : "smooth") << ", penalty k = " << f.penalty
            << " x M V_p / h^2" << std::endl;
      }
    out << "  Newton: " << to_string(prm.newton.criterion) << " test, residual relative "
        << prm.newton.residual_relative << ", absolute " << prm.newton.residual_absolute << ", at most "
        << prm.newton.max_iterations << " iterations; linear solver "
        << (prm.linear.method == LinearSolverOptions::Method::direct   ? "direct (" + prm.linear.direct_package + ")"
            : prm.linear.method == LinearSolverOptions::Method::cg_amg ? std::string("CG + ML AMG")
                                                                       : std::string("GMRES + ML AMG"))
        << std::endl;
  }

  template <int dim>
  double
  Solver<dim>::begin_stage(const unsigned int k, const bool, const bool resumed)
  {
    current_stage = k;
    if (!resumed) // a restart continues with the checkpointed stage start and step
      {
        stage_start_time = time;
        dt               = prm.stage_time_steps[k];
      }
    enter_stage(k);
    if (!prm.staged)
      return prm.end_time;
    const auto        &st = prm.stages[k];
    std::ostringstream os;
    os << "  stage " << k << " '" << st.name << "': t = " << stage_start_time << " s, duration " << st.duration
       << " s, dt = " << dt << " s, gravity " << st.gravity << ", " << st.boundary_conditions.size()
       << " fixed/roller wall(s)";
    const unsigned int own = st.tractions.size() - st.n_global_tractions;
    if (!st.tractions.empty())
      os << ", " << st.tractions.size() << " traction(s) (" << own << " of this stage)";
    if (!st.velocities.empty())
      os << ", " << st.velocities.size() << " velocity condition(s)";
    log() << os.str() << std::endl;
    return stage_start_time + st.duration;
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    std::vector<std::string> c    = {"newton_iterations", "residual_first",    "residual_last", "newton_order",
                                     "increment_order",   "linear_iterations", "load_factor",   "kinetic_energy"};
    const char              *ax[] = {"x", "y", "z"};
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("centre_of_mass_") + ax[d]);
    if (point_contact)
      for (const char *n : {"contact_points", "contact_slipping", "contact_normal_force", "contact_tangential_force"})
        c.push_back(n);
    if (prm.footing.enabled)
      for (const char *n : {"footing_level", "footing_force", "footing_points_behind"})
        c.push_back(n);
    if (any_velocity_condition())
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(std::string("prescribed_force_") + ax[d]);
    for (const auto &n : loads::rigid_plate_series_columns(prm.rigid_plates))
      c.push_back(n);
    balance.add_series_column(c);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool after_step)
  {
    // kinetic energy and centre of mass (the mass-weighted mean position)
    auto sums = diagnostics::sum_points(points);
    sums.sum_over_ranks(comm);
    const double        ke = sums.kinetic;
    std::vector<double> v  = {0, 0, 0, 0, 0, 0, load_factor(time), ke};
    if (after_step)
      v = {double(last.iterations), last.residual_first,
           last.residual_last,      last.observed_order,
           last.increment_order,    double(last.linear_iterations),
           load_factor(time),       ke};
    for (unsigned int d = 0; d < dim; ++d)
      v.push_back(sums.mass_moment[d] / sums.mass);
    if (point_contact)
      {
        const auto &s = last.point_contact; // zeros before the first step
        const bool  a = after_step;
        for (const double x : {double(s.in_contact), double(s.slipping), s.normal_force, s.tangential_force})
          v.push_back(a ? x : 0.0);
      }
    if (prm.footing.enabled)
      {
        v.push_back(prm.footing.level + prm.footing.velocity * time);
        v.push_back(after_step ? last.point_contact.footing_force : 0.0);
        v.push_back(after_step ? double(last.point_contact.behind_footing) : 0.0);
      }
    if (any_velocity_condition())
      for (unsigned int d = 0; d < dim; ++d)
        v.push_back(after_step ? last.prescribed_force[d] : 0.0);
    // the plates (rigid_plate_series_columns): displacement, the force on the
    // material along the axis (force control: F(t); displacement control: the
    // reaction), the tangential reaction's magnitude (rough)
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &plate = prm.rigid_plates[k];
        v.push_back(plate_displacement[k]);
        v.push_back((force_plate(k) ? plate.force_at(time)
                     : after_step   ? plate_reaction[k][plate.axis]
                                    : 0.0) +
                    0.0); // no -0
        if (plate.rough)
          {
            double t2 = 0;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != plate.axis)
                t2 += plate_reaction[k][d] * plate_reaction[k][d];
            v.push_back(after_step ? std::sqrt(t2) : 0.0);
          }
      }
    balance.add_series_value(v);
    return v;
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    this->write_point_sets(counter);
  }

  // ---------------------------------------------------------------- checkpoints
  // The state between two steps is the points (with their accelerations, Eq.
  // 2.16), the loop's state and the Newton totals of the summary: the grid is
  // rebuilt from the points every step. Same rank count: bitwise continuation.
  namespace
  {
    const char *const checkpoint_format  = "talus-implicit-checkpoint";
    const int         checkpoint_version = 1;
  } // namespace

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    return write_checkpoint_file(
      prm, *this, checkpoint_format, checkpoint_version, scene_signature(prm, points.layout.n_properties()), comm,
      [&](io::H5File &f) {
        f.set_attribute("newton iterations", std::int64_t(total_iterations));
        f.set_attribute("linear iterations", std::int64_t(total_linear_iterations));
        f.set_attribute("cut-backs", std::int64_t(cut_backs));
        for (unsigned int k = 0; k < plate_displacement.size(); ++k)
          {
            // the plate's state, and its last reaction for the series
            f.set_attribute("plate " + std::to_string(k) + " displacement", plate_displacement[k]);
            for (unsigned int d = 0; d < dim; ++d)
              f.set_attribute("plate " + std::to_string(k) + " reaction " + std::to_string(d), plate_reaction[k][d]);
          }
        write_points(f, points);
        write_pvd_times(f, "output/pvd", pvd_records);
        balance.write(f); // the partition of the last rebalance
      });
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    this->rewrite_point_set_records();
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto fp = open_checkpoint_to_restore(prm, *this, checkpoint_format, checkpoint_version,
                                               scene_signature(prm, points.layout.n_properties()), comm);
    if (!fp)
      return false;
    total_iterations        = fp->get_int("newton iterations");
    total_linear_iterations = fp->get_int("linear iterations");
    cut_backs               = fp->get_int("cut-backs");
    for (unsigned int k = 0; k < plate_displacement.size(); ++k)
      {
        plate_displacement[k] = fp->get_double("plate " + std::to_string(k) + " displacement");
        for (unsigned int d = 0; d < dim; ++d)
          plate_reaction[k][d] = fp->get_double("plate " + std::to_string(k) + " reaction " + std::to_string(d));
      }
    balance.restore(*fp); // same ranks: the saved partition, before the points go in
    read_points(*fp, points, grid, "checkpoint " + fp->path());
    pvd_records = read_pvd_records(*fp, "output/pvd", "particles");
    return true;
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &)
  {
    if (prm.final_particles_csv)
      write_final_points_csv(points, prm.output_directory, comm);
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &t)
  {
    log() << "done: " << step_number << " steps, " << n_points() << " particles, wall " << std::setprecision(4)
          << t.total << " s; Newton iterations " << total_iterations << " (cut-backs " << cut_backs
          << "), linear iterations " << total_linear_iterations << balance.summary() << std::endl;
    if (point_contact)
      log() << "  contact on the points (walls, footing): " << total_point_contacts << " points came into contact, "
            << total_point_releases << " left it, " << total_point_slip_steps
            << " point-steps slipping; largest penetration / r_p " << worst_penetration_ratio << std::endl;
    else if (!prm.contact_ids.empty())
      log() << "  contact walls: " << total_contact_passes << " Newton solves (active-set passes), "
            << total_contact_released << " node releases, " << total_contact_added << " nodes put in contact, "
            << gap_releases << " nodes released because the material left the wall" << std::endl;
    log() << "  breakdown [s]: assembly " << seconds_assembly << " (" << n_assemblies << "), linear solve "
          << seconds_solve << " (" << n_solves << "), convective phase " << seconds_commit << ", output " << t.output
          << std::endl;
    if (any_force_plate())
      log() << "  rigid plates: the Newton solves " << seconds_plates_solve
            << " s (1 + number of force plates right-hand sides each, within the linear solve above), the products "
               "K e, K^T e, the row and column zeroing and the combination "
            << seconds_plates << " s" << std::endl;
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  template class Solver<2>;
  template class Solver<3>;
} // namespace talus::implicit_mpm
