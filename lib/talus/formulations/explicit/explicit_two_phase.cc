#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/explicit_two_phase.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/formulations/explicit/with_kernel.h>
#include <talus/materials/strain_increments.h>
#include <talus/shape/q1.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/move_point.h>
#include <talus/transfer/pressure_relaxation.h>

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

namespace talus::explicit_mpm
{
  using dealii::Patterns::Double;
  using dealii::Patterns::Selection;

  namespace
  {
    bool
    any_of_drainage(const std::vector<PoreLiquid> &v, const Drainage d)
    {
      for (const auto &p : v)
        if (p.drainage == d)
          return true;
      return false;
    }
  } // namespace

  template <int dim>
  bool
  LiquidParameters<dim>::any_coupled() const
  {
    return any_of_drainage(pore_liquid, Drainage::coupled);
  }

  template <int dim>
  bool
  LiquidParameters<dim>::any_traction() const
  {
    for (const auto &t : tractions)
      if (t.face >= 0)
        return true;
    return false;
  }

  // ================================================================ undrained wrapper
  namespace
  {
    /// Undrained effective-stress analysis (seed 000 §4.3.8): the skeleton model
    /// integrates the effective stress, the excess pore pressure (compression
    /// positive, history 0) follows the volumetric strain, dp = -(K_L / n) tr(d eps)
    /// (Eq. 4.52 with the equivalent bulk modulus of the pore liquid K_L / n for
    /// incompressible grains: the undrained limit v_L = v_S of the storage equation
    /// 3.23). The stress carried by the point is the total stress sigma' - p I.
    class UndrainedEffectiveStress : public materials::Material
    {
    public:
      UndrainedEffectiveStress(std::shared_ptr<const materials::Material> s, const double K_L, const double n)
          : skeleton(std::move(s))
          , K_eq(K_L / n)
      {
        name = skeleton->name;
        id   = skeleton->id;
        set_density(skeleton->density());
      }
      std::string
      model_name() const override
      {
        return skeleton->model_name() + " (undrained)";
      }
      double
      constrained_modulus() const override
      {
        return skeleton->constrained_modulus() + K_eq;
      }
      double
      dynamic_viscosity() const override
      {
        return skeleton->dynamic_viscosity();
      }
      unsigned int
      n_history() const override
      {
        return 1 + skeleton->n_history();
      }
      std::vector<std::string>
      history_names() const override
      {
        std::vector<std::string> n = {"excess pore pressure"};
        for (const auto &s : skeleton->history_names())
          n.push_back(s);
        return n;
      }
      void
      initialize_history(const materials::Stress &sigma, materials::ArrayView<double> h) const override
      {
        h[0] = 0.0; // the initial stress is effective, no excess pore pressure
        skeleton->initialize_history(sigma, materials::ArrayView<double>(h.data() + 1, h.size() - 1));
      }
      void
      update_stress(const materials::Strain &d_eps, const materials::Spin &d_omega, const double dt,
                    materials::Stress &sigma, materials::ArrayView<double> h) const override
      {
        materials::Stress eff = sigma;
        for (unsigned int i = 0; i < 3; ++i)
          eff[i][i] += h[0];
        skeleton->update_stress(d_eps, d_omega, dt, eff, materials::ArrayView<double>(h.data() + 1, h.size() - 1));
        h[0] -= K_eq * trace(d_eps);
        sigma = eff;
        for (unsigned int i = 0; i < 3; ++i)
          sigma[i][i] -= h[0];
      }
      double
      elastic_energy_density(const materials::Stress &sigma) const override
      {
        // the split into sigma' and p is not known from sigma alone: the skeleton's
        // energy of the total stress (a diagnostic only)
        return skeleton->elastic_energy_density(sigma);
      }

    private:
      std::shared_ptr<const materials::Material> skeleton;
      double                                     K_eq;
    };

    bool
    is_liquid_model(const materials::Material &m)
    {
      const std::string n = m.model_name();
      return n == "newtonian" || n == "bingham" || n == "frictional fluid";
    }
  } // namespace

  // ================================================================ parameters
  PoreLiquid
  parse_pore_liquid(dealii::ParameterHandler &prm, const std::string &where_m,
                    std::shared_ptr<const materials::Material> &material)
  {
    const std::string where = where_m + "/pore liquid";
    PoreLiquid        p     = materials::read_pore_liquid(prm);
    if (p.drainage == Drainage::drained)
      return p;
    require(!is_liquid_model(*material), where + "/drainage",
            "'" + materials::drainage_name(p.drainage) + "' needs a soil skeleton model; model '" +
              material->model_name() + "' is a liquid (allowed for liquids: drained)");
    materials::check_porosity(p, where);
    require(p.bulk_modulus > 0, where + "/liquid bulk modulus", "must be > 0");
    if (p.drainage == Drainage::undrained)
      {
        material = std::make_shared<UndrainedEffectiveStress>(material, p.bulk_modulus, p.porosity);
        return p;
      }
    materials::check_seepage(p, where);
    // the 2-phase step's drag n mu_d / kappa uses kappa (Eq. 3.25)
    if (p.conductivity > 0)
      p.intrinsic_permeability = p.conductivity * p.viscosity / (p.density * p.gravity);
    return p;
  }

  void
  declare_body_traction(dealii::ParameterHandler &prm, const unsigned int dim)
  {
    prm.declare_entry("traction face", "none", Selection(dim == 2 ? "none|x-|x+|y-|y+" : "none|x-|x+|y-|y+|z-|z+"),
                      "Box bodies: face whose outermost layer of material points carries 'traction' "
                      "(seed 000 §4.3.2: each point carries traction x its share of the face), constant in "
                      "time. An alias of a global 'loads/traction k' with apply to = body face (the same "
                      "forces); it also selects the separate (unfused) step, as the 2-phase scenes use.");
    prm.declare_entry("traction", dim == 2 ? "0, 0" : "0, 0, 0", dealii::Patterns::Anything(),
                      "Traction vector [Pa] on 'traction face' (e.g. '0, -10000' presses a top face down).");
  }

