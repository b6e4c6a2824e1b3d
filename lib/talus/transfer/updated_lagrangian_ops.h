// talus — point ops of the implicit updated-Lagrangian step (seed 001 §4.4,
// Algorithm 1) on the walk of cell_walk.h:
//
//   UpdatedLagrangianForce   integrand for AssembleSystem: the residual
//                            f_int - f_ext and the consistent tangent
//                            (material + geometric) at the iterate Du
//   NodalProjection          integrand: lumped P2G of mass, m v or m a
//   CommitUpdatedLagrangian  the convective phase: Du and a^{n+1} to the points,
//                            constitutive state committed, points moved
//
// The step's kinematics are written on the grid of the start of the step (the
// grid is reset every step): dF = I + grad_{x_n} Du at the point. The internal
// force of the thesis, sum_p V_{n+1} sigma grad_{x_{n+1}} N_i, equals
// sum_p c_p tau dF^{-T} grad_{x_n} N_i with c_p = V_n / J_n (J_n: det F of the
// model's Kirchhoff stress at t_n, sigma = tau / J), because V_{n+1} = det(dF) V_n
// and grad_{x_{n+1}} N = dF^{-T} grad_{x_n} N. Its derivative by Du is
// therefore exact from the model's d tau / d dF alone: it is the thesis's
// K_material + K_geometric (Eqs. 4.33-4.34 with C = C_tau / J, current volume)
// pulled back to x_n, with no moved grid (docs/implicit.md).
#pragma once

#include <talus/base/errors.h>
#include <talus/grid/nodal_space.h>
#include <talus/materials/material.h>
#include <talus/particles/material_point_set.h>
#include <talus/transfer/matrix_ops.h>
#include <talus/transfer/move_point.h>

#include <deal.II/base/tensor.h>

#include <memory>
#include <string>
#include <vector>

namespace talus::transfer
{
  /// The first point where a pass failed (inverted point, constitutive return
  /// that did not converge). A walk never throws mid-way (the other ranks would
  /// wait in the next collective); the caller reduces `failed` over the ranks.
  struct PointFailure
  {
    bool        failed = false;
    std::string what;
    void
    set(const std::string &w)
    {
      if (!failed)
        what = w;
      failed = true;
    }
  };

  /// dF (3x3; plane strain: dF_33 = 1) = I + sum_a u_a (x) grad N_a.
  template <int dim, class PN>
  inline dealii::Tensor<2, 3>
  incremental_deformation_gradient(const double *u_local, const PN &p)
  {
    dealii::Tensor<2, 3> F;
    for (unsigned int i = 0; i < 3; ++i)
      F[i][i] = 1.0;
    for (unsigned int a = 0; a < p.n; ++a)
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          F[i][j] += u_local[p.local[a] * dim + i] * p.G[a][j];
    return F;
  }

  /// The residual f_int - lambda f_ext of one point and (optionally) its
  /// tangent d(f_int)/d(Du) at the iterate Du (AssembleSystem's field). Loads:
  /// body force m_p g N_i (g already scaled by the load factor).
  template <int dim>
  struct UpdatedLagrangianForce
  {
    const std::vector<std::shared_ptr<const materials::Material>> *materials = nullptr;
    unsigned int                                                   history_offset = 0;
    dealii::Tensor<1, dim>                                         gravity;
    bool                                                           tangent = true;
    PointFailure *                                                 failure = nullptr;

