#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/affine_ops.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/input_checks.h>
#include <talus/formulations/explicit/with_kernel.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/point_output.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/io/output.h>
#include <talus/io/vtu.h>
#include <talus/io/png_snapshots.h>
#include <talus/loads/kinematics.h>
#include <talus/transfer/fbar.h>
#include <talus/transfer/point_ops.h>
#include <talus/transfer/stencil_ops.h>
#include <talus/materials/strain_increments.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/particles/data_out.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <type_traits>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

namespace talus::explicit_mpm
{
  // ================================================================ solver
  template <int dim>
  Solver<dim>::Solver(const Parameters<dim> &p, MPI_Comm c)
      : Simulation<dim>(p, p, c, {"points"})
      , prm(p)
      , points(*this->point_sets[0])
      , gravity(p.gravity)
      , pvd_records(this->point_set_records[0])
  {
  }

  template <int dim>
  Solver<dim>::~Solver() = default;

  template <int dim>
  double
  Solver<dim>::critical_time_step() const
  {
    // seed 000 Eq. 4.120 (solids), 4.121 (liquids, with the viscous limit), 4.129
    // (coupled 2-phase); for quads/hexes L_min is the smallest cell edge.
    double dt_min = std::numeric_limits<double>::max();
    for (const auto &c : critical_time_steps())
      dt_min = std::min(dt_min, c.dt);
    return dt_min;
  }

  template <int dim>
  std::vector<CriticalStep>
  Solver<dim>::critical_time_steps() const
  {
    auto r = explicit_mpm::critical_time_steps(prm.materials, prm.liquid.pore_liquid, grid.min_cell_size());
    // mass scaling (seed 000 Eq. 6.31, 1-phase solid): c / sqrt(beta), dt_cr x sqrt(beta)
    if (mass_scaling != 1.0)
      for (auto &c : r)
        {
          const double f = std::sqrt(mass_scaling);
          c.wave_speed /= f;
          c.dt *= f;
          c.dt_wave *= f;
          c.dt_other *= f;
          c.dt_4_122 *= f;
        }
    return r;
  }

  template <int dim>
  void
  Solver<dim>::setup()
  {
    this->make_grid();
    constrained = loads::wall_dof_flags(grid, prm.boundary_conditions);
    grid.reinit_vector(nodal_mass);
    grid.reinit_vector(nodal_a);
    grid.reinit_vector(nodal_p);

    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    points.layout.n_history = n_history;
    if (prm.loads.active() || !prm.rigid_plates.empty() || any_initial_stress(prm.initial_stress))
      {
        control = std::make_unique<loads::LoadControl<dim>>(prm.loads);
        control->extend_layout(points.layout);
        control->setup_rigid_plates(*this); // node checks (exit 2) and log lines, before any output
      }
    // 2-phase / traction properties and the free-surface flag: only when used
    if (prm.liquid.any_coupled() || prm.liquid.any_traction())
      {
        two_phase = std::make_unique<TwoPhase<dim>>(*this);
        two_phase->extend_layout(points.layout);
      }
    if (prm.liquid.free_surface_factor > 0)
      {
        free_surface = std::make_unique<FreeSurface<dim>>(*this, prm.liquid.free_surface_factor);
        free_surface->extend_layout(points.layout);
      }
    // APIC: the affine velocity matrix C_p, a point property of APIC runs only
    // (saved with the checkpoints like every property)
    if (prm.numerics.apic())
      affine_offset = points.layout.add_extra("affine_velocity", dim * dim);
    // F-bar: the point's dJbar of the step, written before the update pass reads it
    if (prm.numerics.fbar)
      {
        fbar_offset = points.layout.add_extra("smoothed_volume_increment", 1);
        grid.reinit_vector(nodal_dj);
      }
    points.initialize();
    if (prm.numerics.fem())
      fem =
        std::make_unique<FemIntegration<dim>>(*this, prm.numerics.integration == NumericsOptions::Integration::ul_fem);
    require(!two_phase || (!prm.numerics.extended_p2g() && prm.numerics.smoothing == NumericsOptions::Smoothing::none),
            "numerics/integration, numerics/strain smoothing, contact/pairs",
            "MPM-MIXED, strain smoothing and contact are available in the 1-phase step only (not with coupled "
            "2-phase materials or tractions); use integration = mpm, strain smoothing = none, no contact pairs");
    if (prm.numerics.contact())
      contact = std::make_unique<Contact<dim>>(grid, prm.numerics, prm.bodies.size(), prm.bspline(), prm.numerics.fbar,
                                               affine_offset);
    if (prm.numerics.smoothing != NumericsOptions::Smoothing::none)
      smoothing = std::make_unique<StrainSmoothing<dim>>(grid, prm.numerics.smoothing, prm.bspline(),
                                                         contact ? prm.bodies.size() : 1);

    const bool restored = restore_if_asked(prm, [this] { return restore_checkpoint(); });
    if (!restored)
      {
        const std::vector<double> density = material_densities(prm);
        // FEM: the cells these points occupy get Gauss points instead (fem.h)
        auto seeded = seed_scene_bodies(grid, prm.bodies, density, points, "material point", &prm, {}, fem != nullptr);
        if (fem)
          {
            seeded = fem->seed(density);
            require_seeded(prm.bodies, seeded.volume_per_body, "material point");
          }
        if (control)
          control->initial_state(*this); // K0 stresses, stage 0 (gravity, boundaries, mass scaling)
        if (points.layout.n_history)
          initialize_point_histories(prm.materials, points, points.layout.history);
        if (two_phase)
          two_phase->initialize_particles(); // restored points carry their 2-phase state
      }

    const double dt_cr = critical_time_step();
    if (restored)
      ; // the time step of the checkpointed run (bitwise continuation)
    else if (prm.time_step > 0)
      {
        if (prm.time_step > dt_cr && !prm.force_time_step)
          {
            std::ostringstream os;
            os << "time/time step: " << prm.time_step << " s exceeds the critical time step " << dt_cr
               << " s (L_min = " << grid.min_cell_size()
               << " m); lower it, or set 'force time step = true' to run anyway";
            throw InputError(os.str());
          }
        dt = prm.time_step;
      }
    else
      dt = prm.courant * dt_cr;

    // probes: nearest particle at t = 0 (ties: lowest id); restored: saved ids
    if (!restored)
      probes.select(points, prm.probes, comm);

    // energy scale for the instability floor: sum m c^2
    double local_scale = 0;
    for (const auto &pt : points.handler)
      {
        const auto  P = pt.get_properties();
        const auto &m = *prm.materials[static_cast<unsigned int>(P[PropertyLayout<dim>::material])];
        local_scale += P[PropertyLayout<dim>::mass] * m.constrained_modulus() / m.density();
      }
    total_mass_setup = total_mass();
    if (!restored)
      {
        energy_scale     = dealii::Utilities::MPI::sum(local_scale, comm);
        initial_energies = energies();
      }
    // load balancing: partition by points from the start (a restart on as many
    // ranks has recreated its saved partition instead)
    if (!balance.initial())
      collect_active_cells();
  }

