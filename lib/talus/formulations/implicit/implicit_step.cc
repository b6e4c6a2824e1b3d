// talus — the implicit step (implicit_solver.h; docs/implicit.md "The step"):
// advance_by() is the driver of its phases, each a function of its own: the
// step's start (active set, constraints, loads, the external force scale),
// the predictor, Newton with the contact walls' active-set passes, the step's
// report, the reactions of the prescribed nodes and plates, the convective
// phase and the log line. Also the step's preparation, the lifted predictor of
// the prescribed DoFs and the tangent check of the tests.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/formulations/implicit/updated_lagrangian_ops.h>
#include <talus/loads/kinematics.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace talus::implicit_mpm
{
  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    StepState s = begin_step(h);
    if (!predict(s) || !solve_newton(s))
      return cut_back(s);
    report_newton(s);
    const NewtonResult &result = s.result;
    if (!result.converged)
      {
        log() << "  step " << step_number + 1 << " (t = " << time + h << "): Newton " << to_string(result.status)
              << " after " << result.iterations << " iterations (|r|: " << last.history << "); " << result.message
              << std::endl;
        return cut_back(s);
      }
    if (prm.negligible_mass > 0)
      measure_held_load(s);
    if (!apply_reactions(s))
      return cut_back(s);
    convective_phase(s);
    log_step(s);
    load_level = s.load_level;
    return StepOutcome::done;
  }

  template <int dim>
  StepOutcome
  Solver<dim>::cut_back(const StepState &s)
  {
    // a static step under constant loads: the retry's smaller step takes a
    // smaller share of the load still to apply (step_load_level); once the full
    // load is on and nothing else depends on the step size, the retry would
    // replay this failure exactly: stop instead
    if (cut_back_replays())
      throw RunStopped("step " + std::to_string(step_number + 1) + " (t = " + std::to_string(time + s.h) +
                       " s) failed under the full constant load ('implicit/ramp loads = false'), with nothing "
                       "else depending on the step size: a cut-back would retry the same problem, so the run "
                       "stops here (ramp the loads, or refine the grid or the Newton settings)");
    if (!dynamic() && !prm.ramp_loads)
      log() << "  step " << step_number + 1 << ": constant loads: the retry goes from load level " << load_level
            << " by half the share of this step (it went to " << s.load_level << ")" << std::endl;
    return StepOutcome::cut_back;
  }

  template <int dim>
  typename Solver<dim>::StepState
  Solver<dim>::begin_step(const double h)
  {
    newmark.set_time_step(h);
    prepare_step();
    if (!dynamic())
      {
        // the converged state under its own loads: a footing's base where it
        // stood at the end of the last step (at t + h its advance would enter
        // r_0, and the carry would cancel the step's load)
        if (point_contact)
          point_contact->set_time(time, time);
        measure_start_imbalance();
      }
    if (point_contact) // a footing's base to where it is at the step's start and end
      point_contact->set_time(time, time + h);
    const double                 level = step_load_level(h);
    const dealii::Tensor<1, dim> g     = apply_loads_at(time + h, level);
    if (dynamic() && prm.rayleigh_beta > 0)
      assemble_damping_stiffness(g);
    // the external force scale |f_ext| (lumped nodal masses times g)
    double f2 = 0, f1 = 0;
    for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
      {
        const unsigned int c = space.component(k);
        if (c < dim)
          {
            f2 += std::pow(mass.local_element(k) * g[c], 2);
            f1 += std::abs(mass.local_element(k) * g[c]);
          }
      }
    double f_ext = std::sqrt(dealii::Utilities::MPI::sum(f2, comm));
    f1           = dealii::Utilities::MPI::sum(f1, comm);
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
        f1    = residual.l1_norm();
      }
    // the plates' forces at t + h (their own time functions) join the scale
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        plate_target[k] = force_plate(k) ? prm.rigid_plates[k].force_at(time + h) : 0.0;
        plate_step[k]   = 0.0;
        plate_c[k]      = 0.0;
        f_ext           = std::sqrt(f_ext * f_ext + plate_target[k] * plate_target[k]);
        f1 += std::abs(plate_target[k]);
      }
    if (!dynamic()) // 0 where no load acts (displacement control): the norm is in its own column
      start_imbalance_share = f_ext > 0 ? start_imbalance_norm / f_ext : 0.0;
    StepState s;
    s.h          = h;
    s.g          = g;
    s.f_ext      = f_ext;
    s.f_ext_sum  = f1;
    s.load_level = level;
    return s;
  }

  template <int dim>
  void
  Solver<dim>::measure_start_imbalance()
  {
    // the converged state under the loads it converged with (level load_level
    // at the step's start time), assembled on this step's grid at du = 0
    carrying_imbalance             = false;
    const dealii::Tensor<1, dim> g = apply_loads_at(time, load_level);
    du                             = 0;
    du.update_ghost_values();
    if (prm.mixed_up) // the nodal pressure of the state, as the predictor projects it
      predict_pressure();
    assemble(false, g);
    start_imbalance = residual;
    // the displacement rows only: a mixed u-p pressure row is the constraint
    // p = p(J) of this step's projection, not a force
    if (prm.mixed_up)
      for (unsigned int k = 0; k < start_imbalance.locally_owned_size(); ++k)
        if (space.component(k) == dim)
          start_imbalance.local_element(k) = 0;
    // a DoF the last step held and this one frees (a footing's row the moving
    // region has left, a negligible node that gained mass, a released contact):
    // its out-of-balance force is the reaction of that hold, a load the step
    // must answer, not the grid change
    for (const auto i : held_last_step)
      start_imbalance[i] = 0;
    // relative to the step's load scale |f_ext| (begin_step divides)
    start_imbalance_norm = start_imbalance.l2_norm();
    du                   = 0;
    du.update_ghost_values();
    // not at the run's first step: there is no earlier grid, and an initial
    // state out of balance is a load of the problem, not of the grid change
    carrying_imbalance = prm.carry_imbalance && step_number > 0;
  }

  template <int dim>
  bool
  Solver<dim>::predict(const StepState &s)
  {
    const double                  h = s.h;
    const dealii::Tensor<1, dim> &g = s.g;

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
            return false;
          }
      }
    if (prm.mixed_up)
      predict_pressure();
    return true;
  }

  template <int dim>
  bool
  Solver<dim>::solve_newton(StepState &s)
  {
    const double                  h                     = s.h;
    const dealii::Tensor<1, dim> &g                     = s.g;
    const double                  f_ext                 = s.f_ext;
    unsigned int                 &linear_iterations     = s.linear_iterations;
    double                       &worst_linear_residual = s.worst_linear_residual;
    NewtonProblem                 problem;
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
    problem.slope               = [&]() { return delta * residual; };
    problem.residual_reference  = [&]() { return std::max(f_ext, lifted_residual); };
    // Newton, then (contact walls) the active set from the converged state's
    // reactions and penetrations; a change re-solves from there
    NewtonResult       &result     = s.result;
    unsigned int        iterations = 0;
    unsigned int       &passes = s.passes, &released = s.released, &added = s.added;
    std::ostringstream &pass_log = s.pass_log;
    s.any_contact                = dealii::Utilities::MPI::sum(contact_nodes.size(), comm) > 0;
    const bool any_contact       = s.any_contact;
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
            return false;
          }
        released += changed.first;
        added += changed.second;
        total_slip_switches += friction_changes;
        if (changed.first + changed.second + friction_changes == 0)
          break;
        pass_log << " [pass " << passes << ": " << changed.first << " released, " << changed.second << " in contact";
        if (coulomb_nodes())
          pass_log << ", " << friction_changes << " stick/slip changes or slip forces moved";
        pass_log << "]";
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
    return true;
  }

  template <int dim>
  void
  Solver<dim>::report_newton(const StepState &s)
  {
    const NewtonResult &result = s.result;
    const unsigned int  passes = s.passes, released = s.released, added = s.added;
    const unsigned int  linear_iterations = s.linear_iterations;
    const bool          any_contact       = s.any_contact;

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
        unsigned int n[2] = {0, 0}; // in contact, slipping
        for (const auto &c : contact_nodes)
          {
            const auto in = space.node_dof(c.node, c.axis);
            if (space.locally_owned_dofs().is_element(in) && contact_state(in) != 0.0 && mass(in) > 0 &&
                !active.constraints().is_constrained(in))
              {
                ++n[0];
                n[1] += contact_state(in) == 2.0 ? 1 : 0;
              }
          }
        dealii::Utilities::MPI::sum(dealii::ArrayView<const unsigned int>(n, 2), comm,
                                    dealii::ArrayView<unsigned int>(n, 2));
        last.contact_nodes    = n[0];
        last.contact_slipping = n[1];
        total_slip_node_steps += n[1];
      }
  }

  template <int dim>
  bool
  Solver<dim>::apply_reactions(const StepState &s)
  {
    const double                  h = s.h;
    const dealii::Tensor<1, dim> &g = s.g;

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
            return false;
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
    return true;
  }

  template <int dim>
  void
  Solver<dim>::record_held_dofs()
  {
    held_last_step.clear();
    const auto base  = step_constraints(nullptr, false, false, false, false);
    const auto owned = space.locally_owned_dofs();
    for (const auto i : owned)
      if (constraints.is_constrained(i) && !base.is_constrained(i))
        held_last_step.push_back(i);
  }

  template <int dim>
  void
  Solver<dim>::convective_phase(const StepState &s)
  {
    const double h = s.h;

    if (!dynamic() && prm.carry_imbalance)
      record_held_dofs(); // the final pass's constraints, before the points move

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
  }

  template <int dim>
  void
  Solver<dim>::log_step(const StepState &s)
  {
    const double              h      = s.h;
    const NewtonResult       &result = s.result;
    const unsigned int        passes = s.passes, released = s.released, added = s.added;
    const unsigned int        linear_iterations     = s.linear_iterations;
    const double              worst_linear_residual = s.worst_linear_residual;
    const bool                any_contact           = s.any_contact;
    const std::ostringstream &pass_log              = s.pass_log;

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
    if (prm.negligible_mass > 0)
      log() << "; held (negligible mass) " << last.held_dofs << " DoFs carrying " << last.held_load_share << " |f_ext|";
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      log() << "; plate " << k << " displacement " << std::setprecision(8) << plate_displacement[k] << ", force "
            << (force_plate(k) ? plate_sum[k] : plate_reaction[k][prm.rigid_plates[k].axis]) << std::setprecision(6);
    if (any_contact)
      log() << "; contact: " << passes << " pass(es), " << released << " released, " << added << " in contact again, "
            << last.contact_nodes << " nodes in contact"
            << (coulomb_nodes() ? " (" + std::to_string(last.contact_slipping) + " slipping)" : std::string())
            << pass_log.str();
    log() << std::endl;
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
    typename ActiveSet<dim>::ExtraCouplings ghost_couplings;
    if (prm.ghost_penalty > 0)
      {
        double modulus = 0;
        for (const auto &m : prm.materials)
          modulus = std::max(modulus, m->constrained_modulus());
        ghost_stiffness = prm.ghost_penalty * modulus;
        ghost_couplings = [&](dealii::DynamicSparsityPattern &dsp) { ghost.find_faces(active, space, dsp); };
      }
    with_kernel([&](auto k) {
      active.template reinit<decltype(k)>({&points}, ActiveSet<dim>::Couplings::skip, reach, ghost_couplings);
    });
    active.reinit_matrix(tangent);
    project_to_grid();
    find_negligible_nodes();
    // the walls' fixed and roller DoFs as homogeneous constraints on the
    // increment, merged with the pins of the inactive DoFs
    contact_changes.assign(contact_nodes.size(), 0);
    friction_flips.assign(contact_nodes.size(), 0);
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
  double
  Solver<dim>::tangent_error(const double h, const double scale, const double eps, const double pressure_scale)
  {
    newmark.set_time_step(h);
    prepare_step();
    const dealii::Tensor<1, dim> g = apply_loads_at(time + h, step_load_level(h));
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

  template StepOutcome Solver<2>::advance_by(const double);
  template double      Solver<2>::tangent_error(const double, const double, const double, const double);
  template StepOutcome Solver<3>::advance_by(const double);
  template double      Solver<3>::tangent_error(const double, const double, const double, const double);
} // namespace talus::implicit_mpm