  template <int dim>
  BodyTraction<dim>
  parse_body_traction(dealii::ParameterHandler &prm, const std::string &where)
  {
    BodyTraction<dim> t;
    const std::string f = prm.get("traction face");
    if (f == "none")
      return t;
    t.face       = 2 * (f[0] - 'x') + (f[1] == '+' ? 1 : 0);
    const auto v = dealii::Utilities::split_string_list(prm.get("traction"), ',');
    require(v.size() == dim, where + "/traction", "needs exactly " + std::to_string(dim) + " numbers");
    for (unsigned int d = 0; d < dim; ++d)
      {
        try
          {
            std::size_t pos = 0;
            t.traction[d]   = std::stod(v[d], &pos);
            if (pos != v[d].size() || !std::isfinite(t.traction[d]))
              throw std::invalid_argument(v[d]);
          }
        catch (const std::exception &)
          {
            throw InputError(where + "/traction: '" + v[d] + "' is not a finite number");
          }
      }
    return t;
  }

  void
  declare_liquid_output(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("liquid");
    prm.declare_entry("free surface factor", "0", Double(0, 1),
                      "Free-surface detection (seed 000 §6.8, Eq. 6.40): a material point is on the free "
                      "surface when the density interpolated from the nodal density of the non-empty cells "
                      "is <= factor x its material density. 0 = off; suggested 0.7 (mesh dependent, < 1). "
                      "When on: particle field 'free_surface' (1/0) in the VTU output, columns "
                      "free_surface_points and the particle extent (min/max per axis) in series.csv.");
    prm.leave_subsection();
    prm.enter_subsection("two phase");
    prm.declare_entry("local damping", "0", Double(0, 1),
                      "Alias of the top-level 'damping/local damping' (seed 000 §6.3; in the 2-phase step "
                      "each phase is damped with its own unbalanced force, Eqs. 6.24-6.28), 0 <= alpha < 1; "
                      "0 = off. Giving both with different values is an error.");
    prm.declare_entry("pressure relaxation", "1", Double(0, 10),
                      "Quadratic B-splines only (linear shape functions ignore it): at each step the pore "
                      "pressure of every point of a coupled material is blended towards its node map-remap "
                      "(liquid-mass-weighted lumped map to the nodes, interpolated back) with the share "
                      "min(1, C c_v dt / h^2), C this number, c_v = k / (rho_L g (1/E_c + n/K_L)) the "
                      "consolidation coefficient, h the smallest cell edge: the point-pressure patterns the "
                      "nodal liquid force does not see decay at the rate Darcy flow dissipates a pattern of "
                      "the grid scale (C = 1: the rule of the semi-implicit 'pressure smoothing fraction = "
                      "automatic'). 0 = off: Terzaghi's column then keeps a pattern in its top point rows "
                      "(docs/shape-functions.md, \"2-phase on B-splines\"). A number in [0, 10].");
    prm.leave_subsection();
  }

  template <int dim>
  void
  parse_liquid_output(dealii::ParameterHandler &prm, LiquidParameters<dim> &p)
  {
    prm.enter_subsection("liquid");
    p.free_surface_factor = prm.get_double("free surface factor");
    prm.leave_subsection();
    require(p.free_surface_factor < 1, "liquid/free surface factor", "must be < 1 (0 = off)");
    prm.enter_subsection("two phase");
    p.local_damping       = prm.get_double("local damping");
    p.pressure_relaxation = prm.get_double("pressure relaxation");
    prm.leave_subsection();
    require(p.local_damping < 1, "two phase/local damping", "must satisfy 0 <= alpha < 1");
  }

  // ================================================================ critical time steps
  std::vector<CriticalStep>
  critical_time_steps(const std::vector<std::shared_ptr<const materials::Material>> &materials,
                      const std::vector<PoreLiquid> &pore_liquid, const double L)
  {
    std::vector<CriticalStep> r;
    for (std::size_t k = 0; k < materials.size(); ++k)
      {
        const auto      &m  = *materials[k];
        const PoreLiquid pl = k < pore_liquid.size() ? pore_liquid[k] : PoreLiquid();
        CriticalStep     c;
        c.material = m.name;
        c.model    = m.model_name();
        if (pl.drainage == Drainage::coupled)
          {
            // seed 000 §4.6.3. rho_S = 'density', E_c of the skeleton.
            const double n = pl.porosity, rS = m.density(), rL = pl.density, KL = pl.bulk_modulus;
            const double Ec = m.constrained_modulus(), g = pl.gravity,
                         k_d = pl.intrinsic_permeability * pl.density * pl.gravity / pl.viscosity;
            const double rho = (1 - n) * rS + n * rL;           // Eq. 4.127
            const double Ecu = Ec + KL / n;                     // Eq. 4.126
            c.wave_speed     = std::sqrt(Ecu / rho);            // Eq. 4.125
            c.dt_wave        = L / c.wave_speed;                // Eq. 4.123 (m = 1)
            const double rt  = rho + (1.0 / n - 2.0) * rL;      // Eq. 4.128
            c.dt_other       = 2 * rt * k_d / (rL * g);         // Eq. 4.124
            c.dt_4_122       = std::min(c.dt_wave, c.dt_other); // Eq. 4.122
            // Eq. 4.129-4.132. The manual prints L_min in b and c; the dimensions
            // (b in 1/s^2, c in 1/s^4) and the limit k -> infinity (dt -> 2/omega_max
            // with omega_max = 2 c / L for E_c -> 0) need L_min^2 and L_min^4.
            const double a = n * rho * g / ((1 - n) * rS * k_d);
            const double b = 4 * (n * rho * KL + (1 - 2 * n) * rL * KL + n * rL * Ec) / (n * (1 - n) * rS * rL * L * L);
            const double cc = 16 * Ec * KL / ((1 - n) * rS * rL * L * L * L * L);
            const double s  = b + std::sqrt(std::max(0.0, b * b - 4 * cc));
            c.dt            = (-2 * a + std::sqrt(4 * a * a + 8 * s)) / s;
            c.phase         = "coupled";
            c.formula       = "Eq. 4.129";
          }
        else
          {
            c.wave_speed    = std::sqrt(m.constrained_modulus() / m.density());
            c.dt_wave       = L / c.wave_speed; // Eq. 4.120 / 4.121
            c.dt            = c.dt_wave;
            const double mu = m.dynamic_viscosity();
            if (is_liquid_model(m))
              {
                c.phase   = "liquid";
                c.formula = "Eq. 4.121";
                if (mu > 0)
                  {
                    // explicit viscous stress: diffusion limit rho L^2 / (2 mu)
                    c.dt_other = m.density() * L * L / (2 * mu);
                    if (c.dt_other < c.dt)
                      {
                        c.dt      = c.dt_other;
                        c.formula = "viscous limit rho L^2 / (2 mu)";
                      }
                  }
              }
            else
              {
                c.phase   = pl.drainage == Drainage::undrained ? "undrained" : "solid";
                c.formula = pl.drainage == Drainage::undrained ? "Eq. 4.120 with E_c + K_L/n" : "Eq. 4.120";
              }
          }
        r.push_back(c);
      }
    return r;
  }

