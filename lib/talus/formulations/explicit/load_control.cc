#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/formulations/explicit/with_kernel.h>
#include <talus/formulations/common/initial_stress.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/local_damping.h>
#include <talus/shape/q1.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/point_ops.h>

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/mpi.h>

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

namespace talus::loads
{
  template <int dim>
  LoadControl<dim>::LoadControl(const Settings<dim> &s)
      : settings(s)
  {
  }

  template <int dim>
  void
  LoadControl<dim>::extend_layout(PropertyLayout<dim> &layout)
  {
    forces.extend_layout(layout, settings.max_tractions);
  }

  template <int dim>
  bool
  LoadControl<dim>::has_convergence() const
  {
    for (const auto &st : settings.stages)
      if (st.convergence.enabled)
        return true;
    return false;
  }

  // ---------------------------------------------------------------- K0
  template <int dim>
  void
  LoadControl<dim>::initial_state(Solver &s)
  {
    using L = PropertyLayout<dim>;
    // 2-phase points get their solid mass (1 - n0) rho_S V, porosity and liquid
    // velocity now (setup() repeats it after the history initialisation), so that
    // the stage-0 baselines below (potential energy of both masses) are right
    if (s.two_phase)
      s.two_phase->initialize_particles();
    // the K0 procedure (body k/initial stress, formulations/common/initial_stress.h)
    GeostaticState<dim> geo(s.prm.initial_stress, settings.stages[0].gravity);
    geo.find_body_tops({&s.points}, s.grid, s.prm.bodies, s.comm);
    const double gn = geo.gravity_norm();
    // the coupled points are saturated: none may lie above the water level
    unsigned int dry_body = std::numeric_limits<unsigned int>::max();
    for (auto &pt : s.points.handler)
      {
        auto               P = pt.get_properties();
        const unsigned int b = static_cast<unsigned int>(P[L::body]);
        if (!geo.applies(b))
          continue;
        // 2-phase point (solid grains + pore liquid, saturated up to the water
        // level at or above the surface): K0 gives the effective stress from the
        // buoyant weight (1 - n0)(rho_S - rho_L) g depth, the pore pressure is
        // hydrostatic rho_L g (water level - z) (compression positive); total
        // stress sigma' - p I.
        const unsigned int mat = static_cast<unsigned int>(P[L::material]);
        if (s.two_phase && s.two_phase->coupled &&
            s.prm.liquid.pore_liquid[mat].drainage == explicit_mpm::Drainage::coupled)
          {
            const auto  &pl               = s.prm.liquid.pore_liquid[mat];
            const auto   depth            = geo.depths(b, pt.get_location());
            const double buoyant          = (1 - pl.porosity) * (s.prm.materials[mat]->density() - pl.density);
            P[s.two_phase->pore_pressure] = pl.density * gn * depth.water;
            if (depth.dry > 0)
              dry_body = std::min(dry_body, b);
            L::set_stress(geo.stress(b, -(buoyant * gn * depth.depth + geo.of(b).surcharge)), P.data());
          }
        else
          L::set_stress(geo.one_phase_stress(b, pt.get_location(), P[L::mass] / P[L::volume]), P.data());
      }
    dry_body = dealii::Utilities::MPI::min(dry_body, s.comm);
    require(dry_body == std::numeric_limits<unsigned int>::max(),
            "body " + std::to_string(dry_body) + "/initial stress/water level",
            "lies below the body's surface level: talus-explicit's coupled 2-phase points are saturated (allowed: "
            "at or above the surface level, or empty = the surface level)");
    begin_stage(s, 0, false);
  }

  // ---------------------------------------------------------------- stages
  template <int dim>
  void
  LoadControl<dim>::set_time_step(Solver &s)
  {
    const double dt_cr = s.critical_time_step();
    if (s.prm.time_step > 0)
      {
        if (s.prm.time_step > dt_cr && !s.prm.force_time_step)
          {
            std::ostringstream os;
            os << "time/time step: " << s.prm.time_step << " s exceeds the critical time step " << dt_cr
               << " s of stage '" << current->name << "' (mass scaling " << current->mass_scaling
               << "); lower it, or set 'force time step = true' to run anyway";
            throw InputError(os.str());
          }
        s.dt = s.prm.time_step;
      }
    else
      s.dt = s.prm.courant * dt_cr;
  }

