// talus — the semi-implicit Solver's set-up (semi_implicit_solver.h): the grid
// and what lives on its partition, the layouts of both point sets, the rigid
// plates' checks, the seeding and the geostatic state, the checkpoints, the
// run's description and the tool's run(). The Solver is instantiated here.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/semi_implicit/semi_implicit_solver.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/rigid_plate.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/materials/material.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

namespace talus::semi_implicit
{
  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    pspace.setup();
    soil_stencils.clear(); // their DoF indices are of the old partition
    water_stencils.clear();
    constrained = loads::wall_dof_flags(grid, prm.boundary_conditions);

    // node and component of every local grid DoF (from the cells' vertex DoFs)
    const unsigned int nl = n_local();
    node_of.assign(nl, 0);
    component.assign(nl, 0);
    node_x.assign(nl, dealii::Point<dim>());
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cell_iterator(c) != grid.tria.end()) // artificial cells carry no DoFs (their cache is zero)
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              const auto        &cc = grid.cells[c];
              const unsigned int i  = cc.dofs[v * dim + d];
              if (i < nl)
                {
                  node_of[i]   = cc.dofs[v * dim];
                  component[i] = d;
                  for (unsigned int e = 0; e < dim; ++e) // vertex v: bit e set = upper side in direction e
                    node_x[i][e] = cc.lower[e] + ((v >> e) & 1u) * cc.h[e];
                }
            }
    // rigid plates: the axis DoFs they move (a wall keeps what it holds), the
    // tangential DoFs of a rough plate held at zero for both phases (as a
    // wall), p = 0 at a permeable plate's nodes (with the drained faces below)
    plate_of.assign(nl, no_plate);
    plate_tangential_of.assign(nl, no_plate);
    std::vector<unsigned char> plate_drained(nl, 0);
    plate_sealed.assign(nl, 0);
    plate_node_of.assign(nl, no_plate);
    for (const auto &e : loads::rigid_plate_node_dofs(grid, prm.rigid_plates, false))
      {
        const auto &pl        = prm.rigid_plates[e.condition];
        plate_node_of[e.node] = e.condition;
        if (pl.permeable)
          plate_drained[e.node] = 1;
        else
          plate_sealed[e.node] = 1;
        if (constrained[e.dof] && plate_tangential_of[e.dof] == no_plate)
          continue; // a fixed/roller wall holds this component: it keeps it
        if (e.component == pl.axis)
          {
            if (plate_of[e.dof] == no_plate) // a DoF of two plates: refused by check_plates
              plate_of[e.dof] = e.condition;
          }
        else
          {
            plate_tangential_of[e.dof] = e.condition;
            constrained[e.dof]         = 1;
          }
      }
    // drained faces: the drainage conditions' node flags and
    // the water's wall hold freed at a draining boundary (boundary_loads.cc);
    // drained[]: the permeable plates' nodes (p = 0)
    water_constrained = constrained;
    drained.assign(nl, 0);
    for (unsigned int i = 0; i < nl; ++i)
      if (plate_drained[i])
        drained[i] = 1;
    bloads.grid_changed(node_of, component, node_x, water_constrained);
    patches.reinit(prm.grid_lower, prm.grid_upper, prm.grid_cells, prm.patch_size);
    for (Vector *v :
         {&Mdj,    &Mjt,    &Ms,     &Ps,      &Mn,     &Mk,     &Fs,      &Ww,   &Pw0,     &Ww0,     &Mwp,
          &Mw,     &Gpw,    &Gps,    &Mwg,     &n_node, &Q_node, &Mw_node, &vs_t, &vw_t,    &vs_star, &vw_star,
          &vs_new, &vw_new, &p_node, &dp_node, &gs,     &gw,     &wet,     &dry,  &near_wet})
      grid.reinit_vector(*v);
    plate_response.resize(force_plates.size());
    for (auto &r : plate_response)
      for (Vector *v : {&r.es, &r.ew, &r.dp, &r.gs, &r.gw, &r.vs, &r.vw})
        grid.reinit_vector(*v);
    partition_changed = true;    // the next step rebuilds the active set and the matrix
    soil.collect_active_cells(); // the sets' cell lists on the new partition (empty before seeding)
    water.collect_active_cells();
  }

  template <int dim>
  void
  Solver<dim>::setup()
  {
    this->make_grid(); // a box: grid files are refused by the parameters
    plate_state.assign(prm.rigid_plates.size(), PlateState());
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      if (prm.rigid_plates[k].control == loads::RigidPlate<dim>::Control::force)
        force_plates.push_back(k);
    grid_changed();
    check_plates();

    // layouts: soil points carry the solid model's history; both carry porosity
    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    soil.layout.n_history = n_history;
    fs.porosity           = soil.layout.add_extra("porosity", 1);
    fs.initial_porosity   = soil.layout.add_extra("initial_porosity", 1);
    fs.initial_volume     = soil.layout.add_extra("initial_volume", 1);
    fs.conductivity       = soil.layout.add_extra("conductivity", 1);
    fs.surface_offset     = soil.layout.add_extra("surface_offset", dim, true);
    bloads.extend_layout(soil.layout, fs.surface_offset); // the point tractions' slots
    fs.poisson_coefficient = soil.layout.add_extra("poisson_coefficient", 1);
    fs.poisson_flux        = soil.layout.add_extra("poisson_flux", dim, true);
    if (prm.volumetric_stabilisation != VolumetricStabilisation::none)
      fs.smoothed_volume_increment = soil.layout.add_extra("smoothed_volume_increment", 1);
    if (prm.volumetric_stabilisation == VolumetricStabilisation::modified_f_bar)
      fs.patch_elastic_jacobian = soil.layout.add_extra("patch_elastic_jacobian", 1);
    for (const auto &m : prm.materials)
      smooth_jacobian = smooth_jacobian || (prm.smoothed_specific_volume && m->has_specific_volume());
    if (smooth_jacobian)
      fs.smoothed_jacobian = soil.layout.add_extra("smoothed_jacobian", 1);
    if (!force_plates.empty())
      {
        fs.plate_flux = soil.layout.add_extra("plate_flux", dim, true);
        fw.plate_flux = water.layout.add_extra("plate_flux", dim, true);
      }
    if (prm.one_set) // the pore water on the soil points (the water set stays empty)
      {
        fs.pressure          = soil.layout.add_extra("pore_pressure", 1);
        fs.pressure_gradient = soil.layout.add_extra("pore_pressure_gradient", dim, true);
        fs.water_velocity    = soil.layout.add_extra("water_velocity", dim, true);
        fs.water_mass        = soil.layout.add_extra("water_mass", 1);
      }
    fw.pressure            = water.layout.add_extra("pore_pressure", 1);
    fw.pressure_gradient   = water.layout.add_extra("pore_pressure_gradient", dim, true);
    fw.porosity            = water.layout.add_extra("porosity", 1);
    fw.initial_porosity    = water.layout.add_extra("initial_porosity", 1);
    fw.initial_volume      = water.layout.add_extra("initial_volume", 1);
    fw.poisson_coefficient = water.layout.add_extra("poisson_coefficient", 1);
    fw.poisson_flux        = water.layout.add_extra("poisson_flux", dim, true);
    soil.initialize();
    water.initialize();
    initialisation_models = prm.materials;
    for (auto &m : initialisation_models) // nor sand without plasticity, the others as they are
      if (auto elastic = m->initialisation_model())
        m = elastic;
    dt_soil_critical = soil_critical_time_step(prm, grid.min_cell_size());
    if (restore_if_asked(prm, [this] { return restore_checkpoint(); }))
      {
        balance.initial(); // on another number of ranks: partition by points
        return;            // the points, the step and the loop's state as saved
      }
    seed();
    bloads.assign(soil, prm.bodies); // the loaded points' forces and face offsets
    if (any_initial_stress(prm.initial_stress))
      geostatic_state();
    initialize_point_histories(prm.materials, soil, soil.layout.history);
    dt = prm.time_step > 0 ? prm.time_step : prm.courant * dt_soil_critical;
    select_probes();
    // load balancing: partition by the points of both sets from the start
    balance.initial();
  }

  template <int dim>
  void
  Solver<dim>::select_probes()
  {
    probes.select(soil, prm.probes, comm);
    if (has_water()) // one set: the pore pressure of the same soil points
      water_probes.select(prm.one_set ? soil : water, prm.probes, comm);
  }

  template <int dim>
  void
  Solver<dim>::check_plates()
  {
    const unsigned int n = prm.rigid_plates.size();
    plate_nodes.assign(n, 0);
    plate_axis_dofs.assign(n, 0);
    if (n == 0)
      return;
    // the shared node checks (exit 2 naming the plate) with the scene's walls
    const auto counts = loads::check_rigid_plate_nodes(grid, prm.rigid_plates, {prm.boundary_conditions}, {""}, comm);
    for (unsigned int k = 0; k < n; ++k)
      plate_nodes[k] = counts[k].nodes;
    const unsigned int owned = grid.partitioner->locally_owned_size();
    for (unsigned int i = 0; i < owned; ++i)
      if (plate_of[i] != no_plate)
        ++plate_axis_dofs[plate_of[i]];
    MPI_Allreduce(MPI_IN_PLACE, plate_axis_dofs.data(), n, MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm);
    // the wall check above counts a node held if a wall holds its axis
    // component; plate_of[] leaves out the same DoFs, so no plate is left
    // without an axis DoF here
    for (unsigned int k = 0; k < n; ++k)
      AssertThrow(plate_axis_dofs[k] > 0, dealii::ExcInternalError());
  }

  // ---------------------------------------------------------------- checkpoints
  // The state between two steps is the two point sets with everything they
  // carry (soil: velocity, stress, the model's history with b_e, volume,
  // porosity, conductivity, its share of the surface load; water: velocity,
  // pore pressure and its gradient, porosity, volume) and the loop's state:
  // every nodal field of a step (masses, p^t, n_I, the drag, the F-bar dJ and
  // patch means, the free-surface flags, the pressure system) is rebuilt from
  // the points at its start, and the patch tiling is fixed by the .prm. Same
  // rank count: bitwise continuation (docs/semi-implicit.md).
  namespace
  {
    const char *const checkpoint_format  = "talus-semi-implicit-checkpoint";
    const int         checkpoint_version = 1;
  } // namespace

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    // the run restarted from this checkpoint builds a new hierarchy at its first
    // solve: so does this one, so that both go on bitwise alike. The same for
    // the pressure DoF set: a kept one remembers the couplings of its build
    // step, which decide later rebuilds (ActiveSet::couplings_covered)
    pressure_solver.invalidate();
    partition_changed = true;
    return write_checkpoint_file(prm, *this, checkpoint_format, checkpoint_version,
                                 scene_signature(prm, soil.layout.n_properties()), comm, [&](io::H5File &f) {
                                   f.set_attribute("pressure solves", std::int64_t(n_solves));
                                   f.set_attribute("pressure cg iterations", std::int64_t(solver_iterations));
                                   f.set_attribute("pressure amg setups", std::int64_t(pressure_solver.n_setups()));
                                   for (unsigned int k = 0; k < plate_state.size(); ++k) // the plates' state
                                     {
                                       const std::string a = "rigid plate " + std::to_string(k) + " ";
                                       f.set_attribute(a + "displacement", plate_state[k].displacement);
                                       f.set_attribute(a + "velocity", plate_state[k].velocity);
                                       f.set_attribute(a + "force", plate_state[k].force);
                                       f.set_attribute(a + "tangential force", plate_state[k].tangential);
                                       f.set_attribute(a + "node spread", plate_state[k].node_spread);
                                       f.set_attribute(a + "node slip", plate_state[k].node_slip);
                                     }
                                   write_points(f, soil, "soil");
                                   write_points(f, water, "water");
                                   probes.write_ids(f, "probes/soil_ids");
                                   water_probes.write_ids(f, "probes/water_ids");
                                   write_pvd_times(f, "output/soil_pvd", this->point_set_records[0]);
                                   write_pvd_times(f, "output/water_pvd", this->point_set_records[1]);
                                   balance.write(f); // the partition of the last rebalance
                                 });
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto fp = open_checkpoint_to_restore(prm, *this, checkpoint_format, checkpoint_version,
                                               scene_signature(prm, soil.layout.n_properties()), comm);
    if (!fp)
      return false;
    n_solves          = fp->get_int("pressure solves");
    solver_iterations = fp->get_int("pressure cg iterations");
    // (absent in checkpoints written before the AMG reuse)
    if (fp->has_attribute("pressure amg setups"))
      pressure_solver.set_n_setups(fp->get_int("pressure amg setups"));
    const std::string where = "checkpoint " + fp->path();
    for (unsigned int k = 0; k < plate_state.size(); ++k)
      {
        const std::string a = "rigid plate " + std::to_string(k) + " ";
        require(fp->has_attribute(a + "displacement"), where,
                "has no state of 'boundary conditions/rigid plate " + std::to_string(k) +
                  "' (written by a run without it); allowed: a checkpoint of the same scene");
        plate_state[k].displacement = fp->get_double(a + "displacement");
        plate_state[k].velocity     = fp->get_double(a + "velocity");
        plate_state[k].force        = fp->get_double(a + "force");
        plate_state[k].tangential   = fp->get_double(a + "tangential force");
        plate_state[k].node_spread  = fp->get_double(a + "node spread");
        plate_state[k].node_slip    = fp->get_double(a + "node slip");
      }
    balance.restore(*fp); // same ranks: the saved partition, before the points go in
    read_points(*fp, soil, grid, where, "soil");
    read_points(*fp, water, grid, where, "water");
    if (!prm.probes.empty()) // the points the run tracked (their ids saved)
      {
        probes.read_ids(*fp, where, "probes/soil_ids");
        water_probes.read_ids(*fp, where, "probes/water_ids");
        require(probes.ids.size() == prm.probes.size(), "output/probes",
                "the checkpoint " + fp->path() + " tracks " + std::to_string(probes.ids.size()) +
                  " probe(s), the .prm lists " + std::to_string(prm.probes.size()) +
                  "; allowed: the probes of the checkpointed run");
      }
    this->point_set_records[0] = read_pvd_records(*fp, "output/soil_pvd", soil.name());
    this->point_set_records[1] = read_pvd_records(*fp, "output/water_pvd", water.name());
    return true;
  }

  template <int dim>
  void
  Solver<dim>::seed()
  {
    // each set is seeded from the bodies of its phase; the body property keeps
    // the index of the .prm body
    for (const bool is_soil : {true, false})
      {
        if (!is_soil && prm.one_set) // one set: the soil points carry the water
          continue;
        MaterialPointSet<dim>            &set = is_soil ? soil : water;
        std::vector<BodyDescription<dim>> bodies;
        std::vector<unsigned int>         body_index;
        for (unsigned int b = 0; b < prm.bodies.size(); ++b)
          if (prm.phase_of_body[b] == Phase::saturated || (prm.phase_of_body[b] == Phase::soil) == is_soil)
            {
              bodies.push_back(prm.bodies[b]);
              body_index.push_back(b);
            }
        std::vector<double> unit_density(prm.materials.size(), 1.0); // masses set below
        // file bodies: the rows of their particle files, the same rows for both
        // sets of a saturated body (the single-point variant relies on it)
        seed_scene_bodies(grid, bodies, unit_density, set, is_soil ? "soil point" : "water point",
                          is_soil ? &prm : nullptr, body_index);
        const Fields &f = is_soil ? fs : fw;
        for (auto &pt : set.handler)
          {
            auto               P = pt.get_properties();
            const unsigned int b = body_index[static_cast<unsigned int>(P[L::body])];
            P[L::body]           = b;
            const unsigned int m = static_cast<unsigned int>(P[L::material]); // a file body's: its row's
            // a water body's points take the porosity 1 (free water)
            const double n0       = prm.phase_of_body[b] == Phase::water ? 1.0 : prm.soil_of_material[m].porosity;
            const double V0       = P[L::volume];
            P[f.porosity]         = n0;
            P[f.initial_porosity] = n0;
            P[f.initial_volume]   = V0;
            if (is_soil)
              {
                P[L::mass]        = (1 - n0) * prm.materials[m]->density() * V0; // Eq. 35
                P[f.conductivity] = prm.soil_of_material[m].conductivity;
                for (unsigned int d = 0; d < dim; ++d) // its share of a loaded face: BoundaryLoads::assign
                  P[f.surface_offset + d] = 0;
                if (prm.one_set) // its pore water (Eq. 37), none in a soil body
                  {
                    P[f.water_mass] = prm.phase_of_body[b] == Phase::saturated ? n0 * prm.water_density * V0 : 0.0;
                    P[f.pressure]   = 0;
                    for (unsigned int d = 0; d < dim; ++d)
                      P[f.pressure_gradient + d] = P[f.water_velocity + d] = 0;
                  }
              }
            else
              {
                P[L::mass] = n0 * prm.water_density * V0;     // Eq. 37
                L::set_stress(materials::Stress(), P.data()); // a particle file's stress is the soil's
                P[f.pressure] = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  P[f.pressure_gradient + d] = 0;
              }
          }
        set.collect_active_cells();
      }
  }

  template <int dim>
  void
  Solver<dim>::geostatic_state()
  {
    // 'body k/initial stress' (formulations/common/initial_stress.h): the
    // water points of a body below its water level hydrostatic, its soil
    // points the K0 state of the dry weight above the water level and the
    // buoyant weight below it
    GeostaticState<dim> geo(prm.initial_stress, prm.gravity);
    geo.find_body_tops({&soil, &water}, grid, prm.bodies, comm);
    const double g = geo.gravity_norm();
    // (one set: the pore water of the soil points that carry water)
    const Fields &f = prm.one_set ? fs : fw;
    for (auto &pt : (prm.one_set ? soil : water).handler)
      {
        auto               P = pt.get_properties();
        const unsigned int b = static_cast<unsigned int>(P[L::body]);
        if (!geo.applies(b) || (prm.one_set && !(P[fs.water_mass] > 0)))
          continue;
        const double depth = geo.depths(b, pt.get_location()).water;
        P[f.pressure]      = -prm.water_density * g * depth;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double up_d          = geo.up_direction()[d];
            P[f.pressure_gradient + d] = depth > 0 && up_d != 0 ? prm.water_density * g * up_d : 0.0;
          }
      }
    for (auto &pt : soil.handler)
      {
        auto               P = pt.get_properties();
        const unsigned int b = static_cast<unsigned int>(P[L::body]);
        if (!geo.applies(b))
          continue;
        const unsigned int m     = static_cast<unsigned int>(P[L::material]);
        const double       n     = P[fs.porosity];
        const double       rs    = prm.materials[m]->density();
        const auto         depth = geo.depths(b, pt.get_location());
        // dry unit weight above the water level, buoyant below; a soil body
        // (no pore water) dry throughout
        const double sv =
          prm.phase_of_body[b] == Phase::soil
            ? -(1 - n) * g * rs * depth.depth - geo.of(b).surcharge
            : -(1 - n) * g * (rs * depth.dry + (rs - prm.water_density) * depth.submerged) - geo.of(b).surcharge;
        L::set_stress(geo.stress(b, sv), P.data());
      }
  }

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    const auto ns = soil.handler.n_global_particles(), nw = water.handler.n_global_particles();
    out << "talus-semi-implicit: " << dim << "D, grid " << grid.tria.n_global_active_cells() << " cells (h_min "
        << grid.min_cell_size() << " m), " << (prm.bspline() ? "quadratic B-splines" : "linear shape functions") << ", "
        << (prm.one_set ? std::to_string(ns) + " points (one set: soil and pore water on each)"
                        : std::to_string(ns) + " soil + " + std::to_string(nw) + " water points")
        << "\n"
        << "  time step " << dt << " s (soil skeleton critical step " << dt_soil_critical << " s"
        << (prm.time_step > 0 ? ", fixed" : ", courant " + std::to_string(prm.courant))
        << "), pressure: CG + ML AMG to " << prm.pressure_tolerance << " relative residual, AMG rebuilt every "
        << prm.pressure_rebuild_interval << " steps" << std::endl;
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &pl = prm.rigid_plates[k];
        out << "  " << pl.where << ": "
            << (pl.target == loads::RigidPlate<dim>::Target::boundary ? "boundary id " + std::to_string(pl.boundary)
                                                                      : std::string("region"))
            << ", " << plate_nodes[k] << " nodes"
            << (plate_axis_dofs[k] < plate_nodes[k]
                  ? " (" + std::to_string(plate_axis_dofs[k]) + " move along " + "xyz"[pl.axis] + ", the others' " +
                      "xyz"[pl.axis] + " is held by a wall)"
                  : std::string(" moving along ") + "xyz"[pl.axis])
            << ", " << (pl.rough ? "rough" : "frictionless") << ", " << (pl.permeable ? "permeable" : "impermeable")
            << ", "
            << (pl.control == loads::RigidPlate<dim>::Control::force
                  ? "force control: " + number_text(pl.force) + " N x f(t), displacement unknown"
                  : "displacement control: " + number_text(pl.displacement) + " m x f(t), reaction reported")
            << std::endl;
      }
    bloads.describe(out);
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  // the members defined in semi_implicit_step.cc and semi_implicit_output.cc
  // are instantiated there
  template class Solver<2>;
  template class Solver<3>;
} // namespace talus::semi_implicit