  // ================================================================ 2-phase
  template <int dim>
  TwoPhase<dim>::TwoPhase(Solver<dim> &solver)
      : s(solver)
  {
    coupled = s.prm.liquid.any_coupled();
    relax   = coupled && s.prm.bspline() && s.prm.liquid.pressure_relaxation > 0;
    // with B-splines a drained free surface needs 3 point rows per cell for the
    // node of the grid cell above it (one point row in its support with 2)
    if (coupled && s.prm.bspline())
      for (unsigned int b = 0; b < s.prm.bodies.size(); ++b)
        if (s.prm.liquid.pore_liquid[s.prm.bodies[b].material_id].drainage == Drainage::coupled &&
            s.prm.bodies[b].particles_per_direction < 3)
          log() << "  warning: body " << b << " (coupled 2-phase) has " << s.prm.bodies[b].particles_per_direction
                << " particles per direction with quadratic B-splines: the pore pressure of the point rows next "
                   "to a drained free surface is measured off by up to 0.15 q in Terzaghi's column (L2 2.7 % "
                   "at T_v = 0.05 against 0.5 % with 3; docs/shape-functions.md, \"2-phase on B-splines\"); "
                   "use 3 or more\n";
  }

  template <int dim>
  double
  TwoPhase<dim>::liquid_mass(const double *P) const
  {
    if (!coupled)
      return 0.0;
    const auto &pl = s.prm.liquid.pore_liquid[static_cast<unsigned int>(P[PropertyLayout<dim>::material])];
    return pl.drainage == Drainage::coupled ? P[porosity] * pl.density * P[PropertyLayout<dim>::volume] : 0.0;
  }

  template <int dim>
  void
  TwoPhase<dim>::extend_layout(PropertyLayout<dim> &layout)
  {
    if (coupled)
      {
        porosity        = layout.add_extra("porosity", 1);
        pore_pressure   = layout.add_extra("pore_pressure", 1);
        liquid_velocity = layout.add_extra("liquid_velocity", dim, true);
        grid_changed();
      }
  }

  template <int dim>
  void
  TwoPhase<dim>::grid_changed()
  {
    if (coupled)
      for (Vector *v : {&m_liquid, &m_liquid_n, &drag, &f_liquid, &p_liquid, &a_liquid})
        s.grid.reinit_vector(*v);
    if (relax)
      s.grid.reinit_vector(p_node);
  }

  // The share of the relaxed pore pressure in the step h for each coupled
  // material: min(1, C c_v h / h_min^2) (transfer/pressure_relaxation.h, the
  // rule of the semi-implicit 'automatic' smoothing with C), c_v = k M / (rho_L g)
  // with the storage modulus M = 1 / (1 / E_c + n / K_L) of the skeleton and the
  // liquid (the diffusivity of the pore pressure in the storage equation; E_c
  // for an incompressible liquid).
  template <int dim>
  void
  TwoPhase<dim>::relaxation_fractions(const double h)
  {
    const auto  &pl    = s.prm.liquid.pore_liquid;
    const double h_min = s.grid.min_cell_size();
    relax_share.assign(pl.size(), 0.0);
    for (unsigned int m = 0; m < pl.size(); ++m)
      if (pl[m].drainage == Drainage::coupled)
        {
          const double k = pl[m].intrinsic_permeability * pl[m].density * pl[m].gravity / pl[m].viscosity;
          const double M =
            1.0 / (1.0 / s.prm.materials[m]->constrained_modulus() + pl[m].porosity / pl[m].bulk_modulus);
          const double c_v = transfer::consolidation_coefficient(k, M, pl[m].density, pl[m].gravity);
          relax_share[m]   = transfer::pressure_smoothing_fraction(c_v, h, h_min, s.prm.liquid.pressure_relaxation);
        }
  }

  // p_I = sum N mL p / sum N mL on the scalar slot of each node (the sums of
  // particles_to_nodes; mL = n rho_L V, the denominator is Mbar_L), with ghosts.
  template <int dim>
  void
  TwoPhase<dim>::pressure_map()
  {
    const double *const mLn_ = m_liquid_n.begin();
    double *const       PN   = p_node.begin();
    for (const unsigned int i : s.active_dofs)
      PN[i] = mLn_[i] > 0 ? PN[i] / mLn_[i] : 0.0;
    p_node.update_ghost_values();
  }

