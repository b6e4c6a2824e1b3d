// talus — the affine particle-in-cell transfer (APIC, Jiang et al. 2015) as ops
// of the shared cell walk (transfer/cell_walk.h), for both box kernels (shape::Q1Box,
// shape::BSpline2Box). Selected by numerics/velocity transfer = apic; the FLIP
// ops of point_ops.h are untouched. docs/shape-functions.md, section "APIC".
//
// A point carries, besides v_p, the affine velocity matrix C_p (dim x dim, an
// extra property block that exists only in an APIC run). With the node offsets
// r_i = x_i - x_p of the point's stencil and D_p = sum_i N_i r_i r_i^T:
//
//   P2G   p_i  = sum_p N_i m_p (v_p + C_p r_i)
//   G2P   v_p  = sum_i N_i v_i,   B_p = sum_i N_i v_i r_i^T,   C_p = B_p D_p^-1
//
// D_p is computed per point from the stencil, not taken as the interior
// constant (h^2/4 for quadratic B-splines): with talus's wall-modified splines
// (linear hats on the wall half cells) and with Q1, D_p depends on the position.
// Both kernels are tensor products that reproduce linear fields, so D_p is
// diagonal: D_kk = sum_a N_k(a) (a - m_k)^2 h_k^2 per direction, with m_k =
// sum_a a N_k(a) the point's coordinate in node spacings from the first
// stencil node (linear reproduction; no reference location needed).
// For Q1, D_kk = xi_k (1 - xi_k) h_k^2 and B_p D_p^-1 is exactly the gradient of
// the bilinear velocity field (Jiang et al. §5.2); it is used in that form, which
// is also defined where D_kk = 0 (a point on a cell face). With B-splines D_kk
// vanishes only for a point exactly on a wall (the wall half cell's hats); there
// the same gradient form, the limit of B D^-1, is used.
//
// Angular momentum: sum_i x_i x p_i = sum_p m_p (x_p x v_p + eps : (C_p D_p)^T),
// exactly (linear reproduction), which unit tests check (test_explicit_transfer).
#pragma once

#include <talus/particles/material_points.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/point_ops.h>

#include <type_traits>

namespace talus::transfer
{
  /// Calls f(slot, N, digit) for every node of the point's stencil (Q1: the
  /// 2^dim vertices; B-spline: the 3^dim window), with digit[d] the node's
  /// position in node spacings from the stencil's first node per direction.
  template <int dim, class K, class F>
  inline void
  for_each_stencil_node(const typename K::Eval &e, F &&f)
  {
    if constexpr (std::is_same_v<K, shape::Q1Box<dim>>)
      for (unsigned int v = 0; v < K::n_nodes; ++v)
        {
          unsigned int dg[dim];
          for (unsigned int d = 0; d < dim; ++d)
            dg[d] = (v >> d) & 1u;
          f(v, e.N[v], dg);
        }
    else
      {
        using W                  = typename K::W;
        const unsigned int first = W::first_slot(e);
        for (unsigned int w = 0; w < W::n_nodes; ++w)
          {
            unsigned int dg[dim];
            double       N = 1.0;
            for (unsigned int d = 0; d < dim; ++d)
              {
                dg[d] = W::digit(w, d);
                N *= e.N[d][dg[d]];
              }
            f(first + W::window_offset(w), N, dg);
          }
      }
  }

  /// Per direction: m_k (the point's position in node spacings from the first
  /// stencil node) and D_kk = sum_i N_i (x_i - x_p)_k^2.
  template <int dim, class K>
  inline void
  stencil_moments(const typename K::Cell &cell, const typename K::Eval &e, double (&m)[dim], double (&D)[dim])
  {
    double s1[dim] = {}, s2[dim] = {};
    for_each_stencil_node<dim, K>(e, [&](unsigned int, const double N, const unsigned int(&dg)[dim]) {
      for (unsigned int d = 0; d < dim; ++d)
        {
          s1[d] += N * dg[d];
          s2[d] += N * dg[d] * dg[d];
        }
    });
    for (unsigned int d = 0; d < dim; ++d)
      {
        m[d]           = s1[d];
        const double h = cell.cc->h[d];
        D[d]           = std::max(0.0, s2[d] - s1[d] * s1[d]) * h * h;
      }
  }

  /// APIC G2P of one point: from the cell's field du = h v (as gathered by
  /// UpdateAndMove) with its interpolated value dx and gradient gu at the
  /// point, sets v_p = dx / h and C_p (row-major, C[c * dim + k] = C_ck).
  template <int dim, class K>
  inline void
  apic_point_velocity(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du,
                      const double h, const double (&gu)[dim][dim], const double (&dx)[dim], double *vel, double *C)
  {
    const double inv_h = 1.0 / h;
    for (unsigned int d = 0; d < dim; ++d)
      vel[d] = dx[d] * inv_h;
    if constexpr (std::is_same_v<K, shape::Q1Box<dim>>)
      {
        // B_p D_p^-1 = grad v for Q1 (exact, also where D_p is singular)
        for (unsigned int c = 0; c < dim; ++c)
          for (unsigned int k = 0; k < dim; ++k)
            C[c * dim + k] = gu[c][k] * inv_h;
      }
    else
      {
        double m[dim], D[dim];
        stencil_moments<dim, K>(cell, e, m, D);
        double B[dim][dim] = {};
        for_each_stencil_node<dim, K>(e, [&](const unsigned int slot, const double N, const unsigned int(&dg)[dim]) {
          double r[dim];
          for (unsigned int k = 0; k < dim; ++k)
            r[k] = (dg[k] - m[k]) * cell.cc->h[k];
          for (unsigned int c = 0; c < dim; ++c)
            {
              const double Nu = N * du.u[slot][c];
              for (unsigned int k = 0; k < dim; ++k)
                B[c][k] += Nu * r[k];
            }
        });
        for (unsigned int k = 0; k < dim; ++k)
          {
            const double hk = cell.cc->h[k];
            // D_kk = 0 only for a point exactly on a wall (wall half cell, linear
            // hats): the limit of B D^-1 there is the gradient
            const bool singular = !(D[k] > 1e-14 * hk * hk);
            for (unsigned int c = 0; c < dim; ++c)
              C[c * dim + k] = (singular ? gu[c][k] : B[c][k] / D[k]) * inv_h;
          }
      }
  }

