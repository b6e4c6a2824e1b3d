// talus — MPM-MIXED integration (seed 000 §6.6), strain smoothing (§6.7.1) and
// the .prm entries of the chapter-6 numerics; contact is in contact.cc.
#include <talus/base/errors.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/mixed_integration.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1.h>
#include <talus/shape/with_kernel.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/point_ops.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <set>

namespace talus::explicit_mpm
{
  // ================================================================ parameters
  void
  declare_numerics_parameters(dealii::ParameterHandler &prm, const std::string &default_integration)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("numerics");
    // 'shape function' is declared with the shared scene (scene_parameters.cc);
    // quadratic B-splines need integration = mpm, no strain smoothing, no coupled
    // 2-phase materials (or their body tractions) and a box grid of >= 3 cells per
    // direction (refused by parse_parameters in explicit_parameters.cc, as are the
    // passes APIC is not available with); contact, loads, friction and prescribed
    // velocities work on both kernels
    prm.declare_entry(
      "velocity transfer", "flip", Selection("flip|apic"),
      "Velocity transfer of the 1-phase step: 'flip' (seed 000: v_p += h a(x_p), then the nodal "
      "velocity from the points' momentum) or 'apic' (affine particle-in-cell, Jiang et al. 2015: "
      "nodal momentum sum N m_p (v_p + C_p (x_i - x_p)), v_p and the affine matrix C_p from the "
      "updated nodal velocity; conserves linear and angular momentum in the transfers, "
      "docs/shape-functions.md). 'apic' needs shape function = quadratic bspline (measured unstable with linear "
      "shape functions), integration = mpm, no strain smoothing, no contact and 1-phase materials; it works "
      "with tractions, point loads, friction walls, prescribed velocities of boundaries, regions and bodies "
      "(v_p set, C_p = 0 for the prescribed components), rigid plates, damping, stages and load balancing.");
    prm.declare_entry("integration", default_integration, Selection("mpm|mpm-mixed|fem|ul-fem"),
                      "Integration of the internal force (seed 000 §6.6; Anura3D MPM-MP / MPM-MIXED / FEM / "
                      "UL-FEM): 'mpm' at the material points; "
                      "'mpm-mixed' at the Gauss point(s) of every cell whose material points fill more than "
                      "'fill factor' of its volume (Eq. 6.33), with the volume-averaged stress of its points "
                      "(Eq. 6.32); partially filled cells keep material point integration. "
                      "'fem': finite elements on the same grid from the same time loop: the integration points "
                      "are the 2^dim Gauss points of every cell covered by a body (volume = JxW, mass = "
                      "density x JxW) and stay there; small strain on the fixed mesh (no motion, no relocation, "
                      "the displacement accumulates). 'ul-fem': the same points, but the mesh follows the "
                      "material (updated Lagrangian FEM: nodes move with the nodal displacement increments, "
                      "gradients and volumes from the current cell geometry). See docs/fem.md.");
    prm.declare_entry("fill factor", "0.9", Double(0, 10),
                      "F_fill of Eq. 6.33 for 'integration = mpm-mixed': a cell is integrated at its Gauss "
                      "point when the volume of its material points exceeds F_fill x the cell volume.");
    prm.declare_entry("mixed stress field", "linear", Selection("linear|constant"),
                      "Cell stress of 'integration = mpm-mixed': 'linear' = volume-weighted least-squares fit of "
                      "the points' stresses (mean = Eq. 6.32), integrated at the 2^dim Gauss points; 'constant' = "
                      "the volume-averaged stress of Eq. 6.32 alone, as in the manual (exact on tetrahedra, but on "
                      "quads/hexes it leaves the hourglass modes unresisted: measured unstable, docs/explicit.md).");
    prm.declare_entry("strain smoothing", "none", Selection("none|cell|nodal"),
                      "Anti-locking smoothing of the volumetric strain increment (seed 000 §6.7.1): 'none'; "
                      "'cell' replaces each point's volumetric increment by its cell's (mean dilatation); "
                      "'nodal' = nodal mixed discretisation: cell values averaged to the nodes weighted by cell "
                      "volume (Eq. 6.35) and back to the cell as the mean of its nodes (Eqs. 6.36-6.37).");
    prm.leave_subsection();
    prm.enter_subsection("contact");
    prm.declare_entry("pairs", "", Anything(),
                      "Body pairs in frictional contact (seed 000 §6.2): 'a, b, mu, adhesion; ...' with body ids "
                      "a != b, Coulomb friction coefficient mu >= 0 and adhesion >= 0 [Pa] (tangential force cap "
                      "adhesion x contact area of the node). Empty: contact off (all bodies share one velocity "
                      "field). With contact on, bodies whose pair is not listed stick to each other. Works with "
                      "both shape functions (docs/explicit.md); not with velocity transfer = apic, "
                      "volumetric stabilisation = f-bar, integration = fem | ul-fem or coupled 2-phase materials.");
    prm.leave_subsection();
  }

  NumericsOptions
  parse_numerics_parameters(dealii::ParameterHandler &prm, const unsigned int n_bodies)
  {
    NumericsOptions o;
    prm.enter_subsection("numerics");
    o.velocity_transfer = prm.get("velocity transfer") == "apic" ? NumericsOptions::VelocityTransfer::apic
                                                                 : NumericsOptions::VelocityTransfer::flip;
    {
      const std::string i = prm.get("integration");
      o.integration       = i == "mpm-mixed" ? NumericsOptions::Integration::mpm_mixed
                            : i == "fem"     ? NumericsOptions::Integration::fem
                            : i == "ul-fem"  ? NumericsOptions::Integration::ul_fem
                                             : NumericsOptions::Integration::mpm;
    }
    o.fill_factor  = prm.get_double("fill factor");
    o.mixed_linear = prm.get("mixed stress field") == "linear";
    require(o.fill_factor > 0, "numerics/fill factor", "must be > 0 (the manual uses 0.9)");
    const std::string s = prm.get("strain smoothing");
    o.smoothing         = s == "cell"    ? NumericsOptions::Smoothing::cell
                          : s == "nodal" ? NumericsOptions::Smoothing::nodal
                                         : NumericsOptions::Smoothing::none;
    prm.leave_subsection();

    prm.enter_subsection("contact");
    const std::string                               where = "contact/pairs";
    std::set<std::pair<unsigned int, unsigned int>> seen;
    for (const auto &item : dealii::Utilities::split_string_list(prm.get("pairs"), ';'))
      {
        const auto f = dealii::Utilities::split_string_list(item, ',');
        require(f.size() == 4, where, "'" + item + "' must be 'body a, body b, friction coefficient, adhesion'");
        double v[4];
        for (unsigned int k = 0; k < 4; ++k)
          {
            try
              {
                std::size_t pos = 0;
                v[k]            = std::stod(f[k], &pos);
                if (pos != f[k].size())
                  throw std::invalid_argument(f[k]);
              }
            catch (const std::exception &)
              {
                throw InputError(where + ": '" + f[k] + "' in '" + item + "' is not a number");
              }
          }
        for (unsigned int k = 0; k < 2; ++k)
          require(v[k] >= 0 && v[k] == std::floor(v[k]) && v[k] < n_bodies, where,
                  "body id '" + f[k] + "' in '" + item + "' is not one of the bodies 0.." +
                    std::to_string(n_bodies - 1));
        NumericsOptions::ContactPair p;
        p.a        = static_cast<unsigned int>(v[0]);
        p.b        = static_cast<unsigned int>(v[1]);
        p.friction = v[2];
        p.adhesion = v[3];
        require(p.a != p.b, where, "'" + item + "': a body cannot be in contact with itself");
        require(std::isfinite(p.friction) && p.friction >= 0, where,
                "'" + item + "': the friction coefficient must be >= 0");
        require(std::isfinite(p.adhesion) && p.adhesion >= 0, where, "'" + item + "': the adhesion must be >= 0");
        require(seen.insert({std::min(p.a, p.b), std::max(p.a, p.b)}).second, where,
                "'" + item + "': pair listed twice");
        o.contact_pairs.push_back(p);
      }
    prm.leave_subsection();
    return o;
  }

  // ================================================================ extended P2G
  namespace
  {
    /// Per-cell, per-body accumulator for the contact fields.
    template <int dim>
    struct BodyAcc
    {
      using F = shape::Q1Factorised<dim>;
      double lm[F::nv], lvol[F::nv], lp[F::nv][dim];
      double T[dim][F::npairs][dim];
      void
      clear()
      {
        std::fill(&lm[0], &lm[0] + F::nv, 0.0);
        std::fill(&lvol[0], &lvol[0] + F::nv, 0.0);
        std::fill(&lp[0][0], &lp[0][0] + F::nv * dim, 0.0);
        std::fill(&T[0][0][0], &T[0][0][0] + dim * F::npairs * dim, 0.0);
      }
    };


    void
    zero_on(Vector &v, const std::vector<unsigned int> &active_dofs)
    {
      v.zero_out_ghost_values();
      double *x = v.begin();
      for (const unsigned int i : active_dofs)
        x[i] = 0.0;
    }
    /// ScatterMassForce's adjustment with strain smoothing: the point's mean
    /// stress replaced by its cell's (one field: no contact)
    template <int dim>
    struct SmoothedMeanStress
    {
      static constexpr bool       active = true;
      const StrainSmoothing<dim> *smoothing;
      inline void
      operator()(const unsigned int c, const double *P, const double V, double (&t)[dim][dim]) const
      {
        smoothing->force_stress_correction(c, 0, P, V, t);
      }
    };

    /// the volume Omega of a grid cell (its cache entry)
    template <class Cache>
    inline double
    cell_volume(const Cache &cc)
    {
      double v = 1.0;
      for (const double h : cc.h)
        v *= h;
      return v;
    }
  } // namespace

  template <int dim>
  void
  p2g_extended(Solver<dim> &s)
  {
    using L                              = PropertyLayout<dim>;
    using F                              = shape::Q1Factorised<dim>;
    constexpr unsigned int nv            = F::nv;
    const bool             mixed         = s.prm.numerics.integration == NumericsOptions::Integration::mpm_mixed;
    const double           fill          = s.prm.numerics.fill_factor;
    const bool             linear_stress = s.prm.numerics.mixed_linear;
    Contact<dim>          *contact       = s.contact.get();
    const auto             g             = s.gravity; // of the running stage
    if (s.smoothing)                                  // the cells and the force's mean stresses of this step
      s.smoothing->collect(s);
    if (!mixed && contact)
      {
        contact->p2g(s); // contact: on the run's kernel (contact.cc)
        return;
      }
    if (!mixed)
      {
        // strain smoothing alone: the solver's P2G with the force's mean stress
        // of each point's cell (StrainSmoothing::force_stress_correction)
        zero_on(s.nodal_mass, s.active_dofs);
        zero_on(s.nodal_a, s.active_dofs);
        const SmoothedMeanStress<dim> adjust{s.smoothing.get()};
        shape::with_kernel<dim>(s.prm.bspline(), [&](auto kernel) {
          transfer::ScatterMassForce<dim, decltype(kernel), SmoothedMeanStress<dim>> p2g{
            s.grid, g, s.nodal_mass.begin(), s.nodal_a.begin(), adjust};
          transfer::for_each_active_cell(s.points, p2g);
        });
        return;
      }

    double *const M  = s.nodal_mass.begin();
    double *const Fv = s.nodal_a.begin();
    zero_on(s.nodal_mass, s.active_dofs);
    zero_on(s.nodal_a, s.active_dofs);
    const unsigned int         n_bodies = contact ? contact->n_bodies : 0;
    std::vector<BodyAcc<dim>>  bacc(n_bodies);
    std::vector<unsigned int>  touched;
    std::vector<unsigned char> in_cell(n_bodies, 0);
    if (contact)
      for (auto &f : contact->fields)
        {
          zero_on(f.mass, s.active_dofs);
          zero_on(f.volume, s.active_dofs);
          zero_on(f.force, s.active_dofs);
          zero_on(f.momentum, s.active_dofs);
        }
    CellStressFit<dim> stress_fit; // MPM-MIXED: linear cell stress (mixed_integration.h)

    double     lm[nv], T[dim][F::npairs][dim]; // the cell's sums
    const auto begin_cell = [&](const unsigned int) {
      std::fill(lm, lm + nv, 0.0);
      std::fill(&T[0][0][0], &T[0][0][0] + dim * F::npairs * dim, 0.0);
      if (mixed)
        stress_fit.clear();
      touched.clear();
    };
    const auto at_point = [&](const unsigned int, auto &pt) {
      const double *P  = pt->get_properties().data();
      const auto    xi = pt->get_reference_location();
      double        N[nv], w[dim][F::npairs];
      F::weights(xi, N, w);
      const double m = P[L::mass], V = P[L::volume];
      for (unsigned int v = 0; v < nv; ++v)
        lm[v] += m * N[v];
      double t[dim][dim];
      minus_V_sigma<dim>(P, V, t);
      F::add_moments(t, w, T);
      if (mixed)
        stress_fit.add(xi, V, P + L::stress);
      if (contact)
        {
          const unsigned int b = static_cast<unsigned int>(P[L::body]);
          auto              &a = bacc[b];
          if (!in_cell[b])
            {
              in_cell[b] = 1;
              touched.push_back(b);
              a.clear();
            }
          for (unsigned int v = 0; v < nv; ++v)
            {
              a.lm[v] += m * N[v];
              a.lvol[v] += V * N[v];
              for (unsigned int d = 0; d < dim; ++d)
                a.lp[v][d] += m * N[v] * P[L::velocity + d];
            }
          F::add_moments(t, w, a.T);
        }
    };
    const auto end_cell = [&](const unsigned int c) {
      const auto  &cc    = s.grid.cells[c];
      const double Omega = cell_volume(cc);
      // §6.6: a filled cell (Eq. 6.33) is integrated at its 2^dim Gauss points
      // with a stress field linear in the cell, fitted to its points (mean =
      // Eq. 6.32; see mixed_integration.h for why not constant on Q1 cells).
      // With contact, only single-body cells are mixed-integrated (the body's
      // force must equal the cell's).
      const bool use_mixed = mixed && stress_fit.sV > fill * Omega && (!contact || touched.size() <= 1);
      if (use_mixed)
        stress_fit.moments(Omega, linear_stress, T);
      double f[nv][dim];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          f[v][d] = lm[v] * g[d];
      F::expand_moments(T, cc.inv_h, f);
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          {
            const unsigned int i = cc.dofs[v * dim + d];
            M[i] += lm[v];
            Fv[i] += f[v][d];
          }
      if (contact)
        for (const unsigned int b : touched)
          {
            in_cell[b] = 0;
            auto &a    = bacc[b];
            if (use_mixed)
              std::copy(&T[0][0][0], &T[0][0][0] + dim * F::npairs * dim, &a.T[0][0][0]);
            double fb[nv][dim];
            for (unsigned int v = 0; v < nv; ++v)
              for (unsigned int d = 0; d < dim; ++d)
                fb[v][d] = a.lm[v] * g[d];
            F::expand_moments(a.T, cc.inv_h, fb);
            auto         &fl = contact->fields[b];
            double *const bm = fl.mass.begin();
            double *const bv = fl.volume.begin();
            double *const bf = fl.force.begin();
            double *const bp = fl.momentum.begin();
            for (unsigned int v = 0; v < nv; ++v)
              for (unsigned int d = 0; d < dim; ++d)
                {
                  const unsigned int i = cc.dofs[v * dim + d];
                  bm[i] += a.lm[v];
                  bv[i] += a.lvol[v];
                  bf[i] += fb[v][d];
                  bp[i] += a.lp[v][d];
                }
          }
    };
    transfer::for_each_active_cell(s.points, begin_cell, at_point, end_cell);
  }

  // ================================================================ smoothing
  template <int dim>
  StrainSmoothing<dim>::StrainSmoothing(const BackgroundGrid<dim> &grid, const NumericsOptions::Smoothing k,
                                        const bool bspline, const unsigned int n_fields)
      : kind(k)
      , bspline(bspline)
      , n_fields(n_fields)
      , cells(n_fields)
  {
    grid_changed(grid);
  }

  template <int dim>
  void
  StrainSmoothing<dim>::grid_changed(const BackgroundGrid<dim> &grid)
  {
    n_cells             = grid.cells.size();
    const std::size_t n = std::size_t(n_fields) * n_cells;
    cell_value.assign(n, 0.0);
    cell_weight.assign(n, 0.0);
    force_mean.assign(n, 0.0);
    scale.assign(n_cells, 0.0);
    for (auto &list : cells)
      list.clear();
    if (kind == NumericsOptions::Smoothing::nodal)
      grid.reinit_vector(nodal);
  }

  template <int dim>
  void
  StrainSmoothing<dim>::collect(Solver<dim> &s)
  {
    // per field and cell: W = sum V_p, the cell list, and the force's mean
    // stress, first the cell's own sum V_p s_p / W (s_p: the mean in-plane
    // normal stress, the part of sigma the smoothed strain works on)
    using L = PropertyLayout<dim>;
    for (unsigned int f = 0; f < n_fields; ++f)
      {
        for (const unsigned int c : cells[f])
          cell_weight[std::size_t(f) * n_cells + c] = force_mean[std::size_t(f) * n_cells + c] = 0.0;
        cells[f].clear();
      }
    const auto at_point = [&](const unsigned int c, auto &pt) {
      const double     *P = pt->get_properties().data();
      const std::size_t i = std::size_t(field_of(P)) * n_cells + c;
      if (cell_weight[i] == 0.0) // volumes are positive: the field's first point in c
        cells[field_of(P)].push_back(c);
      double m = 0;
      for (unsigned int d = 0; d < dim; ++d)
        m += P[L::stress + d];
      cell_weight[i] += P[L::volume];
      force_mean[i] += P[L::volume] * m / dim;
    };
    transfer::for_each_point(s.points, at_point);
    for (unsigned int f = 0; f < n_fields; ++f)
      {
        if (kind == NumericsOptions::Smoothing::nodal)
          nodal_average_transposed(s, f); // from the sums S_c = W_c s_c
        else
          for (const unsigned int c : cells[f])
            force_mean[std::size_t(f) * n_cells + c] /= cell_weight[std::size_t(f) * n_cells + c];
      }
  }

  template <int dim>
  void
  StrainSmoothing<dim>::compute(Solver<dim> &s, const double dt)
  {
    shape::with_kernel<dim>(bspline, [&](auto kernel) { point_means(kernel, s, dt); });
    if (kind == NumericsOptions::Smoothing::nodal)
      for (unsigned int f = 0; f < n_fields; ++f)
        nodal_average(s, f);
  }

  template <int dim>
  template <class K>
  void
  StrainSmoothing<dim>::point_means(K, Solver<dim> &s, const double dt)
  {
    // The element value of a cell is the volume-weighted mean of its points'
    // volumetric strain increments, sum V_p dt div v(x_p) / sum V_p: the
    // projection onto cell constants with the quadrature the force uses. The
    // value at the cell centre is that only for a filled, symmetric cell: a
    // block sliding across cells with 2 x 2 points gained 5 x its energy with
    // it (docs/explicit.md "Strain smoothing"). Every field from its own
    // velocities: the combined nodal velocity, or with contact each body's
    // corrected v~_b, with which the update pass moves that body.
    using L = PropertyLayout<dim>;
    std::vector<const double *> velocity(n_fields);
    for (unsigned int f = 0; f < n_fields; ++f)
      {
        velocity[f] = s.contact ? s.contact->fields[f].momentum.begin() : s.nodal_p.begin();
        for (const unsigned int c : cells[f])
          cell_value[std::size_t(f) * n_cells + c] = 0.0;
      }
    transfer::for_each_point_stencil<dim, K>(
      s.grid, s.points,
      [&](const unsigned int c, transfer::PointIterator<dim> &it, const transfer::PointStencil<dim, K> &st) {
        const double      *P = it->get_properties().data();
        const unsigned int f = field_of(P);
        cell_value[std::size_t(f) * n_cells + c] += P[L::volume] * dt * st.divergence(velocity[f]);
      });
    for (unsigned int f = 0; f < n_fields; ++f)
      for (const unsigned int c : cells[f])
        cell_value[std::size_t(f) * n_cells + c] /= cell_weight[std::size_t(f) * n_cells + c];
  }

  template <int dim>
  void
  StrainSmoothing<dim>::through_vertices(const Solver<dim> &s, const unsigned int field, double *a, const bool share,
                                         const double *scale)
  {
    // at every vertex i of the field's cells: X0_i = sum_{c at i} a_c w_c,
    // X1_i = sum_{c at i} Omega_c (one distributed vector, deal.II's exchange);
    // then a_c = scale_c sum_{i of c} X0_i / X1_i (no scale: 1 / nv, the mean)
    using F                   = shape::Q1Factorised<dim>;
    constexpr unsigned int nv = F::nv;
    zero_on(nodal, s.active_dofs);
    double *const X = nodal.begin();
    for (const unsigned int c : cells[field])
      {
        const auto  &cc    = s.grid.cells[c];
        const double Omega = cell_volume(cc);
        const double ac    = share ? a[c] / nv : a[c] * Omega;
        for (unsigned int v = 0; v < nv; ++v)
          {
            X[cc.dofs[v * dim + 0]] += ac;
            X[cc.dofs[v * dim + 1]] += Omega;
          }
      }
    nodal.compress(dealii::VectorOperation::add);
    nodal.update_ghost_values();
    for (const unsigned int c : cells[field])
      {
        const auto &cc  = s.grid.cells[c];
        double      sum = 0;
        for (unsigned int v = 0; v < nv; ++v)
          sum += X[cc.dofs[v * dim + 0]] / X[cc.dofs[v * dim + 1]];
        a[c] = (scale ? scale[c] : 1.0 / nv) * sum;
      }
  }

  template <int dim>
  void
  StrainSmoothing<dim>::nodal_average(const Solver<dim> &s, const unsigned int field)
  {
    // Eq. 6.35: nodal value = sum over the surrounding cells with points of
    // eps_el Omega_el / sum Omega_el; Eq. 6.36: the cell's value is the mean
    // of its nodal values
    through_vertices(s, field, cell_value.data() + std::size_t(field) * n_cells, false, nullptr);
  }

  template <int dim>
  void
  StrainSmoothing<dim>::nodal_average_transposed(const Solver<dim> &s, const unsigned int field)
  {
    // The work of the smoothed strain, sum_c S_c e~_c with S_c = sum_p V_p s_p
    // and e~ = nodal_average(e), equals sum_p V_p e_p s~_c(p) with
    // s~_c = Omega_c / W_c sum_{i of c} q_i / sum Omega_i, q_i = sum_{c at i} S_c / nv
    // (the transpose of Eqs. 6.35-6.36 under the point quadrature)
    const std::size_t offset = std::size_t(field) * n_cells;
    for (const unsigned int c : cells[field])
      scale[c] = cell_volume(s.grid.cells[c]) / cell_weight[offset + c];
    through_vertices(s, field, force_mean.data() + offset, true, scale.data()); // in: S_c, out: s~_c
  }

  template void p2g_extended<2>(Solver<2> &);
  template void p2g_extended<3>(Solver<3> &);
  template class StrainSmoothing<2>;
  template class StrainSmoothing<3>;
} // namespace talus::explicit_mpm