  template <int dim>
  void
  TwoPhase<dim>::initialize_particles()
  {
    using L        = PropertyLayout<dim>;
    const auto &pl = s.prm.liquid.pore_liquid;
    for (auto &pt : s.points.handler)
      {
        double            *P   = pt.get_properties().data();
        const unsigned int mat = static_cast<unsigned int>(P[L::material]);
        if (coupled && pl[mat].drainage == Drainage::coupled)
          {
            const double n = pl[mat].porosity;
            P[porosity]    = n;
            P[L::mass]     = (1 - n) * s.prm.materials[mat]->density() * P[L::volume]; // solid mass
            for (unsigned int d = 0; d < dim; ++d)
              P[liquid_velocity + d] = P[L::velocity + d];
          }
      }
  }

  template <int dim>
  void
  TwoPhase<dim>::add_sum_options(diagnostics::SumOptions<dim> &o, const bool strain) const
  {
    using L = PropertyLayout<dim>;
    if (!coupled)
      return;
    o.second_phase = [this](const double *P, const double *&vL) {
      vL = P + liquid_velocity;
      return liquid_mass(P);
    };
    if (strain)
      o.extra_strain = [this](const double *P) {
        const auto &pl = s.prm.liquid.pore_liquid[static_cast<unsigned int>(P[L::material])];
        if (pl.drainage != Drainage::coupled)
          return 0.0;
        return P[L::volume] * P[porosity] * P[pore_pressure] * P[pore_pressure] / (2 * pl.bulk_modulus);
      };
  }

  template <int dim>
  void
  TwoPhase<dim>::step(const double h)
  {
    s.with_kernel([&](auto kernel) { step_with<decltype(kernel)>(h); });
  }

  // ---------------------------------------------------------------- the step
  // One step of §4.5.7 (docs/explicit-liquid-two-phase.md, "One step"): a
  // driver of the phases below, in the order of the algorithm, with the loads'
  // hooks (load_control.h) at the places of the 1-phase step. Three passes over
  // the points (P2G, G2P of the velocities with the momenta, the update), the
  // rest on the nodes.
  template <int dim>
  template <class K>
  void
  TwoPhase<dim>::step_with(const double h)
  {
    auto *const control = s.control.get();
    const auto  t0      = std::chrono::steady_clock::now();
    if (relax)
      relaxation_fractions(h);
    particles_to_nodes<K>(); // 1
    if (relax)
      pressure_map();
    // loads: tractions on the mixture, nodal v^t (the solid momentum of this
    // P2G), friction lift; convergence ratios of both phases
    if (control)
      {
        control->before_nodal_solve(s, h, &s.nodal_p);
        control->nodal_forces_two_phase(s);
      }
    nodal_accelerations(); // 2-3
    if (control)           // prescribed velocities and rigid-wall friction, both phases
      control->nodal_accelerations(s);
    update_ghosts(s.nodal_a, a_liquid);
    g2p_velocity_p2g_momentum<K>(h); // 4, and the momenta of 5
    if (control)
      control->particle_velocities(s); // prescribed point velocities (both phases)
    nodal_velocities();                // 5
    if (control)
      control->nodal_velocities(s); // prescribed values, no penetration at friction walls
    update_ghosts(s.nodal_p, p_liquid);
    s.timings.p2g += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const auto t1 = std::chrono::steady_clock::now();
    g2p_update<K>(h); // 6-11
    s.timings.g2p += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();

    const auto t2 = std::chrono::steady_clock::now();
    s.points.relocate();
    s.p2g_ready = false;
    s.collect_active_dofs();
    s.timings.relocation += std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();
  }

