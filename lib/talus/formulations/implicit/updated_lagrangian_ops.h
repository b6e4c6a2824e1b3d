// talus — point ops of the implicit updated-Lagrangian step (seed 001 §4.4,
// Algorithm 1) on the walk of transfer/cell_walk.h:
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
#include <talus/loads/point_forces.h>
#include <talus/materials/material.h>
#include <talus/materials/neo_hookean.h>
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

  /// dF (3x3; plane strain: dF_33 = 1) = I + sum_a u_a (x) grad N_a; the
  /// displacement of local node a at u_local[a * stride] (stride: the space's
  /// components, displacement first).
  template <int dim, class PN, unsigned int stride = dim>
  inline dealii::Tensor<2, 3>
  incremental_deformation_gradient(const double *u_local, const PN &p)
  {
    dealii::Tensor<2, 3> F;
    for (unsigned int i = 0; i < 3; ++i)
      F[i][i] = 1.0;
    for (unsigned int a = 0; a < p.n; ++a)
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          F[i][j] += u_local[p.local[a] * stride + i] * p.G[a][j];
    return F;
  }

  /// F-bar (de Souza Neto et al. 1996; docs/implicit.md, "F-bar"): the
  /// determinant of the in-plane (2D: plane strain, dF_zz = 1) or full (3D)
  /// block of a step's dF.
  template <int dim>
  inline double
  fbar_det(const dealii::Tensor<2, 3> &dF)
  {
    if constexpr (dim == 2)
      return dF[0][0] * dF[1][1] - dF[0][1] * dF[1][0];
    else
      return determinant(dF);
  }

  /// dF scaled in its in-plane block so that its determinant becomes jbar (the
  /// cell's mean): dFbar = (jbar / j)^(1/dim) dF, dFbar_zz = 1 in plane strain;
  /// j = fbar_det(dF) (the caller has checked it is positive). Returns the factor
  /// s = (jbar / j)^(1/dim).
  template <int dim>
  inline double
  fbar_scale(dealii::Tensor<2, 3> &dF, const double j, const double jbar)
  {
    const double s = dim == 2 ? std::sqrt(jbar / j) : std::cbrt(jbar / j);
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int k = 0; k < dim; ++k)
        dF[i][k] *= s;
    return s;
  }

  /// Axisymmetric (x = radius, y = axis; seed 001 App. C): the step's hoop
  /// stretch dF_zz = r_{n+1} / r_n = 1 + Du_r(x_p) / r_n, Du_r = sum_a N_a Du_a,x
  /// (r_n > 0: points never sit on the axis).
  template <class PN, unsigned int stride>
  inline double
  hoop_stretch(const double *u_local, const PN &p, const double r)
  {
    double ur = 0;
    for (unsigned int a = 0; a < p.n; ++a)
      ur += p.N[a] * u_local[p.local[a] * stride];
    return 1.0 + ur / r;
  }

  /// Axisymmetric residual and tangent of one point from the full 3x3 first
  /// Piola form Pk (c tau dF^-T) and its derivative A = d Pk / d dF: the
  /// virtual dF of node a, component i, is e_i (x) grad_{x_n} N_a plus, for the
  /// radial component, the hoop entry N_a / r_n at (z, z), so
  ///   r_a,i  += sum_b Pk_ib G_a,b + [i = x] Pk_zz N_a / r_n - fe_i N_a
  ///   K_ai,bk = that virtual dF of (a, i) : A : that of (b, k).
  template <unsigned int stride, class PN>
  inline void
  add_axisymmetric_point(const double (&Pk)[3][3], const double (*A)[3][3][3], const double (&fe)[2], const double r,
                         const PN &p, LocalSystem &ls)
  {
    const double ir = 1.0 / r;
    for (unsigned int a = 0; a < p.n; ++a)
      for (unsigned int i = 0; i < 2; ++i)
        {
          double f = -fe[i] * p.N[a] + Pk[i][0] * p.G[a][0] + Pk[i][1] * p.G[a][1];
          if (i == 0)
            f += Pk[2][2] * p.N[a] * ir;
          ls.b[p.local[a] * stride + i] += f;
        }
    if (!A)
      return;
    for (unsigned int a = 0; a < p.n; ++a)
      for (unsigned int b = 0; b < p.n; ++b)
        {
          const auto  &Ga = p.G[a];
          const auto  &Gb = p.G[b];
          const double ha = p.N[a] * ir, hb = p.N[b] * ir; // hoop entries of the virtual dF
          for (unsigned int i = 0; i < 2; ++i)
            for (unsigned int k = 0; k < 2; ++k)
              {
                double s = 0;
                for (unsigned int j = 0; j < 2; ++j)
                  for (unsigned int d = 0; d < 2; ++d)
                    s += A[i][j][k][d] * Ga[j] * Gb[d];
                if (k == 0)
                  for (unsigned int j = 0; j < 2; ++j)
                    s += A[i][j][2][2] * Ga[j] * hb;
                if (i == 0)
                  {
                    for (unsigned int d = 0; d < 2; ++d)
                      s += A[2][2][k][d] * ha * Gb[d];
                    if (k == 0)
                      s += A[2][2][2][2] * ha * hb;
                  }
                ls.a(p.local[a] * stride + i, p.local[b] * stride + k) += s;
              }
        }
  }

  /// The step's first Piola form times c: Pk_ib = c sum_e tau_ie Finv_be
  /// (c tau dF^-T; V_{n+1} sigma grad_{x_{n+1}} N = Pk grad_{x_n} N for c = V_n / J_n).
  template <int dim>
  inline void
  scaled_piola(const double c, const materials::Stress &tau, const dealii::Tensor<2, 3> &Finv, double (&Pk)[dim][dim])
  {
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int b = 0; b < dim; ++b)
        {
          double s = 0;
          for (unsigned int e = 0; e < 3; ++e)
            s += tau[i][e] * Finv[b][e];
          Pk[i][b] = c * s;
        }
  }

  /// Its derivative A_ijkd = d Pk_ij / d dF_kd = c (dtau_iekd Finv_je - tau_ie
  /// Finv_jk Finv_de): material + geometric stiffness (Eqs. 4.33-4.34 pulled back).
  /// The geometric term as c (tau dF^-T)_id Finv_jk: tau dF^-T once per point.
  template <int dim>
  inline void
  scaled_piola_tangent(const double c, const materials::Stress &tau, const dealii::Tensor<4, 3> &dtau,
                       const dealii::Tensor<2, 3> &Finv, double (&A)[dim][dim][dim][dim])
  {
    double TF[dim][dim]; // (tau dF^-T)_id
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int d = 0; d < dim; ++d)
        TF[i][d] = tau[i][0] * Finv[d][0] + tau[i][1] * Finv[d][1] + tau[i][2] * Finv[d][2];
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int j = 0; j < dim; ++j)
        for (unsigned int k = 0; k < dim; ++k)
          for (unsigned int d = 0; d < dim; ++d)
            A[i][j][k][d] = c * (dtau[i][0][k][d] * Finv[j][0] + dtau[i][1][k][d] * Finv[j][1] +
                                 dtau[i][2][k][d] * Finv[j][2] - TF[i][d] * Finv[j][k]);
  }

  /// Residual rows b[a * stride + i] += sum_b Pk_ib G_a,b - fe_i N_a.
  template <int dim, unsigned int stride, class PN>
  inline void
  add_internal_minus_external(const double (&Pk)[dim][dim], const double (&fe)[dim], const PN &p, LocalSystem &ls)
  {
    for (unsigned int a = 0; a < p.n; ++a)
      for (unsigned int i = 0; i < dim; ++i)
        {
          double f = -fe[i] * p.N[a];
          for (unsigned int b = 0; b < dim; ++b)
            f += Pk[i][b] * p.G[a][b];
          ls.b[p.local[a] * stride + i] += f;
        }
  }

  /// Displacement block K[a * stride + i, b * stride + k] += sum_jd A_ijkd G_a,j G_b,d,
  /// factorised: AG_a,ikd = sum_j A_ijkd G_a,j once per node a (dim^4 per node),
  /// then sum_d AG_a,ikd G_b,d per node pair (dim^3 instead of 2 dim^4).
  template <int dim, unsigned int stride, class PN>
  inline void
  add_displacement_stiffness(const double (&A)[dim][dim][dim][dim], const PN &p, LocalSystem &ls)
  {
    for (unsigned int a = 0; a < p.n; ++a)
      {
        const auto &Ga = p.G[a];
        double      AG[dim][dim][dim];
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int k = 0; k < dim; ++k)
            for (unsigned int d = 0; d < dim; ++d)
              {
                double s = A[i][0][k][d] * Ga[0];
                for (unsigned int j = 1; j < dim; ++j)
                  s += A[i][j][k][d] * Ga[j];
                AG[i][k][d] = s;
              }
        for (unsigned int i = 0; i < dim; ++i)
          {
            double *row = ls.A + (p.local[a] * stride + i) * ls.stride;
            for (unsigned int b = 0; b < p.n; ++b)
              {
                const auto &Gb  = p.G[b];
                double     *out = row + p.local[b] * stride;
                for (unsigned int k = 0; k < dim; ++k)
                  {
                    double s = AG[i][k][0] * Gb[0];
                    for (unsigned int d = 1; d < dim; ++d)
                      s += AG[i][k][d] * Gb[d];
                    out[k] += s;
                  }
              }
          }
      }
  }

  /// External force of one point on its nodes: (m_p g + scale f_p) N_i, f_p
  /// the traction point force (loads::PointForces; null: none). Dead loads:
  /// neither g nor f_p follows the deformation, so they add no tangent.
  template <int dim>
  inline void
  external_point_force(const double *P, const dealii::Tensor<1, dim> &g, const loads::PointForces<dim> *forces,
                       const double scale, double (&f)[dim])
  {
    const double m       = P[PropertyLayout<dim>::mass];
    double       fp[dim] = {};
    if (forces && forces->any())
      forces->force(P, fp);
    for (unsigned int d = 0; d < dim; ++d)
      f[d] = m * g[d] + scale * fp[d];
  }

  /// Integrand: the nodal external force sum_p N_i (m_p g + scale f_p) (the
  /// force scale of a step's residual test).
  template <int dim>
  struct ExternalForce
  {
    dealii::Tensor<1, dim>         gravity;
    const loads::PointForces<dim> *point_forces = nullptr;
    double                         load_scale   = 1;
    static constexpr bool          matrix = false, vector = true;
    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc >= dim && d_ == dim, "ExternalForce: the displacement components come first");
      double f[dim];
      external_point_force<dim>(P, gravity, point_forces, load_scale, f);
      for (unsigned int a = 0; a < p.n; ++a)
        for (unsigned int i = 0; i < dim; ++i)
          ls.b[p.local[a] * nc + i] += f[i] * p.N[a];
    }
  };

  /// The residual f_int - f_ext of one point and (optionally) its tangent
  /// d(f_int)/d(Du) at the iterate Du (AssembleSystem's field). Loads: body
  /// force m_p g N_i (g already scaled by the load factor) and the traction
  /// point forces times load_scale (external_point_force).
  template <int dim>
  struct UpdatedLagrangianForce
  {
    const std::vector<std::shared_ptr<const materials::Material>> *materials      = nullptr;
    unsigned int                                                   history_offset = 0;
    dealii::Tensor<1, dim>                                         gravity;
    const loads::PointForces<dim>                                 *point_forces = nullptr;
    double                                                         load_scale   = 1;
    bool                                                           tangent      = true;
    PointFailure                                                  *failure      = nullptr;
    /// axisymmetric (2D): the property holding the point's radius r_n; invalid: plane strain / 3D
    unsigned int radius_offset = dealii::numbers::invalid_unsigned_int;
    /// F-bar: the mean det dF of each active cell (CellMeanJacobian, indexed by
    /// the walk's cell index) at the field being assembled; null: no F-bar
    const std::vector<double> *jbar = nullptr;

    static constexpr bool         matrix = true, vector = true, cell_terms = true;
    static constexpr unsigned int max_local = 8 * dim;
    // F-bar, per cell: jbar, sum V_n, and the two factors of the coupling term
    // d r / d ln jbar (x) d ln jbar / d Du (one column and one row over the cell's DoFs)
    mutable double cell_jbar = 1, cell_v = 0, row_factor[max_local], column_factor[max_local];

    void
    begin_cell_terms(const unsigned int c) const
    {
      if (!jbar)
        return;
      cell_jbar = (*jbar)[c];
      cell_v    = 0;
      std::fill(std::begin(row_factor), std::end(row_factor), 0.0);
      std::fill(std::begin(column_factor), std::end(column_factor), 0.0);
    }

    /// F-bar's coupling of all points of a cell through jbar:
    /// K_(a i)(b k) += row_a,i column_b,k / (sum V_n jbar), with
    /// row_a,i = sum_p (d Pk_p / d ln jbar)_ij G_a,j(p) and
    /// column_b,k = sum_q V_n,q j_q Finv_q,dk G_b,d(q) (= sum_q V_n d j_q / d Du_b,k).
    template <int d_, unsigned int nc>
    void
    end_cell_terms(LocalSystem &ls, const unsigned int n_local) const
    {
      if (!jbar || !tangent || cell_v <= 0)
        return;
      const unsigned int m     = n_local * nc;
      const double       scale = 1.0 / (cell_v * cell_jbar);
      for (unsigned int r = 0; r < m; ++r)
        for (unsigned int q = 0; q < m; ++q)
          ls.a(r, q) += row_factor[r] * column_factor[q] * scale;
    }

    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim && d_ == dim, "UpdatedLagrangianForce: a vector space (nc = dim)");
      using L                 = PropertyLayout<dim>;
      const auto          &m  = *(*materials)[static_cast<unsigned int>(P[L::material])];
      const unsigned int   nh = m.n_history();
      double               history_new[64];
      dealii::Tensor<2, 3> dF           = incremental_deformation_gradient<dim>(ls.u, p);
      const bool           axisymmetric = dim == 2 && radius_offset != dealii::numbers::invalid_unsigned_int;
      if (axisymmetric)
        dF[2][2] = hoop_stretch<PN, dim>(ls.u, p, P[radius_offset]);
      // F-bar: the model sees dFbar (det = the cell's jbar); the spatial
      // gradients below keep the point's own dF
      dealii::Tensor<2, 3> dF_bar = dF;
      double               fbar_s = 1, fbar_j = 1;
      if (jbar)
        {
          fbar_j = fbar_det<dim>(dF);
          if (!(fbar_j > 0))
            {
              failure->set("a material point's det dF is not positive (F-bar)");
              return;
            }
          fbar_s = fbar_scale<dim>(dF_bar, fbar_j, cell_jbar);
        }
      materials::Stress    tau;
      dealii::Tensor<4, 3> dtau;
      try
        {
          m.finite_strain_update(dF_bar, dealii::ArrayView<const double>(P + history_offset, nh),
                                 dealii::ArrayView<double>(history_new, nh), tau, tangent ? &dtau : nullptr);
        }
      catch (const std::exception &e) // inverted point, return mapping failed: cut the step
        {
          failure->set(e.what());
          return;
        }
      const double c = P[L::volume] / m.kirchhoff_jacobian(dealii::ArrayView<const double>(P + history_offset, nh));
      const dealii::Tensor<2, 3> Finv = invert(dF);
      if constexpr (dim == 2)
        if (axisymmetric)
          {
            double Pk3[3][3];
            scaled_piola<3>(c, tau, Finv, Pk3);
            double fe[2];
            external_point_force<2>(P, gravity, point_forces, load_scale, fe);
            double A3[3][3][3][3];
            if (tangent)
              scaled_piola_tangent<3>(c, tau, dtau, Finv, A3);
            add_axisymmetric_point<2>(Pk3, tangent ? A3 : nullptr, fe, P[radius_offset], p, ls);
            return;
          }
      double Pk[dim][dim];
      scaled_piola<dim>(c, tau, Finv, Pk);
      double fe[dim];
      external_point_force<dim>(P, gravity, point_forces, load_scale, fe);
      add_internal_minus_external<dim, dim>(Pk, fe, p, ls);
      if (!tangent)
        return;
      double A[dim][dim][dim][dim];
      if (jbar)
        {
          // tau = tau(dFbar), dFbar = s dF (in-plane), s = (jbar / j)^(1/dim):
          // d dFbar_mn / d dF_kd = s (delta_mk delta_nd - Finv_dk dF_mn / dim) at fixed jbar, and
          // d dFbar / d ln jbar = dFbar / dim. T = d tau / d ln jbar = dtau : dFbar / dim.
          const double s = fbar_s;
          double       T[3][3];
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int e = 0; e < 3; ++e)
              {
                double t = 0;
                for (unsigned int mm = 0; mm < dim; ++mm)
                  for (unsigned int n = 0; n < dim; ++n)
                    t += dtau[i][e][mm][n] * dF_bar[mm][n];
                T[i][e] = t / dim;
              }
          dealii::Tensor<4, 3> dtau_local;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int e = 0; e < 3; ++e)
              for (unsigned int k = 0; k < dim; ++k)
                for (unsigned int d = 0; d < dim; ++d)
                  dtau_local[i][e][k][d] = s * dtau[i][e][k][d] - T[i][e] * Finv[d][k];
          scaled_piola_tangent<dim>(c, tau, dtau_local, Finv, A);
          // the cell coupling's factors of this point
          double Q[dim][dim]; // d Pk / d ln jbar = c T Finv^T
          for (unsigned int i = 0; i < dim; ++i)
            for (unsigned int b = 0; b < dim; ++b)
              {
                double q = 0;
                for (unsigned int e = 0; e < 3; ++e)
                  q += T[i][e] * Finv[b][e];
                Q[i][b] = c * q;
              }
          const double vj = P[PropertyLayout<dim>::volume] * fbar_j;
          for (unsigned int a = 0; a < p.n; ++a)
            for (unsigned int i = 0; i < dim; ++i)
              {
                double r = 0, q = 0;
                for (unsigned int b = 0; b < dim; ++b)
                  {
                    r += Q[i][b] * p.G[a][b];
                    q += Finv[b][i] * p.G[a][b];
                  }
                row_factor[p.local[a] * dim + i] += r;
                column_factor[p.local[a] * dim + i] += vj * q;
              }
          cell_v += P[PropertyLayout<dim>::volume];
        }
      else
        scaled_piola_tangent<dim>(c, tau, dtau, Finv, A);
      add_displacement_stiffness<dim, dim>(A, p, ls);
    }
  };

  /// Mixed u-p (seed 001 ch. 5) on a space of dim + 1 components (the
  /// displacement increment Du, then the nodal pressure p = mean Cauchy stress,
  /// tension positive): the residual and the exact tangent of
  ///   R_u,i = sum_p [c_p tau_dev dF^-T + V_n j p_p cof-form] grad_{x_n} N_i - f_ext
  ///         = sum_p V_{n+1} (sigma_dev + p_p I) grad_{x_{n+1}} N_i - f_ext   (Eq. 5.6)
  ///   R_p,i = sum_p V_{n+1} N_i (U'(J) - p_p / K) - S_ij p_j           (Eq. 5.7 / K, 5.16)
  /// with j = det dF, J = J_n j, p_p = N p (the nodal pressure, not the
  /// model's), K U'(J) = p(J) and tau_dev = tau - J p(J) I of any model with
  /// the volumetric/deviatoric split (Material::split_update: split
  /// Neo-Hookean, J2; the plastic history is advanced in the commit, once per
  /// step, from the converged state). The pressure row is divided by K
  /// (Kratos's form: the blocks are of one scale and K_pu = K_up^T at J = 1).
  /// S is the PPP stabilisation (Eqs. 5.14-5.19), over the points of one grid
  /// cell, with w_p = alpha V_n / G_p on the volume at the start of the step:
  ///   S_ij = sum_p w_p (N_i - m_i)(N_j - m_j),  m_i = sum_p V_n N_i / sum_p V_n
  /// i.e. int (alpha/G)(q - q~)(p - p~) with q~, p~ the cell means over the
  /// points (the projection onto P0 of Eq. 5.14); S is symmetric positive
  /// semi-definite and vanishes for a pressure constant in the cell.
  /// docs/implicit.md writes out the linearisation.
  template <int dim>
  struct MixedUpForce
  {
    /// per material id: a model with has_volumetric_split() (checked when read)
    const std::vector<const materials::Material *> *models         = nullptr;
    unsigned int                                    history_offset = 0;
    dealii::Tensor<1, dim>                          gravity;
    const loads::PointForces<dim>                  *point_forces = nullptr;
    double                                          load_scale   = 1;
    double                                          alpha        = 1; ///< stabilisation factor of Eq. 5.15
    bool                                            tangent      = true;
    PointFailure                                   *failure      = nullptr;

    static constexpr bool         matrix = true, vector = true, cell_terms = true;
    static constexpr unsigned int nc = dim + 1, max_local = 64;
    // the cell's sums for the projection onto the cell mean
    mutable double cell_vn[max_local], cell_wn[max_local], cell_w = 0, cell_v = 0;

    void
    begin_cell_terms(const unsigned int) const
    {
      std::fill(std::begin(cell_vn), std::end(cell_vn), 0.0);
      std::fill(std::begin(cell_wn), std::end(cell_wn), 0.0);
      cell_w = cell_v = 0;
    }

    template <int d_, unsigned int nc_, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc_ == dim + 1 && d_ == dim, "MixedUpForce: a space of dim + 1 components");
      using L                       = PropertyLayout<dim>;
      const auto                &m  = *(*models)[static_cast<unsigned int>(P[L::material])];
      const unsigned int         nh = m.n_history();
      double                     history_new[64];
      const dealii::Tensor<2, 3> dF = incremental_deformation_gradient<dim, PN, nc>(ls.u, p);
      materials::Stress          tau_dev;
      dealii::Tensor<4, 3>       dtau;
      double                     J = 1;
      try
        {
          m.split_update(dF, dealii::ArrayView<const double>(P + history_offset, nh),
                         dealii::ArrayView<double>(history_new, nh), tau_dev, J, tangent ? &dtau : nullptr);
        }
      catch (const std::exception &e)
        {
          failure->set(e.what());
          return;
        }
      const double               Vn = P[L::volume];
      const double               c = Vn / m.kirchhoff_jacobian(dealii::ArrayView<const double>(P + history_offset, nh));
      const double               j = determinant(dF);
      const dealii::Tensor<2, 3> Finv = invert(dF);
      double                     pp   = 0;
      for (unsigned int a = 0; a < p.n; ++a)
        pp += p.N[a] * ls.u[p.local[a] * nc + dim];
      const double K = m.split_bulk_modulus(), w = alpha * Vn / m.split_shear_modulus();
      const double Up = m.split_pressure(J) / K, Upp = m.split_dpressure_dJ(J) / K;
      // first Piola form of (sigma_dev + p I) V_{n+1}: Pk_ib
      double Pk[dim][dim];
      scaled_piola<dim>(c, tau_dev, Finv, Pk);
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int b = 0; b < dim; ++b)
          Pk[i][b] += Vn * j * pp * Finv[b][i];
      double fe[dim];
      external_point_force<dim>(P, gravity, point_forces, load_scale, fe);
      add_internal_minus_external<dim, nc>(Pk, fe, p, ls);
      const double rp = Vn * j * (Up - pp / K) - w * pp;
      for (unsigned int a = 0; a < p.n; ++a)
        {
          ls.b[p.local[a] * nc + dim] += p.N[a] * rp;
          cell_vn[p.local[a]] += Vn * p.N[a];
          cell_wn[p.local[a]] += w * p.N[a];
        }
      cell_w += w;
      cell_v += Vn;
      if (!tangent)
        return;
      // d(Pk_ij)/d dF_kd: deviatoric (material + geometric) and pressure parts
      double A[dim][dim][dim][dim];
      scaled_piola_tangent<dim>(c, tau_dev, dtau, Finv, A);
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int jj = 0; jj < dim; ++jj)
          for (unsigned int k = 0; k < dim; ++k)
            for (unsigned int d = 0; d < dim; ++d)
              A[i][jj][k][d] += Vn * pp * j * (Finv[d][k] * Finv[jj][i] - Finv[jj][k] * Finv[d][i]);
      add_displacement_stiffness<dim, nc>(A, p, ls);
      // d R_p / d dF_kd = Vn N_a ((U' + J U'') - p/K) j Finv_dk
      const double vol_coef = Vn * j * ((Up + J * Upp) - pp / K);
      double       gx[PN::capacity][dim]; // grad_{x_{n+1}} N = dF^-T grad_{x_n} N
      for (unsigned int a = 0; a < p.n; ++a)
        for (unsigned int k = 0; k < dim; ++k)
          {
            double s = 0;
            for (unsigned int d = 0; d < dim; ++d)
              s += Finv[d][k] * p.G[a][d];
            gx[a][k] = s;
          }
      for (unsigned int a = 0; a < p.n; ++a)
        for (unsigned int b = 0; b < p.n; ++b)
          {
            const unsigned int ra = p.local[a] * nc, rb = p.local[b] * nc;
            for (unsigned int i = 0; i < dim; ++i)
              {
                ls.a(ra + i, rb + dim) += Vn * j * gx[a][i] * p.N[b];   // K_up
                ls.a(ra + dim, rb + i) += vol_coef * p.N[a] * gx[b][i]; // K_pu
              }
            ls.a(ra + dim, rb + dim) -= (Vn * j / K + w) * p.N[a] * p.N[b]; // K_pp
          }
    }

    /// The cell-mean part of S: -m_a wn_b - wn_a m_b + m_a m_b W.
    template <int d_, unsigned int nc_>
    void
    end_cell_terms(LocalSystem &ls, const unsigned int n_local) const
    {
      if (cell_v <= 0)
        return;
      for (unsigned int a = 0; a < n_local; ++a)
        for (unsigned int b = 0; b < n_local; ++b)
          {
            const double ma = cell_vn[a] / cell_v, mb = cell_vn[b] / cell_v;
            const double S = -ma * cell_wn[b] - cell_wn[a] * mb + ma * mb * cell_w;
            ls.b[a * nc + dim] -= S * ls.u[b * nc + dim];
            if (tangent)
              ls.a(a * nc + dim, b * nc + dim) -= S;
          }
    }
  };

  /// Lumped projection of the point pressure (Eq. 5.20) onto the pressure
  /// component (the last) of a mixed space: sum_p m_p N_i p_p (weighted) or
  /// sum_p m_p N_i; their ratio is the nodal pressure.
  template <int dim>
  struct PressureProjection
  {
    unsigned int          pressure_offset = 0;
    bool                  weighted        = true;
    static constexpr bool matrix = false, vector = true;
    template <int d_, unsigned int nc, class PN>
    inline void
    add(const double *P, const PN &p, LocalSystem &ls) const
    {
      static_assert(nc == dim + 1 && d_ == dim, "PressureProjection: a space of dim + 1 components");
      const double m = P[PropertyLayout<dim>::mass] * (weighted ? P[pressure_offset] : 1.0);
      for (unsigned int a = 0; a < p.n; ++a)
        ls.b[p.local[a] * nc + dim] += m * p.N[a];
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
      static_assert(nc >= dim && d_ == dim, "NodalProjection: the displacement components come first");
      if (offset == dealii::numbers::invalid_unsigned_int)
        add_lumped<dim, nc>(P, p, ls, [](const unsigned int) { return 1.0; });
      else
        add_lumped<dim, nc>(P, p, ls, [P, this](const unsigned int c) { return P[offset + c]; });
    }
  };

  /// The dim components of a space vector with ghost values at the K::n_nodes
  /// nodes of a cell (0 where the cell's slot has no node).
  template <int dim, class K>
  inline void
  gather_cell_vector(const typename K::Cell &cell, const NodalSpace<dim> &space, const Vector &v,
                     double (&out)[K::n_nodes][dim])
  {
    for (unsigned int s = 0; s < K::n_nodes; ++s)
      for (unsigned int k = 0; k < dim; ++k)
        {
          const unsigned int i = cell.dofs[s * dim];
          out[s][k]            = i != dealii::numbers::invalid_unsigned_int ? v(space.node_dof(i, k)) : 0.0;
        }
  }

  /// A point's step dF = I + grad Du from the cell's nodal Du (gather_cell_vector)
  /// and its stencil (slots, gradients).
  template <int dim, unsigned int n>
  inline dealii::Tensor<2, 3>
  stencil_deformation_gradient(const double (*un)[dim], const unsigned int (&slot)[n], const double (&G)[n][dim])
  {
    dealii::Tensor<2, 3> dF;
    for (unsigned int i = 0; i < 3; ++i)
      dF[i][i] = 1.0;
    for (unsigned int w = 0; w < n; ++w)
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = 0; j < dim; ++j)
          dF[i][j] += un[slot[w]][i] * G[w][j];
    return dF;
  }

  /// F-bar's cell means: for every active cell c of the walk, jbar[c] = sum_p
  /// V_n,p j_p / sum_p V_n,p over its points, j_p = det dF_p (in-plane in 2D) of
  /// the field Du (a vector of `space` with ghost values). sum V_n jbar = sum
  /// V_n j: the cell's volume is that of its points' own dF. jbar has one entry
  /// per active cell of the grid (1 where a cell has no point).
  template <int dim, class K>
  struct CellMeanJacobian
  {
    const BackgroundGrid<dim> &grid;
    const NodalSpace<dim>     &space;
    const Vector              &du;
    std::vector<double>       &jbar;

    static constexpr bool prefetch_location = false;
    typename K::Cell      cell{};
    double                un[K::n_nodes][dim]{};
    double                sum_vj = 0, sum_v = 0;

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      gather_cell_vector<dim, K>(cell, space, du, un);
      sum_vj = sum_v = 0;
    }
    inline bool
    point(const unsigned int, PointIterator<dim> &it)
    {
      unsigned int slot[K::n_point_nodes];
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      const dealii::Tensor<2, 3> dF = stencil_deformation_gradient<dim>(un, slot, G);
      const double               V  = it->get_properties()[PropertyLayout<dim>::volume];
      sum_vj += V * fbar_det<dim>(dF);
      sum_v += V;
      return true;
    }
    inline void
    end_cell(const unsigned int c)
    {
      jbar[c] = sum_v > 0 ? sum_vj / sum_v : 1.0;
    }
  };

  /// The convective phase (Algorithm 1 step 3, Eqs. 2.14-2.17): per point
  /// Du_p = N Du, the constitutive update at dF committed (stress = tau / J,
  /// history), V *= det dF; with accelerations (dynamic), a_p^{n+1} = N a^{n+1}
  /// and v_p += h ((1 - gamma) a_p^n + gamma a_p^{n+1}) (Eq. 2.16: integrated,
  /// not interpolated); x_p and u_p += Du_p; points that left their cell are
  /// handed to the set's relocation. Du and a_new: vectors of `space` with
  /// ghost values; a_new null in a static analysis (v_p = 0 then). Mixed u-p
  /// (`pressure_offset` valid; the space's last component is p): the point
  /// pressure p_p = N p (Eq. 5.21) is stored there and replaces the mean of
  /// the point's stress (sigma = dev(tau / J) + p_p I).
  template <int dim, class K>
  struct CommitUpdatedLagrangian
  {
    CommitUpdatedLagrangian(MaterialPointSet<dim> &set, const NodalSpace<dim> &space, const Vector &du,
                            const Vector *a_new, const std::vector<std::shared_ptr<const materials::Material>> &mats,
                            const unsigned int acceleration_offset, const double h, const double gamma,
                            PointFailure      &failure,
                            const unsigned int pressure_offset = dealii::numbers::invalid_unsigned_int,
                            const unsigned int radius_offset   = dealii::numbers::invalid_unsigned_int)
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
        , pressure(pressure_offset)
        , radius(radius_offset)
    {
    }
    MaterialPointSet<dim>                                         &set;
    const BackgroundGrid<dim>                                     &grid;
    const NodalSpace<dim>                                         &space;
    const Vector                                                  &du;
    const Vector                                                  *a_new;
    const std::vector<std::shared_ptr<const materials::Material>> &materials;
    const unsigned int                                             acceleration;
    const double                                                   h, gamma;
    PointFailure                                                  &failure;
    const unsigned int                                             pressure;
    const unsigned int radius; ///< axisymmetric: the property with r_n (invalid: plane / 3D)
    /// F-bar: each active cell's mean det dF of the converged Du (CellMeanJacobian); null: none.
    /// The model is updated with dFbar and V *= det dFbar = jbar (the cell keeps its volume).
    const std::vector<double> *jbar = nullptr;

    static constexpr bool prefetch_location = true;
    typename K::Cell      cell;
    double                un[K::n_nodes][dim], an[K::n_nodes][dim], pn[K::n_nodes];

    inline void
    begin_cell(const unsigned int c)
    {
      cell = K::cell(grid, c);
      gather_cell_vector<dim, K>(cell, space, du, un);
      if (a_new)
        gather_cell_vector<dim, K>(cell, space, *a_new, an);
      else
        std::fill(&an[0][0], &an[0][0] + K::n_nodes * dim, 0.0);
      for (unsigned int s = 0; s < K::n_nodes; ++s)
        {
          const unsigned int i = cell.dofs[s * dim];
          pn[s] = i != dealii::numbers::invalid_unsigned_int && pressure != dealii::numbers::invalid_unsigned_int
                    ? du(space.node_dof(i, dim))
                    : 0.0;
        }
    }
    inline bool
    point(const unsigned int c, PointIterator<dim> &it)
    {
      using L        = PropertyLayout<dim>;
      double      *P = it->get_properties().data();
      unsigned int slot[K::n_point_nodes];
      double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
      K::point_stencil(cell, it->get_reference_location(), slot, N, G);
      double dx[dim] = {}, ap[dim] = {}, pp = 0;
      for (unsigned int w = 0; w < K::n_point_nodes; ++w)
        for (unsigned int i = 0; i < dim; ++i)
          {
            dx[i] += N[w] * un[slot[w]][i];
            ap[i] += N[w] * an[slot[w]][i];
            if (i == 0)
              pp += N[w] * pn[slot[w]];
          }
      dealii::Tensor<2, 3> dF = stencil_deformation_gradient<dim>(un, slot, G);
      if (dim == 2 && radius != dealii::numbers::invalid_unsigned_int)
        dF[2][2] = 1.0 + dx[0] / P[radius]; // the hoop stretch r_{n+1} / r_n
      if (jbar)
        {
          const double j = fbar_det<dim>(dF);
          if (!(j > 0))
            {
              failure.set("a material point's det dF is not positive (F-bar)");
              return true;
            }
          fbar_scale<dim>(dF, j, (*jbar)[c]);
        }
      const auto        &m  = *materials[static_cast<unsigned int>(P[L::material])];
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
      materials::Stress sigma = tau / m.kirchhoff_jacobian(dealii::ArrayView<const double>(P + L::history, nh));
      if (pressure != dealii::numbers::invalid_unsigned_int)
        {
          sigma       = dealii::deviator(sigma) + pp * dealii::unit_symmetric_tensor<3>();
          P[pressure] = pp;
        }
      L::set_stress(sigma, P);
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
    {
    }
  };
} // namespace talus::transfer
