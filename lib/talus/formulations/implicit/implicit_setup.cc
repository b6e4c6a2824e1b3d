// talus — the implicit Solver's set-up (implicit_solver.h): the point layout,
// the seeding and the axisymmetric ring measure, what lives on the grid's
// partition (grid_changed), the stages (entry, walls, prescribed nodes, the
// loads at a time), the rigid plates' DoFs and checks, the run's description
// and the tool's run(). The Solver is instantiated here.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/rigid_plate_nodes.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace talus::implicit_mpm
{
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
        probes.select(points, prm.probes, comm); // the nearest points at t = 0
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
      ring_measure();
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap,
                      &contact_friction})
      space.reinit_vector(*v);
    reset_contact_state(); // all in contact; a restart: the saved state

    // load balancing: partition by points from the start (a restart on as many
    // ranks has recreated its saved partition instead)
    balance.initial();
  }

  template <int dim>
  void
  Solver<dim>::ring_measure()
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
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(totals, 2), comm, dealii::ArrayView<double>(totals, 2));
    log() << "  axisymmetric: points carry their rings (2 pi r x area): volume " << totals[0] << " m^3, mass "
          << totals[1] << " kg" << std::endl;
    if (prm.grid_lower[0] == 0)
      for (const auto &bc : prm.boundary_conditions)
        if (bc.id == 0)
          log() << "  axisymmetric: the x-min wall is the axis, u_r = 0 there ("
                << (bc.kind == BoundaryCondition::Kind::roller ? "roller" : "fixed") << ")" << std::endl;
  }

  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    space.setup();
    held_last_step.clear(); // numbered on the old partition
    if (current_stage < prm.stages.size())
      stage_nodes(current_stage);
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap,
                      &contact_friction})
      space.reinit_vector(*v);
    reset_contact_state(); // (load balancing is refused with contact walls on the nodes)
    points.collect_active_cells();
  }

  template <int dim>
  double
  Solver<dim>::load_factor(const double t) const
  {
    if (dynamic())
      return 1.0;
    if (!prm.ramp_loads)
      return load_level;
    if (!prm.staged)
      return std::min(1.0, t / prm.end_time);
    return std::min(1.0, (t - stage_start_time) / prm.stages[current_stage].duration);
  }

  template <int dim>
  double
  Solver<dim>::step_load_level(const double h) const
  {
    if (dynamic() || prm.ramp_loads)
      return load_factor(time + h);
    const double stage_end = prm.staged ? stage_start_time + prm.stages[current_stage].duration : prm.end_time;
    const double full_step = std::min(dt, stage_end - time);
    if (h >= full_step * (1 - 1e-12))
      return 1.0;
    return load_level + (1.0 - load_level) * h / full_step;
  }

  template <int dim>
  bool
  Solver<dim>::cut_back_replays() const
  {
    if (dynamic() || prm.ramp_loads || load_level < 1.0 || any_velocity_condition() || !prm.rigid_plates.empty() ||
        prm.footing.enabled || point_contact)
      return false;
    for (const auto &t : prm.tractions)
      if (t.function.settle_time() > time)
        return false;
    return true;
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::apply_loads_at(const double t, const double r)
  {
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
  double
  Solver<dim>::begin_stage(const unsigned int k, const bool, const bool resumed)
  {
    current_stage = k;
    if (!resumed) // a restart continues with the checkpointed stage start and step
      {
        stage_start_time = time;
        dt               = prm.stage_time_steps[k];
        load_level       = 0; // constant loads: the stage's load still to apply
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
    if (prm.ghost_penalty > 0)
      out << "  ghost penalty: gamma = " << prm.ghost_penalty
          << " on the faces of cells at the edge of the material (the largest constrained modulus as E)" << std::endl;
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
        << (prm.linear.method == LinearSolverOptions::Method::direct      ? "direct (" + prm.linear.direct_package + ")"
            : prm.linear.method == LinearSolverOptions::Method::cg_amg    ? std::string("CG + ML AMG")
            : prm.linear.method == LinearSolverOptions::Method::gmres_amg ? std::string("GMRES + ML AMG")
                                                                          : std::string("GMRES + block AMG (u-p)"))
        << std::endl;
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  // the members defined in implicit_constraints.cc, implicit_assembly.cc,
  // implicit_step.cc and implicit_output.cc are instantiated there
  template class Solver<2>;
  template class Solver<3>;
} // namespace talus::implicit_mpm
