// talus — contact between bodies (seed 000 §6.2): the predictor-corrector
// algorithm of Bardenhagen et al. with Coulomb friction and adhesion.
#include <talus/base/errors.h>
#include <talus/formulations/explicit/affine_ops.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/shape/with_kernel.h>
#include <talus/transfer/cell_walk.h>

#include <algorithm>
#include <cmath>


namespace talus::explicit_mpm
{
  template <int dim>
  Contact<dim>::Contact(const BackgroundGrid<dim> &g, const NumericsOptions &o, const unsigned int nb,
                        const bool bspline, const bool fbar, const unsigned int affine)
      : grid(g)
      , n_bodies(nb)
      , fbar(fbar)
      , affine(affine)
      , bspline(bspline)
  {
    fields.resize(n_bodies);
    grid_changed();
    pair_index.assign(n_bodies * n_bodies, -1);
    pairs = o.contact_pairs;
    for (unsigned int k = 0; k < pairs.size(); ++k)
      {
        pair_index[pairs[k].a * n_bodies + pairs[k].b] = k;
        pair_index[pairs[k].b * n_bodies + pairs[k].a] = k;
      }
    // box grids are uniform: the cell size of any non-artificial cell
    for (const auto &cc : grid.cells)
      if (cc.h[0] > 0)
        {
          cell_volume = 1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              h[d] = cc.h[d];
              cell_volume *= h[d];
            }
          break;
        }
  }

  template <int dim>
  void
  Contact<dim>::grid_changed()
  {
    for (auto &f : fields)
      {
        grid.reinit_vector(f.mass);
        grid.reinit_vector(f.volume);
        grid.reinit_vector(f.force);
        grid.reinit_vector(f.momentum);
        grid.reinit_vector(f.gradient);
        if (fbar)
          grid.reinit_vector(f.volume_increment);
      }
    node_marker.clear();
    nodes.clear();
    capacity_ready = false;
  }

  template <int dim>
  template <class K>
  void
  Contact<dim>::compute_capacity(K)
  {
    // integral of N_i over the owned cells, scattered and summed over the
    // ranks: per direction 2-point Gauss on each half cell (the quadratic
    // B-spline and its wall-modified form are polynomials of degree <= 2 on
    // each half cell: exact)
    grid.reinit_vector(capacity);
    constexpr unsigned int nq    = 4;
    const double           a     = 0.25 / std::sqrt(3.0);
    const double           q[nq] = {0.25 - a, 0.25 + a, 0.75 - a, 0.75 + a};
    double                 ones[dim];
    std::fill(ones, ones + dim, 1.0);
    unsigned int n_points = 1;
    for (unsigned int d = 0; d < dim; ++d)
      n_points *= nq;
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cells[c].locally_owned)
        {
          const typename K::Cell cell = K::cell(grid, c);
          typename K::Momentum   sums;
          sums.clear();
          double volume = 1.0;
          for (unsigned int d = 0; d < dim; ++d)
            volume *= grid.cells[c].h[d];
          const double w = volume / n_points;
          for (unsigned int k = 0; k < n_points; ++k)
            {
              dealii::Point<dim> xi;
              for (unsigned int d = 0, r = k; d < dim; ++d, r /= nq)
                xi[d] = q[r % nq];
              typename K::Eval e;
              K::evaluate(cell, xi, e);
              sums.add(e, w, ones);
            }
          sums.scatter(cell, capacity.begin());
        }
    capacity.compress(dealii::VectorOperation::add);
    capacity_ready = true;
  }

  template <int dim>
  void
  Contact<dim>::p2g(Solver<dim> &s)
  {
    shape::with_kernel<dim>(bspline, [&](auto kernel) { p2g_with(kernel, s); });
  }

  template <int dim>
  template <class K>
  void
  Contact<dim>::p2g_with(K, Solver<dim> &s)
  {
    // The solver's P2G (ScatterMassForce: the combined lumped mass and
    // internal + gravity force) and, in the same pass, every body's: per cell,
    // the kernel's sums for each body with points in it, scattered once per
    // cell. Quadratic B-splines: the outward normal of the body at a node is
    // sum_p m_p grad N_i(x_p) (minus the gradient of the body's mass density;
    // the C1 kernel makes it continuous in the point positions).
    using L         = PropertyLayout<dim>;
    const auto zero = [&](Vector &x) { s.zero_on_active(x); };
    zero(s.nodal_mass);
    zero(s.nodal_a);
    for (auto &f : fields)
      {
        zero(f.mass);
        zero(f.volume);
        zero(f.force);
        zero(f.momentum);
        if (bspline)
          zero(f.gradient);
      }
    struct BodySums
    {
      typename K::MassForce mass_force;
      typename K::Momentum  momentum;
      typename K::Momentum  volume; // sum V N (all components)
    };
    std::vector<BodySums>      acc(n_bodies);
    std::vector<unsigned char> in_cell(n_bodies, 0);
    std::vector<unsigned int>  touched;
    typename K::Cell           cell;
    typename K::MassForce      all;
    double                     ones[dim];
    std::fill(ones, ones + dim, 1.0);
    const dealii::Tensor<1, dim> g        = s.gravity; // of the running stage
    const auto                   begin_ce = [&](const unsigned int c) {
      cell = K::cell(grid, c);
      all.clear();
      touched.clear();
    };
    const auto at_point = [&](const unsigned int c, auto &pt) {
      const double            *P  = pt->get_properties().data();
      const dealii::Point<dim> xi = pt->get_reference_location();
      typename K::Eval         e;
      K::evaluate(cell, xi, e);
      const double m = P[L::mass], V = P[L::volume];
      double       t[dim][dim];
      minus_V_sigma<dim>(P, V, t);
      const unsigned int b = static_cast<unsigned int>(P[L::body]);
      if (s.smoothing) // the body's cell mean stress (StrainSmoothing)
        s.smoothing->force_stress_correction(c, b, P, V, t);
      all.add(e, m, t);
      auto &a = acc[b];
      if (!in_cell[b])
        {
          in_cell[b] = 1;
          touched.push_back(b);
          a.mass_force.clear();
          a.momentum.clear();
          a.volume.clear();
        }
      a.mass_force.add(e, m, t);
      if (affine) // APIC: m (v_p + C_p (x_i - x_p))
        transfer::add_affine_momentum<dim, K>(cell, e, m, P + L::velocity, P + affine, a.momentum.lp);
      else
        a.momentum.add(e, m, P + L::velocity);
      a.volume.add(e, V, ones);
      if (bspline)
        {
          unsigned int slot[K::n_point_nodes];
          double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
          K::point_stencil(cell, xi, slot, N, G);
          double *X = fields[b].gradient.begin();
          for (unsigned int w = 0; w < K::n_point_nodes; ++w)
            for (unsigned int d = 0; d < dim; ++d)
              X[cell.dofs[slot[w] * dim + d]] += m * G[w][d];
        }
    };
    const auto end_ce = [&](const unsigned int) {
      all.scatter(cell, g, s.nodal_mass.begin(), s.nodal_a.begin());
      for (const unsigned int b : touched)
        {
          in_cell[b] = 0;
          auto &a    = acc[b];
          auto &f    = fields[b];
          a.mass_force.scatter(cell, g, f.mass.begin(), f.force.begin());
          a.momentum.scatter(cell, f.momentum.begin());
          a.volume.scatter(cell, f.volume.begin());
        }
    };
    transfer::for_each_active_cell(s.points, begin_ce, at_point, end_ce);
  }

  template <int dim>
  void
  Contact<dim>::collect_nodes(const Solver<dim> &s)
  {
    shape::with_kernel<dim>(bspline, [&](auto kernel) { collect_nodes_with(kernel, s); });
  }

  template <int dim>
  template <class K>
  void
  Contact<dim>::collect_nodes_with(K, const Solver<dim> &s)
  {
    // owned nodes among the active DoFs (their component-0 DoF identifies them):
    // the nodes of the kernel's stencils of the active cells (Q1: the cell's
    // vertices; B-splines: its patch, slots outside the grid skipped)
    const unsigned int n_owned = s.nodal_mass.locally_owned_size();
    if (node_marker.size() != n_owned)
      node_marker.assign(n_owned, 0);
    nodes.clear();
    const auto add_node = [&](const unsigned int *node_dofs) {
      const unsigned int i0 = node_dofs[0];
      if (i0 < n_owned && !node_marker[i0]) // invalid (outside the grid) > n_owned
        {
          node_marker[i0] = 1;
          std::array<unsigned int, dim> d;
          for (unsigned int c = 0; c < dim; ++c)
            d[c] = node_dofs[c];
          nodes.push_back(d);
        }
    };
    for (const auto &ac : s.points.active_cells())
      {
        const typename K::Cell cell = K::cell(grid, ac.cell);
        for (unsigned int n = 0; n < K::n_nodes; ++n)
          add_node(cell.dofs + n * dim);
      }
    // owned nodes that only other ranks' particles touch (every owned node is a
    // vertex of an owned cell): the vertices of the cells around them
    if (dealii::Utilities::MPI::n_mpi_processes(s.comm) > 1)
      {
        std::vector<unsigned char> wanted(n_owned, 0);
        for (const auto &range : grid.partitioner->import_indices())
          for (unsigned int i = range.first; i < range.second; ++i)
            wanted[i] = 1;
        for (const auto &cc : grid.cells)
          if (cc.h[0] > 0)
            for (unsigned int v = 0; v < (1u << dim); ++v)
              if (cc.dofs[v * dim] < n_owned && wanted[cc.dofs[v * dim]] && !node_marker[cc.dofs[v * dim]])
                for (unsigned int u = 0; u < (1u << dim); ++u)
                  add_node(cc.dofs + u * dim);
      }
    for (const auto &d : nodes)
      node_marker[d[0]] = 0;
  }

  template <int dim>
  void
  Contact<dim>::compute_normals(const Solver<dim> &s)
  {
    if (bspline) // scattered by p2g_with from the points
      {
        for (auto &f : fields)
          f.gradient.compress(dealii::VectorOperation::add);
        return;
      }
    // Linear shape functions: outward normal of body b at node i: minus the gradient of the body's
    // nodal mass field, summed over the active cells around the node (cell
    // centre value x cell volume). Unlike sum_p m_p grad N_i(x_p), which jumps
    // whenever a point crosses a cell boundary (a sliding block's bottom normal
    // tilted by up to ~30 degrees), this is continuous in the point positions.
    using F                   = shape::Q1Factorised<dim>;
    constexpr unsigned int nv = F::nv;
    for (auto &f : fields)
      {
        f.mass.update_ghost_values();
        f.gradient.zero_out_ghost_values();
        double *x = f.gradient.begin();
        for (const unsigned int i : s.active_dofs)
          x[i] = 0.0;
      }
    const double w = dim == 2 ? 0.5 : 0.25; // pair weight at the cell centre
    for (const auto &ac : s.points.active_cells())
      {
        const auto &cc = grid.cells[ac.cell];
        for (auto &f : fields)
          {
            const double *M = f.mass.begin();
            double        m[nv], any = 0;
            for (unsigned int v = 0; v < nv; ++v)
              any += (m[v] = M[cc.dofs[v * dim]]);
            if (!(any > 0))
              continue;
            double grad[dim] = {};
            for (unsigned int k = 0; k < dim; ++k)
              for (unsigned int j = 0; j < F::npairs; ++j)
                {
                  const unsigned int v0 = F::pair_vertex(k, j), v1 = v0 | (1u << k);
                  grad[k] += w * (m[v1] - m[v0]) * cc.inv_h[k];
                }
            double *G = f.gradient.begin();
            for (unsigned int v = 0; v < nv; ++v)
              for (unsigned int d = 0; d < dim; ++d)
                G[cc.dofs[v * dim + d]] -= grad[d] * cell_volume;
          }
      }
    for (auto &f : fields)
      f.gradient.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  bool
  Contact<dim>::correct_node(const std::array<unsigned int, dim> &dofs, const std::vector<unsigned char> &constrained,
                             std::vector<double> &mb, std::vector<std::array<double, dim>> &vb, const double dt)
  {
    double m = 0;
    for (unsigned int b = 0; b < n_bodies; ++b)
      m += mb[b];
    if (!(m > 0))
      return false;
    unsigned int n_present = 0;
    for (unsigned int b = 0; b < n_bodies; ++b)
      if (mb[b] > 1e-12 * m)
        ++n_present;
      else
        mb[b] = 0;
    for (unsigned int b = 0; b < n_bodies; ++b)
      for (unsigned int d = 0; d < dim; ++d)
        if (constrained[dofs[d]])
          vb[b][d] = 0;
    if (n_present < 2)
      return false;
    if (bspline)
      {
        // B-splines: a node is a contact node only where at least two bodies
        // each fill a share of it; a body that reaches the node only with the
        // tail of its shape function (the support extends 1.5 cells, its mass
        // up to 1.25 cells beyond its surface) does not meet another body there
        const double cap     = capacity.begin()[dofs[0]];
        unsigned int n_share = 0;
        for (unsigned int b = 0; b < n_bodies; ++b)
          if (mb[b] > 0 && fields[b].volume.begin()[dofs[0]] >= bspline_share * cap)
            ++n_share;
        if (n_share < 2)
          return false;
      }
    ++contact_nodes;
    // combined velocity (Eq. 6.3)
    std::array<double, dim> v{};
    for (unsigned int b = 0; b < n_bodies; ++b)
      if (mb[b] > 0)
        for (unsigned int d = 0; d < dim; ++d)
          v[d] += mb[b] * vb[b][d] / m;
    std::vector<std::array<double, dim>> out(vb);
    bool                                 corrected = false;
    for (unsigned int g = 0; g < n_bodies; ++g)
      {
        if (!(mb[g] > 0))
          continue;
        // partner: the other body with the largest nodal mass
        unsigned int partner = g;
        for (unsigned int b = 0; b < n_bodies; ++b)
          if (b != g && mb[b] > 0 && (partner == g || mb[b] > mb[partner]))
            partner = b;
        const int k = pair_index[g * n_bodies + partner];
        if (k < 0)
          {
            out[g] = v; // pair not listed: the bodies stick (one velocity field)
            continue;
          }
        // outward normal of g from the mass gradients sum m grad N: that of the
        // body whose gradient is larger (the better resolved surface; at the
        // corner of a block on a flat body it is the flat body's), negated for
        // the partner, so that both bodies of a node use exactly opposite normals
        std::array<double, dim> n;
        double                  ng = 0, np = 0, nn = 0;
        const double           *Gg = fields[g].gradient.begin();
        const double           *Gp = fields[partner].gradient.begin();
        for (unsigned int d = 0; d < dim; ++d)
          {
            ng += Gg[dofs[d]] * Gg[dofs[d]];
            np += Gp[dofs[d]] * Gp[dofs[d]];
          }
        const bool own = ng > np || (ng == np && g < partner);
        for (unsigned int d = 0; d < dim; ++d)
          {
            n[d] = own ? Gg[dofs[d]] : -Gp[dofs[d]];
            nn += n[d] * n[d];
          }
        if (!(nn > 0))
          {
            out[g] = v;
            continue;
          }
        nn        = std::sqrt(nn);
        double dn = 0; // (v_g - v) . n > 0: approaching
        // the decision from the relative velocity (v_g - v_partner) . n, whose value is the
        // same, negated twice, for both bodies: dn of the two can differ in sign by round-off
        // when they barely approach, and then the adhesion term (not proportional to dn)
        // moved one body alone (momentum not conserved; docs/composability.md)
        double rel = 0;
        for (unsigned int d = 0; d < dim; ++d)
          {
            n[d] /= nn;
            dn += (vb[g][d] - v[d]) * n[d];
            rel += (vb[g][d] - vb[partner][d]) * n[d];
          }
        if (rel <= 0)
          continue;                    // separating: free
        dn        = std::max(dn, 0.0); // approaching: dn >= 0 up to round-off
        corrected = true;
        std::array<double, dim> vt;
        double                  vt_norm = 0;
        for (unsigned int d = 0; d < dim; ++d)
          {
            vt[d] = vb[g][d] - v[d] - dn * n[d];
            vt_norm += vt[d] * vt[d];
          }
        vt_norm = std::sqrt(vt_norm);
        // tangential cap in velocity units: mu dn + a A dt / m_g (Eqs. 6.8, 6.19),
        // A = contact area of the node, 2 V_node / h_n (exact on a grid-aligned
        // interface), the smaller of the two bodies' so the pair is symmetric
        double cap = pairs[k].friction * dn;
        if (pairs[k].adhesion > 0)
          {
            double hn = 0;
            for (unsigned int d = 0; d < dim; ++d)
              hn += std::abs(n[d]) * h[d];
            const double Vg   = fields[g].volume.begin()[dofs[0]];
            const double Vp   = fields[partner].volume.begin()[dofs[0]];
            const double area = 2.0 * std::min(Vg, Vp) / hn;
            cap += pairs[k].adhesion * area * dt / mb[g];
          }
        if (vt_norm <= cap)
          out[g] = v; // stick
        else
          for (unsigned int d = 0; d < dim; ++d) // slip (Eq. 6.20)
            out[g][d] = vb[g][d] - dn * n[d] - cap * vt[d] / vt_norm;
      }
    for (unsigned int b = 0; b < n_bodies; ++b)
      for (unsigned int d = 0; d < dim; ++d)
        vb[b][d] = constrained[dofs[d]] ? 0.0 : out[b][d];
    if (corrected)
      ++corrected_nodes;
    return corrected;
  }

  template <int dim>
  void
  Contact<dim>::correct_accelerations(Solver<dim> &s, const double dt)
  {
    for (auto &f : fields)
      {
        f.mass.compress(dealii::VectorOperation::add);
        f.volume.compress(dealii::VectorOperation::add);
        f.force.compress(dealii::VectorOperation::add);
        f.momentum.compress(dealii::VectorOperation::add);
      }
    compute_normals(s);
    collect_nodes(s);
    if (bspline && !capacity_ready)
      compute_capacity(shape::BSpline2Box<dim>());
    contact_nodes = corrected_nodes = 0;
    // every body's acceleration F_b / m_b with the loads' share of the body
    // (damping, mass scaling, friction walls, prescribed nodes: the rules of
    // the combined field, docs/explicit.md "Contact and nodal loads"); the
    // force vector holds the acceleration from here on
    wall_state.resize(n_bodies);
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        auto         &f = fields[b];
        double       *A = f.force.begin();
        const double *M = f.mass.begin();
        if (s.control)
          s.control->damp_and_scale(s, A, M, f.momentum.begin());
        for (const unsigned int i : s.active_dofs)
          A[i] = (M[i] > 0 && !s.constrained[i]) ? A[i] / M[i] : 0.0;
        if (s.control)
          s.control->body_accelerations(s, A, M, f.momentum.begin(), wall_state[b]);
      }
    std::vector<double>                  mb(n_bodies);
    std::vector<std::array<double, dim>> vb(n_bodies), v0(n_bodies);
    for (const auto &dofs : nodes)
      {
        // Bardenhagen et al.: the per-body velocities at time t are corrected
        // first (v~_b^t), then the predicted ones at t + dt (Eqs. 6.1-6.3); the
        // acceleration is their difference (Eq. 6.21 with v~_b^t), so that a
        // sticking node gives exactly the acceleration of the combined field.
        for (unsigned int b = 0; b < n_bodies; ++b)
          {
            const auto &f = fields[b];
            mb[b]         = f.mass.begin()[dofs[0]];
            for (unsigned int d = 0; d < dim; ++d)
              v0[b][d] = mb[b] > 0 ? f.momentum.begin()[dofs[d]] / mb[b] : 0.0;
          }
        std::vector<double> m_all(mb);
        correct_node(dofs, s.constrained, mb, v0, dt);
        for (unsigned int b = 0; b < n_bodies; ++b)
          for (unsigned int d = 0; d < dim; ++d)
            vb[b][d] = m_all[b] > 0 ? v0[b][d] + dt * fields[b].force.begin()[dofs[d]] : 0.0;
        mb = m_all;
        correct_node(dofs, s.constrained, mb, vb, dt);
        // corrected acceleration, stored in the force vector (APIC: and v^L_b
        // in the momentum vector)
        for (unsigned int b = 0; b < n_bodies; ++b)
          {
            double *A = fields[b].force.begin();
            double *V = fields[b].momentum.begin();
            for (unsigned int d = 0; d < dim; ++d)
              {
                const bool free = m_all[b] > 0 && !s.constrained[dofs[d]];
                A[dofs[d]]      = free ? (vb[b][d] - v0[b][d]) / dt : 0.0;
                if (affine)
                  V[dofs[d]] = free ? vb[b][d] : 0.0;
              }
          }
      }
    for (auto &f : fields)
      {
        f.force.update_ghost_values();
        f.mass.update_ghost_values();
        if (affine)
          f.momentum.update_ghost_values();
      }
  }

  template <int dim>
  void
  Contact<dim>::g2p_velocity_p2g_momentum(Solver<dim> &s, const double h)
  {
    shape::with_kernel<dim>(bspline, [&](auto kernel) { g2p_with(kernel, s, h); });
  }

  template <int dim>
  template <class K>
  void
  Contact<dim>::g2p_with(K, Solver<dim> &s, const double h)
  {
    // UpdateVelocityScatterMomentum with the point's own body's corrected
    // acceleration (gathered once per cell and body) and the momentum scattered
    // into the combined and the body's vectors
    using L         = PropertyLayout<dim>;
    const auto zero = [&](Vector &x) { s.zero_on_active(x); };
    zero(s.nodal_p);
    for (auto &f : fields)
      zero(f.momentum);
    std::vector<typename K::Field>    a(n_bodies);
    std::vector<typename K::Momentum> pb(n_bodies);
    std::vector<unsigned char>        in_cell(n_bodies, 0);
    std::vector<unsigned int>         touched;
    typename K::Cell                  cell;
    typename K::Momentum              all;
    const auto                        begin_ce = [&](const unsigned int c) {
      cell = K::cell(grid, c);
      all.clear();
      touched.clear();
    };
    const auto at_point = [&](const unsigned int, auto &pt) {
      double            *P = pt->get_properties().data();
      const unsigned int b = static_cast<unsigned int>(P[L::body]);
      if (!in_cell[b])
        {
          in_cell[b] = 1;
          touched.push_back(b);
          K::gather(cell, fields[b].force.begin(), 1.0, a[b], false);
          pb[b].clear();
        }
      typename K::Values N;
      K::values(cell, pt->get_reference_location(), N);
      double ap[dim];
      K::interpolate(a[b], N, ap);
      double *vel = P + L::velocity;
      for (unsigned int d = 0; d < dim; ++d)
        vel[d] += h * ap[d]; // Eq. 4.46 with the corrected acceleration
      all.add(N, P[L::mass], vel);
      pb[b].add(N, P[L::mass], vel);
    };
    const auto end_ce = [&](const unsigned int) {
      all.scatter(cell, s.nodal_p.begin());
      for (const unsigned int b : touched)
        {
          in_cell[b] = 0;
          pb[b].scatter(cell, fields[b].momentum.begin());
        }
    };
    transfer::for_each_active_cell(s.points, begin_ce, at_point, end_ce);
    s.nodal_p.compress(dealii::VectorOperation::add);
    for (auto &f : fields)
      f.momentum.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Contact<dim>::correct_velocities(Solver<dim> &s, const double h)
  {
    // v_b = p_b / m_b with the walls' and prescribed nodes' conditions
    // (LoadControl::body_velocities, by the states of correct_accelerations)
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        double       *V = fields[b].momentum.begin();
        const double *M = fields[b].mass.begin();
        for (const unsigned int i : s.active_dofs)
          V[i] = M[i] > 0 ? V[i] / M[i] : 0.0;
        if (s.control)
          s.control->body_velocities(s, V, wall_state[b]);
      }
    std::vector<double>                  mb(n_bodies);
    std::vector<std::array<double, dim>> vb(n_bodies);
    for (const auto &dofs : nodes)
      {
        for (unsigned int b = 0; b < n_bodies; ++b)
          {
            mb[b] = fields[b].mass.begin()[dofs[0]];
            for (unsigned int d = 0; d < dim; ++d)
              vb[b][d] = mb[b] > 0 ? fields[b].momentum.begin()[dofs[d]] : 0.0;
          }
        // the points' velocities keep the Lagrangian-phase values: applying
        // this correction to them too was measured to add energy (disks +38 %)
        // and to destabilise sticking contact
        correct_node(dofs, s.constrained, mb, vb, h);
        for (unsigned int b = 0; b < n_bodies; ++b)
          for (unsigned int d = 0; d < dim; ++d)
            fields[b].momentum.begin()[dofs[d]] = vb[b][d]; // now the velocity v~_b
      }
    for (auto &f : fields)
      f.momentum.update_ghost_values();
  }

  template class Contact<2>;
  template class Contact<3>;
} // namespace talus::explicit_mpm