  // Step 1, P2G at time t (Eqs. 4.97-4.103), one pass over the points: lumped
  // solid mass M_S and momentum P_S, the mixture force f (total stress sigma' -
  // p I, the weight of both phases), and for the points of coupled materials
  // the liquid masses M_L (rho_L V) and Mbar_L (n rho_L V), the drag Q, the
  // liquid force f_L and momentum P_L. The traction point forces of the loads
  // are scattered in the same pass (no pass of their own).
  template <int dim>
  template <class K>
  void
  TwoPhase<dim>::particles_to_nodes()
  {
    using L = PropertyLayout<dim>;
    // each point reads and writes the nodes of its kernel stencil (Q1: the
    // cell's vertices; B-spline: its 3^dim window), slot[v] in the cell's list
    constexpr unsigned int nv      = K::n_point_nodes;
    const auto            &pl      = s.prm.liquid.pore_liquid;
    const auto             g       = s.gravity; // of the running stage
    auto *const            control = s.control.get();

    Vector &MSv = s.nodal_mass, &FSv = s.nodal_a, &PSv = s.nodal_p;
    // local (owned + ghost) indices, as in the cell cache
    double *const MS = MSv.begin(), *const FS = FSv.begin(), *const PS = PSv.begin();
    double *const mLt_ = coupled ? m_liquid.begin() : nullptr, *const mLn_ = coupled ? m_liquid_n.begin() : nullptr;
    double *const Q_ = coupled ? drag.begin() : nullptr, *const FL_ = coupled ? f_liquid.begin() : nullptr;
    double *const PL_ = coupled ? p_liquid.begin() : nullptr;
    double *const PN  = relax ? p_node.begin() : nullptr; // sum N mL p (pressure_map)
    s.zero_on_active(MSv);
    s.zero_on_active(FSv);
    s.zero_on_active(PSv);
    if (coupled)
      for (Vector *v : {&m_liquid, &m_liquid_n, &drag, &f_liquid, &p_liquid})
        s.zero_on_active(*v);
    if (relax)
      s.zero_on_active(p_node);
    // traction point forces (loads/traction, at t) scattered in this pass
    double *const T = control ? control->begin_traction_scatter(s) : nullptr;
    transfer::for_each_point(s.points, [&](const unsigned int c, transfer::PointIterator<dim> &pt) {
      const auto         kc  = K::cell(s.grid, c);
      const double      *P   = pt->get_properties().data();
      const unsigned int mat = static_cast<unsigned int>(P[L::material]);
      unsigned int       slot[nv];
      double             N[nv], G[nv][dim];
      K::point_stencil(kc, pt->get_reference_location(), slot, N, G);
      const double mS = P[L::mass], V = P[L::volume];
      auto         sig = L::get_stress(P);
      const bool   cp  = coupled && pl[mat].drainage == Drainage::coupled;
      double       mL = 0, mLt = 0, q = 0, p = 0;
      if (cp)
        {
          const double n = P[porosity];
          mLt            = pl[mat].density * V;
          mL             = n * mLt;
          q              = n * pl[mat].viscosity / pl[mat].intrinsic_permeability * V; // n rho_L g / k V
          p              = P[pore_pressure];
          for (unsigned int i = 0; i < 3; ++i)
            sig[i][i] -= p; // total stress (Eq. 4.117)
        }
      double fp[dim] = {};
      bool   loaded  = false;
      if (T)
        {
          control->point_force(P, fp);
          for (unsigned int d = 0; d < dim; ++d)
            loaded = loaded || fp[d] != 0.0;
        }
      if (loaded) // Eq. 5.3, added to the mixture force by nodal_forces_two_phase
        for (unsigned int v = 0; v < nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            T[kc.dofs[slot[v] * dim + d]] += N[v] * fp[d];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int i  = kc.dofs[slot[v] * dim + d];
            double             fi = 0;
            for (unsigned int e = 0; e < dim; ++e)
              fi -= V * sig[d][e] * G[v][e];
            MS[i] += mS * N[v];
            FS[i] += fi + (mS + mL) * N[v] * g[d];
            PS[i] += mS * N[v] * P[L::velocity + d];
            if (cp)
              {
                mLt_[i] += mLt * N[v];
                mLn_[i] += mL * N[v];
                Q_[i] += q * N[v];
                FL_[i] += V * p * G[v][d] + mLt * N[v] * g[d];
                PL_[i] += mL * N[v] * P[liquid_velocity + d];
              }
          }
      if (cp && PN) // the scalar slot of each node
        for (unsigned int v = 0; v < nv; ++v)
          PN[kc.dofs[slot[v] * dim]] += mL * N[v] * p;
    });
    for (Vector *v : {&MSv, &FSv, &PSv})
      v->compress(dealii::VectorOperation::add);
    if (coupled)
      for (Vector *v : {&m_liquid, &m_liquid_n, &drag, &f_liquid, &p_liquid})
        v->compress(dealii::VectorOperation::add);
    if (relax)
      p_node.compress(dealii::VectorOperation::add);
    if (control)
      control->end_traction_scatter();
  }

  // Steps 2-3, per free DoF: the liquid's acceleration a_L from its own
  // equation (Eq. 4.106, drag with the velocities at t), then the solid's a_S
  // from the mixture equation with the liquid's inertia moved to the right
  // (4.107); both 0 on constrained DoFs (a fixed/roller wall is impermeable).
  // The solid's a_S is left in the solver's nodal_a (the 1-phase step's
  // place), a_L in a_liquid; the ghosts are updated by the caller, after the
  // loads' prescribed accelerations.
  template <int dim>
  void
  TwoPhase<dim>::nodal_accelerations()
  {
    const double *const MS = s.nodal_mass.begin(), *const PS = s.nodal_p.begin();
    double *const       FS   = s.nodal_a.begin();
    const double *const mLt_ = coupled ? m_liquid.begin() : nullptr, *const mLn_ =
                                                                       coupled ? m_liquid_n.begin() : nullptr;
    const double *const Q_ = coupled ? drag.begin() : nullptr, *const FL_ = coupled ? f_liquid.begin() : nullptr;
    const double *const PL_     = coupled ? p_liquid.begin() : nullptr;
    double *const       AL_     = coupled ? a_liquid.begin() : nullptr;
    const auto         *control = s.control.get();
    const auto         &con     = s.constrained;
    const double        alpha   = control ? control->local_damping() : 0.0;
    const double        av      = control ? control->viscous_damping() : 0.0;
    const double        beta    = s.mass_scaling;
    // local damping, 2-phase form of §6.3.2 (Eqs. 6.24-6.28): water
    // f_w^damp = -alpha |f_w| sign(v_L) with f_w its unbalanced force (traction,
    // gravity, internal; no drag); solid f_s^damp = -alpha |f - n f_w| sign(v_S);
    // the mixture receives f_s^damp + n f_w^damp (the liquid equation here is the
    // one divided by n, so its forces enter the mixture with the nodal n = Mbar_L / M_L).
    // Viscous damping -alpha_v m v acts on each phase's own mass the same way
    // (liquid: -alpha_v M_L v_L in the equation divided by n). Mass scaling
    // (Eq. 6.31): the inertia of both phases is beta M, the forces and the drag
    // keep their size.
    const auto damping = [alpha](const double f, const double v) {
      return (alpha > 0 && v != 0) ? -alpha * std::abs(f) * (v > 0 ? 1.0 : -1.0) : 0.0;
    };
    for (const unsigned int i : s.active_dofs)
      {
        double       aL = 0, n_i = 0, dL = 0;
        const double vS = MS[i] > 0 ? PS[i] / MS[i] : 0.0;
        if (coupled)
          {
            if (mLt_[i] > 0 && !con[i])
              {
                const double vL = PL_[i] / mLn_[i];
                n_i             = mLn_[i] / mLt_[i];
                dL              = damping(FL_[i], vL) - av * mLt_[i] * vL;
                aL              = (FL_[i] - Q_[i] * (vL - vS) + dL) / (beta * mLt_[i]);
              }
            AL_[i] = aL;
          }
        const double dS = damping(FS[i] - (coupled ? n_i * FL_[i] : 0.0), vS) - av * MS[i] * vS;
        FS[i]           = (MS[i] > 0 && !con[i])
                            ? (FS[i] - (coupled ? beta * mLn_[i] * aL : 0.0) + dS + n_i * dL) / (beta * MS[i])
                            : 0.0;
      }
  }

