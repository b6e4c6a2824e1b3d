// talus — the implicit step's constraints (implicit_solver.h): the contact
// walls on the grid nodes (the gaps at the step's start, the active set from
// the converged state's reactions and penetrations), the constraints of a
// step (walls, contact, prescribed DoFs, nodes of negligible mass, the inactive
// pins), the prescribed increments and the reactions of the prescribed nodes
// and the rigid plates.
#include <talus/base/errors.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/loads/kinematics.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

namespace talus::implicit_mpm
{
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
        const auto   xi   = pt.get_reference_location();
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            const int k = node_contact[cc.dofs[v * dim]];
            if (k < 0)
              continue;
            const auto &c = contact_nodes[k];
            // a point counts for the wall node nearest to it along the wall (its
            // tangential reference coordinates within half a cell of the node's):
            // counted for every node of its cell it held the material a cell
            // wide about each node, so that a rolling body rocked over the
            // held patch (docs/implicit.md, "Rolling disk")
            bool near = true;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != c.axis && std::abs(xi[d] - double((v >> d) & 1)) > 0.5)
                near = false;
            if (!near)
              continue;
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
            for (unsigned int d = 0; d < dim; ++d)
              contact_friction(space.node_dof(c.node, d)) = 0.0;
            ++left;
          }
      }
    contact_state.update_ghost_values();
    contact_friction.update_ghost_values();
    gap_releases += dealii::Utilities::MPI::sum(left, comm);
  }

  template <int dim>
  dealii::AffineConstraints<double>
  Solver<dim>::step_constraints(const std::vector<double> *values, const bool with_contact, const bool with_prescribed,
                                const bool hold_plates, const bool hold_negligible) const
  {
    // the contact nodes now in contact: their normal DoF, with no slip all
    std::vector<dealii::types::global_dof_index> held;
    if (with_contact)
      for (const auto &c : contact_nodes)
        {
          const auto in = space.node_dof(c.node, c.axis);
          if (contact_state(in) == 0.0)
            continue;
          // the tangential DoFs: held with no slip and on a sticking Coulomb
          // node, free when frictionless and on a slipping Coulomb node
          const bool stick = prm.contact_no_slip || (coulomb_nodes() && contact_state(in) == 1.0);
          for (unsigned int d = 0; d < dim; ++d)
            if (d == c.axis || stick)
              held.push_back(space.node_dof(c.node, d));
        }
    if (hold_negligible)
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
  Vector
  Solver<dim>::residual_under(dealii::AffineConstraints<double> &other, const dealii::Tensor<1, dim> &g)
  {
    // r = f_int + m a - f_ext at the iterate du, assembled under `other` in
    // place of the step's constraints: at a DoF the step holds and `other`
    // leaves free it is the force that hold exerts (the contact, prescribed and
    // negligible-mass reactions). The step's constraints and residual are
    // unchanged on return, also when the assembly throws.
    Vector kept(residual);
    std::swap(constraints, other); // `other` holds the step's constraints until swapped back
    try
      {
        assemble(false, g);
        // 'carry start imbalance' belongs to the DoFs the step solves for: at a DoF the
        // step holds the reaction is the whole force, so give the carried part back
        // (subtracted, the plate and contact reactions read as their increment only)
        if (carrying_imbalance)
          {
            const auto &owned = space.locally_owned_dofs();
            for (unsigned int k = 0; k < residual.locally_owned_size(); ++k)
              {
                const auto i = owned.nth_index_in_set(k);
                if (other.is_constrained(i) && !constraints.is_constrained(i))
                  residual.local_element(k) += start_imbalance.local_element(k);
              }
          }
      }
    catch (...)
      {
        std::swap(constraints, other);
        residual.swap(kept);
        throw;
      }
    std::swap(constraints, other);
    residual.swap(kept);
    return kept;
  }

  template <int dim>
  std::pair<unsigned int, unsigned int>
  Solver<dim>::update_contact(const dealii::Tensor<1, dim> &g, const double force_scale)
  {
    // the residual assembled without the contact constraints: at a contact
    // DoF it is the force the wall must exert on the node, r = f_int + m a - f_ext
    auto         free_contact = step_constraints(nullptr, false);
    const Vector r            = residual_under(free_contact, g);
    const auto  &owned        = space.locally_owned_dofs();
    const auto  &pins         = active.constraints();
    const double du_max       = du.linfty_norm();
    // a pull below 1e-8 of the load scale and a penetration below 1e-8 of the
    // largest increment are round-off of the Newton solve, not a change
    const double tol_pull = 1e-8 * force_scale, tol_in = 1e-8 * du_max;
    // a slip force that changed by less than 1e-6 of the load scale between two
    // passes has converged
    const double tol_friction = 1e-6 * force_scale;
    const bool   coulomb      = coulomb_nodes();
    const double mu           = prm.contact_mu;
    unsigned int released = 0, added = 0, friction = 0;
    for (std::size_t k = 0; k < contact_nodes.size(); ++k)
      {
        const auto &c  = contact_nodes[k];
        const auto  in = space.node_dof(c.node, c.axis);
        if (!owned.is_element(in) || pins.is_constrained(in) || free_contact.is_constrained(in) || mass(in) == 0)
          continue;
        if (contact_changes[k] < 2) // changed twice in this step: held
          {
            if (contact_state(in) != 0.0)
              {
                // compressive: the wall pushes the node into the domain, r . n_out < 0
                if (r(in) * c.sign > tol_pull)
                  {
                    contact_state(in) = 0.0;
                    for (unsigned int d = 0; d < dim; ++d)
                      contact_friction(space.node_dof(c.node, d)) = 0.0;
                    ++contact_changes[k];
                    ++released;
                    continue;
                  }
              }
            else if (du(in) * c.sign > tol_in && contact_gap(in) <= contact_gap_tolerance(c))
              {
                contact_state(in) = 1.0; // in contact, sticking
                ++contact_changes[k];
                ++added;
                continue; // its reactions come from the next solve
              }
          }
        if (!coulomb || contact_state(in) == 0.0)
          continue;
        // Coulomb: the wall's tangential force on the node is r_t (sticking: the
        // reaction of the held tangential DoFs; slipping: ~0 plus the friction
        // force already applied), its normal force -r_n . n_out >= 0
        const double           normal = std::max(0.0, -r(in) * c.sign);
        const double           limit  = mu * normal;
        dealii::Tensor<1, dim> rt, slip, f_old;
        for (unsigned int d = 0; d < dim; ++d)
          if (d != c.axis)
            {
              const auto i = space.node_dof(c.node, d);
              rt[d]        = r(i) + contact_friction(i);
              slip[d]      = du(i);
              f_old[d]     = contact_friction(i);
            }
        dealii::Tensor<1, dim> f_new;
        if (contact_state(in) == 1.0)
          {
            if (rt.norm() <= limit + tol_pull || friction_flips[k] >= 4)
              continue;
            // sticks no more: slips against the direction the wall had to hold it
            f_new             = limit * rt / rt.norm();
            contact_state(in) = 2.0;
            ++friction_flips[k];
            ++friction;
          }
        else
          {
            // slipping: the increment's tangential part is the slip; a slip
            // along the friction force (reversed) sticks again
            if (slip * f_old > 0 && friction_flips[k] < 4)
              {
                contact_state(in) = 1.0;
                for (unsigned int d = 0; d < dim; ++d)
                  contact_friction(space.node_dof(c.node, d)) = 0.0;
                ++friction_flips[k];
                ++friction;
                continue;
              }
            const double s = slip.norm();
            f_new          = s > 0 ? -limit * slip / s : (f_old.norm() > 0 ? limit * f_old / f_old.norm() : f_old);
            // the force follows the normal reaction (a fixed point over the passes)
            if ((f_new - f_old).norm() > tol_friction)
              ++friction;
          }
        for (unsigned int d = 0; d < dim; ++d)
          if (d != c.axis)
            contact_friction(space.node_dof(c.node, d)) = f_new[d];
      }
    contact_state.update_ghost_values();
    contact_friction.update_ghost_values();
    friction_changes = dealii::Utilities::MPI::sum(friction, comm);
    return {dealii::Utilities::MPI::sum(released, comm), dealii::Utilities::MPI::sum(added, comm)};
  }

  template <int dim>
  void
  Solver<dim>::reset_contact_state()
  {
    // every contact node starts in contact and sticking (released in the first
    // step where the wall would pull on it); a restart takes its saved state
    contact_state                                                = 1.0;
    contact_friction                                             = 0.0;
    const auto                                            &owned = space.locally_owned_dofs();
    const unsigned int                                     cols  = 2 + dim;
    std::map<dealii::types::global_dof_index, std::size_t> by_dof; // normal DoF -> contact node
    if (!restored_contact.empty())
      for (std::size_t k = 0; k < contact_nodes.size(); ++k)
        by_dof[space.node_dof(contact_nodes[k].node, contact_nodes[k].axis)] = k;
    for (std::size_t row = 0; row + cols <= restored_contact.size(); row += cols)
      {
        const auto in = static_cast<dealii::types::global_dof_index>(restored_contact[row]);
        const auto it = by_dof.find(in);
        if (!owned.is_element(in) || it == by_dof.end())
          continue;
        const auto &c     = contact_nodes[it->second];
        contact_state(in) = restored_contact[row + 1];
        for (unsigned int d = 0; d < dim; ++d)
          contact_friction(space.node_dof(c.node, d)) = restored_contact[row + 2 + d];
      }
    restored_contact.clear();
    contact_state.update_ghost_values();
    contact_friction.update_ghost_values();
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
    auto         free_prescribed = step_constraints(nullptr, true, false);
    const Vector r               = residual_under(free_prescribed, g);
    const auto  &owned           = space.locally_owned_dofs();
    const auto  &pins            = active.constraints();
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
        f[slot * dim + p.component] += r(i);
      }
    dealii::Utilities::MPI::sum(f, comm, f);
    for (unsigned int d = 0; d < dim; ++d)
      last.prescribed_force[d] = f[d];
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        plate_reaction[k][d] = f[(1 + k) * dim + d];
  }

  template <int dim>
  void
  Solver<dim>::measure_held_load(const StepState &s)
  {
    // the residual assembled with no hold at all (only the pins of the inactive
    // DoFs): at a constrained DoF (wall, prescribed, contact, held) it is the
    // force the constraint exerts, at a free one ~0. The held DoFs' share of
    // all the forces on the nodes, loads and reactions, says how much of the
    // answer the hold decides: with it small the answer is the posed problem's.
    last.held_dofs       = 0;
    last.held_load_share = 0;
    if (dealii::Utilities::MPI::sum(negligible_dofs.size(), comm) == 0) // collective: the same on every rank
      return;
    dealii::AffineConstraints<double> bare; // (no copy constructor in 9.4)
    bare.copy_from(active.constraints());
    const Vector                                 r = residual_under(bare, s.g);
    std::vector<dealii::types::global_dof_index> held(negligible_dofs); // relevant DoFs: a node once
    std::sort(held.begin(), held.end());
    held.erase(std::unique(held.begin(), held.end()), held.end());
    const auto  &owned   = space.locally_owned_dofs();
    const auto  &pins    = active.constraints();
    double       sums[2] = {0, 0}; // held, all
    unsigned int n       = 0;
    for (unsigned int k = 0; k < r.locally_owned_size(); ++k)
      if (space.component(k) < dim && !pins.is_constrained(owned.nth_index_in_set(k)))
        sums[1] += std::abs(r.local_element(k));
    // a light node's DoF that a wall, a prescribed line or contact holds keeps
    // that line (find_negligible_nodes): its force is that condition's reaction
    const auto unheld = step_constraints(nullptr, true, true, false, false);
    for (const auto i : held)
      if (owned.is_element(i) && space.component(owned.index_within_set(i)) < dim && !unheld.is_constrained(i))
        {
          sums[0] += std::abs(r(i));
          ++n;
        }
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums, 2), comm, dealii::ArrayView<double>(sums, 2));
    last.held_dofs       = dealii::Utilities::MPI::sum(n, comm);
    last.held_load_share = sums[0] / std::max(s.f_ext_sum + sums[1], 1e-300);
    if (last.held_load_share > prm.negligible_load_limit)
      {
        std::ostringstream os;
        os << "step " << step_number + 1 << " (t = " << time + s.h << "): the " << last.held_dofs
           << " displacement DoFs held by 'implicit/negligible nodal mass = " << prm.negligible_mass << "' carry "
           << std::setprecision(3) << last.held_load_share << " of the forces on the nodes (loads " << s.f_ext_sum
           << " N, reactions " << sums[1]
           << " N, summed magnitudes; limit 'implicit/negligible mass load limit' = " << prm.negligible_load_limit
           << "): the converged answer is not that of the posed problem. Lower 'negligible nodal mass' (0 = off), "
              "refine the load steps, or raise the limit knowingly.";
        throw RunStopped(os.str());
      }
  }

  template void                                  Solver<2>::measure_contact_gaps();
  template dealii::AffineConstraints<double>     Solver<2>::step_constraints(const std::vector<double> *, const bool,
                                                                             const bool, const bool, const bool) const;
  template void                                  Solver<2>::find_negligible_nodes();
  template std::pair<unsigned int, unsigned int> Solver<2>::update_contact(const dealii::Tensor<1, 2> &, const double);
  template void                                  Solver<2>::reset_contact_state();
  template dealii::Tensor<1, 2>                  Solver<2>::condition_increment(const unsigned int, const double) const;
  template double Solver<2>::prescribed_increment(const loads::PrescribedNodeDof &, const double) const;
  template void   Solver<2>::prescribed_reaction(const dealii::Tensor<1, 2> &);
  template void   Solver<2>::measure_held_load(const StepState &);
  template Vector Solver<2>::residual_under(dealii::AffineConstraints<double> &, const dealii::Tensor<1, 2> &);
  template void   Solver<3>::measure_contact_gaps();
  template dealii::AffineConstraints<double>     Solver<3>::step_constraints(const std::vector<double> *, const bool,
                                                                             const bool, const bool, const bool) const;
  template void                                  Solver<3>::find_negligible_nodes();
  template std::pair<unsigned int, unsigned int> Solver<3>::update_contact(const dealii::Tensor<1, 3> &, const double);
  template void                                  Solver<3>::reset_contact_state();
  template dealii::Tensor<1, 3>                  Solver<3>::condition_increment(const unsigned int, const double) const;
  template double Solver<3>::prescribed_increment(const loads::PrescribedNodeDof &, const double) const;
  template void   Solver<3>::prescribed_reaction(const dealii::Tensor<1, 3> &);
  template void   Solver<3>::measure_held_load(const StepState &);
  template Vector Solver<3>::residual_under(dealii::AffineConstraints<double> &, const dealii::Tensor<1, 3> &);
} // namespace talus::implicit_mpm