  template <int dim>
  void
  Solver<dim>::collect_active_cells()
  {
    points.collect_active_cells();
    collect_active_dofs();
  }

  template <int dim>
  void
  Solver<dim>::collect_active_dofs()
  {
    // owned DoFs that can carry mass this step: those of active cells, plus the
    // owned DoFs other ranks contribute to (their particles' ghost nodes)
    const unsigned int n_owned = nodal_mass.locally_owned_size();
    if (dof_marker.size() != n_owned)
      dof_marker.assign(n_owned, 0);
    active_dofs.clear();
    const auto add = [&](const unsigned int i) {
      if (i < n_owned && !dof_marker[i])
        {
          dof_marker[i] = 1;
          active_dofs.push_back(i);
        }
    };
    if (prm.bspline()) // the nodes of the cells' patches (invalid outside the grid: skipped)
      for (const auto &ac : points.active_cells())
        {
          const unsigned int *dofs = grid.patch(ac.cell).dofs;
          for (unsigned int n = 0; n < BSplinePatch<dim>::n_slots; ++n)
            if (dofs[n * dim] < n_owned && !dof_marker[dofs[n * dim]]) // a node's components: all or none new
              for (unsigned int d = 0; d < dim; ++d)
                add(dofs[n * dim + d]);
        }
    else // a vertex's dim DoFs: all or none owned, all or none new (as for the patches)
      for (const auto &ac : points.active_cells())
        {
          const unsigned int *dofs = grid.cells.filled_entry(ac.cell).dofs;
          for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
            if (dofs[v * dim] < n_owned && !dof_marker[dofs[v * dim]])
              for (unsigned int d = 0; d < dim; ++d)
                add(dofs[v * dim + d]);
        }
    for (const auto &range : grid.partitioner->import_indices())
      for (unsigned int i = range.first; i < range.second; ++i)
        if (!dof_marker[i])
          {
            dof_marker[i] = 1;
            active_dofs.push_back(i);
          }
    for (const unsigned int i : active_dofs)
      dof_marker[i] = 0;
  }