  template <int dim>
  double
  LoadControl<dim>::begin_stage(Solver &s, const unsigned int k, const bool resume)
  {
    AssertThrow(k < settings.stages.size(), dealii::ExcInternalError());
    current         = &settings.stages[k];
    stage_index     = k;
    s.current_stage = k;
    if (!resume)
      s.stage_start_time = s.time;
    stage_t0    = s.stage_start_time;
    stage_step0 = s.step_number;
    converged   = false;
    force_ratio = energy_ratio = std::numeric_limits<double>::quiet_NaN();
    s.gravity                  = current->gravity;
    s.mass_scaling             = current->mass_scaling;
    s.constrained              = wall_dof_flags(s.grid, current->boundary_conditions);
    s.p2g_ready                = false; // gravity may have changed: redo the mass/force P2G
    if (!resume)
      set_time_step(s); // a restart continues with the checkpointed step

    settle_time = 0;
    for (unsigned int j = 0; j < current->tractions.size(); ++j)
      {
        const bool glob = j < current->n_global_tractions;
        settle_time     = std::max(settle_time, current->tractions[j].function.settle_time() - (glob ? stage_t0 : 0.0));
      }
    for (unsigned int j = 0; j < current->velocities.size(); ++j)
      {
        const bool glob = j < current->n_global_velocities;
        settle_time = std::max(settle_time, current->velocities[j].function.settle_time() - (glob ? stage_t0 : 0.0));
      }
    for (const auto &plate : s.prm.rigid_plates) // absolute time
      settle_time = std::max(settle_time, plate.function.settle_time() - stage_t0);

    if (settings.max_tractions > 0)
      {
        // a restart: the checkpointed points carry the forces of the stage's
        // assignment; assigning anew from the current volumes gave other shares
        // (1 ulp off in a consolidating layer, more where the loaded points'
        // volumes change unevenly), so the restart was not bitwise
        if (resume)
          forces.resume(current->tractions);
        else
          assign_tractions(s);
      }
    build_node_lists(s);
    if (!resume)
      s.initial_energies = s.energies(); // baseline of the stability check (restored on restart)
    potential0 = s.energies().gravity_potential;
    work_loads = s.external_work;

    std::ostringstream os;
    os << "  stage " << k << " '" << current->name << "': t = " << s.time << " s, duration " << current->duration
       << " s, dt = " << s.dt << " s";
    if (current->mass_scaling != 1.0)
      os << " (mass scaling " << current->mass_scaling << ")";
    if (current->damping > 0)
      os << ", local damping " << current->damping;
    if (current->viscous_damping > 0)
      os << ", viscous damping " << current->viscous_damping << " 1/s";
    if (!current->tractions.empty())
      os << ", " << current->tractions.size() << " traction(s)";
    if (!current->velocities.empty())
      os << ", " << current->velocities.size() << " velocity condition(s)";
    if (!current->friction_ids.empty())
      os << ", friction mu = " << current->friction_coefficient << " on " << friction_nodes.size()
         << " node(s) of this rank";
    if (current->convergence.enabled)
      os << ", convergence F < " << current->convergence.force_tolerance << ", E < "
         << current->convergence.energy_tolerance;
    log() << os.str() << std::endl;
    return stage_t0 + current->duration;
  }

  template <int dim>
  void
  LoadControl<dim>::assign_tractions(Solver &s)
  {
    forces.assign(current->tractions, s.points, s.grid, s.prm.bodies, s.comm);
  }

  template <int dim>
  void
  LoadControl<dim>::build_node_lists(Solver &s)
  {
    const unsigned int n_owned = s.nodal_mass.locally_owned_size();
    const unsigned int n_local = n_owned + s.grid.partitioner->n_ghost_indices();
    component.assign(n_local, -1);
    for (const auto &cc : s.grid.cells)
      if (cc.h[0] > 0)
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            component[cc.dofs[v * dim + d]] = d;
    excluded.assign(n_local, 0);
    for (unsigned int i = 0; i < n_local; ++i)
      excluded[i] = s.constrained[i];

    // friction nodes: vertices of boundary faces with a friction id (owned
    // DoFs; faces of ghost cells add their area share to owned nodes)
    friction_nodes.clear();
    friction_faces.assign(s.grid.cells.size(), 0);
    std::map<unsigned int, unsigned int> node_of; // first DoF -> index
    for (unsigned int c = 0; c < s.grid.cells.size(); ++c)
      {
        const auto &cc = s.grid.cells[c];
        if (!(cc.h[0] > 0) || current->friction_ids.empty())
          continue;
        const auto &cell = s.grid.cell_iterator(c);
        for (unsigned int f = 0; f < dealii::GeometryInfo<dim>::faces_per_cell; ++f)
          {
            if (!cell->face(f)->at_boundary())
              continue;
            const auto id = cell->face(f)->boundary_id();
            if (std::find(current->friction_ids.begin(), current->friction_ids.end(), id) ==
                current->friction_ids.end())
              continue;
            friction_faces[c] |= static_cast<unsigned char>(1u << f);
            const unsigned int axis = f / 2;
            double             area = 1.0;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != axis)
                area *= cc.h[d];
            for (unsigned int i = 0; i < dealii::GeometryInfo<dim>::vertices_per_face; ++i)
              {
                const unsigned int v = dealii::GeometryInfo<dim>::face_to_cell_vertices(f, i);
                if (cc.dofs[v * dim] >= n_owned)
                  continue;
                const unsigned int key = cc.dofs[v * dim] * 8 + f; // a node may sit on two boundaries
                auto               it  = node_of.find(key);
                if (it == node_of.end())
                  {
                    FrictionNode n;
                    for (unsigned int d = 0; d < dim; ++d)
                      n.dofs[d] = cc.dofs[v * dim + d];
                    n.axis           = axis;
                    n.side           = (f % 2) ? +1 : -1;
                    n.area           = 0;
                    n.h              = cc.h[axis];
                    n.liquid_stopped = false;
                    it               = node_of.emplace(key, friction_nodes.size()).first;
                    friction_nodes.push_back(n);
                  }
                friction_nodes[it->second].area += area / dealii::GeometryInfo<dim>::vertices_per_face;
              }
          }
      }
    for (const auto &n : friction_nodes)
      for (unsigned int d = 0; d < dim; ++d)
        excluded[n.dofs[d]] = 1;
    wall_state.assign(friction_nodes.size(), 0);
    any_friction = dealii::Utilities::MPI::logical_or(!friction_nodes.empty(), s.comm);
    if (any_friction && lift.size() == 0)
      s.grid.reinit_vector(lift);

