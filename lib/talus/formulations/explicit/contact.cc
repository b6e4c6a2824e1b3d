// talus — contact between bodies (seed 000 §6.2): the predictor-corrector
// algorithm of Bardenhagen et al. with Coulomb friction and adhesion.
#include <talus/base/errors.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/numerics.h>
#include <talus/transfer/cell_walk.h>
#include <talus/shape/q1.h>

#include <algorithm>
#include <cmath>


namespace talus::explicit_mpm
{
  template <int dim>
  Contact<dim>::Contact(const BackgroundGrid<dim> &g, const NumericsOptions &o, const unsigned int nb)
      : grid(g)
      , n_bodies(nb)
  {
    fields.resize(n_bodies);
    for (auto &f : fields)
      {
        grid.reinit_vector(f.mass);
        grid.reinit_vector(f.force);
        grid.reinit_vector(f.momentum);
        grid.reinit_vector(f.gradient);
      }
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
        grid.reinit_vector(f.force);
        grid.reinit_vector(f.momentum);
        grid.reinit_vector(f.gradient);
      }
    node_marker.clear();
    nodes.clear();
  }

  template <int dim>
  void
  Contact<dim>::collect_nodes(const Solver<dim> &s)
  {
    // owned nodes among the active DoFs (their component-0 DoF identifies them)
    const unsigned int n_owned = s.nodal_mass.locally_owned_size();
    if (node_marker.size() != n_owned)
      node_marker.assign(n_owned, 0);
    nodes.clear();
    const auto add = [&](const CellCache<dim> &cc) {
      for (unsigned int v = 0; v < (1u << dim); ++v)
        {
          const unsigned int i0 = cc.dofs[v * dim];
          if (i0 < n_owned && !node_marker[i0])
            {
              node_marker[i0] = 1;
              std::array<unsigned int, dim> d;
              for (unsigned int c = 0; c < dim; ++c)
                d[c] = cc.dofs[v * dim + c];
              nodes.push_back(d);
            }
        }
    };
    for (const auto &ac : s.points.active_cells())
      add(grid.cells[ac.cell]);
    // owned nodes that only other ranks' particles touch: any cell around them
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
                add(cc);
      }
    for (const auto &d : nodes)
      node_marker[d[0]] = 0;
  }

  template <int dim>
  void
  Contact<dim>::compute_normals(const Solver<dim> &s)
  {
    // Outward normal of body b at node i: minus the gradient of the body's
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
            const double Vg   = fields[g].mass.begin()[dofs[1]];
            const double Vp   = fields[partner].mass.begin()[dofs[1]];
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
        f.force.compress(dealii::VectorOperation::add);
        f.momentum.compress(dealii::VectorOperation::add);
      }
    compute_normals(s);
    collect_nodes(s);
    contact_nodes = corrected_nodes = 0;
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
            vb[b][d] = m_all[b] > 0 ? v0[b][d] + dt * fields[b].force.begin()[dofs[d]] / m_all[b] : 0.0;
        mb = m_all;
        correct_node(dofs, s.constrained, mb, vb, dt);
        // corrected acceleration, stored in the force vector
        for (unsigned int b = 0; b < n_bodies; ++b)
          {
            double *A = fields[b].force.begin();
            for (unsigned int d = 0; d < dim; ++d)
              A[dofs[d]] = (m_all[b] > 0 && !s.constrained[dofs[d]]) ? (vb[b][d] - v0[b][d]) / dt : 0.0;
          }
      }
    for (auto &f : fields)
      {
        f.force.update_ghost_values();
        f.mass.update_ghost_values();
      }
  }

  template <int dim>
  void
  Contact<dim>::g2p_velocity_p2g_momentum(Solver<dim> &s, const double h)
  {
    using L                     = PropertyLayout<dim>;
    constexpr unsigned int nv   = 1u << dim;
    double *const          Pn   = s.nodal_p.begin();
    const auto             zero = [&](Vector &x) {
      x.zero_out_ghost_values();
      double *p = x.begin();
      for (const unsigned int i : s.active_dofs)
        p[i] = 0.0;
    };
    zero(s.nodal_p);
    for (auto &f : fields)
      zero(f.momentum);
    const CellCache<dim> *cell     = nullptr;
    const auto            at_point = [&](const unsigned int, auto &pt) {
      const auto        &cc = *cell;
      double            *P  = pt->get_properties().data();
      const unsigned int b  = static_cast<unsigned int>(P[L::body]);
      const double      *A  = fields[b].force.begin();
      double            *Pb = fields[b].momentum.begin();
      double             N[nv];
      shape::Q1<dim>::values(pt->get_reference_location(), N);
      double *vel = P + L::velocity;
      for (unsigned int d = 0; d < dim; ++d)
        {
          double sum = 0;
          for (unsigned int v = 0; v < nv; ++v)
            sum += N[v] * A[cc.dofs[v * dim + d]];
          vel[d] += h * sum; // Eq. 4.46 with the corrected acceleration
        }
      const double m = P[L::mass];
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double q = m * N[v] * vel[d];
            Pn[cc.dofs[v * dim + d]] += q;
            Pb[cc.dofs[v * dim + d]] += q;
          }
    };
    transfer::for_each_active_cell(
      s.points, [&](const unsigned int c) { cell = &s.grid.cells[c]; }, at_point, [](const unsigned int) {});
    s.nodal_p.compress(dealii::VectorOperation::add);
    for (auto &f : fields)
      f.momentum.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Contact<dim>::correct_velocities(Solver<dim> &s, const double h)
  {
    std::vector<double>                  mb(n_bodies);
    std::vector<std::array<double, dim>> vb(n_bodies);
    for (const auto &dofs : nodes)
      {
        for (unsigned int b = 0; b < n_bodies; ++b)
          {
            mb[b] = fields[b].mass.begin()[dofs[0]];
            for (unsigned int d = 0; d < dim; ++d)
              vb[b][d] = mb[b] > 0 ? fields[b].momentum.begin()[dofs[d]] / mb[b] : 0.0;
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
