// talus — the semi-implicit step (seed 002 §4.5; semi_implicit_solver.h):
// step() is the driver of the fractional step, each phase a function of its
// own: P2N of both sets, the water and mixture predictors with the implicit
// Darcy drag, the pressure-increment Poisson equation, the correction, the
// rigid plates' balance, the FLIP update and MUSL remap, the soil's kinematics
// and stress (with the F-bar averages) and the move of both sets.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/transfer/fbar.h>
#include <talus/formulations/semi_implicit/semi_implicit_solver.h>
#include <talus/loads/rigid_plate.h>
#include <talus/materials/material.h>
#include <talus/materials/strain_increments.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/matrix_ops.h>
#include <talus/transfer/point_ops.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

namespace talus::semi_implicit
{
  namespace
  {
    /// The pressure-increment Poisson terms of one point: K += V c grad N grad N,
    /// f -= V (phi v*) . grad N (the weak form of div(phi v*), integrated by
    /// parts: it keeps the phi jump of a free-water / soil interface, which the
    /// point form phi div v* drops; docs/semi-implicit.md)
    struct PoissonWithFlux
    {
      unsigned int          coefficient = 0, flux = 0; ///< property offsets (flux: dim values)
      static constexpr bool matrix = true, vector = true;
      template <int dim, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc == 1, "PoissonWithFlux: a scalar space");
        const double V = P[PropertyLayout<dim>::volume];
        const double a = P[coefficient] * V;
        // symmetric: each product once, added at (i, j) and (j, i) (the same
        // value either way: bitwise the full loop)
        for (unsigned int i = 0; i < p.n; ++i)
          {
            double fg = 0;
            {
              double gg = 0;
              for (unsigned int d = 0; d < dim; ++d)
                gg += p.G[i][d] * p.G[i][d];
              ls.a(p.local[i], p.local[i]) += a * gg;
            }
            for (unsigned int j = i + 1; j < p.n; ++j)
              {
                double gg = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  gg += p.G[i][d] * p.G[j][d];
                const double v = a * gg;
                ls.a(p.local[i], p.local[j]) += v;
                ls.a(p.local[j], p.local[i]) += v;
              }
            for (unsigned int d = 0; d < dim; ++d)
              fg += P[flux + d] * p.G[i][d];
            ls.b[p.local[i]] -= V * fg;
          }
      }
      /// add's terms, the matrix as its upper triangle (local[i] < local[j]
      /// for i < j: AssembleSystem's patch path, transfer::has_add_upper)
      static constexpr bool upper_triangle = true;
      template <int dim, unsigned int nc, class PN>
      inline void
      add_upper(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc == 1, "PoissonWithFlux: a scalar space");
        const double           V = P[PropertyLayout<dim>::volume];
        const double           a = P[coefficient] * V;
        constexpr unsigned int n = PN::capacity; // the patch path passes the whole window (p.n == capacity)
        for (unsigned int i = 0; i < n; ++i)
          {
            double *row = ls.A + p.local[i] * ls.stride;
            {
              double gg = 0;
              for (unsigned int d = 0; d < dim; ++d)
                gg += p.G[i][d] * p.G[i][d];
              row[p.local[i]] += a * gg;
            }
            for (unsigned int j = i + 1; j < n; ++j)
              {
                double gg = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  gg += p.G[i][d] * p.G[j][d];
                row[p.local[j]] += a * gg;
              }
            double fg = 0;
            for (unsigned int d = 0; d < dim; ++d)
              fg += P[flux + d] * p.G[i][d];
            ls.b[p.local[i]] -= V * fg;
          }
      }
    };

    /// The source part of PoissonWithFlux alone (f -= V flux . grad N): the
    /// right-hand side of a force-controlled rigid plate's unit velocity, on
    /// the matrix already assembled (rigid plates, docs/semi-implicit.md)
    struct PoissonFluxSource
    {
      unsigned int          flux   = 0;
      static constexpr bool matrix = false, vector = true;
      template <int dim, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        const double V = P[PropertyLayout<dim>::volume];
        for (unsigned int i = 0; i < p.n; ++i)
          {
            double fg = 0;
            for (unsigned int d = 0; d < dim; ++d)
              fg += P[flux + d] * p.G[i][d];
            ls.b[p.local[i]] -= V * fg;
          }
      }
      static constexpr bool upper_triangle = true; // no matrix: add_upper is add
      template <int dim, unsigned int nc, class PN>
      inline void
      add_upper(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        add<dim, nc>(P, p, ls);
      }
    };

    /// Nodal masses below this fraction of the largest nodal mass count as
    /// empty (decision A3: no division by the tiny masses at a support's edge).
    constexpr double relative_mass_cutoff = 1e-10;

    /// the local (owned, then ghost) values of a grid vector
    inline double *
    at(Vector &v)
    {
      return v.begin();
    }

    /// The water's part of update_and_move_points: its points move with the
    /// nodal velocity given, nothing else of theirs changes.
    template <int dim, class K>
    struct WaterMove
    {
      using It = transfer::PointIterator<dim>;
      struct PointState
      {
      };
      inline void
      increments(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du, const double *,
                 double (&gu)[dim][dim], double (&dx)[dim])
      {
        transfer::default_increments<dim, K>(cell, e, du, gu, dx);
      }
      inline void
      update(const unsigned int, const typename K::Cell &, double *, const double (&)[dim][dim], PointState &)
      {
      }
      inline void
      moved(const It &, double *, const dealii::Point<dim> &, PointState &)
      {
      }
    };
  } // namespace

  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    if (prm.bspline())
      step<shape::BSpline2Box<dim>>(h);
    else
      step<shape::Q1Box<dim>>(h);
    return StepOutcome::done;
  }

  template <int dim>
  void
  Solver<dim>::exchange(std::initializer_list<Vector *> vs) const
  {
    for (auto *v : vs)
      v->compress(dealii::VectorOperation::add);
    for (auto *v : vs)
      v->update_ghost_values();
  }

  // ---------------------------------------------------------------- the step
  template <int dim>
  template <class K>
  void
  Solver<dim>::step(const double h)
  {
    StepState this_step = begin_step(h);
    particles_to_nodes<K>(this_step);
    sealed_surface<K>(this_step);
    plate_surface<K>(this_step);
    add_lap(phase.p2n);
    water_and_mixture_predictors(this_step);
    add_lap(phase.grid);
    pressure_poisson<K>(this_step);
    correction<K>(this_step);
    if (!prm.rigid_plates.empty())
      plate_balance(this_step);
    velocity_reactions(this_step);
    add_lap(phase.grid);
    if (prm.one_set) // both phases in one walk
      one_set_to_particles<K>();
    else
      nodes_to_particles<K>();
    remap_soil_velocity(this_step);
    if (!prm.rigid_plates.empty()) // what the nodes moved the soil with: node_spread
      plate_node_spread(this_step);
    add_lap(phase.n2p);

    if (prm.volumetric_stabilisation != VolumetricStabilisation::none || smooth_jacobian)
      volume_averages<K>(h, this_step.ms_cut);
    update_and_move_points<K>(this_step);
    if (this_step.initial_stage && !initialising(time + h))
      end_initialisation();
  }

  template <int dim>
  typename Solver<dim>::StepState
  Solver<dim>::begin_step(const double h)
  {
    lap = Clock::now();
    StepState this_step;
    this_step.h = h;
    // App. B.4 stage: gravity ramped over it (the factor at mid-step), elastic
    // models, the water on the soil, the initialisation conductivity
    this_step.initial_stage = initialising(time);
    this_step.g =
      (this_step.initial_stage ? std::min(1.0, (time + 0.5 * h) / prm.initialisation_time) : 1.0) * prm.gravity;

    for (Vector *v :
         {&Ms, &Ps, &Mn, &Mk, &Fs, &Ww, &Pw0, &Ww0, &Mwp, &Mw, &Gpw, &Gps, &Mwg, &gs, &gw, &wet, &dry, &near_wet})
      *v = 0;
    bloads.begin_step(time, h); // the loads' time factors over [t, t + h]
    smoothing_fraction_of_material =
      smoothing_fractions_of_materials(prm, h, grid.min_cell_size(), this_step.initial_stage);
    // the displacement-controlled plates' velocities over the step (those of
    // force control follow from the plates' balance at its end)
    const unsigned int   n_plates = prm.rigid_plates.size();
    std::vector<double> &plate_v  = this_step.plate_v;
    plate_v.assign(n_plates, 0.0);
    for (unsigned int k = 0; k < n_plates; ++k)
      if (prm.rigid_plates[k].control == loads::RigidPlate<dim>::Control::displacement)
        plate_v[k] = (prm.rigid_plates[k].displacement_at(time + h) - plate_state[k].displacement) / h;
    return this_step;
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::particles_to_nodes(StepState &this_step)
  {
    if (prm.one_set) // the sums of both phases in one walk (water_to_nodes then walks an empty set)
      one_set_to_nodes<K>(this_step);
    else
      soil_to_nodes<K>(this_step);
    soil_nodal_fields(this_step);
    water_to_nodes<K>(this_step);
    pore_pressure_forces<K>();
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::soil_to_nodes(StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    // (1)-(2) P2N of the soil (scatter_soil_point); a loaded point's traction
    // force at the body surface
    const SoilSums to{at(Ms), at(Ps), at(Mn), at(Mk), at(Fs)};
    Stencil        surface; // a loaded point's stencil at its share of the face
    transfer::for_each_point_stencil<dim, K>(
      grid, soil, stencils<K>(soil), [&](unsigned int c, It &it, const Stencil &s) {
        const double *P = it->get_properties().data();
        scatter_soil_point(P, s, to, this_step.initial_stage, this_step.g);
        bloads.template scatter_point_traction<K>(c, it->get_location(), P, s, surface, to.fs);
      });
  }

  template <int dim>
  void
  Solver<dim>::soil_nodal_fields(StepState &this_step)
  {
    const unsigned int nl = n_local();
    exchange({&Ms, &Ps, &Mn, &Mk, &Fs});
    double ms_max = 0;
    for (unsigned int i = 0; i < nl; ++i)
      ms_max = std::max(ms_max, Ms.local_element(i));
    const double ms_cut = relative_mass_cutoff * dealii::Utilities::MPI::max(ms_max, comm);
    this_step.ms_cut    = ms_cut;
    bloads.add_boundary_tractions(Fs, Ms, ms_cut); // tractions on grid boundary ids
    // nodal porosity; nodes without soil: n = 1, no drag (A1)
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        {
          const double m          = Ms.local_element(i);
          n_node.local_element(i) = m > ms_cut ? Mn.local_element(i) / m : 1.0;
        }
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double m        = Ms.local_element(node_of[i]);
        vs_t.local_element(i) = m > ms_cut ? Ps.local_element(i) / m : 0.0;
      }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::water_to_nodes(StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    const double       rw     = prm.water_density;
    const unsigned int nl     = n_local();
    const double       ms_cut = this_step.ms_cut;
    // (2)(e)-(f) P2N of the water: porosity at the water points from the nodes
    // (48, Alg. 8(h)) and their volume (36); water mass with the nodal porosity
    // (50), velocity with the weights rho_w V0 (51); the mass-weighted nodal
    // pore pressure (77 / A5); the water volume of each cell (free surface)
    if (!prm.one_set) // (one set: summed by one_set_to_nodes)
      cell_water_volume.assign(grid.cells.size(), 0.0);
    {
      const double *nn = at(n_node);
      double       *ww = at(Ww), *pw0 = at(Pw0), *ww0 = at(Ww0), *mwp = at(Mwp), *mw = at(Mw), *mwg = at(Mwg);
      const bool    linear = prm.linear_smoothing;
      transfer::for_each_point_stencil<dim, K>(
        grid, water, stencils<K>(water), [&](unsigned int c, It &it, const Stencil &s) {
          double      *P  = it->get_properties().data();
          const double n  = std::clamp(s.value(nn), 1e-6, 1.0);
          const double V0 = P[fw.initial_volume];
          P[fw.porosity]  = n;
          P[L::volume]    = P[fw.initial_porosity] / n * V0; // Eq. 36
          s.scatter(ww, rw * P[L::volume]);
          s.scatter_vector(pw0, rw * V0, P + L::velocity);
          s.scatter(ww0, rw * V0);
          if (linear) // sum N m (p - grad p . x_p); the node adds (sum N m grad p) . x_I
            {
              const auto x  = it->get_location();
              double     px = P[fw.pressure];
              for (unsigned int d = 0; d < dim; ++d)
                px -= P[fw.pressure_gradient + d] * x[d];
              s.scatter(mwp, P[L::mass] * px);
              s.scatter_vector(mwg, P[L::mass], P + fw.pressure_gradient);
            }
          else
            s.scatter(mwp, P[L::mass] * P[fw.pressure]);
          s.scatter(mw, P[L::mass]);
          cell_water_volume[c] += P[L::volume];
        });
    }
    exchange({&Ww, &Pw0, &Ww0, &Mwp, &Mw, &Mwg});
    if (prm.linear_smoothing) // the node's share (sum N m grad p) . x_I, component by component
      for (unsigned int i = 0; i < nl; ++i)
        Mwp.local_element(node_of[i]) += Mwg.local_element(i) * node_x[i][component[i]];
    double mw_max = 0;
    for (unsigned int i = 0; i < nl; ++i)
      mw_max = std::max(mw_max, Mw.local_element(i));
    const double mw_cut = relative_mass_cutoff * dealii::Utilities::MPI::max(mw_max, comm);
    this_step.mw_cut    = mw_cut;
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        {
          const bool has_water     = Mw.local_element(i) > mw_cut;
          p_node.local_element(i)  = has_water ? Mwp.local_element(i) / Mw.local_element(i) : 0.0;
          Mw_node.local_element(i) = has_water ? n_node.local_element(i) * Ww.local_element(i) : 0.0; // Eq. 50
          // the drag Q_I = sum_s N n^2 rho_w g V / k over the soil points: Eq. 58
          // (g n_I M_wI / k_I) integrates the drag over the node's whole water
          // volume, which at a free-water interface includes the free water
          // (docs/semi-implicit.md: 2.7 % less Darcy flux through a 1 m column)
          Q_node.local_element(i) = has_water && Ms.local_element(i) > ms_cut ? Mk.local_element(i) : 0.0;
        }
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double w        = Ww0.local_element(node_of[i]);
        vw_t.local_element(i) = Mw.local_element(node_of[i]) > mw_cut && w > 0 ? Pw0.local_element(i) / w : 0.0;
      }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::pore_pressure_forces()
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // (3a)/(4a) smoothed pore pressure at the water points (77); the pore
    // pressure force in the form of the correction (66)-(67): the water's
    // n_I sum_w V N grad p^t, the soil's (1 - n_I) sum_s V N grad p^t, from the
    // nodal p^t (decision 'pressure force form' in docs/semi-implicit.md: the
    // printed mixture form -sum_w V p grad N split by n_I gives the soil of a
    // node at a free-water interface the buoyancy of the whole support)
    if (prm.one_set) // both phases in one walk
      {
        one_set_pressure_forces<K>();
        return exchange({&Gpw, &Gps});
      }
    {
      const double *pn  = at(p_node);
      double       *gpw = at(Gpw), *gps = at(Gps);
      transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), pn, L::volume, gpw,
                                              [&](It &it, const Stencil &s) {
                                                if (prm.pressure_smoothing)
                                                  {
                                                    double *P = it->get_properties().data();
                                                    smooth_pressure(s, pn, P, P[fw.pressure]);
                                                  }
                                              });
      transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), pn, L::volume, gps);
    }
    exchange({&Gpw, &Gps});
  }

  template <int dim>
  void
  Solver<dim>::water_and_mixture_predictors(const StepState &this_step)
  {
    const double               h       = this_step.h;
    const auto                &g       = this_step.g;
    const unsigned int         nl      = n_local();
    const double               ms_cut  = this_step.ms_cut;
    const std::vector<double> &plate_v = this_step.plate_v;
    // (3) water predictor (53, 59) and (4) mixture predictor (52), the drag
    // implicit in both velocities: the 2 x 2 system per node and component
    //   (M_s + Q h) v_s* - Q h v_w*         = M_s v_s^t + h (F_s + (1 - n) G_s p)
    //   -Q h v_s*         + (M_w + Q h) v_w* = M_w v_w^t + h (M_w b + n G_w p)
    // whose sum is the mixture equation (52); the printed sequence takes v_s^t
    // in the drag of (53), which amplifies v_s - v_w by about M_w / M_s per step
    // where M_w > M_s (the nodes at a free-water interface; docs/semi-implicit.md)
    // Rigid plates (docs/semi-implicit.md 'Rigid plate'): at a plate's axis
    // DoFs the soil moves with the plate, v_s* = V; the water too when the
    // plate is impermeable (v_w* = V), else its own row with v_s = V. V is the
    // history's for displacement control; for force control the step is
    // solved for V = 0 and, per force plate, for a unit V (es, ew here, the
    // pressure increment and correction below); V follows from the plate's
    // momentum balance at the end of the step.
    for (auto &r : plate_response)
      for (Vector *v : {&r.es, &r.ew, &r.dp, &r.gs, &r.gw})
        *v = 0;
    for (unsigned int i = 0; i < nl; ++i)
      {
        const unsigned int j   = node_of[i];
        const double       Mwi = Mw_node.local_element(j), Msi = Ms.local_element(j);
        const double       Q = Q_node.local_element(j), n = n_node.local_element(j);
        const double       b = g[component[i]];
        // a sealed surface's node: the surface term -beta_J p_J^t of the pore pressure (sealed_surface)
        const double surface = any_sealed ? beta.local_element(i) * p_node.local_element(j) : 0.0;
        // the plate's corner on a draining face: the surface term -beta_out p^t on both phases
        const double out = any_plate_outflow ? beta_out.local_element(i) * p_node.local_element(j) : 0.0;
        const double rs =
          Msi * vs_t.local_element(i) + h * (Fs.local_element(i) + (1 - n) * (Gps.local_element(i) - out) - surface);
        const double rwv = Mwi * vw_t.local_element(i) + h * (Mwi * b + n * (Gpw.local_element(i) - out));
        double       vw = 0, vs = 0;
        const bool   has_soil = Msi > ms_cut, has_water = Mwi > 0;
        if (prm.rigid_skeleton) // v_s = 0: the water alone, its drag implicit
          vw = has_water ? rwv / (Mwi + h * Q) : 0.0;
        else if (has_soil && has_water)
          {
            const double a = Msi + h * Q, c = Mwi + h * Q, o = h * Q, det = a * c - o * o;
            vs = (c * rs + o * rwv) / det;
            vw = (o * rs + a * rwv) / det;
          }
        else if (has_soil)
          vs = rs / Msi;
        else if (has_water)
          vw = rwv / Mwi;
        if (constrained[i]) // same conditions on both phases (A10), except the water at a drained face
          vs = 0;
        if (water_constrained[i])
          vw = 0;
        // a wall holds the soil while a drained face frees the water: the
        // water's own row with v_s = 0 (the 2 x 2 solve gave it the mixture's
        // velocity, i.e. the momentum of the wall's reaction; docs/semi-implicit.md
        // 'A drained face on a wall')
        if (has_soil && has_water && constrained[i] && !water_constrained[i] && !prm.rigid_skeleton)
          vw = rwv / (Mwi + h * Q);
        bloads.predictor(i, has_soil, has_water, Mwi, Q, h, rwv, vs, vw); // prescribed velocities
        if (const unsigned int k = plate_of[i]; k != no_plate)
          {
            const bool permeable = prm.rigid_plates[k].permeable;
            // the water's factor of V: 1 (impermeable), its row's drag share
            // (permeable, with soil at the node), 0 (no coupling)
            const double ew =
              !permeable ? (has_water ? 1.0 : 0.0) : (has_soil && has_water ? h * Q / (Mwi + h * Q) : 0.0);
            vs = plate_v[k];
            if (!permeable)
              vw = ew * plate_v[k];
            else if (has_soil && has_water)
              vw = (rwv + h * Q * plate_v[k]) / (Mwi + h * Q);
            for (unsigned int r = 0; r < force_plates.size(); ++r)
              if (force_plates[r] == k)
                {
                  plate_response[r].es.local_element(i) = 1.0;
                  plate_response[r].ew.local_element(i) = ew;
                }
          }
        vw_star.local_element(i) = vw;
        vs_star.local_element(i) = vs;
      }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::pressure_poisson(const StepState &this_step)
  {
    point_poisson_terms<K>(this_step);
    add_lap(phase.poisson); // the points' Poisson coefficient and flux (also in a dry scene)
    // a dry scene (soil points only) is a single-phase solid: no pressure
    if (!has_water())
      {
        dp_node = 0;
        return;
      }
    const bool new_pattern = update_pressure_pattern<K>();
    if (!this_step.surface_marked)
      mark_free_surface();
    dealii::AffineConstraints<double> dirichlet, dirichlet_homogeneous; // the second: a plate's unit response
    pressure_dirichlet_values(this_step, dirichlet, dirichlet_homogeneous);
    const auto constraints = active.constraints_with(dirichlet);
    assemble_pressure_system<K>(constraints, new_pattern);
    add_lap(phase.poisson);
    solve_pressure(constraints);

    // rigid plates under force control: the pressure increment of a unit
    // plate velocity, on the same matrix and hierarchy, with homogeneous
    // Dirichlet values (the equation is linear in V: dp = dp(V = 0) + V dp_1)
    if (!force_plates.empty())
      plate_unit_pressures<K>(dirichlet, dirichlet_homogeneous);
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::point_poisson_terms(const StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    const double h  = this_step.h;
    const double rw = prm.water_density;
    // (5) pressure-increment Poisson equation (60)-(63): per point the
    // coefficient dt phi / rho and the source phi div v* (phi = 1 - n for the
    // soil, n for the water; point porosity, see docs/semi-implicit.md)
    if (prm.one_set) // both phases' terms summed on each point
      return one_set_poisson_terms<K>(this_step);
    {
      const double *vss = at(vs_star), *vws = at(vw_star);
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          double      *P            = it->get_properties().data();
          const double phi          = 1 - P[fs.porosity];
          const double rs           = prm.materials[static_cast<unsigned int>(P[L::material])]->density();
          P[fs.poisson_coefficient] = prm.rigid_skeleton ? 0.0 : h * phi / rs;
          double v[dim];
          s.vector_value(vss, v);
          for (unsigned int d = 0; d < dim; ++d)
            P[fs.poisson_flux + d] = prm.rigid_skeleton ? 0.0 : phi * v[d];
        });
      transfer::for_each_point_stencil<dim, K>(grid, water, stencils<K>(water),
                                               [&](unsigned int, It &it, const Stencil &s) {
                                                 double      *P            = it->get_properties().data();
                                                 const double phi          = P[fw.porosity];
                                                 P[fw.poisson_coefficient] = h * phi / rw;
                                                 double v[dim];
                                                 s.vector_value(vws, v);
                                                 for (unsigned int d = 0; d < dim; ++d)
                                                   P[fw.poisson_flux + d] = phi * v[d];
                                               });
    }
  }

  template <int dim>
  template <class K>
  bool
  Solver<dim>::update_pressure_pattern()
  {
    // the pressure DoF set: rebuilt (with the sparsity, the matrix and the AMG
    // hierarchy) only when a point set's cells changed on some rank, or a
    // point's B-spline window moved (a half-cell line) onto a pair the kept
    // pattern lacks (couplings_covered). The decision is global:
    // ActiveSet::reinit and the AMG set-up are collective.
    // The pattern is the union of both sets' stencils: a set's cells changing
    // inside the cells the pattern was built on (a double-point water point
    // entering or leaving a cell that soil points hold) leaves it to the
    // couplings check, as a window move does (docs/semi-implicit.md 'The
    // pressure solve: reuse between steps')
    const auto union_changed = [&] {
      std::vector<unsigned int> held;
      for (const MaterialPointSet<dim> *set : {&soil, &water})
        for (const auto &ac : set->active_cells())
          held.push_back(ac.cell);
      std::sort(held.begin(), held.end());
      held.erase(std::unique(held.begin(), held.end()), held.end());
      return held != active.cells();
    };
    const bool cells_changed = step_number == 0 || partition_changed || A.m() == 0 ||
                               ((soil.cell_set_changed() || water.cell_set_changed()) && union_changed());
    const bool         window_moved = !cells_changed && !active.template couplings_covered<K>({&soil, &water});
    const unsigned int why          = dealii::Utilities::MPI::max(cells_changed ? 2u : window_moved ? 1u : 0u, comm);
    const bool         new_pattern  = why != 0;
    if (new_pattern)
      {
        active.template reinit<K>({&soil, &water}, ActiveSet<dim>::Couplings::record);
        ++n_pattern_changes;
        if (why == 1)
          ++n_pattern_window_changes;
      }
    partition_changed = false;
    return new_pattern;
  }

  template <int dim>
  void
  Solver<dim>::mark_free_surface()
  {
    // free water surface: per node, whether it is a vertex of a wet and of a
    // dry cell, and whether it is a vertex of a cell next to a wet one
    // (shares a vertex with it: the layer of nodes just outside the water)
    {
      double *wt = at(wet), *dr = at(dry);
      for (unsigned int c = 0; c < grid.cells.size(); ++c)
        if (grid.cells[c].locally_owned)
          {
            double cell_volume = 1;
            for (unsigned int d = 0; d < dim; ++d)
              cell_volume *= grid.cells[c].h[d];
            const bool is_wet = cell_water_volume[c] >= prm.free_surface_fraction * cell_volume;
            for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
              (is_wet ? wt : dr)[grid.cells[c].dofs[v * dim]] += 1;
          }
    }
    exchange({&wet, &dry});
    {
      const double *wt = at(wet);
      double       *nr = at(near_wet);
      for (unsigned int c = 0; c < grid.cells.size(); ++c)
        if (grid.cells[c].locally_owned)
          {
            bool touches_wet = false;
            for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
              touches_wet = touches_wet || wt[grid.cells[c].dofs[v * dim]] > 0;
            if (touches_wet)
              for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
                nr[grid.cells[c].dofs[v * dim]] += 1;
          }
    }
    exchange({&near_wet});
  }

  template <int dim>
  void
  Solver<dim>::pressure_dirichlet_values(const StepState &this_step, dealii::AffineConstraints<double> &dirichlet,
                                         dealii::AffineConstraints<double> &dirichlet_homogeneous)
  {
    const unsigned int nl     = n_local();
    const double       mw_cut = this_step.mw_cut;
    dirichlet.reinit(pspace.locally_relevant_dofs());
    dirichlet_homogeneous.reinit(pspace.locally_relevant_dofs());
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        {
          const auto gdof = pspace.node_dof(i, 0);
          if (!pspace.locally_relevant_dofs().is_element(gdof) || dirichlet.is_constrained(gdof))
            continue;
          const bool has_water = Mw.local_element(i) > mw_cut;
          // the pressure row from the free-surface rule (A6),
          // the drainage conditions and the sealing of loaded faces
          // (BoundaryLoads::pressure_row): dp = -p^t at a drained node (p^{t+1}
          // = 0), dp = 0 at a node without water or one that keeps its mapped p^t
          const auto row =
            bloads.pressure_row(i, has_water, drained[i], plate_sealed[i], wet.local_element(i), dry.local_element(i),
                                near_wet.local_element(i), p_node.local_element(i));
          if (row.first)
            {
              dirichlet.add_line(gdof);
              dirichlet_homogeneous.add_line(gdof);
              dirichlet.set_inhomogeneity(gdof, row.second);
            }
        }
    dirichlet.close();
    dirichlet_homogeneous.close();
    bloads.check_pressure_reference(); // a sealed box is refused
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::assemble_pressure_system(const dealii::AffineConstraints<double> &constraints, const bool new_pattern)
  {
    if (new_pattern)
      {
        active.reinit_matrix(A); // a new Epetra matrix: the kept hierarchy referenced the old one
        pressure_solver.invalidate();
      }
    else
      A = 0; // same pattern: refill the values in place
    pspace.reinit_vector(rhs);
    pspace.reinit_vector(dp_solution);
    {
      // one local system per cell for the soil and the water points of the
      // cell, distributed once (the distribution was the step's largest single
      // cost when each set's cells were distributed on their own)
      const PoissonWithFlux                                terms[2] = {{fs.poisson_coefficient, fs.poisson_flux},
                                                                       {fw.poisson_coefficient, fw.poisson_flux}};
      transfer::AssembleSystem<dim, K, 1, PoissonWithFlux> assembly(active, constraints, terms[0], &A, &rhs);
      transfer::for_each_cell_of_sets<dim>(grid, {&soil, &water}, assembly,
                                           [&](const unsigned int k) { assembly.integrand = terms[k]; });
      if (any_sealed)
        add_sealed_surface_terms<K>(constraints);
      if (any_plate_sealed)
        add_plate_surface_flux(constraints, vs_star, rhs);
      if (any_plate_outflow)
        {
          add_plate_outflow_terms<K>(constraints);
          add_plate_outflow_flux(constraints, vs_star, vw_star, rhs);
        }
      transfer::finish_assembly(active, assembly.diag_sum, assembly.diag_count, &A, &rhs);
    }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::sealed_surface(StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // (the same answer on every rank: collective below)
    any_sealed = false;
    sealed_h   = this_step.h;
    if (!has_water() || !bloads.may_seal_surface() || prm.rigid_skeleton)
      return;
    mark_free_surface();
    this_step.surface_marked = true;
    const unsigned int nl = n_local(), owned = grid.partitioner->locally_owned_size();
    sealed.assign(nl, 0);
    // the surface's nodes (at a dry cell), and the candidates inside the
    // water: of the seal where they share a cell with a surface node of it
    // (the nodes whose support crosses the sealed surface)
    std::vector<unsigned char> candidate(nl, 0);
    grid.reinit_vector(beta); // first: per node, the cells it shares with a sealed surface node
    unsigned int n_sealed = 0;
    // a node on a face of the grid box is a node of the body's surface where
    // the body reaches that face (no dry cell beyond it: the grid ends): a
    // loaded face there is sealed as at a free surface
    const auto on_box_face = [&](const unsigned int i) {
      for (unsigned int d = 0; d < dim; ++d)
        {
          const double tol = 1e-9 * (prm.grid_upper[d] - prm.grid_lower[d]);
          if (std::abs(node_x[i][d] - prm.grid_lower[d]) < tol || std::abs(node_x[i][d] - prm.grid_upper[d]) < tol)
            return true;
        }
      return false;
    };
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0 && Ms.local_element(i) > this_step.ms_cut)
        {
          const bool has_water = Mw.local_element(i) > this_step.mw_cut;
          const bool s         = bloads.sealed_surface(i, has_water, drained[i], plate_sealed[i], wet.local_element(i),
                                                       dry.local_element(i), near_wet.local_element(i));
          const bool surface   = dry.local_element(i) > 0 || on_box_face(i);
          (surface ? sealed : candidate)[i] = s;
          n_sealed += s && surface && i < owned ? 1 : 0;
        }
    any_sealed = dealii::Utilities::MPI::sum(n_sealed, comm) > 0;
    if (!any_sealed)
      return;
    {
      double *ns = at(beta);
      for (unsigned int c = 0; c < grid.cells.size(); ++c)
        if (grid.cells[c].locally_owned)
          {
            bool touches = false;
            for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
              touches = touches || sealed[grid.cells[c].dofs[v * dim]];
            if (touches)
              for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
                ns[grid.cells[c].dofs[v * dim]] += 1;
          }
      exchange({&beta});
      for (unsigned int i = 0; i < nl; ++i)
        if (candidate[i] && beta.local_element(i) > 0)
          sealed[i] = 1;
    }
    // beta_J = sum_s V grad N_J over the soil points: the point quadrature of
    // the surface integral of N_J n (the divergence theorem; zero inside)
    beta = 0;
    {
      double *bt = at(beta);
      transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                               [&](unsigned int, It &it, const Stencil &s) {
                                                 const double V = it->get_properties()[L::volume];
                                                 for (unsigned int w = 0; w < s.n; ++w)
                                                   if (sealed[s.dof[w][0]])
                                                     for (unsigned int d = 0; d < dim; ++d)
                                                       bt[s.dof[w][d]] += V * s.G[w][d];
                                               });
    }
    exchange({&beta});
    // the held components (walls, prescribed velocities, plates) take no surface force
    for (unsigned int i = 0; i < nl; ++i)
      if (!sealed[node_of[i]] || constrained[i] || bloads.prescribed(i) || plate_of[i] != no_plate)
        beta.local_element(i) = 0;
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::add_sealed_surface_terms(const dealii::AffineConstraints<double> &constraints)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // The sealed surface in the Poisson rows (docs/semi-implicit.md 'A sealed
    // surface'). The soil's correction at a sealed node J adds
    // -h beta_J dp_J / M_sJ; row I of the continuity sees it through the
    // points' flux (sum_s V (1 - n_J) grad N_I N_J) and, at a sealed row, loses
    // the surface's flux beta_I . v_s^{t+1}_I. Both together: the symmetric
    //   A_IJ += -h (1 - n_J) / M_sJ sum_s V N_J grad N_I . beta_J  (and A_JI),
    //   A_JJ += h |beta_J|^2 / M_sJ,   f_J += beta_J . v_s*_J.
    // A Dirichlet row is skipped, a Dirichlet column moves its value to f.
    const double  h     = sealed_h;
    const auto    entry = [&](const dealii::types::global_dof_index r, const dealii::types::global_dof_index c,
                           const double v) { add_poisson_entry(constraints, r, c, v); };
    const double *bt    = at(beta);
    transfer::for_each_point_stencil<dim, K>(
      grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
        const double V = it->get_properties()[L::volume];
        for (unsigned int j = 0; j < s.n; ++j)
          {
            const unsigned int J = s.dof[j][0];
            if (!sealed[J])
              continue;
            const double c  = -h * (1 - n_node.local_element(J)) / Ms.local_element(J) * V * s.N[j];
            const auto   gJ = pspace.node_dof(J, 0);
            for (unsigned int i = 0; i < s.n; ++i)
              {
                double gb = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  gb += s.G[i][d] * bt[s.dof[j][d]];
                const auto gI = pspace.node_dof(s.dof[i][0], 0);
                entry(gI, gJ, c * gb);
                entry(gJ, gI, c * gb);
              }
          }
      });
    // the nodal terms once, by the node's owner
    const unsigned int  nl = n_local(), owned = grid.partitioner->locally_owned_size();
    std::vector<double> bb(nl, 0.0), bv(nl, 0.0);
    for (unsigned int i = 0; i < nl; ++i)
      if (const unsigned int J = node_of[i]; J < owned && sealed[J])
        {
          bb[J] += bt[i] * bt[i];
          bv[J] += bt[i] * vs_star.local_element(i);
        }
    for (unsigned int J = 0; J < owned; ++J)
      if (component[J] == 0 && sealed[J])
        {
          const auto gJ = pspace.node_dof(J, 0);
          if (constraints.is_constrained(gJ))
            continue;
          A.add(gJ, gJ, h * bb[J] / Ms.local_element(J));
          rhs(gJ) += bv[J];
        }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::plate_surface(const StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // An impermeable rigid plate covers the surface: the pore pressure under
    // it pushes on it (the gradient form of the pressure force lacks the
    // surface integral -integral N_J p n, as at a sealed surface) and the
    // continuity rows of its nodes see the surface move with the plate
    // (integral grad N_J . q = surface integral N_J V . n). beta_plate at the
    // plate's axis DoFs only (the plate holds them: no correction there).
    // The plate's solved nodes whose support reaches a draining face (the
    // corner where the plate meets a drained face or a free surface): the
    // water leaves through that face, which their rows (the weak form
    // without boundary term) would state as zero outflow. beta_out, the same
    // sum over the components the plate leaves free, is that face's share;
    // the pore pressure's surface term -beta_out p on both phases (the force
    // in divergence form, p = 0 beyond the face) and its transpose, the
    // outflow beta_out . q in the node's row, keep the system symmetric
    // (docs/semi-implicit.md 'The plate's corner on a draining face').
    any_plate_sealed  = false;
    any_plate_outflow = false;
    outflow_ms_cut    = this_step.ms_cut;
    for (const auto &pl : prm.rigid_plates)
      any_plate_sealed = any_plate_sealed || !pl.permeable;
    if (!any_plate_sealed || !has_water())
      {
        any_plate_sealed = false;
        return;
      }
    const unsigned int nl = n_local();
    grid.reinit_vector(beta_plate);
    grid.reinit_vector(beta_out);
    {
      double *bt = at(beta_plate), *bo = at(beta_out);
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          const double V = it->get_properties()[L::volume];
          for (unsigned int w = 0; w < s.n; ++w)
            for (unsigned int d = 0; d < dim; ++d)
              {
                if (const unsigned int k = plate_of[s.dof[w][d]]; k != no_plate && !prm.rigid_plates[k].permeable)
                  bt[s.dof[w][d]] += V * s.G[w][d];
                else if (plate_sealed[s.dof[w][0]])
                  bo[s.dof[w][d]] += V * s.G[w][d];
              }
        });
    }
    exchange({&beta_plate, &beta_out});
    unsigned int n_out = 0;
    for (unsigned int i = 0; i < nl; ++i)
      {
        if (const unsigned int k = plate_of[i]; k == no_plate || prm.rigid_plates[k].permeable)
          beta_plate.local_element(i) = 0;
        // the plate's axis, walls (the soil's or the water's) and prescribed
        // velocities hold their components: no flux, no force through them
        if (!plate_sealed[node_of[i]] || plate_of[i] != no_plate || constrained[i] || water_constrained[i] ||
            bloads.prescribed(i))
          beta_out.local_element(i) = 0;
        n_out += beta_out.local_element(i) != 0 ? 1 : 0;
      }
    outflow_bb.assign(nl, 0.0); // per node: |beta_out|^2
    for (unsigned int i = 0; i < nl; ++i)
      outflow_bb[node_of[i]] += beta_out.local_element(i) * beta_out.local_element(i);
    any_plate_outflow = dealii::Utilities::MPI::sum(n_out, comm) > 0;
  }

  template <int dim>
  void
  Solver<dim>::add_plate_surface_flux(const dealii::AffineConstraints<double> &constraints, const Vector &v,
                                      Vector &f) const
  {
    const unsigned int  nl = n_local(), owned = grid.partitioner->locally_owned_size();
    std::vector<double> bv(nl, 0.0);
    for (unsigned int i = 0; i < nl; ++i)
      if (const unsigned int J = node_of[i]; J < owned)
        bv[J] += beta_plate.local_element(i) * v.local_element(i);
    for (unsigned int J = 0; J < owned; ++J)
      if (component[J] == 0 && bv[J] != 0)
        {
          const auto gJ = pspace.node_dof(J, 0);
          if (!constraints.is_constrained(gJ))
            f(gJ) += bv[J];
        }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::add_plate_outflow_terms(const dealii::AffineConstraints<double> &constraints)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // The plate's corner on a draining face (plate_surface; docs/semi-implicit.md
    // 'The plate's corner on a draining face'). With c_s = (1 - n_J)^2 / M_sJ,
    // c_w = n_J^2 / M_wJ, the correction at such a node J adds
    // -h phi beta_out_J dp_J / M_J to each phase (phi = 1 - n_J, n_J), which row I of the continuity
    // sees through the points' flux (sum V phi grad N_I N_J); row J loses the
    // outflow beta_out_J . q_J^{t+1} of the correction's velocities. Both:
    //   A_IJ += -h sum_phases c sum V N_J grad N_I . beta_out_J  (and A_JI),
    //   A_JJ += h (c_s + c_w) |beta_out_J|^2,   f_J += beta_out_J . q*_J,
    // the lumped h (B + S)^T M^-1 (B + S) of the divergence-form force: SPD.
    // A Dirichlet row is skipped, a Dirichlet column moves its value to f.
    const double  h       = sealed_h;
    const auto    entry   = [&](const dealii::types::global_dof_index r, const dealii::types::global_dof_index c,
                           const double v) { add_poisson_entry(constraints, r, c, v); };
    const double *bo      = at(beta_out);
    const auto    has_out = [&](const unsigned int J) { return outflow_bb[J] > 0; };
    // one phase's points: V their volume (the weak gradients' weight), c the coefficient at J
    const auto add_points = [&](MaterialPointSet<dim> &set, const bool soil_phase, const bool water_on_soil) {
      transfer::for_each_point_stencil<dim, K>(
        grid, set, stencils<K>(set), [&](unsigned int, It &it, const Stencil &s) {
          const double *P = it->get_properties().data();
          double        V = P[L::volume];
          if (water_on_soil)
            {
              if (!(P[fs.water_mass] > 0))
                return;
              V = water_volume(P);
            }
          for (unsigned int j = 0; j < s.n; ++j)
            {
              const unsigned int J = s.dof[j][0];
              if (!plate_sealed[J] || !has_out(J))
                continue;
              const double n = n_node.local_element(J), Ms_J = Ms.local_element(J), Mw_J = Mw_node.local_element(J);
              double       c = 0;
              if (soil_phase && Ms_J > outflow_ms_cut)
                c = (1 - n) * (1 - n) / Ms_J;
              else if (!soil_phase && Mw_J > 0)
                c = n * n / Mw_J;
              if (c == 0)
                continue;
              c *= -h * V * s.N[j];
              const auto gJ = pspace.node_dof(J, 0);
              for (unsigned int i = 0; i < s.n; ++i)
                {
                  double gb = 0;
                  for (unsigned int d = 0; d < dim; ++d)
                    gb += s.G[i][d] * bo[s.dof[j][d]];
                  if (gb == 0)
                    continue;
                  const auto gI = pspace.node_dof(s.dof[i][0], 0);
                  entry(gI, gJ, c * gb);
                  entry(gJ, gI, c * gb);
                }
            }
        });
    };
    add_points(soil, true, false);
    if (prm.one_set) // the water on the soil points, on their water volume
      add_points(soil, false, true);
    else
      add_points(water, false, false);
    // the nodal terms once, by the node's owner
    const unsigned int owned = grid.partitioner->locally_owned_size();
    for (unsigned int J = 0; J < owned; ++J)
      if (component[J] == 0 && plate_sealed[J] && has_out(J))
        {
          const auto gJ = pspace.node_dof(J, 0);
          if (constraints.is_constrained(gJ))
            continue;
          const double n = n_node.local_element(J), Ms_J = Ms.local_element(J), Mw_J = Mw_node.local_element(J);
          const double c = (Ms_J > outflow_ms_cut ? (1 - n) * (1 - n) / Ms_J : 0.0) + (Mw_J > 0 ? n * n / Mw_J : 0.0);
          A.add(gJ, gJ, h * c * outflow_bb[J]);
        }
  }

  template <int dim>
  void
  Solver<dim>::add_plate_outflow_flux(const dealii::AffineConstraints<double> &constraints, const Vector &vs,
                                      const Vector &vw, Vector &f) const
  {
    const unsigned int  nl = n_local(), owned = grid.partitioner->locally_owned_size();
    std::vector<double> bq(nl, 0.0);
    for (unsigned int i = 0; i < nl; ++i)
      if (const unsigned int J = node_of[i]; J < owned && beta_out.local_element(i) != 0)
        {
          const double n = n_node.local_element(J);
          const double q = (Ms.local_element(J) > outflow_ms_cut ? (1 - n) * vs.local_element(i) : 0.0) +
                           (Mw_node.local_element(J) > 0 ? n * vw.local_element(i) : 0.0);
          bq[J] += beta_out.local_element(i) * q;
        }
    for (unsigned int J = 0; J < owned; ++J)
      if (component[J] == 0 && bq[J] != 0)
        {
          const auto gJ = pspace.node_dof(J, 0);
          if (!constraints.is_constrained(gJ))
            f(gJ) += bq[J];
        }
  }

  template <int dim>
  void
  Solver<dim>::solve_pressure(const dealii::AffineConstraints<double> &constraints)
  {
    const unsigned int nl = n_local();
    {
      const auto          t0 = Clock::now();
      LinearSolverOptions options;
      options.method             = LinearSolverOptions::Method::cg_amg;
      options.relative_tolerance = prm.pressure_tolerance;
      pressure_solver.set_rebuild_interval(prm.pressure_rebuild_interval);
      if (rhs.l2_norm() > 0)
        last_solve = pressure_solver.solve(A, dp_solution, rhs, options, step_number);
      else
        last_solve = {"cg_amg", 0, 0.0};
      constraints.distribute(dp_solution);
      dp_solution.update_ghost_values();
      seconds_solve += seconds_since(t0);
      solver_iterations += last_solve.iterations;
      ++n_solves;
      lap = Clock::now();
    }
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        dp_node.local_element(i) = dp_solution(pspace.node_dof(i, 0));
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::plate_unit_pressures(const dealii::AffineConstraints<double> &dirichlet,
                                    const dealii::AffineConstraints<double> &dirichlet_homogeneous)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    const unsigned int nl = n_local();
    // without any Dirichlet row the pressure is fixed only up to a
    // constant and a plate's unit inflow has no consistent answer
    const unsigned int n_dirichlet =
      dealii::Utilities::MPI::sum(static_cast<unsigned int>(dirichlet.n_constraints()), comm);
    require(n_dirichlet > 0, prm.rigid_plates[force_plates[0]].where,
            "the pore water has no pressure reference: no free surface, drained boundary or permeable plate "
            "(a closed, impermeable box); allowed: 'drainage = permeable', 'semi implicit/drained boundaries', "
            "or water with a free surface");
    const auto constraints_h = active.constraints_with(dirichlet_homogeneous);
    for (auto &r : plate_response)
      {
        const double *es = at(r.es), *ew = at(r.ew);
        transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                                 [&](unsigned int, It &it, const Stencil &s) {
                                                   double *P = it->get_properties().data();
                                                   double  v[dim];
                                                   s.vector_value(es, v);
                                                   for (unsigned int d = 0; d < dim; ++d)
                                                     P[fs.plate_flux + d] = (1 - P[fs.porosity]) * v[d];
                                                 });
        if (prm.one_set) // the water's share on the same points (the water set is empty)
          one_set_plate_flux<K>(ew);
        transfer::for_each_point_stencil<dim, K>(grid, water, stencils<K>(water),
                                                 [&](unsigned int, It &it, const Stencil &s) {
                                                   double *P = it->get_properties().data();
                                                   double  v[dim];
                                                   s.vector_value(ew, v);
                                                   for (unsigned int d = 0; d < dim; ++d)
                                                     P[fw.plate_flux + d] = P[fw.porosity] * v[d];
                                                 });
        Vector rhs1, x1;
        pspace.reinit_vector(rhs1);
        pspace.reinit_vector(x1);
        const PoissonFluxSource                                terms[2] = {{fs.plate_flux}, {fw.plate_flux}};
        transfer::AssembleSystem<dim, K, 1, PoissonFluxSource> assembly(active, constraints_h, terms[0], nullptr,
                                                                        &rhs1);
        transfer::for_each_cell_of_sets<dim>(grid, {&soil, &water}, assembly,
                                             [&](const unsigned int k) { assembly.integrand = terms[k]; });
        if (any_plate_sealed)
          add_plate_surface_flux(constraints_h, r.es, rhs1);
        if (any_plate_outflow)
          add_plate_outflow_flux(constraints_h, r.es, r.ew, rhs1);
        transfer::finish_assembly(active, assembly.diag_sum, assembly.diag_count, nullptr, &rhs1);
        const auto          t0 = Clock::now();
        LinearSolverOptions options;
        options.method             = LinearSolverOptions::Method::cg_amg;
        options.relative_tolerance = prm.pressure_tolerance;
        if (rhs1.l2_norm() > 0)
          {
            const auto info = pressure_solver.solve(A, x1, rhs1, options, step_number);
            solver_iterations += info.iterations;
            last_solve.iterations += info.iterations;
            last_solve.relative_residual = std::max(last_solve.relative_residual, info.relative_residual);
          }
        constraints_h.distribute(x1);
        x1.update_ghost_values();
        seconds_solve += seconds_since(t0);
        for (unsigned int i = 0; i < nl; ++i)
          if (component[i] == 0)
            r.dp.local_element(i) = x1(pspace.node_dof(i, 0));
      }
    lap = Clock::now();
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::correction(const StepState &this_step)
  {
    const unsigned int         nl      = n_local();
    const std::vector<double> &plate_v = this_step.plate_v;
    // (6) correction (64)-(68): sum V N grad(Delta p) over each phase's points
    {
      const double *dpn = at(dp_node);
      double       *gsv = at(gs), *gwv = at(gw);
      if (prm.one_set) // both phases in one walk
        one_set_weak_gradients<K>(dpn, gsv, gwv);
      else
        transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), dpn, L::volume, gsv);
      transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), dpn, L::volume, gwv);
    }
    for (auto &r : plate_response) // the unit responses' pressure forces
      {
        const double *dpn = at(r.dp);
        if (prm.one_set)
          one_set_weak_gradients<K>(dpn, at(r.gs), at(r.gw));
        else
          transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), dpn, L::volume, at(r.gs));
        transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), dpn, L::volume, at(r.gw));
        exchange({&r.gs, &r.gw});
      }
    exchange({&gs, &gw});
    add_lap(phase.p2n);
    for (unsigned int i = 0; i < nl; ++i)
      correct_velocities(this_step, i, vs_star.local_element(i), vw_star.local_element(i), gs.local_element(i),
                         gw.local_element(i), at(dp_node), plate_v.data(), vs_new.local_element(i),
                         vw_new.local_element(i));
  }

  // v^{t+1} from v* and the pressure increment's force; a plate's axis DoF
  // moves with its velocity Vp[k] (the water too at an impermeable plate)
  template <int dim>
  void
  Solver<dim>::correct_velocities(const StepState &this_step, const unsigned int i, const double vss, const double vws,
                                  const double gsi, const double gwi, const double *dpv, const double *Vp, double &vs,
                                  double &vw) const
  {
    const double       h      = this_step.h;
    const double       ms_cut = this_step.ms_cut;
    const unsigned int j      = node_of[i];
    const double       Mwi = Mw_node.local_element(j), Msi = Ms.local_element(j), n = n_node.local_element(j);
    // a sealed surface's node: the surface term -beta_J dp_J (sealed_surface)
    const double surface = any_sealed ? beta.local_element(i) * dpv[j] : 0.0;
    // the plate's corner on a draining face: -beta_out dp_J on both phases (plate_surface)
    const double out = any_plate_outflow ? beta_out.local_element(i) * dpv[j] : 0.0;
    vw               = Mwi > 0 ? vws + h * n * (gwi - out) / Mwi : 0.0;
    vs               = Msi > ms_cut && !prm.rigid_skeleton ? vss + h * ((1 - n) * (gsi - out) - surface) / Msi : 0.0;
    if (constrained[i])
      vs = 0;
    if (water_constrained[i])
      vw = 0;
    bloads.correct(i, Mwi, vs, vw); // prescribed velocities
    if (const unsigned int k = plate_of[i]; k != no_plate)
      {
        vs = Vp[k];
        if (!prm.rigid_plates[k].permeable)
          vw = Mwi > 0 ? Vp[k] : 0.0;
      }
  }

  template <int dim>
  void
  Solver<dim>::plate_balance(StepState &this_step)
  {
    const double               h        = this_step.h;
    const auto                &g        = this_step.g;
    const unsigned int         n_plates = prm.rigid_plates.size();
    const std::vector<double> &plate_v  = this_step.plate_v;
    // The plates' momentum balance at the end of the step. Per plate j the
    // force it exerts on the material along its axis is the mixture's
    // residual over its owned axis DoFs (the drag between the phases
    // cancels in the sum; at a permeable plate the water's own row is
    // satisfied, so what remains is the soil's with the drag):
    //   R_j = sum [M_s (v_s - v_s^t) + M_w (v_w - v_w^t)] / h
    //         - F_s - M_w b - (1 - n)(G_s p^t + g_s) - n (G_w p^t + g_w),
    // g_s, g_w the weak gradients of the pressure increment. Every term is
    // affine in the force plates' velocities: R = R0 + R1 V, R0 from the
    // step with V = 0, column r of R1 from force plate r's unit response.
    const std::vector<double> R     = plate_residuals(this_step);
    const unsigned int        owned = grid.partitioner->locally_owned_size();
    const unsigned int        nf    = force_plates.size();
    if (nf > 0)
      solve_force_plates(this_step, R);
    // the tangential reaction of a rough plate: the same residual over its
    // held tangential DoFs, per component
    std::vector<double> T(n_plates * dim, 0.0);
    for (unsigned int i = 0; i < owned; ++i)
      if (const unsigned int k = plate_tangential_of[i]; k != no_plate)
        {
          const unsigned int j   = node_of[i];
          const double       Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
          T[k * dim + component[i]] += (Msi * (vs_new.local_element(i) - vs_t.local_element(i)) +
                                        Mwi * (vw_new.local_element(i) - vw_t.local_element(i))) /
                                         h -
                                       Fs.local_element(i) - Mwi * g[component[i]] -
                                       (1 - n) * (Gps.local_element(i) + gs.local_element(i)) -
                                       n * (Gpw.local_element(i) + gw.local_element(i));
        }
    MPI_Allreduce(MPI_IN_PLACE, T.data(), static_cast<int>(T.size()), MPI_DOUBLE, MPI_SUM, comm);
    for (unsigned int k = 0; k < n_plates; ++k)
      {
        PlateState &st = plate_state[k];
        double      f  = R[k];
        for (unsigned int r = 0; r < nf; ++r)
          f += R[(1 + r) * n_plates + k] * plate_v[force_plates[r]];
        double t2 = 0;
        for (unsigned int d = 0; d < dim; ++d)
          t2 += T[k * dim + d] * T[k * dim + d];
        st.velocity = plate_v[k];
        st.displacement += plate_v[k] * h;
        st.force      = f;
        st.tangential = std::sqrt(t2);
      }
  }

  template <int dim>
  void
  Solver<dim>::velocity_reactions(const StepState &this_step)
  {
    const double h = this_step.h;
    const auto  &g = this_step.g;
    // the reactions of the velocity conditions, the mixture's
    // momentum residual over their DoFs (the plates' R and T)
    bloads.reactions([&](const unsigned int i) {
      const unsigned int j   = node_of[i];
      const double       Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
      return (Msi * (vs_new.local_element(i) - vs_t.local_element(i)) +
              Mwi * (vw_new.local_element(i) - vw_t.local_element(i))) /
               h -
             Fs.local_element(i) - Mwi * g[component[i]] - (1 - n) * (Gps.local_element(i) + gs.local_element(i)) -
             n * (Gpw.local_element(i) + gw.local_element(i));
    });
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::plate_residuals(const StepState &this_step)
  {
    const double       h        = this_step.h;
    const auto        &g        = this_step.g;
    const unsigned int nl       = n_local();
    const unsigned int n_plates = prm.rigid_plates.size();
    const unsigned int owned    = grid.partitioner->locally_owned_size();
    const unsigned int nf       = force_plates.size();
    // R0 (the V = 0 step, displacement plates at their velocities) and R1
    std::vector<double> R(n_plates * (1 + nf), 0.0);
    const auto add_residual = [&](const unsigned int column, const Vector &vsn, const Vector &vwn, const Vector &gsv,
                                  const Vector &gwv, const Vector &dpv, const bool base) {
      for (unsigned int i = 0; i < owned; ++i)
        if (const unsigned int k = plate_of[i]; k != no_plate)
          {
            const unsigned int j   = node_of[i];
            const double       Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
            double r = (Msi * vsn.local_element(i) + Mwi * vwn.local_element(i)) / h - (1 - n) * gsv.local_element(i) -
                       n * gwv.local_element(i);
            if (base)
              r -= (Msi * vs_t.local_element(i) + Mwi * vw_t.local_element(i)) / h + Fs.local_element(i) +
                   Mwi * g[component[i]] + (1 - n) * Gps.local_element(i) + n * Gpw.local_element(i);
            // an impermeable plate: the pore pressure's push on it, the
            // surface term -beta p^{t+1} of the force on the material
            if (any_plate_sealed)
              r += beta_plate.local_element(i) * ((base ? p_node.local_element(j) : 0.0) + dpv.local_element(j));
            R[column * n_plates + k] += r;
          }
    };
    add_residual(0, vs_new, vw_new, gs, gw, dp_node, true);
    for (unsigned int r = 0; r < nf; ++r)
      {
        PlateResponse      &u = plate_response[r];
        std::vector<double> unit(n_plates, 0.0);
        unit[force_plates[r]] = 1.0;
        for (unsigned int i = 0; i < nl; ++i)
          correct_velocities(this_step, i, u.es.local_element(i), u.ew.local_element(i), u.gs.local_element(i),
                             u.gw.local_element(i), at(u.dp), unit.data(), u.vs.local_element(i),
                             u.vw.local_element(i));
        add_residual(1 + r, u.vs, u.vw, u.gs, u.gw, u.dp, false);
      }
    // the same sums, so the same V, on every rank
    MPI_Allreduce(MPI_IN_PLACE, R.data(), static_cast<int>(R.size()), MPI_DOUBLE, MPI_SUM, comm);
    return R;
  }

  template <int dim>
  void
  Solver<dim>::solve_force_plates(StepState &this_step, const std::vector<double> &R)
  {
    const double         h        = this_step.h;
    const unsigned int   nl       = n_local();
    const unsigned int   n_plates = prm.rigid_plates.size();
    std::vector<double> &plate_v  = this_step.plate_v;
    const unsigned int   nf       = force_plates.size();
    std::vector<double>  a(nf * nf), x(nf);
    for (unsigned int q = 0; q < nf; ++q)
      {
        const auto &pl = prm.rigid_plates[force_plates[q]];
        for (unsigned int r = 0; r < nf; ++r)
          a[q * nf + r] = R[(1 + r) * n_plates + force_plates[q]];
        x[q] = pl.force_at(time + h) - R[force_plates[q]];
        if (!(a[q * nf + q] > 0))
          throw InstabilityError(pl.where + ": the plate touches no material (its nodes carry no mass), so "
                                            "its velocity under a force is undetermined");
      }
    for (unsigned int c = 0; c < nf; ++c) // no pivoting: R1 is dominated by its diagonal (mass / h)
      for (unsigned int q = c + 1; q < nf; ++q)
        {
          const double f = a[q * nf + c] / a[c * nf + c];
          for (unsigned int r = c; r < nf; ++r)
            a[q * nf + r] -= f * a[c * nf + r];
          x[q] -= f * x[c];
        }
    for (unsigned int c = nf; c-- > 0;)
      {
        for (unsigned int r = c + 1; r < nf; ++r)
          x[c] -= a[c * nf + r] * x[r];
        x[c] /= a[c * nf + c];
      }
    for (unsigned int r = 0; r < nf; ++r)
      {
        const double   V         = x[r];
        PlateResponse &u         = plate_response[r];
        plate_v[force_plates[r]] = V;
        for (unsigned int i = 0; i < nl; ++i) // owned and ghost entries alike
          {
            vs_new.local_element(i) += V * u.vs.local_element(i);
            vw_new.local_element(i) += V * u.vw.local_element(i);
            dp_node.local_element(i) += V * u.dp.local_element(i);
            gs.local_element(i) += V * u.gs.local_element(i);
            gw.local_element(i) += V * u.gw.local_element(i);
          }
      }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::nodes_to_particles()
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    // (7) FLIP velocities of both sets, pore pressure to the water points;
    // (8a) MUSL: the soil's new momentum to the nodes (Ps reused)
    Ps = 0;
    {
      const double *vsn = at(vs_new), *vst = at(vs_t), *vwn = at(vw_new), *vwt = at(vw_t), *dpn = at(dp_node),
                   *pn = at(p_node);
      double *ps       = at(Ps);
      transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                               [&](unsigned int, It &it, const Stencil &s) {
                                                 double *P = it->get_properties().data();
                                                 flip_update(s, vsn, vst, P + L::velocity);
                                                 s.scatter_vector(ps, P[L::mass], P + L::velocity);
                                               });
      transfer::for_each_point_stencil<dim, K>(grid, water, stencils<K>(water),
                                               [&](unsigned int, It &it, const Stencil &s) {
                                                 double *P = it->get_properties().data();
                                                 flip_update(s, vwn, vwt, P + L::velocity);
                                                 pressure_update(s, pn, dpn, fw, P);
                                               });
    }
  }

  template <int dim>
  void
  Solver<dim>::remap_soil_velocity(const StepState &this_step)
  {
    const unsigned int         nl      = n_local();
    const double               ms_cut  = this_step.ms_cut;
    const std::vector<double> &plate_v = this_step.plate_v;
    exchange({&Ps});
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double m        = Ms.local_element(node_of[i]);
        vs_t.local_element(i) = (m > ms_cut && !constrained[i]) ? Ps.local_element(i) / m : 0.0; // remapped
        if (plate_of[i] != no_plate) // the plate's velocity, as the walls' zero (A11)
          vs_t.local_element(i) = plate_v[plate_of[i]];
        bloads.remap(i, vs_t.local_element(i)); // prescribed velocities
      }
  }

  template <int dim>
  void
  Solver<dim>::plate_node_spread(const StepState &this_step)
  {
    const double               h       = this_step.h;
    const std::vector<double> &plate_v = this_step.plate_v;
    // [0, n): axis spread; [n, 2n): tangential slip of the nodes
    const unsigned int  np = prm.rigid_plates.size();
    std::vector<double> spread(2 * np, 0.0);
    for (unsigned int i = 0; i < grid.partitioner->locally_owned_size(); ++i)
      {
        const unsigned int k = plate_node_of[node_of[i]];
        if (k == no_plate)
          continue;
        if (plate_of[i] != no_plate)
          spread[k] = std::max(
            {spread[k], std::abs(vs_new.local_element(i) - plate_v[k]), std::abs(vs_t.local_element(i) - plate_v[k])});
        else if (component[i] != prm.rigid_plates[k].axis && (!constrained[i] || plate_tangential_of[i] != no_plate))
          spread[np + k] =
            std::max({spread[np + k], std::abs(vs_new.local_element(i)), std::abs(vs_t.local_element(i))});
      }
    MPI_Allreduce(MPI_IN_PLACE, spread.data(), static_cast<int>(spread.size()), MPI_DOUBLE, MPI_MAX, comm);
    for (unsigned int k = 0; k < np; ++k)
      {
        plate_state[k].node_spread += 2 * h * spread[k];
        plate_state[k].node_slip += h * spread[np + k];
      }
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::update_and_move_points(const StepState &this_step)
  {
    const double h             = this_step.h;
    const bool   initial_stage = this_step.initial_stage;
    // (7a) positions from the new nodal velocities; (8b-g) soil: ΔF from the
    // remapped increment at x^t, volume, J, porosity, conductivity, stress
    {
      SoilUpdate<K> su{*this, initial_stage ? initialisation_models : prm.materials, at(vs_new), h};
      transfer::UpdateAndMove<dim, K, SoilUpdate<K>> move_soil(grid, soil, at(vs_t), h, su);
      transfer::for_each_active_cell(soil, move_soil);
      add_lap(phase.stress);
      soil.relocate();
      WaterMove<dim, K> wm;
      // single point: the water rides on the soil points (the same positions,
      // moved by the same velocity field and the same arithmetic)
      transfer::UpdateAndMove<dim, K, WaterMove<dim, K>> move_water(
        grid, water, at(prm.single_point || initial_stage ? vs_new : vw_new), h, wm);
      transfer::for_each_active_cell(water, move_water);
      water.relocate();
      add_lap(phase.relocation);
    }
  }

  template <int dim>
  template <class K>
  struct Solver<dim>::SoilUpdate
  {
    using It = transfer::PointIterator<dim>;
    const Solver                                                  &s;
    const std::vector<std::shared_ptr<const materials::Material>> &models; // per material, this step's
    const double                                                  *v_grid; // v_s^{t+1}: the point moves with it
    const double                                                   h;
    struct PointState
    {
    };
    inline void
    increments(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du, const double *,
               double (&gu)[dim][dim], double (&dx)[dim])
    {
      double unused[dim];
      K::value_and_gradient(cell, du, e, unused, gu);
      typename K::Field vg;
      K::gather(cell, v_grid, h, vg, false);
      K::interpolate(vg, e, dx);
    }
    inline void
    update(const unsigned int, const typename K::Cell &, double *P, const double (&gu)[dim][dim], PointState &)
    {
      // ΔF = I + grad Δu (Alg. 8(b), the usual index order)
      const dealii::Tensor<2, 3> dF = transfer::increment_tensor<dim>(gu, 1.0);
      const double               dJ = dealii::determinant(dF);
      if (!(dJ > 0))
        throw InstabilityError("a soil point's volume increment det(ΔF) = " + std::to_string(dJ) + " is not positive");
      const unsigned int         mid     = static_cast<unsigned int>(P[L::material]);
      const materials::Material &m       = *models[mid];
      double *const              history = P + s.soil.layout.history;
      // the increment the model sees: ΔF, or ΔF-bar (79); the modified F-bar
      // also replaces the model's b_e by b_e-bar (82) before the push (81)
      dealii::Tensor<2, 3> dF_model = dF;
      if (s.prm.volumetric_stabilisation != VolumetricStabilisation::none)
        {
          const double dJ_bar = P[s.fs.smoothed_volume_increment];
          if (!(dJ_bar > 0))
            throw InstabilityError("a soil point's smoothed volume increment (F-bar) " + std::to_string(dJ_bar) +
                                   " is not positive");
          if (s.prm.volumetric_stabilisation == VolumetricStabilisation::modified_f_bar)
            transfer::scale_elastic_b(history,
                                      P[s.fs.patch_elastic_jacobian] /
                                        m.elastic_jacobian(dealii::ArrayView<const double>(history, m.n_history())));
          dF_model = transfer::stabilised_increment<dim>(dF, dJ_bar);
        }
      P[L::volume] *= dJ;             // (8d)
      if (s.bloads.carries_offsets()) // the loaded face moves with the material: d <- dF d (0 stays 0)
        {
          double d[dim];
          for (unsigned int i = 0; i < dim; ++i)
            d[i] = P[s.fs.surface_offset + i];
          for (unsigned int i = 0; i < dim; ++i)
            {
              double di = 0;
              for (unsigned int j = 0; j < dim; ++j)
                di += dF[i][j] * d[j];
              P[s.fs.surface_offset + i] = di;
            }
        }
      const double J   = P[L::volume] / P[s.fs.initial_volume]; // (8e)
      const double n0  = P[s.fs.initial_porosity];
      const double n   = std::clamp(1 - (1 - n0) / J, 1e-6, 1 - 1e-6); // (8f)
      P[s.fs.porosity] = n;
      if (s.prm.kozeny_carman) // (8g), C1 from k0 and n0
        {
          const double k0      = s.prm.soil_of_material[mid].conductivity;
          const double C1      = k0 * (1 - n0) * (1 - n0) / (n0 * n0 * n0);
          P[s.fs.conductivity] = C1 * n * n * n / ((1 - n) * (1 - n));
        }
      // Nor-Sand (96): v^{t+1} = v0 Jbar^{t+1}; the model multiplies its v by
      // det of the increment it is given, so it gets v0 Jbar / det(dF_model)
      if (s.smooth_jacobian && m.has_specific_volume())
        m.set_specific_volume(P[s.fs.smoothed_jacobian], dealii::determinant(dF_model),
                              dealii::ArrayView<double>(history, m.n_history()));
      auto                            sigma = L::get_stress(P);
      const dealii::ArrayView<double> hist(history, m.n_history());
      if (m.has_finite_strain_form())
        {
          // the finite-strain return with the increment itself (Hencky
          // Mohr-Coulomb, Nor-Sand, Neo-Hookean): b_e^tr = ΔF b_e ΔF^T, the
          // return in principal logarithmic strains, Kirchhoff tau; then
          // sigma' = tau / J with the point's own J = V / V0 (Alg. step
          // 10(d)), so that V sigma' = V0 tau: the model's J follows the
          // stabilised increments, which may wander from the point's volume
          // (a gas-like point of a landslide: 4e-6 against 1.0)
          sigma = m.finite_strain_step(dF_model, hist) / J;
        }
      else
        {
          // small-strain models: the rate form with the strain and spin
          // increments of ΔF (as the explicit family)
          materials::Strain d_eps;
          materials::Spin   d_omega;
          double            gu_model[dim][dim];
          for (unsigned int i = 0; i < dim; ++i)
            for (unsigned int j = 0; j < dim; ++j)
              gu_model[i][j] = dF_model[i][j] - (i == j ? 1.0 : 0.0);
          materials::strain_and_spin_increments<dim>(gu_model, d_eps, d_omega);
          if (dim == 2) // the out-of-plane stretch of the F-bar's isotropic factor
            d_eps[2][2] = dF_model[2][2] - 1;
          m.update_stress(d_eps, d_omega, h, sigma, hist);
        }
      L::set_stress(sigma, P);
    }
    inline void
    moved(const It &, double *, const dealii::Point<dim> &, PointState &)
    {
    }
  };

  template <int dim>
  void
  Solver<dim>::end_initialisation()
  {
    // the conductivity jumps to k0: the pressure matrix with it (at the same
    // step in a restarted run)
    pressure_solver.invalidate();
    unsigned long long n = 0;
    for (auto &pt : soil.handler)
      {
        auto                       P = pt.get_properties();
        const materials::Material &m = *prm.materials[static_cast<unsigned int>(P[L::material])];
        if (m.reinitialize_reference(dealii::ArrayView<double>(P.data() + soil.layout.history, m.n_history())))
          ++n;
      }
    n = dealii::Utilities::MPI::sum(n, comm);
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      std::cout << "initialisation (seed 002 App. B.4) ends at t = " << prm.initialisation_time << " s: " << n
                << " nor sand points take their current pressure and elastic volumetric strain as the reference, "
                   "the image pressure from the OCR (Eq. 113); plasticity on, conductivity k0, water points free"
                << std::endl;
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::volume_averages(const double h, const double ms_cut)
  {
    const bool fbar     = prm.volumetric_stabilisation != VolumetricStabilisation::none;
    using Stencil       = transfer::PointStencil<dim, K>;
    using It            = transfer::PointIterator<dim>;
    const bool modified = prm.volumetric_stabilisation == VolumetricStabilisation::modified_f_bar;
    if (modified)
      {
        patch_mass.assign(patches.size(), 0.0);
        patch_mass_Je.assign(patches.size(), 0.0);
      }
    // dJ of the increment the update will use (h x the remapped velocity, at x^t)
    Mdj = 0;
    Mjt = 0;
    {
      const double *v  = vs_t.begin();
      double       *mj = Mdj.begin(), *mt = Mjt.begin();
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          double *P = it->get_properties().data();
          double  gv[dim][dim];
          s.vector_gradient(v, gv);
          const double dJ = dealii::determinant(transfer::increment_tensor<dim>(gv, h)); // I + h grad v
          if (fbar)
            s.scatter(mj, P[L::mass] * dJ);
          if (smooth_jacobian) // J^{t+1} = (V / V0) dJ
            s.scatter(mt, P[L::mass] * P[L::volume] / P[fs.initial_volume] * dJ);
          if (modified)
            {
              const auto        &m = *prm.materials[static_cast<unsigned int>(P[L::material])];
              const unsigned int k = patches.index(it->get_location());
              patch_mass[k] += P[L::mass];
              patch_mass_Je[k] +=
                P[L::mass] *
                m.elastic_jacobian(dealii::ArrayView<const double>(P + soil.layout.history, m.n_history()));
            }
        });
    }
    exchange({&Mdj, &Mjt});
    // every rank needs the sums of the patches its points are in; a patch may
    // span cells of several ranks: one sum over all ranks (2 x the number of
    // patches per step; a neighbour exchange would scale better, not needed yet)
    if (modified && dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
      {
        dealii::Utilities::MPI::sum(patch_mass, comm, patch_mass);
        dealii::Utilities::MPI::sum(patch_mass_Je, comm, patch_mass_Je);
      }
    for (unsigned int i = 0; i < n_local(); ++i)
      if (component[i] == 0)
        {
          const double m       = Ms.local_element(i);
          Mdj.local_element(i) = m > ms_cut ? Mdj.local_element(i) / m : 0.0; // now dJ_I
          Mjt.local_element(i) = m > ms_cut ? Mjt.local_element(i) / m : 0.0; // now J_I
        }
    const double *dj = Mdj.begin(), *jt = Mjt.begin();
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               double *P = it->get_properties().data();
                                               // the stencil's nodes all carry soil mass (this point's), so the
                                               // partition of unity holds: a uniform dJ is returned exactly
                                               if (fbar)
                                                 P[fs.smoothed_volume_increment] = s.value(dj);
                                               if (smooth_jacobian)
                                                 P[fs.smoothed_jacobian] = s.value(jt);
                                               if (modified)
                                                 {
                                                   const unsigned int k         = patches.index(it->get_location());
                                                   P[fs.patch_elastic_jacobian] = patch_mass_Je[k] / patch_mass[k];
                                                 }
                                             });
  }

  template StepOutcome Solver<2>::advance_by(const double);
  template StepOutcome Solver<3>::advance_by(const double);
} // namespace talus::semi_implicit