    // prescribed nodal velocities (the node selection is shared: loads/kinematics)
    prescribed_dofs = prescribed_node_dofs(s.grid, current->velocities);
    for (const auto &p : prescribed_dofs)
      excluded[p.dof] = 1;
    particle_conditions.clear();
    for (unsigned int j = 0; j < current->velocities.size(); ++j)
      if (current->velocities[j].target == PrescribedVelocity<dim>::Target::body)
        particle_conditions.push_back(j);
    // the collectives first, on every rank: inside a short-circuit || they ran
    // only on the ranks without friction/prescribed nodes of their own, which then
    // reduced against the other ranks' next collective (ExcMPI on one rank, a hang
    // on the others: a prescribed base velocity on 2 ranks)
    any_prescribed = dealii::Utilities::MPI::logical_or(!prescribed_dofs.empty(), s.comm);
    // rigid plates: their owned DoFs (axis; every component of a rough plate)
    // that no wall of this stage holds (the wall keeps what it holds); the
    // nodes' own forces are reactions inside the plate: out of the force ratio,
    // the plate's unbalanced force enters it instead (nodal_forces)
    any_plate = !s.prm.rigid_plates.empty();
    plate_dofs.clear();
    for (const auto &p : rigid_plate_node_dofs(s.grid, s.prm.rigid_plates))
      if (!s.constrained[p.dof])
        {
          plate_dofs.push_back(p);
          excluded[p.dof] = 1;
        }
    need_vt = any_friction || any_prescribed || any_plate || current->damping > 0 || current->viscous_damping > 0;
    if ((need_vt || current->convergence.enabled) && vt.size() == 0)
      s.grid.reinit_vector(vt);
    if (forces.any() && trac.size() == 0)
      s.grid.reinit_vector(trac);
  }

  // ---------------------------------------------------------------- step hooks
  template <int dim>
  bool
  LoadControl<dim>::check_step(const Solver &s) const
  {
    const auto &conv = current->convergence;
    return conv.enabled && s.step_number > stage_step0 && (s.step_number - stage_step0) % conv.interval == 0;
  }

  template <int dim>
  void
  LoadControl<dim>::before_nodal_solve(Solver &s, const double step, const Vector *momentum_t)
  {
    using L           = PropertyLayout<dim>;
    h                 = step;
    const bool vt_now = need_vt || check_step(s);
    vt_scattered      = false;
    if (vt_now && momentum_t) // the caller's nodal momentum at t (owned entries)
      {
        const double *src = momentum_t->begin();
        double       *dst = vt.begin();
        for (const unsigned int i : s.active_dofs)
          dst[i] = src[i];
      }
    else if (vt_now) // nodal momentum p^t of the points (the shape functions of the run)
      {
        s.scatter_point_momentum(vt);
        vt_scattered = true;
      }
    // with momentum_t (the 2-phase step) the caller has scattered the tractions
    // in its own P2G pass (begin/end_traction_scatter)
    const bool scatter = forces.any() && !momentum_t;
    if (!scatter && !any_friction)
      return;
    double *const T = scatter ? trac.begin() : nullptr;
    if (scatter)
      {
        s.zero_on_active(trac);
        update_factors(s);
      }
    if (any_friction)
      friction_lift(s);
    if (!scatter)
      return;
    // Eq. 5.3: f_trac,i = sum_p N_i(x_p) f_p, with the shape functions of the run
    double work   = 0;
    auto   source = [&](const double *P, double(&w)[1], double(&f)[1][dim]) {
      if (!forces.force_if_loaded(P, f[0]))
        return false;
      w[0] = 1.0;
      for (unsigned int d = 0; d < dim; ++d)
        work += f[0][d] * P[L::velocity + d] * h;
      return true;
    };
    s.with_kernel([&](auto kernel) {
      transfer::ScatterPointVectors<dim, decltype(kernel), decltype(source)> op(s.grid, source, {{T}});
      transfer::for_each_active_cell(s.points, op);
    });
    trac.compress(dealii::VectorOperation::add);
    s.external_work += dealii::Utilities::MPI::sum(work, s.comm);
  }

  template <int dim>
  void
  LoadControl<dim>::friction_lift(Solver &s)
  {
    // frictional walls: the material's displacement away from the wall at each
    // friction node (min over the points of the adjacent cells)
    for (unsigned int i = 0; i < lift.locally_owned_size() + lift.get_partitioner()->n_ghost_indices(); ++i)
      lift.local_element(i) = std::numeric_limits<double>::max();
    transfer::MinDisplacementAwayFromWalls<dim> op(s.grid, friction_faces, lift.begin());
    transfer::for_each_active_cell(s.points, op);
    lift.compress(dealii::VectorOperation::min);
  }

  template <int dim>
  void
  LoadControl<dim>::update_factors(const Solver &s)
  {
    forces.update_factors(current->tractions, current->n_global_tractions, s.time, stage_t0);
  }

  template <int dim>
  double *
  LoadControl<dim>::begin_traction_scatter(Solver &s)
  {
    if (!forces.any())
      return nullptr;
    update_factors(s);
    s.zero_on_active(trac);
    return trac.begin();
  }

  template <int dim>
  void
  LoadControl<dim>::end_traction_scatter()
  {
    if (forces.any())
      trac.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  LoadControl<dim>::nodal_forces(Solver &s)
  {
    double *const       F = s.nodal_a.begin();
    const double *const M = s.nodal_mass.begin();
    if (forces.any())
      {
        const double *T = trac.begin();
        for (const unsigned int i : s.active_dofs)
          F[i] += T[i];
      }
    if (any_plate) // the plates' momentum balance, on the force before damping
      rigid_plate_balance(s, F, M);
    // quasi-static convergence (seed 000 §6.4), on the unbalanced force before damping
    if (check_step(s))
      {
        const double *T    = forces.any() ? trac.begin() : nullptr;
        double        v[4] = {0, 0, 0, 0};
        for (const unsigned int i : s.active_dofs)
          if (!excluded[i] && component[i] >= 0)
            {
              const double fext = M[i] * s.gravity[component[i]] + (T ? T[i] : 0.0);
              v[0] += F[i] * F[i];
              v[1] += fext * fext;
            }
        // kinetic energy of the grid motion, 1/2 sum p_i^2 / m_i: velocity
        // fields of the points that project to zero nodal momentum (the MPM
        // null space) carry energy that no force acts on, and must not block
        // convergence
        const double *Pm = vt.begin();
        for (const unsigned int i : s.active_dofs)
          if (M[i] > 0)
            v[2] += 0.5 * Pm[i] * Pm[i] / M[i];
        v[3] = s.local_sums.gravity_potential;
        // rigid plates (once, on rank 0): a force-controlled plate adds its
        // unbalanced force and its load; a displacement-controlled one is
        // balanced by construction and adds its reaction as a load on the
        // material (without it a scene loaded only by the plate has no
        // external force to measure the unbalance against)
        if (dealii::Utilities::MPI::this_mpi_process(s.comm) == 0)
          for (unsigned int k = 0; k < plate_run.size(); ++k)
            {
              if (s.prm.rigid_plates[k].control == RigidPlate<dim>::Control::force)
                v[0] += plate_run[k].unbalanced * plate_run[k].unbalanced;
              v[1] += plate_run[k].force * plate_run[k].force;
            }
        evaluate_convergence(s, v);
      }
    damp_and_scale(s, F, M, vt.begin());
  }

  template <int dim>
  void
  LoadControl<dim>::damp_and_scale(const Solver &s, double *F, const double *M, const double *P) const
  {
    // local damping (Eq. 6.23) with the nodal velocity at t (sign(p) = sign(v))
    if (current->damping > 0)
      for (const unsigned int i : s.active_dofs)
        if (M[i] > 0)
          F[i] += local_damping_force(current->damping, F[i], P[i]);
    // mass-proportional (Rayleigh alpha) damping: -alpha_v m_i v_i = -alpha_v p_i
    if (current->viscous_damping > 0)
      for (const unsigned int i : s.active_dofs)
        if (M[i] > 0)
          F[i] -= current->viscous_damping * P[i];
    // mass scaling (Eq. 6.31): inertia beta m, forces unchanged
    if (current->mass_scaling != 1.0)
      {
        const double inv = 1.0 / current->mass_scaling;
        for (const unsigned int i : s.active_dofs)
          F[i] *= inv;
      }
  }

  template <int dim>
  void
  LoadControl<dim>::evaluate_convergence(const Solver &s, double (&v)[4])
  {
    const auto &conv = current->convergence;
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 4), s.comm, dealii::ArrayView<double>(v, 4));
    const double w_ext   = (potential0 - v[3]) + (s.external_work - work_loads) + 0.0;
    force_ratio          = std::sqrt(v[0]) / std::max(std::sqrt(v[1]), 1e-300);
    const double ke      = current->mass_scaling * v[2]; // of the scaled inertia
    energy_ratio         = w_ext > 0 ? ke / w_ext : (ke > 0 ? std::numeric_limits<double>::infinity() : 0.0);
    const double t_stage = s.time - stage_t0;
    if (conv.end_stage && t_stage >= settle_time - 1e-9 * s.dt && force_ratio < conv.force_tolerance &&
        energy_ratio < conv.energy_tolerance)
      converged = true;
  }

  template <int dim>
  void
  LoadControl<dim>::nodal_forces_two_phase(Solver &s)
  {
    // s.nodal_a holds the mixture force f = f_trac + f_grav - f_int (total
    // stress, both masses), the 2-phase step's f_liquid the liquid force of the
    // equation divided by n (pressure gradient + gravity, no drag)
    double *const       F  = s.nodal_a.begin();
    const double *const MS = s.nodal_mass.begin();
    if (forces.any()) // a traction on the surface of the mixture is a total stress
      {
        const double *T = trac.begin();
        for (const unsigned int i : s.active_dofs)
          F[i] += T[i];
      }
    if (any_plate) // the plates' sums before the damping (coupled: V after the liquid's a_L)
      rigid_plate_balance(s, F, MS);
    if (!check_step(s))
      return;
    // Static equilibrium of both phases: the mixture force and the liquid's
    // unbalanced force f_w (Eq. 6.24 without the drag) must vanish. During
    // consolidation the accelerations are ~0 but f_w, balanced by the drag of
    // the seepage, is not: a criterion on the mixture alone would end a stage in
    // undrained equilibrium, long before the excess pore pressure has gone.
    // f_w enters with the nodal porosity n = Mbar_L / M_L (force on the liquid
    // mass itself), its external part is the liquid's weight Mbar_L g.
    const auto   *tp  = s.two_phase.get();
    const bool    cp  = tp->coupled;
    const double *T   = forces.any() ? trac.begin() : nullptr;
    const double *mLt = cp ? tp->m_liquid.begin() : nullptr, *mLn = cp ? tp->m_liquid_n.begin() : nullptr;
    const double *FL = cp ? tp->f_liquid.begin() : nullptr, *PL = cp ? tp->p_liquid.begin() : nullptr;
    double        v[4] = {0, 0, 0, 0};
    for (const unsigned int i : s.active_dofs)
      if (!excluded[i] && component[i] >= 0)
        {
          const double g    = s.gravity[component[i]];
          const double mL   = cp ? mLn[i] : 0.0;
          const double fext = (MS[i] + mL) * g + (T ? T[i] : 0.0);
          v[0] += F[i] * F[i];
          v[1] += fext * fext;
          if (cp && mLt[i] > 0)
            {
              const double fw = mLn[i] / mLt[i] * FL[i];
              v[0] += fw * fw;
              v[1] += mL * g * mL * g;
            }
        }
    // kinetic energy of the grid motion of both phases
    const double *Pm = vt.begin();
    for (const unsigned int i : s.active_dofs)
      {
        if (MS[i] > 0)
          v[2] += 0.5 * Pm[i] * Pm[i] / MS[i];
        if (cp && mLn[i] > 0)
          v[2] += 0.5 * PL[i] * PL[i] / mLn[i];
      }
    v[3] = s.local_sums.gravity_potential;                     // of both masses (TwoPhase::step)
    if (dealii::Utilities::MPI::this_mpi_process(s.comm) == 0) // rigid plates, as in nodal_forces
      for (unsigned int k = 0; k < plate_run.size(); ++k)
        {
          if (s.prm.rigid_plates[k].control == RigidPlate<dim>::Control::force)
            v[0] += plate_run[k].unbalanced * plate_run[k].unbalanced;
          v[1] += plate_run[k].force * plate_run[k].force;
        }
    evaluate_convergence(s, v);
  }

  template <int dim>
  void
  LoadControl<dim>::nodal_accelerations(Solver &s)
  {
    // every rank takes the same path: the work of the reactions is summed over
    // the ranks below, also by a rank that owns none of the prescribed nodes (a
    // rank-local test here left the other ranks waiting in the sum: a prescribed
    // base velocity hung on 2 ranks)
    if (!any_friction && !any_prescribed && !any_plate)
      return;
    double *const       A    = s.nodal_a.begin();
    const double *const M    = s.nodal_mass.begin();
    const double *const Pm   = vt.begin();
    const double        beta = current->mass_scaling;
    wall_law(s, A, M, Pm, wall_state.data());
    // 2-phase: the pore liquid (nodal momentum at t, acceleration, mass Mbar_L)
    const bool    cp  = s.two_phase && s.two_phase->coupled;
    double *const AL  = cp ? s.two_phase->a_liquid.begin() : nullptr;
    const double *PL  = cp ? s.two_phase->p_liquid.begin() : nullptr;
    const double *mLn = cp ? s.two_phase->m_liquid_n.begin() : nullptr;
    // the rigid wall is impermeable: the liquid cannot flow into it (same
    // predictor test as the solid) but slides freely along it (a Darcy liquid
    // carries no shear stress); where the material has lifted off, nothing
    for (auto &n : friction_nodes)
      {
        n.liquid_stopped     = false;
        const unsigned int i = n.dofs[n.axis];
        if (!cp || !(mLn[i] > 0) || s.constrained[i])
          continue;
        const double v0 = PL[i] / mLn[i];
        if (n.side * (v0 + h * AL[i]) > 0 && !(lift.local_element(i) > lift_tolerance * n.h))
          {
            AL[i]            = -v0 / h;
            n.liquid_stopped = true;
          }
      }
    // prescribed nodal velocities: a = (vbar(t + dt) - v^t) / dt (both phases of
    // a 2-phase node); the work of the reaction goes to the external work
    double work = 0;
    for (const auto &p : prescribed_dofs)
      {
        const double m    = M[p.dof];
        const double vbar = prescribed_value(s, p);
        if (cp && mLn[p.dof] > 0)
          {
            const double anew = (vbar - PL[p.dof] / mLn[p.dof]) / h;
            work += beta * mLn[p.dof] * (anew - AL[p.dof]) * vbar * h;
            AL[p.dof] = anew;
          }
        if (!(m > 0))
          continue;
        const double anew = (vbar - Pm[p.dof] / m) / h;
        work += beta * m * (anew - A[p.dof]) * vbar * h;
        A[p.dof] = anew;
      }
    if (any_prescribed)
      s.external_work += dealii::Utilities::MPI::sum(work, s.comm);
    // rigid plates (after the friction walls and prescribed nodes: the plate
    // wins there): a = (V - v_i^t) / h along the axis, (0 - v_i^t) / h for the
    // tangential components of a rough plate; the plate's work was counted by
    // rigid_plate_balance
    if (any_plate && cp)
      {
        // the liquid's share of the plate nodes' balance, sum beta Mbar_L a_L per
        // plate and component (a_L of the 2-phase nodal solve), then V
        std::vector<double> liquid(s.prm.rigid_plates.size() * dim, 0.0);
        for (const auto &p : plate_dofs)
          if (plate_active[p.dof] && M[p.dof] > 0 && mLn[p.dof] > 0)
            liquid[p.condition * dim + p.component] += beta * mLn[p.dof] * AL[p.dof];
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(liquid), s.comm, dealii::ArrayView<double>(liquid));
        rigid_plate_velocities(s, liquid.data());
      }
    for (const auto &p : plate_dofs)
      if (plate_active[p.dof] && M[p.dof] > 0)
        {
          const auto  &pl      = s.prm.rigid_plates[p.condition];
          const bool   on_axis = p.component == pl.axis;
          const double V       = on_axis ? plate_run[p.condition].velocity : 0.0;
          A[p.dof]             = (V - Pm[p.dof] / M[p.dof]) / h;
          // impermeable: the pore liquid moves with the plate along its axis
          if (cp && on_axis && !pl.permeable && mLn[p.dof] > 0)
            AL[p.dof] = (V - PL[p.dof] / mLn[p.dof]) / h;
        }
  }

  template <int dim>
  void
  LoadControl<dim>::particle_velocities(Solver &s, const unsigned int affine)
  {
    if (particle_conditions.empty())
      return;
    using L         = PropertyLayout<dim>;
    const bool cp   = s.two_phase && s.two_phase->coupled;
    double     work = 0;
    // the velocity change of the points of a conditioned body, and its momentum
    // m_p dv_p (solid) and m_L dv_L (pore liquid) added to the nodal momentum
    auto source = [&](double *P, double(&w)[2], double(&dv)[2][dim]) {
      const unsigned int b   = static_cast<unsigned int>(P[L::body]);
      bool               hit = false;
      w[0]                   = P[L::mass];
      w[1]                   = 0.0;
      for (unsigned int d = 0; d < dim; ++d)
        dv[0][d] = dv[1][d] = 0.0;
      for (const unsigned int j : particle_conditions)
        {
          const auto &pv = current->velocities[j];
          if (pv.body != b)
            continue;
          hit            = true;
          const double t = (j < current->n_global_velocities ? s.time : s.time - stage_t0) + h;
          const double f = pv.function.value(t);
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double change = pv.component[d] ? pv.velocity[d] * f - P[L::velocity + d] : 0.0;
              P[L::velocity + d] += change;
              dv[0][d] += change;
              work += P[L::mass] * change * P[L::velocity + d];
              // APIC: the prescribed field is uniform over the body, its gradient 0
              if (affine && pv.component[d])
                for (unsigned int k = 0; k < dim; ++k)
                  P[affine + d * dim + k] = 0.0;
            }
          // 2-phase point: its pore liquid moves with the body as well
          const double mL = cp ? s.two_phase->liquid_mass(P) : 0.0;
          if (mL > 0)
            {
              w[1] = mL;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  double      &vl     = P[s.two_phase->liquid_velocity + d];
                  const double change = pv.component[d] ? pv.velocity[d] * f - vl : 0.0;
                  vl += change;
                  dv[1][d] += change;
                  work += mL * change * vl;
                }
            }
        }
      return hit;
    };
    if (affine) // APIC: the caller projects the points' (v_p, C_p) anew
      {
        double w[2], dv[2][dim];
        transfer::for_each_point(s.points, [&](const unsigned int, transfer::PointIterator<dim> &it) {
          source(it->get_properties().data(), w, dv);
        });
        s.external_work += dealii::Utilities::MPI::sum(work, s.comm);
        return;
      }
    s.with_kernel([&](auto kernel) {
      transfer::ScatterPointVectors<dim, decltype(kernel), decltype(source), 2> op(
        s.grid, source, {{s.nodal_p.begin(), cp ? s.two_phase->p_liquid.begin() : nullptr}});
      transfer::for_each_active_cell(s.points, op);
    });
    s.nodal_p.compress(dealii::VectorOperation::add);
    if (cp)
      s.two_phase->p_liquid.compress(dealii::VectorOperation::add);
    s.external_work += dealii::Utilities::MPI::sum(work, s.comm);
  }

  template <int dim>
  void
  LoadControl<dim>::nodal_velocities(Solver &s)
  {
    double *const V = s.nodal_p.begin();
    wall_and_prescribed_velocities(s, V, wall_state.data());
    // 2-phase: the liquid's nodal velocities (after the division by Mbar_L)
    double *const VL = (s.two_phase && s.two_phase->coupled) ? s.two_phase->p_liquid.begin() : nullptr;
    if (VL)
      {
        for (const auto &n : friction_nodes)
          if (n.liquid_stopped && n.side * VL[n.dofs[n.axis]] > 0)
            VL[n.dofs[n.axis]] = 0; // no flow into the wall
        for (const auto &p : prescribed_dofs)
          VL[p.dof] = V[p.dof];
      }
    for (const auto &p : plate_dofs)
      if (plate_active[p.dof] && s.nodal_mass.local_element(p.dof) > 0)
        {
          const auto &pl      = s.prm.rigid_plates[p.condition];
          const bool  on_axis = p.component == pl.axis;
          V[p.dof]            = on_axis ? plate_run[p.condition].velocity : 0.0;
          if (VL && on_axis && !pl.permeable && s.two_phase->m_liquid_n.local_element(p.dof) > 0)
            VL[p.dof] = V[p.dof];
        }
  }

  template <int dim>
  double
  LoadControl<dim>::prescribed_value(const Solver &s, const PrescribedNodeDof &p) const
  {
    const auto  &pv = current->velocities[p.condition];
    const double t  = (p.condition < current->n_global_velocities ? s.time : s.time - stage_t0) + h;
    return pv.velocity[p.component] * pv.function.value(t);
  }

  template <int dim>
  void
  LoadControl<dim>::wall_law(const Solver &s, double *A, const double *M, const double *P, unsigned char *state) const
  {
    // frictional contact with a rigid fixed boundary: seed 000 Eqs. 6.4-6.21
    // with the other body at rest (v = 0): predicted v* = v^t + dt a; if it
    // moves into the wall, the normal component is removed and the tangential
    // one is reduced by mu |v*_n| + a A dt / m (stick if that stops it).
    const double mu = current->friction_coefficient, adh = current->adhesion;
    const double beta = current->mass_scaling;
    for (unsigned int k = 0; k < friction_nodes.size(); ++k)
      {
        const auto  &n = friction_nodes[k];
        const double m = M[n.dofs[0]];
        state[k]       = 0;
        if (!(m > 0))
          continue;
        double v0[dim], vs[dim];
        for (unsigned int d = 0; d < dim; ++d)
          {
            const bool fixed = s.constrained[n.dofs[d]];
            v0[d]            = fixed ? 0.0 : P[n.dofs[d]] / m;
            vs[d]            = fixed ? 0.0 : v0[d] + h * A[n.dofs[d]];
          }
        const double vn = n.side * vs[n.axis];
        if (!(vn > 0))
          continue; // separating: no correction
        // the material at this node has moved away from the wall (a gap): free.
        // Without this test the node blocks every motion towards the wall even
        // after the material lifted off, so velocity noise is rectified into a
        // drift away from the wall (a block sliding on the floor rose 3.8 mm).
        if (lift.local_element(n.dofs[n.axis]) > lift_tolerance * n.h)
          continue;
        vs[n.axis] = 0;
        double vt2 = 0;
        for (unsigned int d = 0; d < dim; ++d)
          vt2 += vs[d] * vs[d];
        const double vtan   = std::sqrt(vt2);
        const double budget = mu * vn + adh * n.area * h / (beta * m);
        if (vtan <= budget)
          {
            state[k] = 1; // stick
            for (unsigned int d = 0; d < dim; ++d)
              vs[d] = 0;
          }
        else
          {
            state[k]        = 2; // slip
            const double fr = 1.0 - budget / vtan;
            for (unsigned int d = 0; d < dim; ++d)
              vs[d] *= fr;
          }
        for (unsigned int d = 0; d < dim; ++d)
          if (!s.constrained[n.dofs[d]])
            A[n.dofs[d]] = (vs[d] - v0[d]) / h;
      }
  }

  template <int dim>
  void
  LoadControl<dim>::wall_and_prescribed_velocities(const Solver &s, double *V, const unsigned char *state) const
  {
    for (unsigned int k = 0; k < friction_nodes.size(); ++k)
      if (state[k] != 0)
        {
          const auto &n = friction_nodes[k];
          if (n.side * V[n.dofs[n.axis]] > 0)
            V[n.dofs[n.axis]] = 0; // no penetration
          if (state[k] == 1)
            for (unsigned int d = 0; d < dim; ++d)
              V[n.dofs[d]] = 0; // stick
        }
    for (const auto &p : prescribed_dofs)
      V[p.dof] = prescribed_value(s, p);
  }

  template <int dim>
  void
  LoadControl<dim>::body_accelerations(const Solver &s, double *A, const double *M, const double *P,
                                       std::vector<unsigned char> &wall) const
  {
    wall.assign(friction_nodes.size(), 0);
    wall_law(s, A, M, P, wall.data());
    for (const auto &p : prescribed_dofs)
      if (M[p.dof] > 0)
        A[p.dof] = (prescribed_value(s, p) - P[p.dof] / M[p.dof]) / h;
  }

  template <int dim>
  void
  LoadControl<dim>::body_velocities(const Solver &s, double *V, const std::vector<unsigned char> &wall) const
  {
    wall_and_prescribed_velocities(s, V, wall.data());
  }

  // ---------------------------------------------------------------- rigid plates
  template <int dim>
  void
  LoadControl<dim>::setup_rigid_plates(Solver &s)
  {
    const auto &plates = s.prm.rigid_plates;
    this->plates       = &plates;
    plate_run.assign(plates.size(), PlateRun());
    if (plates.empty())
      return;
    // the shared node checks (exit 2 naming the plate) of every stage's walls
    std::vector<std::vector<BoundaryCondition>> walls;
    std::vector<std::string>                    names;
    for (const auto &st : settings.stages)
      walls.push_back(st.boundary_conditions), names.push_back(st.name);
    const auto counts = check_rigid_plate_nodes(s.grid, plates, walls, names, s.comm);
    for (unsigned int k = 0; k < plates.size(); ++k)
      {
        const auto &pl = plates[k];
        PlateRun   &r  = plate_run[k];
        r.force        = pl.control == RigidPlate<dim>::Control::force ? pl.force_at(s.time) : 0.0;
        log() << rigid_plate_log_line(pl, k, counts[k]) << std::endl;
      }
  }

  template <int dim>
  void
  LoadControl<dim>::rigid_plate_balance(Solver &s, const double *F, const double *M)
  {
    const auto        &plates  = s.prm.rigid_plates;
    const unsigned int n_owned = s.nodal_mass.locally_owned_size();
    // the nodes of this step (a DoF off the active list may hold a stale mass)
    plate_active.assign(n_owned, 0);
    for (const unsigned int i : s.active_dofs)
      plate_active[i] = 1;
    // per plate (plate_sum_size values): M_P, F_P, P_P along the axis, the
    // pore liquid's Mbar_L and momentum along the axis (coupled 2-phase), then
    // F_d, P_d per component (the tangential reaction of a rough plate)
    const bool    cp  = s.two_phase && s.two_phase->coupled;
    const double *mLn = cp ? s.two_phase->m_liquid_n.begin() : nullptr;
    const double *PL  = cp ? s.two_phase->p_liquid.begin() : nullptr;
    plate_sum.assign(plates.size() * plate_sum_size, 0.0);
    const double *const Pm = vt.begin();
    for (const auto &p : plate_dofs)
      if (plate_active[p.dof] && M[p.dof] > 0)
        {
          double *q = &plate_sum[p.condition * plate_sum_size];
          if (p.component == plates[p.condition].axis)
            {
              q[0] += M[p.dof];
              q[1] += F[p.dof];
              q[2] += Pm[p.dof];
              if (cp && mLn[p.dof] > 0)
                {
                  q[3] += mLn[p.dof];
                  q[4] += PL[p.dof];
                }
            }
          else
            {
              q[5 + p.component] += F[p.dof];
              q[5 + dim + p.component] += Pm[p.dof];
            }
        }
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(plate_sum), s.comm,
                                dealii::ArrayView<double>(plate_sum));
    if (!cp) // else after the liquid's accelerations (nodal_accelerations)
      rigid_plate_velocities(s, nullptr);
  }

  template <int dim>
  void
  LoadControl<dim>::rigid_plate_velocities(Solver &s, const double *liquid)
  {
    const auto  &plates = s.prm.rigid_plates;
    const double beta = current->mass_scaling, alpha = current->damping, av = current->viscous_damping;
    for (unsigned int k = 0; k < plates.size(); ++k)
      {
        const auto   &pl = plates[k];
        const double *q  = &plate_sum[k * plate_sum_size];
        // the plate's inertia and its force: the solid alone (1-phase; a
        // permeable plate, through which the liquid flows with its own
        // acceleration a_L, carried by the solid's equation as -beta Mbar_L a_L),
        // or solid and liquid moving together (impermeable)
        const double *lq = liquid ? &liquid[k * dim] : nullptr; // sum beta Mbar_L a_L per component
        double        Mp = q[0], Fp = q[1], Pp = q[2];
        if (lq && pl.permeable)
          Fp -= lq[pl.axis];
        else if (lq)
          {
            Mp += q[3];
            Pp += q[4];
          }
        PlateRun &r = plate_run[k];
        double    V = 0;
        if (pl.control == RigidPlate<dim>::Control::force)
          {
            // M_P dV/dt = F_P + F_plate (+ local and viscous damping of the
            // plate's own unbalanced force and momentum); a plate without
            // material under it (M_P = 0) waits at rest
            r.force      = pl.force_at(s.time);
            double R     = Fp + r.force;
            r.unbalanced = R;
            if (alpha > 0)
              R += local_damping_force(alpha, R, Pp);
            R -= av * Pp;
            V = Mp > 0 ? Pp / Mp + h * R / (beta * Mp) : 0.0;
          }
        else
          {
            V       = (pl.displacement_at(s.time + h) - r.displacement) / h;
            r.force = beta * (Mp * V - Pp) / h - Fp; // sum (beta m a - f) over the nodes
          }
        if (pl.rough) // the liquid slides along the plate: its a_L enters as in the solid's equation
          {
            double t2 = 0;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != pl.axis)
                {
                  const double Rd = beta * (0.0 - q[5 + dim + d]) / h - q[5 + d] + (lq ? lq[d] : 0.0);
                  t2 += Rd * Rd;
                }
            r.tangential = std::sqrt(t2);
          }
        r.velocity = V;
        r.displacement += h * V;
        s.external_work += r.force * h * V; // identical on every rank
      }
  }

  template <int dim>
  std::vector<double>
  LoadControl<dim>::rigid_plate_series() const
  {
    std::vector<double> v;
    for (unsigned int k = 0; k < plate_run.size(); ++k)
      {
        v.push_back(plate_run[k].displacement);
        v.push_back(plate_run[k].force);
        if ((*plates)[k].rough)
          v.push_back(plate_run[k].tangential);
      }
    return v;
  }

  template <int dim>
  std::vector<double>
  LoadControl<dim>::rigid_plate_state() const
  {
    std::vector<double> v;
    for (const auto &r : plate_run)
      v.insert(v.end(), {r.displacement, r.velocity, r.force, r.tangential});
    return v;
  }

  template <int dim>
  void
  LoadControl<dim>::restore_rigid_plate_state(const std::vector<double> &v)
  {
    AssertThrow(v.size() == rigid_plate_state_size * plate_run.size(), dealii::ExcInternalError());
    for (unsigned int k = 0; k < plate_run.size(); ++k)
      {
        const double *x = &v[k * rigid_plate_state_size];
        plate_run[k]    = {x[0], x[1], x[2], x[3], 0.0};
      }
  }


  template class LoadControl<2>;
  template class LoadControl<3>;
} // namespace talus::loads