  /// APIC G2P of v_p and C_p alone (no point update) from the nodal velocity
  /// V: the first half of the step with body velocity conditions (Solver::step),
  /// whose points are then set to the prescribed field and projected anew.
  template <int dim, class K>
  struct ApicVelocity
  {
    ApicVelocity(const BackgroundGrid<dim> &grid, const double *V, const unsigned int affine)
        : grid(grid)
        , V(V)
        , affine(affine)
    {
    }
    const BackgroundGrid<dim> &grid;
    const double *const        V;
    const unsigned int         affine;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell;
    typename K::Field     v;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      K::gather(cell, V, 1.0, v, true);
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      using L            = PropertyLayout<dim>;
      double          *P = it->get_properties().data();
      typename K::Eval e;
      K::evaluate(cell, it->get_reference_location(), e);
      double gv[dim][dim], vp[dim];
      default_increments<dim, K>(cell, e, v, gv, vp);
      apic_point_velocity<dim, K>(cell, e, v, 1.0, gv, vp, P + L::velocity, P + affine);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
    }
  };

  /// APIC P2G of one point's momentum with the affine term into the kernel's
  /// per-cell momentum sums: lp[slot] += N m (v + C r).
  template <int dim, class K, class Row>
  inline void
  add_affine_momentum(const typename K::Cell &cell, const typename K::Eval &e, const double mass, const double *vel,
                      const double *C, Row *lp)
  {
    double m[dim], D[dim];
    stencil_moments<dim, K>(cell, e, m, D);
    for_each_stencil_node<dim, K>(e, [&](const unsigned int slot, const double N, const unsigned int(&dg)[dim]) {
      double r[dim];
      for (unsigned int k = 0; k < dim; ++k)
        r[k] = (dg[k] - m[k]) * cell.cc->h[k];
      const double mN = mass * N;
      for (unsigned int c = 0; c < dim; ++c)
        {
          double v = vel[c];
          for (unsigned int k = 0; k < dim; ++k)
            v += C[c * dim + k] * r[k];
          lp[slot][c] += mN * v;
        }
    });
  }

  /// P2G of the points' momentum with the affine term (APIC) at their current
  /// reference locations into Pn; `affine` is the offset of C_p in the
  /// properties (PropertyLayout::add_extra).
  template <int dim, class K>
  struct ScatterAffineMomentum : CellSums<dim, K, typename K::Momentum>
  {
    using Base = CellSums<dim, K, typename K::Momentum>;
    using Base::cell;
    using Base::sums;
    ScatterAffineMomentum(const BackgroundGrid<dim> &grid, double *Pn, const unsigned int affine)
        : Base(grid)
        , Pn(Pn)
        , affine(affine)
    {
    }
    double *const      Pn;
    const unsigned int affine;
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      using L            = PropertyLayout<dim>;
      const double    *P = it->get_properties().data();
      typename K::Eval e;
      K::evaluate(cell, it->get_reference_location(), e);
      add_affine_momentum<dim, K>(cell, e, P[L::mass], P + L::velocity, P + affine, sums.lp);
      return true;
    }
    inline void
    end_cell(const unsigned int)
    {
      sums.scatter(cell, Pn);
    }
  };

  /// The APIC angular momentum a point carries (what the P2G above hands to
  /// the grid): m (x_p x v_p) + m eps : (C_p D_p)^T; 2D: the z component
  /// (out[0]); 3D: the three components. For conservation checks.
  template <int dim, class K>
  inline void
  affine_angular_momentum(const typename K::Cell &cell, const dealii::Point<dim> &xi, const dealii::Point<dim> &x,
                          const double mass, const double *vel, const double *C, double *out)
  {
    typename K::Eval e;
    K::evaluate(cell, xi, e);
    double m[dim], D[dim];
    stencil_moments<dim, K>(cell, e, m, D);
    auto CD = [&](const unsigned int c, const unsigned int k) { return C[c * dim + k] * D[k]; };
    if constexpr (dim == 2)
      out[0] += mass * (x[0] * vel[1] - x[1] * vel[0] + CD(1, 0) - CD(0, 1));
    else
      {
        out[0] += mass * (x[1] * vel[2] - x[2] * vel[1] + CD(2, 1) - CD(1, 2));
        out[1] += mass * (x[2] * vel[0] - x[0] * vel[2] + CD(0, 2) - CD(2, 0));
        out[2] += mass * (x[0] * vel[1] - x[1] * vel[0] + CD(1, 0) - CD(0, 1));
      }
  }
} // namespace talus::transfer