  // ---------------------------------------------------------------- load balancing
  // (formulations/common/load_balance.h; grid_changed() is its rebuild)
  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    constrained = loads::wall_dof_flags(grid, prm.boundary_conditions);
    grid.reinit_vector(nodal_mass);
    grid.reinit_vector(nodal_a);
    grid.reinit_vector(nodal_p);
    if (fbar_offset)
      grid.reinit_vector(nodal_dj);
    dof_marker.clear();
    if (free_surface)
      free_surface->grid_changed();
    if (two_phase)
      two_phase->grid_changed();
    if (contact)
      contact->grid_changed();
    if (smoothing)
      smoothing->grid_changed(grid);
    if (fem)
      fem->grid_changed();
    collect_active_cells();
    if (control)
      control->grid_changed(*this); // nodes of prescribed velocities and friction
    p2g_ready = false;              // the next step starts with a full P2G
  }

  template <int dim>
  void
  Solver<dim>::zero_on_active(Vector &v) const
  {
    // only entries of active cells (and ghosts) can be non-zero: clear those
    // instead of the whole vector, so empty regions of the grid cost nothing
    v.zero_out_ghost_values();
    double *x = v.begin();
    for (const unsigned int i : active_dofs)
      x[i] = 0.0;
  }

  // ---------------------------------------------------------------- P2G (A)
  template <int dim>
  void
  Solver<dim>::p2g_mass_and_force()
  {
    if (fem)
      {
        fem->p2g_mass_and_force(); // Gauss points, current cell geometry (fem.cc)
        p2g_ready = true;
        return;
      }
    if (prm.numerics.extended_p2g())
      {
        p2g_extended(*this); // MPM-MIXED and/or per-body contact fields
        p2g_ready = true;
        return;
      }
    zero_on_active(nodal_mass);
    zero_on_active(nodal_a);
    with_kernel([&](auto kernel) {
      transfer::ScatterMassForce<dim, decltype(kernel)> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
      transfer::for_each_active_cell(points, p2g);
    });
    p2g_ready = true;
  }

  // ---------------------------------------------------------------- nodal a
  template <int dim>
  void
  Solver<dim>::nodal_acceleration()
  {
    nodal_mass.compress(dealii::VectorOperation::add);
    nodal_a.compress(dealii::VectorOperation::add);
    if (control)
      control->nodal_forces(*this); // tractions, convergence ratios, damping, mass scaling
    const double *M = nodal_mass.begin();
    double       *A = nodal_a.begin();
    for (const unsigned int i : active_dofs)
      A[i] = (M[i] > 0 && !constrained[i]) ? A[i] / M[i] : 0.0;
    if (control)
      control->nodal_accelerations(*this); // prescribed velocities, boundary friction
    nodal_a.update_ghost_values();
  }

  // ---------------------------------------------------------------- G2P + P2G (B)
  template <int dim>
  void
  Solver<dim>::g2p_velocity_p2g_momentum(const double h)
  {
    zero_on_active(nodal_p);
    with_kernel([&](auto kernel) {
      transfer::UpdateVelocityScatterMomentum<dim, decltype(kernel)> op{grid, nodal_a.begin(), nodal_p.begin(), h};
      transfer::for_each_active_cell(points, op);
    });
    nodal_p.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Solver<dim>::scatter_point_momentum(Vector &v)
  {
    zero_on_active(v);
    with_kernel([&](auto kernel) {
      if (affine_offset)
        {
          transfer::ScatterAffineMomentum<dim, decltype(kernel)> op(grid, v.begin(), affine_offset);
          transfer::for_each_active_cell(points, op);
        }
      else
        {
          transfer::ScatterMomentum<dim, decltype(kernel)> op(grid, v.begin());
          transfer::for_each_active_cell(points, op);
        }
    });
    v.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Solver<dim>::apic_nodal_velocity(const double h)
  {
    // p^t with the affine term, then the Lagrangian nodal velocity
    // v^L = p^t / m + h a (a after the loads: a prescribed node gets
    // a = (vbar - v^t) / h, so v^L = vbar there), as nodal_velocity() leaves it.
    // The loads' p^t of this step, when they scattered one, is the same P2G of
    // the same points (bitwise): copied instead of a second pass
    const Vector *pt = control ? control->point_momentum_at_t() : nullptr;
    if (pt)
      {
        nodal_p.zero_out_ghost_values();
        const double *src = pt->begin();
        double       *dst = nodal_p.begin();
        for (const unsigned int i : active_dofs)
          dst[i] = src[i];
      }
    else
      scatter_point_momentum(nodal_p);
    const double *M = nodal_mass.begin();
    const double *A = nodal_a.begin();
    double       *V = nodal_p.begin();
    for (const unsigned int i : active_dofs)
      V[i] = (M[i] > 0 && !constrained[i]) ? V[i] / M[i] + h * A[i] : 0.0;
    if (control)
      control->nodal_velocities(*this);
    nodal_p.update_ghost_values();
  }

  template <int dim>
  void
  Solver<dim>::apic_body_velocities()
  {
    with_kernel([&](auto kernel) {
      transfer::ApicVelocity<dim, decltype(kernel)> op(grid, nodal_p.begin(), affine_offset);
      transfer::for_each_active_cell(points, op);
    });
    control->particle_velocities(*this, affine_offset);
    scatter_point_momentum(nodal_p);
    nodal_velocity();
  }

  template <int dim>
  void
  Solver<dim>::nodal_velocity()
  {
    const double *M = nodal_mass.begin();
    double       *V = nodal_p.begin();
    for (const unsigned int i : active_dofs)
      V[i] = (M[i] > 0 && !constrained[i]) ? V[i] / M[i] : 0.0; // Eq. 4.48
    if (control)
      control->nodal_velocities(*this);
    nodal_p.update_ghost_values();
  }

  // ---------------------------------------------------------------- G2P update (C)
  namespace
  {
    /// The explicit point physics of the update pass (seed 000 §4.3.7): strain
    /// and spin increments from the gradient of the displacement increment,
    /// the constitutive update, the volume update, and the sums of energies,
    /// momentum, finiteness and probes at the new position. `with_contact`:
    /// the displacement increments come from each body's own nodal velocities
    /// (a compile-time switch: a run-time branch on `contact` in the per-point
    /// loop, whose taken side calls out of line, cost the contact-free update
    /// pass ~40 instructions per point-step, docs/scaling.md)
    template <int dim, class K, bool with_contact>
    struct ExplicitPointUpdate
    {
      using L = PropertyLayout<dim>;
      const std::vector<std::shared_ptr<const materials::Material>> &materials;
      const unsigned int                                             history;
      const double                                                   h;
      const dealii::Tensor<1, dim>                                   g;
      Contact<dim>                                                  *contact;
      const StrainSmoothing<dim>                                    *smoothing;
      const bool                                                     need_strain_energy;
      PointProbes<dim>                                              &probes;
      /// F-bar: offset of the point's dJbar - 1 (0: off; Solver::volume_averages_with)
      const unsigned int fbar = 0;

      diagnostics::PointSums<dim> sums = {};
      bool                        bad  = false;
      /// contact: each body's displacement increments on the stencil of the
      /// cell (its dofs) they were last gathered for
      std::vector<typename K::Field>    body_du   = {};
      std::vector<const unsigned int *> body_cell = {};
      /// from update() to moved() of one point
      struct PointState
      {
        dealii::SymmetricTensor<2, 3> sigma;
        const materials::Material    *material;
      };

      /// the displacement increments the point moves with: du of the combined
      /// field, or with contact its body's own (§6.2), gathered once per cell and body
      inline const typename K::Field &
      displacement_field(const typename K::Cell &cell, const typename K::Field &du, const double *P)
      {
        if constexpr (with_contact)
          {
            const unsigned int b = static_cast<unsigned int>(P[L::body]);
            if (body_du.empty())
              {
                body_du.resize(contact->fields.size());
                body_cell.assign(contact->fields.size(), nullptr);
              }
            if (body_cell[b] != cell.dofs)
              {
                contact->template body_increments<K>(cell, b, h, body_du[b]);
                body_cell[b] = cell.dofs;
              }
            return body_du[b];
          }
        return du;
      }

      inline void
      increments(const typename K::Cell &cell, const typename K::Eval &ev, const typename K::Field &du, const double *P,
                 double (&gu)[dim][dim], double (&dx)[dim])
      {
        transfer::default_increments<dim, K>(cell, ev, displacement_field(cell, du, P), gu, dx);
      }

      /// The strain and spin increments the model sees: those of grad du, or
      /// with F-bar those of dF-bar - I, dF-bar = (dJbar / dJ)^(1/dim) dF (seed
      /// 002 Eq. 79, in plane in 2D: d_eps_zz stays 0), from dJ - 1 and the
      /// point's dJbar - 1 without cancellation (transfer/fbar.h)
      inline void
      increments_of(const double (&gu)[dim][dim], const double *P, materials::Strain &d_eps, materials::Spin &d_omega)
      {
        if (!fbar)
          {
            materials::strain_and_spin_increments<dim>(gu, d_eps, d_omega);
            return;
          }
        const double e = transfer::volume_increment_minus_one<dim>(gu); // dJ - 1
        if (!(e > -1) || !(P[fbar] > -1)) // flagged by the stability check (the volume turns non-positive)
          {
            materials::strain_and_spin_increments<dim>(gu, d_eps, d_omega);
            bad = true;
            return;
          }
        double g[dim][dim];
        transfer::stabilised_gradient_increment<dim>(gu, e, P[fbar], g);
        materials::strain_and_spin_increments<dim>(g, d_eps, d_omega);
      }

      inline void
      update(const unsigned int c, const typename K::Cell &cell, double *P, const double (&gu)[dim][dim],
             PointState &state)
      {
        materials::Strain d_eps;
        materials::Spin   d_omega;
        increments_of(gu, P, d_eps, d_omega);
        if (smoothing) // §6.7.1: smoothed volumetric part (with contact: of the point's body)
          smoothing->apply(c, smoothing->field_of(P), d_eps);
        const materials::Material &m     = *materials[static_cast<unsigned int>(P[L::material])];
        auto                       sigma = L::get_stress(P);
        m.update_stress(d_eps, d_omega, h, sigma, dealii::ArrayView<double>(P + history, m.n_history()));
        L::set_stress(sigma, P);
        state.sigma       = sigma;
        state.material    = &m;
        const double dvol = trace(d_eps);
        P[L::volume] *= (1.0 + dvol); // Eq. 4.50 (density follows as m / V)
        // A point never integrates more than the volume of its cell. Without
        // this bound, points that separate from the mass at a free surface
        // (cohesionless material at the apex, sigma = 0) dilate without limit
        // under the grid's velocity gradient (1e6 x measured in the demo
        // column collapse) and blow the run up when they land again.
        double cell_volume = 1.0;
        for (unsigned int d = 0; d < dim; ++d)
          cell_volume *= cell.cc->h[d];
        if (P[L::volume] > cell_volume)
          P[L::volume] = cell_volume;
      }

      /// update() for the n points of cell c (UpdateAndMove::whole_cell): the
      /// same arithmetic per point, with one update_stresses() call per run of
      /// points of one model instead of a virtual call per point.
      static constexpr bool              updates_whole_cells = true;
      std::vector<materials::RateUpdate> batch               = {};
      template <class CellPoint>
      inline void
      update_cell(const unsigned int c, const typename K::Cell &cell, const unsigned int n, CellPoint *points)
      {
        if (batch.size() < n)
          batch.resize(n);
        for (unsigned int k = 0; k < n; ++k)
          {
            materials::RateUpdate &r = batch[k];
            if constexpr (dim == 2) // the out-of-plane entries stay zero
              {
                r.d_eps   = materials::Strain();
                r.d_omega = materials::Spin();
              }
            increments_of(points[k].gu, points[k].P, r.d_eps, r.d_omega);
            if (smoothing) // §6.7.1: smoothed volumetric part
              smoothing->apply(c, smoothing->field_of(points[k].P), r.d_eps);
            r.sigma   = L::get_stress(points[k].P);
            r.history = points[k].P + history;
          }
        for (unsigned int k0 = 0; k0 < n;)
          {
            const double material = points[k0].P[L::material];
            unsigned int k1       = k0 + 1;
            while (k1 < n && points[k1].P[L::material] == material)
              ++k1;
            materials[static_cast<unsigned int>(material)]->update_stresses(batch.data() + k0, k1 - k0, h);
            for (unsigned int k = k0; k < k1; ++k)
              points[k].state.material = materials[static_cast<unsigned int>(material)].get();
            k0 = k1;
          }
        double cell_volume = 1.0; // see update()
        for (unsigned int d = 0; d < dim; ++d)
          cell_volume *= cell.cc->h[d];
        for (unsigned int k = 0; k < n; ++k)
          {
            double *P = points[k].P;
            L::set_stress(batch[k].sigma, P);
            points[k].state.sigma = batch[k].sigma;
            const double dvol     = trace(batch[k].d_eps);
            P[L::volume] *= (1.0 + dvol); // Eq. 4.50
            if (P[L::volume] > cell_volume)
              P[L::volume] = cell_volume;
          }
      }

      inline void
      moved(const transfer::PointIterator<dim> &it, const double *P, const dealii::Point<dim> &x,
            const PointState &state)
      {
        const double v2 = sums.add(P[L::mass], P + L::velocity, x, g);
        if (need_strain_energy)
          sums.add_strain(P[L::volume] * state.material->elastic_energy_density(state.sigma));
        const auto &sigma = state.sigma;
        if (!std::isfinite(sigma[0][0] + sigma[1][1] + sigma[0][1] + x[0] + x[1] + v2 + P[L::volume]) ||
            !(P[L::volume] > 0))
          bad = true;
        if (!probes.ids.empty())
          probes.record(it->get_id(), P);
      }
    };

    /// The same physics with the APIC G2P of the velocity (formulations/explicit/affine_ops.h):
    /// v_p and C_p from the nodal velocity of the update pass (v^L), instead of
    /// the FLIP increment of the separate G2P/P2G pass.
    /// With contact, each point from its body's own v^L_b (Contact::correct_accelerations).
    template <int dim, class K, bool with_contact>
    struct ApicPointUpdate : ExplicitPointUpdate<dim, K, with_contact>
    {
      using L             = PropertyLayout<dim>;
      unsigned int affine = 0;
      inline void
      increments(const typename K::Cell &cell, const typename K::Eval &ev, const typename K::Field &du, double *P,
                 double (&gu)[dim][dim], double (&dx)[dim])
      {
        const typename K::Field &v = this->displacement_field(cell, du, P);
        transfer::default_increments<dim, K>(cell, ev, v, gu, dx);
        transfer::apic_point_velocity<dim, K>(cell, ev, v, this->h, gu, dx, P + L::velocity, P + affine);
      }
    };
  } // namespace

  template <int dim>
  void
  Solver<dim>::g2p_update(const double h)
  {
    with_kernel([&](auto kernel) { g2p_update_with(kernel, h); });
  }

  template <int dim>
  template <class K, bool apic>
  void
  Solver<dim>::g2p_update_with(K, const double h)
  {
    probes.clear_values();
    const auto run = [&](auto with_contact) {
      constexpr bool contact_on = decltype(with_contact)::value;
      using Point               = ExplicitPointUpdate<dim, K, contact_on>;
      // APIC: v_p, C_p from v^L in the same pass
      using Physics = std::conditional_t<apic, ApicPointUpdate<dim, K, contact_on>, Point>;
      const Point point{prm.materials,   points.layout.history, h,      gravity,    contact.get(),
                        smoothing.get(), need_strain_energy,    probes, fbar_offset};
      Physics     physics = [&]() -> Physics {
        if constexpr (apic)
          return Physics{point, affine_offset};
        else
          return point;
      }();
      // the mass and force of the next step are accumulated here, at the updated
      // state, for every particle that stays in its cell (seed 000 §4.3.7 step 1 of
      // the next cycle fused into this pass) and for every particle that entered
      // an owned neighbour cell (into that cell); particles received from other
      // ranks are added by the relocation, and any deal.II sort falls back to a
      // full P2G pass (with contact or MPM-MIXED: always, per body).
      // Every non-zero entry of the mass/force vectors belongs to a cell that
      // holds particles now (writes go only to cells that hold particles after
      // the relocation), so clearing the active DoFs clears everything, and the
      // cells that receive moved particles below start from zero.
      zero_on_active(nodal_mass);
      zero_on_active(nodal_a);
      transfer::UpdateAndMove<dim, K, Physics> update{grid, points, nodal_p.begin(), h, physics};
      if (prm.numerics.extended_p2g()) // a full P2G pass follows
        transfer::for_each_active_cell(points, update);
      else
        {
          transfer::ScatterMassForce<dim, K> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
          transfer::Fused                    fused{update, p2g};
          transfer::for_each_active_cell(points, fused);
        }
      local_sums = physics.sums;
      local_bad  = physics.bad;
    };
    if (contact)
      run(std::true_type());
    else
      run(std::false_type());
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::volume_averages_with(K, const double h)
  {
    // the map: sum N m (dJ - 1) at the nodes (the scalar slot: component 0), dJ
    // of the increment the update pass will use (h x the nodal velocity, at x^t;
    // dJ - 1 without cancellation, transfer/fbar.h). With
    // contact every body maps and remaps on its own, like its update pass: dJ
    // from its corrected velocities v~_b, over its own lumped mass (a body in
    // contact deforms with its own field, docs/explicit.md "F-bar with contact")
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    using L       = PropertyLayout<dim>;
    struct Field
    {
      Vector       *dj;
      const double *v; ///< nodal velocities
      const double *m; ///< lumped masses
    };
    std::vector<Field> fields;
    if (contact)
      for (auto &f : contact->fields)
        fields.push_back({&f.volume_increment, f.momentum.begin(), f.mass.begin()});
    else
      fields.push_back({&nodal_dj, nodal_p.begin(), nodal_mass.begin()});
    const auto field_of = [&](const double *P) -> const Field & {
      return contact ? fields[static_cast<unsigned int>(P[L::body])] : fields[0];
    };
    for (const Field &f : fields)
      zero_on_active(*f.dj);
    transfer::for_each_point_stencil<dim, K>(grid, points, [&](unsigned int, It &it, const Stencil &s) {
      const double *P = it->get_properties().data();
      const Field  &f = field_of(P);
      double        gv[dim][dim];
      s.vector_gradient(f.v, gv);
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          gv[i][j] *= h;
      s.scatter(f.dj->begin(), P[L::mass] * transfer::volume_increment_minus_one<dim>(gv));
    });
    // dJ_I - 1 = sum N m (dJ - 1) / sum N m (the lumped mass of this step; every
    // node a point's N reaches carries mass, so a uniform dJ comes back exactly)
    for (const Field &f : fields)
      {
        f.dj->compress(dealii::VectorOperation::add);
        double *mj = f.dj->begin();
        for (const unsigned int i : active_dofs)
          mj[i] = f.m[i] > 0 ? mj[i] / f.m[i] : 0.0;
        f.dj->update_ghost_values();
      }
    // the remap: dJbar - 1 = sum N (dJ_I - 1) at the point
    transfer::for_each_point_stencil<dim, K>(grid, points, [&](unsigned int, It &it, const Stencil &s) {
      double *P      = it->get_properties().data();
      P[fbar_offset] = s.value(field_of(P).dj->begin());
    });
  }

  template <int dim>
  void
  Solver<dim>::relocate()
  {
    // points received from other ranks add their mass and force to the next
    // step's sums (points that entered an owned neighbour cell were added by the
    // fused update pass already); a deal.II sort recomputes reference locations
    // and may move points to other ranks: the fused P2G is then redone from scratch
    bool sorted = false;
    with_kernel([&](auto kernel) {
      transfer::ScatterMassForce<dim, decltype(kernel)> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
      sorted = points.relocate(
        [&](const unsigned int c, const dealii::Point<dim> &xi, const double *P) { p2g.scatter_one(c, xi, P); });
    });
    p2g_ready = !sorted && !prm.numerics.extended_p2g();
    // recompute the active DoFs only when the set of cells with points changed:
    // otherwise the cell list holds the same cells in the same order (only
    // counts changed), and the DoF list would come out identical, order included
    if (points.cell_set_changed())
      collect_active_dofs();
  }

  template <int dim>
  void
  Solver<dim>::step(const double h)
  {
    if (two_phase)
      {
        two_phase->step(h); // separate passes (explicit_two_phase.cc)
        return;
      }
    auto t0 = Clock::now();
    if (!p2g_ready)
      p2g_mass_and_force();
    if (control)
      control->before_nodal_solve(*this, h); // traction point forces, nodal v^t
    timings.p2g += seconds_since(t0);
    t0 = Clock::now();
    nodal_acceleration();
    if (contact)
      contact->correct_accelerations(*this, h);
    timings.grid += seconds_since(t0);
    t0 = Clock::now();
    if (affine_offset)
      {
        // APIC (FEM, MPM-MIXED and 2-phase are refused with it; with contact the
        // update pass takes each body's v^L_b of correct_accelerations)
        apic_nodal_velocity(h);
        const bool body = control && control->has_particle_conditions();
        if (body) // v_p, C_p from v^L, the prescribed ones set, then v = p / m
          apic_body_velocities();
        if (smoothing) // from the nodal velocity the update pass moves with
          smoothing->compute(*this, h);
        if (fbar_offset)
          with_kernel([&](auto kernel) { volume_averages_with(kernel, h); });
        timings.grid += seconds_since(t0);
        t0 = Clock::now();
        if (body) // the update pass of the FLIP step: v_p, C_p are set already
          g2p_update(h);
        else
          with_kernel([&](auto kernel) { g2p_update_with<decltype(kernel), true>(kernel, h); });
        timings.g2p += seconds_since(t0);
        t0 = Clock::now();
        relocate();
        timings.relocation += seconds_since(t0);
        return;
      }
    if (contact)
      contact->g2p_velocity_p2g_momentum(*this, h);
    else
      g2p_velocity_p2g_momentum(h);
    if (control)
      control->particle_velocities(*this); // prescribed material point velocities
    timings.p2g += seconds_since(t0);
    t0 = Clock::now();
    nodal_velocity();
    if (contact)
      contact->correct_velocities(*this, h);
    if (smoothing)
      smoothing->compute(*this, h);
    if (fbar_offset)
      with_kernel([&](auto kernel) { volume_averages_with(kernel, h); });
    timings.grid += seconds_since(t0);
    t0 = Clock::now();
    if (fem)
      {
        // FEM / UL-FEM: points stay in their cells, no relocation; the update
        // pass accumulates the next step's mass and force (fem.cc)
        fem->update(h);
        p2g_ready = true;
        timings.g2p += seconds_since(t0);
        return;
      }
    g2p_update(h);
    timings.g2p += seconds_since(t0);
    t0 = Clock::now();
    relocate();
    timings.relocation += seconds_since(t0);
  }

  template <int dim>
  void
  Solver<dim>::advance(const unsigned int n_steps)
  {
    TimeLoop(*this, loop_settings(prm), comm).advance_steps(n_steps);
  }

  template <int dim>
  Energies
  Solver<dim>::energies() const
  {
    const auto s = point_sums(true);
    return {s.kinetic, s.strain, s.gravity_potential, external_work};
  }

  template <int dim>
  diagnostics::PointSums<dim>
  Solver<dim>::point_sums(const bool strain) const
  {
    diagnostics::SumOptions<dim> o;
    o.gravity          = gravity;
    o.add_displacement = fem && !fem->updated_lagrangian(); // at their Gauss points: x = X + u
    if (strain)
      o.materials = &prm.materials;
    if (two_phase)
      two_phase->add_sum_options(o, strain); // the pore liquid of the points
    auto s = diagnostics::sum_points(points, o);
    s.sum_over_ranks(comm);
    return s;
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::total_momentum() const
  {
    return point_sums(false).total_momentum();
  }

  template <int dim>
  double
  Solver<dim>::total_mass() const
  {
    return point_sums(false).mass; // of the solid (the first phase)
  }

  template <int dim>
  std::pair<double, bool>
  Solver<dim>::check_incremental_state()
  {
    const bool same = points.check_active_cells();
    collect_active_dofs();
    if (!p2g_ready)
      return {0.0, same};
    const unsigned int  n = nodal_mass.locally_owned_size() + grid.partitioner->n_ghost_indices();
    std::vector<double> m0(nodal_mass.begin(), nodal_mass.begin() + n), f0(nodal_a.begin(), nodal_a.begin() + n);
    p2g_mass_and_force();
    double                     scale_m = 0, scale_f = 0, dm = 0, df = 0;
    std::vector<unsigned char> check(n, 0);
    for (const unsigned int i : active_dofs)
      check[i] = 1;
    for (unsigned int i = nodal_mass.locally_owned_size(); i < n; ++i)
      check[i] = 1;
    for (unsigned int i = 0; i < n; ++i)
      if (check[i])
        {
          scale_m = std::max(scale_m, std::abs(nodal_mass.local_element(i)));
          scale_f = std::max(scale_f, std::abs(nodal_a.local_element(i)));
          dm      = std::max(dm, std::abs(nodal_mass.local_element(i) - m0[i]));
          df      = std::max(df, std::abs(nodal_a.local_element(i) - f0[i]));
        }
    const double err = std::max(dm / std::max(scale_m, 1e-300), df / std::max(scale_f, 1e-300));
    return {dealii::Utilities::MPI::max(err, comm), !dealii::Utilities::MPI::logical_or(!same, comm)};
  }

  template <int dim>
  std::pair<double, dealii::Tensor<1, dim>>
  Solver<dim>::grid_mass_and_momentum()
  {
    // P2G of mass and of momentum of the current particle velocities (a = 0)
    p2g_mass_and_force();
    nodal_mass.compress(dealii::VectorOperation::add);
    nodal_a   = 0.0;
    p2g_ready = false;
    g2p_velocity_p2g_momentum(0.0);
    double                 m = 0;
    dealii::Tensor<1, dim> p;
    const unsigned int     n = nodal_mass.locally_owned_size();
    // component of each owned DoF from the cell cache
    std::vector<int> component(n + grid.partitioner->n_ghost_indices(), -1);
    for (const auto &cc : grid.cells)
      for (unsigned int v = 0; v < shape::Q1<dim>::n_vertices; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          if (cc.h[0] > 0) // skip artificial cells (never filled)
            component[cc.dofs[v * dim + d]] = d;
    for (unsigned int i = 0; i < n; ++i)
      {
        if (component[i] == 0)
          m += nodal_mass.local_element(i);
        if (component[i] >= 0)
          p[component[i]] += nodal_p.local_element(i);
      }
    return {dealii::Utilities::MPI::sum(m, comm), dealii::Utilities::MPI::sum(p, comm)};
  }

  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    double v[5] = {local_sums.kinetic, need_strain_energy ? local_sums.strain : 0.0, local_sums.gravity_potential,
                   local_bad ? 1.0 : 0.0, 0.0};
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 5), comm, dealii::ArrayView<double>(v, 5));
    std::ostringstream os;
    os << std::setprecision(4);
    if (v[3] > 0 || !std::isfinite(v[0] + v[1] + v[2]))
      {
        // the point (fields up to the stress; the history may hold infinities)
        const std::string which = diagnostics::find_invalid_point(points, comm, PropertyLayout<dim>::history);
        os << "step " << step_number << " (t = " << time << " s, dt = " << dt
           << " s): the state became non-finite or a material point volume became non-positive "
              "(velocity, stress or position"
           << (which.empty() ? std::string() : "; first: " + which)
           << "). Reduce the time step (courant number) or check the material data.";
        throw InstabilityError(os.str());
      }
    const double available = initial_energies.kinetic + initial_energies.strain +
                             std::max(0.0, initial_energies.gravity_potential - v[2]) + std::abs(external_work);
    const double now = v[0] + v[1];
    // floor: 1e-4 of the potential energy of the mass over the grid's diagonal,
    // so that an undamped oscillation returning to its start (released
    // potential ~0) with a round-off-sized energy error is not taken for growth
    double diagonal = 0;
    for (unsigned int d = 0; d < dim; ++d)
      diagonal += (prm.grid_upper[d] - prm.grid_lower[d]) * (prm.grid_upper[d] - prm.grid_lower[d]);
    const double floor = 1e-12 * energy_scale + 1e-4 * total_mass_setup * gravity.norm() * std::sqrt(diagonal);
    if (now > prm.energy_growth_limit * available + floor)
      {
        os << "step " << step_number << " (t = " << time << " s, dt = " << dt << " s): kinetic + strain energy grew to "
           << now << " J, more than " << prm.energy_growth_limit << " x the energy available (" << available
           << " J: initial kinetic + strain, released potential, external work). "
              "The time step is above the stability limit or the material data are inconsistent.";
        throw InstabilityError(os.str());
      }
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    if (free_surface)
      free_surface->update();
    this->write_point_sets(counter);
    if (prm.write_grid)
      {
        dealii::DataOut<dim> dout;
        dout.attach_dof_handler(grid.dof_handler);
        std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> interp(
          dim, dealii::DataComponentInterpretation::component_is_part_of_vector);
        dout.add_data_vector(nodal_mass, std::vector<std::string>(dim, "nodal_mass"),
                             dealii::DataOut<dim>::type_dof_data, interp);
        dout.add_data_vector(nodal_p, std::vector<std::string>(dim, "nodal_velocity"),
                             dealii::DataOut<dim>::type_dof_data, interp);
        dout.build_patches();
        const std::string gname = io::write_vtu_atomic(dout, prm.output_directory, "grid", counter, comm);
        grid_pvd_records.emplace_back(time, gname);
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          io::write_pvd(prm.output_directory + "/grid.pvd", grid_pvd_records);
      }
  }

  template <int dim>
  void
  Solver<dim>::write_final_particles() const
  {
    // fem: the point stays at its Gauss point; its position is that plus u
    write_final_points_csv(points, prm.output_directory, comm, fem && !fem->updated_lagrangian());
  }

  // ================================================================ Formulation interface

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    const double dt_cr = critical_time_step();
    out << "talus-explicit: " << dim << "D, " << grid.tria.n_global_active_cells() << " cells, "
        << grid.dof_handler.n_dofs() << " DoFs, " << n_particles()
        << (fem ? (fem->updated_lagrangian() ? " Gauss points (ul-fem), " : " Gauss points (fem), ")
                : " material points, ")
        << dealii::Utilities::MPI::n_mpi_processes(comm) << " rank(s)\n"
        << "  critical time step " << dt_cr << " s (L_min " << grid.min_cell_size() << " m), dt = " << dt << " s ("
        << dt / dt_cr << " x critical), end time " << prm.end_time << " s\n";
  }

  template <int dim>
  unsigned int
  Solver<dim>::n_stages() const
  {
    return control ? control->n_stages() : 1;
  }

  template <int dim>
  double
  Solver<dim>::begin_stage(const unsigned int k, const bool first, const bool resumed)
  {
    if (!control)
      return prm.end_time;
    // stage 0 of a fresh run was begun by setup()
    if (first && !resumed && k == 0)
      return stage_start_time + control->stage(0).duration;
    return control->begin_stage(*this, k, resumed);
  }

  template <int dim>
  bool
  Solver<dim>::stage_converged(std::string &message)
  {
    if (!control || !control->stage_converged())
      return false;
    std::ostringstream os;
    os << std::setprecision(6) << "force ratio " << control->force_ratio << ", energy ratio " << control->energy_ratio;
    message = os.str();
    return true;
  }

  template <int dim>
  void
  Solver<dim>::before_step(const double, const bool diagnostics_due)
  {
    // the stability check uses KE (+ SE when summed), a series row needs SE
    need_strain_energy = diagnostics_due || step_number % 10 == 0;
  }

  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    step(h);
    return StepOutcome::done;
  }

  template <int dim>
  void
  Solver<dim>::prepare_output()
  {
    // probe values at the start (after a step, the update pass fills them)
    if (!probes.ids.empty())
      for (const auto &pt : points.handler)
        probes.record(pt.get_id(), pt.get_properties());
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    const char              *ax[] = {"x", "y", "z"};
    std::vector<std::string> c    = {"kinetic_energy", "strain_energy", "gravity_potential_energy", "external_work",
                                     "total_energy"};
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("momentum_") + ax[d]);
    c.push_back("n_particles");
    c.push_back("lost_particles");
    c.push_back("mass"); // both phases: the composability matrix checks it is conserved
    balance.add_series_column(c);
    if (control && control->has_convergence())
      {
        c.push_back("force_ratio");
        c.push_back("energy_ratio");
      }
    if (free_surface)
      {
        c.push_back("free_surface_points");
        for (unsigned int d = 0; d < dim; ++d)
          {
            c.push_back(std::string("extent_") + ax[d] + "_min");
            c.push_back(std::string("extent_") + ax[d] + "_max");
          }
      }
    probes.add_columns(c, points.layout);
    for (const auto &name : loads::rigid_plate_series_columns(prm.rigid_plates))
      c.push_back(name);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool after_step)
  {
    // After a step, the update pass has already summed the energies and the
    // momentum of the new state (strain energy when need_strain_energy was
    // set); only at the start and after a deal.II sort (points may have been
    // lost) are they summed by separate passes.
    Energies               e;
    dealii::Tensor<1, dim> p;
    double                 mass = 0;
    if (after_step && !points.relocator().sorted_last)
      {
        auto s = local_sums;
        s.sum_over_ranks(comm);
        e    = {s.kinetic, s.strain, s.gravity_potential, external_work};
        p    = s.total_momentum();
        mass = s.mass + s.second_mass;
      }
    else
      {
        const auto s = point_sums(true);
        e            = {s.kinetic, s.strain, s.gravity_potential, external_work};
        p            = s.total_momentum();
        mass         = s.mass + s.second_mass;
      }
    if (free_surface)
      free_surface->update();
    std::vector<double> r = {e.kinetic, e.strain, e.gravity_potential, e.external_work, e.total()};
    for (unsigned int d = 0; d < dim; ++d)
      r.push_back(p[d]);
    r.push_back(static_cast<double>(n_particles()));
    r.push_back(static_cast<double>(points.relocation_stats.lost));
    r.push_back(mass);
    balance.add_series_value(r);
    if (control && control->has_convergence())
      {
        r.push_back(control->force_ratio);
        r.push_back(control->energy_ratio);
      }
    if (free_surface)
      {
        r.push_back(free_surface->count);
        for (const double x : free_surface->extent)
          r.push_back(x);
      }
    probes.add_values(r, comm);
    if (!prm.rigid_plates.empty())
      {
        const auto v = control->rigid_plate_series();
        r.insert(r.end(), v.begin(), v.end());
      }
    return r;
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    this->rewrite_point_set_records();
    if (prm.write_grid && dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      io::write_pvd(prm.output_directory + "/grid.pvd", grid_pvd_records);
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &series_csv)
  {
    if (prm.final_particles_csv)
      write_final_particles();
    if (!prm.results_file.empty())
      write_results(series_csv);
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &loop_timings)
  {
    timings.output  = loop_timings.output;
    timings.total   = loop_timings.total;
    const double ns = 1e9 * timings.total / std::max(1.0, double(step_number) * double(n_particles()));
    const auto  &rs = points.relocation_stats;
    // moves are counted per rank: the totals
    const unsigned long long moved = dealii::Utilities::MPI::sum(rs.moved_locally, comm),
                             sent  = dealii::Utilities::MPI::sum(rs.sent_to_ranks, comm);
    log() << std::setprecision(4) << "  breakdown [s]: P2G " << timings.p2g << ", grid " << timings.grid
          << ", G2P+stress " << timings.g2p << ", relocation " << timings.relocation << " (moves " << rs.seconds_moves
          << ", sorts " << rs.seconds_sorts << "), output " << timings.output << " (" << loop_timings.n_snapshots
          << " VTU snapshots " << loop_timings.snapshots << ")"
          << "; particles moved cell " << moved << " (to other ranks " << sent << "), full sorts " << rs.global_sorts
          << ", memory-order sorts " << rs.storage_sorts << ", lost " << rs.lost;
    log() << balance.summary();
    log() << "\n";
    log() << "talus-explicit: done: " << step_number << " steps, " << n_particles() << " particles, wall "
          << timings.total << " s, " << std::setprecision(3) << ns << " ns/particle-step, output in "
          << prm.output_directory << "/ (particles.pvd, series.csv)" << std::endl;
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  template class Solver<2>;
  template class Solver<3>;
} // namespace talus::explicit_mpm