  // Step 4 and the momenta of step 5, one pass over the points: the point
  // velocities of both phases updated with the interpolated nodal
  // accelerations (Eqs. 4.108-4.109, FLIP), and right away their new momenta
  // m_S v_S, Mbar_L v_L scattered back to the nodes (the numerators of
  // 4.110-4.111). The loads' prescribed point velocities act after this pass
  // (LoadControl::particle_velocities), before nodal_velocities().
  template <int dim>
  template <class K>
  void
  TwoPhase<dim>::g2p_velocity_p2g_momentum(const double h)
  {
    using L                    = PropertyLayout<dim>;
    constexpr unsigned int nv  = K::n_point_nodes;
    const auto            &pl  = s.prm.liquid.pore_liquid;
    const double *const    FS  = s.nodal_a.begin();
    double *const          PS  = s.nodal_p.begin();
    const double *const    AL_ = coupled ? a_liquid.begin() : nullptr;
    double *const          PL_ = coupled ? p_liquid.begin() : nullptr;
    s.zero_on_active(s.nodal_p);
    if (coupled)
      s.zero_on_active(p_liquid);
    transfer::for_each_point(s.points, [&](const unsigned int c, transfer::PointIterator<dim> &pt) {
      const auto         kc  = K::cell(s.grid, c);
      double            *P   = pt->get_properties().data();
      const unsigned int mat = static_cast<unsigned int>(P[L::material]);
      const bool         cp  = coupled && pl[mat].drainage == Drainage::coupled;
      unsigned int       slot[nv];
      double             N[nv], G[nv][dim];
      K::point_stencil(kc, pt->get_reference_location(), slot, N, G);
      const double mL = cp ? P[porosity] * pl[mat].density * P[L::volume] : 0.0;
      for (unsigned int d = 0; d < dim; ++d)
        {
          double aS = 0, aL = 0;
          for (unsigned int v = 0; v < nv; ++v)
            {
              aS += N[v] * FS[kc.dofs[slot[v] * dim + d]];
              if (cp)
                aL += N[v] * AL_[kc.dofs[slot[v] * dim + d]];
            }
          P[L::velocity + d] += h * aS;
          if (cp)
            P[liquid_velocity + d] += h * aL;
          for (unsigned int v = 0; v < nv; ++v)
            {
              const unsigned int i = kc.dofs[slot[v] * dim + d];
              PS[i] += P[L::mass] * N[v] * P[L::velocity + d];
              if (cp)
                PL_[i] += mL * N[v] * P[liquid_velocity + d];
            }
        }
    });
    s.nodal_p.compress(dealii::VectorOperation::add);
    if (coupled)
      p_liquid.compress(dealii::VectorOperation::add);
  }

  // Step 5: the nodal velocities v_S = P_S / M_S, v_L = P_L / Mbar_L of the
  // new momenta (Eqs. 4.110-4.111), in place of the momenta (nodal_p,
  // p_liquid); 0 on constrained DoFs. The ghosts are updated by the caller,
  // after the loads' prescribed nodal velocities.
  template <int dim>
  void
  TwoPhase<dim>::nodal_velocities()
  {
    const double *const MS   = s.nodal_mass.begin();
    double *const       PS   = s.nodal_p.begin();
    const double *const mLn_ = coupled ? m_liquid_n.begin() : nullptr;
    double *const       PL_  = coupled ? p_liquid.begin() : nullptr;
    for (const unsigned int i : s.active_dofs)
      {
        const bool free = !s.constrained[i];
        PS[i]           = (MS[i] > 0 && free) ? PS[i] / MS[i] : 0.0;
        if (coupled)
          PL_[i] = (mLn_[i] > 0 && free) ? PL_[i] / mLn_[i] : 0.0;
      }
  }

  // The nodal values of a phase pair (solid vector of the solver, the
  // liquid's own) made visible to the ghost DoFs of the next pass.
  template <int dim>
  void
  TwoPhase<dim>::update_ghosts(Vector &solid, Vector &liquid)
  {
    solid.update_ghost_values();
    if (coupled)
      liquid.update_ghost_values();
  }

  // Steps 8 and 10 at one point of a coupled material: the storage equation
  // updates the pore pressure (Eqs. 4.115-4.116, compression positive) with
  // the volumetric strains of both phases; the porosity follows from the
  // solid's mass conservation (1 - n) V = const (Eq. 3.19). Adds the pore
  // pressure's energy to the sums when asked, flags a non-finite state.
  // Returns the liquid mass n rho_L V at the new volume (for the point sums).
  template <int dim>
  inline double
  TwoPhase<dim>::pore_liquid_update(double *P, const PoreLiquid &pl, const double dvS, const double div_uL,
                                    diagnostics::PointSums<dim> &sums, bool &bad) const
  {
    using L        = PropertyLayout<dim>;
    const double n = P[porosity];
    P[pore_pressure] -= pl.bulk_modulus / n * ((1 - n) * dvS + n * div_uL);
    P[porosity]      = 1.0 - (1.0 - n) / (1.0 + dvS);
    const double mL  = P[porosity] * pl.density * P[L::volume] * (1.0 + dvS);
    double       vl2 = 0;
    for (unsigned int d = 0; d < dim; ++d)
      vl2 += P[liquid_velocity + d] * P[liquid_velocity + d];
    if (s.need_strain_energy)
      sums.add_strain(P[L::volume] * (1.0 + dvS) * P[porosity] * P[pore_pressure] * P[pore_pressure] /
                      (2 * pl.bulk_modulus));
    if (!std::isfinite(P[pore_pressure] + vl2) || !(P[porosity] > 0 && P[porosity] < 1))
      bad = true;
    return mL;
  }

