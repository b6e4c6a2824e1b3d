// talus — MPM-MIXED integration (seed 000 §6.6), strain smoothing (§6.7.1) and
// the .prm entries of the chapter-6 numerics; contact is in contact.cc.
#include <talus/base/errors.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/mixed_integration.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/point_ops.h>

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
    if (!mixed)
      {
        contact->p2g(s); // contact alone: on the run's kernel (contact.cc)
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
      const auto &cc          = s.grid.cells[c];
      double      cell_volume = 1.0;
      for (unsigned int d = 0; d < dim; ++d)
        cell_volume *= cc.h[d];
      // §6.6: a filled cell (Eq. 6.33) is integrated at its 2^dim Gauss points
      // with a stress field linear in the cell, fitted to its points (mean =
      // Eq. 6.32; see mixed_integration.h for why not constant on Q1 cells).
      // With contact, only single-body cells are mixed-integrated (the body's
      // force must equal the cell's).
      const bool use_mixed = mixed && stress_fit.sV > fill * cell_volume && (!contact || touched.size() <= 1);
      if (use_mixed)
        stress_fit.moments(cell_volume, linear_stress, T);
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
                                        const bool bspline)
      : kind(k)
      , bspline(bspline)
  {
    cell_value.assign(grid.cells.size(), 0.0);
    if (kind == NumericsOptions::Smoothing::nodal)
      grid.reinit_vector(nodal);
  }

  template <int dim>
  void
  StrainSmoothing<dim>::grid_changed(const BackgroundGrid<dim> &grid)
  {
    cell_value.assign(grid.cells.size(), 0.0);
    if (kind == NumericsOptions::Smoothing::nodal)
      grid.reinit_vector(nodal);
  }

  template <int dim>
  void
  StrainSmoothing<dim>::compute(const Solver<dim> &s, const double dt)
  {
    using F                   = shape::Q1Factorised<dim>;
    constexpr unsigned int nv = F::nv;
    if (bspline)
      bspline_cell_values(s, dt);
    else
      q1_cell_values(s, dt);
    if (kind == NumericsOptions::Smoothing::cell)
      return;
    // Eq. 6.35: nodal value = sum over the surrounding active cells of
    // eps_el Omega_el / sum Omega_el (component 0 / component 1 of the vector)
    zero_on(nodal, s.active_dofs);
    double *const X = nodal.begin();
    for (const auto &ac : s.points.active_cells())
      {
        const auto &cc     = s.grid.cells[ac.cell];
        double      volume = 1.0;
        for (unsigned int d = 0; d < dim; ++d)
          volume *= cc.h[d];
        for (unsigned int v = 0; v < nv; ++v)
          {
            X[cc.dofs[v * dim + 0]] += cell_value[ac.cell] * volume;
            X[cc.dofs[v * dim + 1]] += volume;
          }
      }
    nodal.compress(dealii::VectorOperation::add);
    nodal.update_ghost_values();
    // Eq. 6.36: the cell's value is the mean of its nodal values
    for (const auto &ac : s.points.active_cells())
      {
        const auto &cc  = s.grid.cells[ac.cell];
        double      sum = 0;
        for (unsigned int v = 0; v < nv; ++v)
          sum += X[cc.dofs[v * dim + 0]] / X[cc.dofs[v * dim + 1]];
        cell_value[ac.cell] = sum / nv;
      }
  }

  template <int dim>
  void
  StrainSmoothing<dim>::q1_cell_values(const Solver<dim> &s, const double dt)
  {
    // element value: the volumetric strain increment of the Q1 field at the cell
    // centre, which is its cell average (the divergence of a Q1 field is linear
    // in each coordinate)
    using F                   = shape::Q1Factorised<dim>;
    constexpr unsigned int nv = F::nv;
    const double *const    Vn = s.nodal_p.begin();
    double                 w[dim][F::npairs];
    {
      double             N[nv];
      dealii::Point<dim> centre;
      for (unsigned int d = 0; d < dim; ++d)
        centre[d] = 0.5;
      F::weights(centre, N, w);
    }
    for (const auto &ac : s.points.active_cells())
      {
        const auto &cc = s.grid.cells[ac.cell];
        double      du[nv][dim], D[dim][F::npairs][dim], gu[dim][dim];
        for (unsigned int v = 0; v < nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            du[v][d] = dt * Vn[cc.dofs[v * dim + d]];
        F::differences(du, D);
        F::gradient(D, w, cc.inv_h, gu);
        double tr = 0;
        for (unsigned int d = 0; d < dim; ++d)
          tr += gu[d][d];
        cell_value[ac.cell] = tr;
      }
  }

  template <int dim>
  void
  StrainSmoothing<dim>::bspline_cell_values(const Solver<dim> &s, const double dt)
  {
    // the cell average of tr grad du of the quadratic B-spline field: its pieces
    // break at the cell centre, so 2 Gauss points on each half per direction
    // (exact: on a piece the divergence is at most quadratic in each coordinate)
    using K                  = shape::BSpline2Box<dim>;
    const double       g     = 0.25 / std::sqrt(3.0);
    const double       x1[4] = {0.25 - g, 0.25 + g, 0.75 - g, 0.75 + g};
    const double      *Vn    = s.nodal_p.begin();
    constexpr unsigned n     = dim == 2 ? 16 : 64;
    typename K::Field  du;
    for (const auto &ac : s.points.active_cells())
      {
        const typename K::Cell cell = K::cell(s.grid, ac.cell);
        K::gather(cell, Vn, dt, du, true);
        double tr = 0;
        for (unsigned int q = 0; q < n; ++q)
          {
            dealii::Point<dim> xi;
            for (unsigned int d = 0, r = q; d < dim; ++d, r /= 4)
              xi[d] = x1[r % 4];
            typename K::Eval e;
            K::evaluate(cell, xi, e);
            double gu[dim][dim], dx[dim];
            transfer::default_increments<dim, K>(cell, e, du, gu, dx);
            for (unsigned int d = 0; d < dim; ++d)
              tr += gu[d][d];
          }
        cell_value[ac.cell] = tr / n;
      }
  }

  template void p2g_extended<2>(Solver<2> &);
  template void p2g_extended<3>(Solver<3> &);
  template class StrainSmoothing<2>;
  template class StrainSmoothing<3>;
} // namespace talus::explicit_mpm