    static constexpr bool matrix = true, vector = true;

    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim && d_ == dim, "UpdatedLagrangianForce: a vector space (nc = dim)");
      using L                = PropertyLayout<dim>;
      const auto &         m = *(*materials)[static_cast<unsigned int>(P[L::material])];
      const unsigned int   nh = m.n_history();
      double               history_new[64];
      dealii::Tensor<2, 3> dF = incremental_deformation_gradient<dim>(ls.u, p);
      materials::Stress    tau;
      dealii::Tensor<4, 3> dtau;
      try
        {
          m.finite_strain_update(dF,
                                 dealii::ArrayView<const double>(P + history_offset, nh),
                                 dealii::ArrayView<double>(history_new, nh),
                                 tau,
                                 tangent ? &dtau : nullptr);
        }
      catch (const std::exception &e) // inverted point, return mapping failed: cut the step
        {
          failure->set(e.what());
          return;
        }
      const double c = P[L::volume] / m.kirchhoff_jacobian(dealii::ArrayView<const double>(P + history_offset, nh));
      const dealii::Tensor<2, 3> Finv = invert(dF);
      // first Piola stress of the step, times c: Pk_ib = c tau_ie Finv_be
      double Pk[dim][dim];
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int b = 0; b < dim; ++b)
          {
            double s = 0;
            for (unsigned int e = 0; e < 3; ++e)
              s += tau[i][e] * Finv[b][e];
            Pk[i][b] = c * s;
          }
      const double mass = P[L::mass];
      for (unsigned int a = 0; a < p.n; ++a)
        for (unsigned int i = 0; i < dim; ++i)
          {
            double f = -mass * gravity[i] * p.N[a];
            for (unsigned int b = 0; b < dim; ++b)
              f += Pk[i][b] * p.G[a][b];
            ls.b[p.local[a] * dim + i] += f;
          }
      if (!tangent)
        return;
      // A_ijkd = c d(tau_ie Finv_je)/d dF_kd
      //        = c (dtau_iekd Finv_je - tau_ie Finv_jk Finv_de)
      double A[dim][dim][dim][dim];
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          for (unsigned int k = 0; k < dim; ++k)
            for (unsigned int d = 0; d < dim; ++d)
              {
                double s = 0;
                for (unsigned int e = 0; e < 3; ++e)
                  s += dtau[i][e][k][d] * Finv[j][e] - tau[i][e] * Finv[j][k] * Finv[d][e];
                A[i][j][k][d] = c * s;
              }
      for (unsigned int a = 0; a < p.n; ++a)
        for (unsigned int b = 0; b < p.n; ++b)
          {
            const auto &Ga = p.G[a];
            const auto &Gb = p.G[b];
            for (unsigned int i = 0; i < dim; ++i)
              for (unsigned int k = 0; k < dim; ++k)
                {
                  double s = 0;
                  for (unsigned int j = 0; j < dim; ++j)
                    for (unsigned int d = 0; d < dim; ++d)
                      s += A[i][j][k][d] * Ga[j] * Gb[d];
                  ls.a(p.local[a] * dim + i, p.local[b] * dim + k) += s;
                }
          }
    }
  };

  /// Lumped P2G (vector only): m_p N_i per component (`offset` invalid: the
  /// nodal mass), or m_p N_i q_c with q the dim-block at property `offset`
  /// (velocity: momentum; acceleration: m a).
  template <int dim>
  struct NodalProjection
  {
    unsigned int          offset = dealii::numbers::invalid_unsigned_int;
    static constexpr bool matrix = false, vector = true;
    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim && d_ == dim, "NodalProjection: a vector space (nc = dim)");
      if (offset == dealii::numbers::invalid_unsigned_int)
        add_lumped<dim>(P, p, ls, [](const unsigned int) { return 1.0; });
      else
        add_lumped<dim>(P, p, ls, [P, this](const unsigned int c) { return P[offset + c]; });
    }
  };

  /// The convective phase (Algorithm 1 step 3, Eqs. 2.14-2.17): per point
  /// Du_p = N Du, the constitutive update at dF committed (stress = tau / J,
  /// history), V *= det dF; with accelerations (dynamic), a_p^{n+1} = N a^{n+1}
  /// and v_p += h ((1 - gamma) a_p^n + gamma a_p^{n+1}) (Eq. 2.16: integrated,
  /// not interpolated); x_p and u_p += Du_p; points that left their cell are
  /// handed to the set's relocation. Du and a_new: vectors of `space` with
  /// ghost values; a_new null in a static analysis (v_p = 0 then).
  template <int dim, class K>
  struct CommitUpdatedLagrangian
  {
    CommitUpdatedLagrangian(MaterialPointSet<dim> &set, const NodalSpace<dim> &space, const Vector &du,
                            const Vector *a_new, const std::vector<std::shared_ptr<const materials::Material>> &mats,
                            const unsigned int acceleration_offset, const double h, const double gamma,
                            PointFailure &failure)
      : set(set)
      , grid(space.grid)
      , space(space)
      , du(du)
      , a_new(a_new)
      , materials(mats)
      , acceleration(acceleration_offset)
      , h(h)
      , gamma(gamma)
      , failure(failure)
    {}
    MaterialPointSet<dim> &                                        set;
    const BackgroundGrid<dim> &                                    grid;
    const NodalSpace<dim> &                                        space;
    const Vector &                                                 du;
    const Vector *                                                 a_new;
    const std::vector<std::shared_ptr<const materials::Material>> &materials;
    const unsigned int                                             acceleration;
    const double                                                   h, gamma;
    PointFailure &                                                 failure;

    static constexpr bool prefetch_location = true;
    typename K::Cell      cell;
    double                un[K::n_nodes][dim], an[K::n_nodes][dim];

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      gather_space_vector<dim, K, dim>(space, cell, du, un);
      if (a_new)
        gather_space_vector<dim, K, dim>(space, cell, *a_new, an);
      else
        for (auto &node : an)
          for (double &value : node)
            value = 0.0;
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      using L   = PropertyLayout<dim>;
      double *P = it->get_properties().data();
      unsigned int slot[K::n_point_nodes];
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      double               dx[dim] = {}, ap[dim] = {};
      dealii::Tensor<2, 3> dF;
      for (unsigned int i = 0; i < 3; ++i)
        dF[i][i] = 1.0;
      for (unsigned int w = 0; w < K::n_point_nodes; ++w)
        for (unsigned int i = 0; i < dim; ++i)
          {
            const double u = un[slot[w]][i];
            dx[i] += N[w] * u;
            ap[i] += N[w] * an[slot[w]][i];
            for (unsigned int j = 0; j < dim; ++j)
              dF[i][j] += u * G[w][j];
          }
      const auto &       m  = *materials[static_cast<unsigned int>(P[L::material])];
      const unsigned int nh = m.n_history();
      double             old[64];
      std::copy(P + L::history, P + L::history + nh, old);
      materials::Stress tau;
      try
        {
          m.finite_strain_update(dF, dealii::ArrayView<const double>(old, nh),
                                 dealii::ArrayView<double>(P + L::history, nh), tau, nullptr);
        }
      catch (const std::exception &e)
        {
          failure.set(e.what());
          return true;
        }
      L::set_stress(tau / m.kirchhoff_jacobian(dealii::ArrayView<const double>(P + L::history, nh)), P);
      P[L::volume] *= determinant(dF);
      for (unsigned int i = 0; i < dim; ++i)
        {
          if (a_new)
            {
              P[L::velocity + i] += h * ((1.0 - gamma) * P[acceleration + i] + gamma * ap[i]);
              P[acceleration + i] = ap[i];
            }
          else
            P[L::velocity + i] = 0.0;
          P[L::displacement + i] += dx[i];
        }
      return move_point(set, grid, c, it, dx);
    }
    inline void
    end_cell(const unsigned int)
    {}
  };
} // namespace talus::transfer