  // Steps 6-11, one pass over the points: the solid's strain and spin
  // increments and the liquid's volumetric strain from the nodal velocities
  // (Eqs. 4.112-4.114), the effective stress by the skeleton model (Jaumann
  // rotation inside), pore pressure and porosity (pore_liquid_update), the
  // volume (4.118, at most the cell's) and the position (4.119); then the
  // point sums (energies, momentum), the finiteness check, the probes and the
  // work of the tractions over the step (f_p . dx_p), and the move to the
  // point's new cell (the relocation follows in step_with).
  template <int dim>
  template <class K>
  void
  TwoPhase<dim>::g2p_update(const double h)
  {
    using L                             = PropertyLayout<dim>;
    constexpr unsigned int      nv      = K::n_point_nodes;
    const auto                 &pl      = s.prm.liquid.pore_liquid;
    const auto                  g       = s.gravity; // of the running stage
    auto *const                 control = s.control.get();
    const double *const         PS      = s.nodal_p.begin();
    const double *const         PL_     = coupled ? p_liquid.begin() : nullptr;
    const double *const         PN      = relax ? p_node.begin() : nullptr; // pressure_map
    diagnostics::PointSums<dim> sums;
    bool                        bad    = false;
    double                      work   = 0; // of the tractions over this step
    const bool                  loaded = control && control->any_traction();
    s.probes.clear_values();
    transfer::for_each_point(s.points, [&](const unsigned int c, transfer::PointIterator<dim> &pt) {
      const auto &cc          = s.grid.cells[c];
      double      cell_volume = 1.0;
      for (unsigned int d = 0; d < dim; ++d)
        cell_volume *= cc.h[d];
      double            *P   = pt->get_properties().data();
      const unsigned int mat = static_cast<unsigned int>(P[L::material]);
      const bool         cp  = coupled && pl[mat].drainage == Drainage::coupled;
      const auto         kc  = K::cell(s.grid, c);
      unsigned int       slot[nv];
      double             N[nv], G[nv][dim];
      K::point_stencil(kc, pt->get_reference_location(), slot, N, G);
      double gu[dim][dim] = {}, dx[dim] = {}, div_uL = 0;
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int i  = kc.dofs[slot[v] * dim + d];
            const double       du = h * PS[i]; // Eq. 4.112
            dx[d] += N[v] * du;
            for (unsigned int e2 = 0; e2 < dim; ++e2)
              gu[d][e2] += du * G[v][e2];
            if (cp)
              div_uL += h * PL_[i] * G[v][d]; // Eq. 4.113 (volumetric part)
          }
      materials::Strain d_eps;
      materials::Spin   d_omega;
      materials::strain_and_spin_increments<dim>(gu, d_eps, d_omega);
      const materials::Material &m     = *s.prm.materials[mat];
      auto                       sigma = L::get_stress(P);
      m.update_stress(d_eps, d_omega, h, sigma, dealii::ArrayView<double>(P + s.points.layout.history, m.n_history()));
      L::set_stress(sigma, P);
      const double dvS = trace(d_eps);
      if (cp && PN) // the relaxation towards the node map-remap, before the increment
        {
          double ps = 0;
          for (unsigned int v = 0; v < nv; ++v)
            ps += N[v] * PN[kc.dofs[slot[v] * dim]];
          P[pore_pressure] = transfer::blend_pressure(P[pore_pressure], ps, relax_share[mat]);
        }
      const double mL = cp ? pore_liquid_update(P, pl[mat], dvS, div_uL, sums, bad) : 0.0;
      P[L::volume] *= (1.0 + dvS); // Eq. 4.118
      if (P[L::volume] > cell_volume)
        P[L::volume] = cell_volume;

      if (loaded)
        {
          double f[dim];
          control->point_force(P, f);
          for (unsigned int d = 0; d < dim; ++d)
            work += f[d] * dx[d];
        }
      auto x = pt->get_location();
      for (unsigned int d = 0; d < dim; ++d)
        {
          x[d] += dx[d]; // Eq. 4.119
          P[L::displacement + d] += dx[d];
        }
      const double v2 = cp ? sums.add(P[L::mass], P + L::velocity, mL, P + liquid_velocity, x, g)
                           : sums.add(P[L::mass], P + L::velocity, x, g);
      if (s.need_strain_energy)
        sums.add_strain(P[L::volume] * m.elastic_energy_density(sigma));
      if (!std::isfinite(sigma[0][0] + sigma[1][1] + sigma[0][1] + x[0] + x[1] + v2 + P[L::volume]) ||
          !(P[L::volume] > 0))
        bad = true;
      s.probes.record(pt->get_id(), P);
      dealii::Point<dim> xi_new;
      transfer::place_moved_point(s.points, s.grid, c, pt, x, xi_new);
    });
    s.local_sums = sums;
    s.local_bad  = bad;
    if (loaded)
      s.external_work += dealii::Utilities::MPI::sum(work, s.comm);
  }

  // ================================================================ free surface
  template <int dim>
  FreeSurface<dim>::FreeSurface(Solver<dim> &solver, const double f)
      : s(solver)
      , factor(f)
  {
  }

  template <int dim>
  void
  FreeSurface<dim>::extend_layout(PropertyLayout<dim> &layout)
  {
    flag = layout.add_extra("free_surface", 1);
    grid_changed(); // sizes the nodal vectors
  }

  template <int dim>
  void
  FreeSurface<dim>::grid_changed()
  {
    s.grid.reinit_vector(mass);
    s.grid.reinit_vector(volume);
  }

  template <int dim>
  void
  FreeSurface<dim>::update()
  {
    s.with_kernel([&](auto kernel) { update_with<decltype(kernel)>(); });
  }

  template <int dim>
  template <class K>
  void
  FreeSurface<dim>::update_with()
  {
    using L                   = PropertyLayout<dim>;
    using Q                   = shape::Q1<dim>;
    constexpr bool         q1 = std::is_same_v<K, shape::Q1Box<dim>>;
    constexpr unsigned int nv = q1 ? Q::n_vertices : K::n_point_nodes;
    // nodal density (Eq. 6.38) on the scalar slot of each node: mass share over
    // the volume share of the non-empty cells around the node. Q1: the share of
    // a vertex is Omega_el / n_vertices; other kernels: int_cell N_i, by a
    // 2-point Gauss rule on each half of the cell per direction (exact for the
    // quadratic B-spline, whose pieces break at the cell centre)
    mass             = 0.0;
    volume           = 0.0;
    double *const Mn = mass.begin(), *const Vn = volume.begin();
    // the point's nodes and values: slot i of the scalar slots `at`, N[i]
    const auto stencil = [&](const unsigned int c, const dealii::Point<dim> &xi, unsigned int(&at)[nv],
                             double(&N)[nv]) {
      if constexpr (q1)
        {
          const auto &cc = s.grid.cells[c];
          Q::values(xi, N);
          for (unsigned int v = 0; v < nv; ++v)
            at[v] = cc.dofs[v * dim];
        }
      else
        {
          const auto   kc = K::cell(s.grid, c);
          unsigned int slot[nv];
          double       G[nv][dim];
          K::point_stencil(kc, xi, slot, N, G);
          for (unsigned int v = 0; v < nv; ++v)
            at[v] = kc.dofs[slot[v] * dim];
        }
    };
    transfer::for_each_active_cell(
      s.points,
      [&](const unsigned int c) {
        const auto &cc  = s.grid.cells[c];
        double      vol = 1.0;
        for (unsigned int d = 0; d < dim; ++d)
          vol *= cc.h[d];
        if constexpr (q1)
          for (unsigned int v = 0; v < nv; ++v)
            Vn[cc.dofs[v * dim]] += vol / nv;
        else
          {
            const double g    = 0.25 / std::sqrt(3.0);
            const double r[4] = {0.25 - g, 0.25 + g, 0.75 - g, 0.75 + g};
            unsigned int n_q  = 1;
            for (unsigned int d = 0; d < dim; ++d)
              n_q *= 4;
            const double w = vol / n_q;
            for (unsigned int k = 0; k < n_q; ++k)
              {
                dealii::Point<dim> xi;
                for (unsigned int d = 0, kk = k; d < dim; ++d, kk /= 4)
                  xi[d] = r[kk % 4];
                unsigned int at[nv];
                double       N[nv];
                stencil(c, xi, at, N);
                for (unsigned int v = 0; v < nv; ++v)
                  Vn[at[v]] += w * N[v];
              }
          }
      },
      [&](const unsigned int c, transfer::PointIterator<dim> &pt) {
        unsigned int at[nv];
        double       N[nv];
        stencil(c, pt->get_reference_location(), at, N);
        const double m = pt->get_properties()[L::mass];
        for (unsigned int v = 0; v < nv; ++v)
          Mn[at[v]] += m * N[v];
      },
      [](const unsigned int) {});
    mass.compress(dealii::VectorOperation::add);
    volume.compress(dealii::VectorOperation::add);
    for (unsigned int i = 0; i < mass.locally_owned_size(); ++i)
      mass.local_element(i) = volume.local_element(i) > 0 ? mass.local_element(i) / volume.local_element(i) : 0.0;
    mass.update_ghost_values();

    unsigned long long  n_flagged = 0;
    std::vector<double> lo(dim, std::numeric_limits<double>::max()), hi(dim, -std::numeric_limits<double>::max());
    transfer::for_each_point(s.points, [&](const unsigned int c, transfer::PointIterator<dim> &pt) {
      unsigned int at[nv];
      double       N[nv];
      stencil(c, pt->get_reference_location(), at, N);
      double rho = 0;
      for (unsigned int v = 0; v < nv; ++v)
        rho += N[v] * Mn[at[v]]; // Eq. 6.39
      double            *P   = pt->get_properties().data();
      const unsigned int mat = static_cast<unsigned int>(P[L::material]);
      // reference density: that of the material, or of the solid mass per
      // volume of a coupled point (its P[mass] is the solid mass)
      double rho0 = s.prm.materials[mat]->density();
      if (s.two_phase && s.two_phase->coupled && s.prm.liquid.pore_liquid[mat].drainage == Drainage::coupled)
        rho0 *= 1 - s.prm.liquid.pore_liquid[mat].porosity;
      const bool on = rho <= factor * rho0; // Eq. 6.40
      P[flag]       = on ? 1.0 : 0.0;
      n_flagged += on;
      for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::min(lo[d], pt->get_location()[d]);
          hi[d] = std::max(hi[d], pt->get_location()[d]);
        }
    });
    count = dealii::Utilities::MPI::sum(n_flagged, s.comm);
    extent.assign(2 * dim, 0.0);
    for (unsigned int d = 0; d < dim; ++d)
      {
        extent[2 * d]     = dealii::Utilities::MPI::min(lo[d], s.comm);
        extent[2 * d + 1] = dealii::Utilities::MPI::max(hi[d], s.comm);
      }
  }

  template struct LiquidParameters<2>;
  template struct LiquidParameters<3>;
  template void            parse_liquid_output<2>(dealii::ParameterHandler &, LiquidParameters<2> &);
  template void            parse_liquid_output<3>(dealii::ParameterHandler &, LiquidParameters<3> &);
  template BodyTraction<2> parse_body_traction<2>(dealii::ParameterHandler &, const std::string &);
  template BodyTraction<3> parse_body_traction<3>(dealii::ParameterHandler &, const std::string &);
  template class TwoPhase<2>;
  template class TwoPhase<3>;
  template class FreeSurface<2>;
  template class FreeSurface<3>;
} // namespace talus::explicit_mpm
