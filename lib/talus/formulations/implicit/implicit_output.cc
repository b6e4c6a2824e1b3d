// talus — the implicit Solver's diagnostics and files (implicit_solver.h): the
// stability check, the series columns and values, the points' .vtu/.pvd files,
// the checkpoints (write, restore), the final particle table and the run's
// summary with its timings.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/diagnostics.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/point_output.h>
#include <talus/formulations/common/results_file.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/io/output.h>
#include <talus/loads/rigid_plate.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <iomanip>

namespace talus::implicit_mpm
{
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
    if (prm.negligible_mass > 0)
      for (const char *n : {"held_dofs", "held_load_share"})
        c.push_back(n);
    if (!dynamic())
      for (const char *n : {"start_imbalance_norm", "start_imbalance"})
        c.push_back(n);
    probes.add_columns(c, points.layout);
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
    if (prm.negligible_mass > 0)
      {
        v.push_back(after_step ? double(last.held_dofs) : 0.0);
        v.push_back(after_step ? last.held_load_share : 0.0);
      }
    if (!dynamic())
      {
        v.push_back(after_step ? start_imbalance_norm : 0.0);
        v.push_back(after_step ? start_imbalance_share : 0.0);
      }
    probes.sample(points);
    probes.add_values(v, comm);
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
        f.set_attribute("load level", load_level);
        for (unsigned int k = 0; k < plate_displacement.size(); ++k)
          {
            // the plate's state, and its last reaction for the series
            f.set_attribute("plate " + std::to_string(k) + " displacement", plate_displacement[k]);
            for (unsigned int d = 0; d < dim; ++d)
              f.set_attribute("plate " + std::to_string(k) + " reaction " + std::to_string(d), plate_reaction[k][d]);
          }
        if (!prm.contact_ids.empty() && !prm.contact_on_points) // (collective)
          {
            // the contact walls on the nodes: each owned node's state and friction force
            // (rows: normal DoF, state, the dim components of the friction force)
            std::vector<double> rows;
            const auto         &owned = space.locally_owned_dofs();
            for (const auto &c : contact_nodes)
              {
                const auto in = space.node_dof(c.node, c.axis);
                if (!owned.is_element(in))
                  continue;
                rows.push_back(double(in));
                rows.push_back(contact_state(in));
                for (unsigned int d = 0; d < dim; ++d)
                  rows.push_back(contact_friction(space.node_dof(c.node, d)));
              }
            f.write_rows("contact_nodes", rows, 2 + dim);
          }
        write_points(f, points);
        probes.write_ids(f);
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
    // (absent in checkpoints written before the constant-load level: full)
    load_level = fp->has_attribute("load level") ? fp->get_double("load level") : 1.0;
    for (unsigned int k = 0; k < plate_displacement.size(); ++k)
      {
        plate_displacement[k] = fp->get_double("plate " + std::to_string(k) + " displacement");
        for (unsigned int d = 0; d < dim; ++d)
          plate_reaction[k][d] = fp->get_double("plate " + std::to_string(k) + " reaction " + std::to_string(d));
      }
    restored_contact.clear();
    if (fp->exists("contact_nodes")) // the node walls' state (applied when the vectors are set up)
      restored_contact = fp->read_all("contact_nodes");
    balance.restore(*fp); // same ranks: the saved partition, before the points go in
    read_points(*fp, points, grid, "checkpoint " + fp->path());
    if (!prm.probes.empty()) // the points the run tracked (its ids saved)
      {
        probes.read_ids(*fp, "checkpoint " + fp->path());
        require(probes.ids.size() == prm.probes.size(), "output/probes",
                "the checkpoint " + fp->path() + " tracks " + std::to_string(probes.ids.size()) +
                  " probe(s), the .prm lists " + std::to_string(prm.probes.size()) +
                  "; allowed: the probes of the checkpointed run");
      }
    pvd_records = read_pvd_records(*fp, "output/pvd", "particles");
    return true;
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &series_csv)
  {
    if (prm.final_particles_csv)
      write_final_points_csv(points, prm.output_directory, comm);
    if (!prm.results_file.empty())
      {
        ResultsFileInfo info;
        info.path        = prm.results_file;
        info.integration = "implicit";
        info.time        = time;
        info.steps       = step_number;
        write_results_file(info, grid, points, probes.ids, series_csv, comm);
      }
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
    if (coulomb_nodes())
      log() << "  contact friction (Coulomb mu = " << prm.contact_mu << ", nodes): " << total_slip_node_steps
            << " node-steps slipping, " << total_slip_switches << " stick/slip changes or slip-force updates"
            << std::endl;
    log() << "  breakdown [s]: assembly " << seconds_assembly << " (" << n_assemblies << "), linear solve "
          << seconds_solve << " (" << n_solves << "), convective phase " << seconds_commit << ", output " << t.output
          << std::endl;
    log() << "  assembly CPU time [s]: " << cpu_seconds_assembly
          << " (this thread's CPU clock; the wall time above also counts waits for a core)" << std::endl;
    if (any_force_plate())
      log() << "  rigid plates: the Newton solves " << seconds_plates_solve
            << " s (1 + number of force plates right-hand sides each, within the linear solve above), the products "
               "K e, K^T e, the row and column zeroing and the combination "
            << seconds_plates << " s" << std::endl;
  }

  template void                     Solver<2>::check_stability() const;
  template std::vector<std::string> Solver<2>::series_columns() const;
  template std::vector<double>      Solver<2>::series_values(const bool);
  template void                     Solver<2>::write_vtu(const unsigned int);
  template std::string              Solver<2>::write_checkpoint();
  template void                     Solver<2>::rewrite_records();
  template bool                     Solver<2>::restore_checkpoint();
  template void                     Solver<2>::finish(const std::string &);
  template void                     Solver<2>::summary(const LoopTimings &);
  template void                     Solver<3>::check_stability() const;
  template std::vector<std::string> Solver<3>::series_columns() const;
  template std::vector<double>      Solver<3>::series_values(const bool);
  template void                     Solver<3>::write_vtu(const unsigned int);
  template std::string              Solver<3>::write_checkpoint();
  template void                     Solver<3>::rewrite_records();
  template bool                     Solver<3>::restore_checkpoint();
  template void                     Solver<3>::finish(const std::string &);
  template void                     Solver<3>::summary(const LoopTimings &);
} // namespace talus::implicit_mpm
