#include <talus/materials/finite_strain_tools.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace talus::materials::fs
{
  Sym2
  load_sym(const dealii::ArrayView<const double> &h, const unsigned int o)
  {
    Sym2 t;
    t[0][0] = h[o + 0];
    t[1][1] = h[o + 1];
    t[2][2] = h[o + 2];
    t[0][1] = h[o + 3];
    t[1][2] = h[o + 4];
    t[0][2] = h[o + 5];
    return t;
  }

  void
  store_sym(const Sym2 &t, const dealii::ArrayView<double> &h, const unsigned int o)
  {
    h[o + 0] = t[0][0];
    h[o + 1] = t[1][1];
    h[o + 2] = t[2][2];
    h[o + 3] = t[0][1];
    h[o + 4] = t[1][2];
    h[o + 5] = t[0][2];
  }

  Spectral
  spectral_decomposition(const Sym2 &b)
  {
    Eigen::Matrix3d m;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        m(i, j) = b[i][j];
    // QL iteration (not the closed-form solver): accurate eigenvectors also for
    // nearly repeated eigenvalues.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
    Spectral                                       s;
    // Eigen sorts ascending; we want descending.
    for (unsigned int A = 0; A < 3; ++A)
      {
        s.x[A] = es.eigenvalues()(2 - A);
        for (unsigned int i = 0; i < 3; ++i)
          s.e[A][i] = es.eigenvectors()(i, 2 - A);
      }
    return s;
  }

  Sym2
  assemble(const Spectral &s, const double y[3])
  {
    Sym2 r;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = i; j < 3; ++j)
        r[i][j] = y[0] * s.e[0][i] * s.e[0][j] + y[1] * s.e[1][i] * s.e[1][j] + y[2] * s.e[2][i] * s.e[2][j];
    return r;
  }

  Tensor4
  isotropic_derivative(const Spectral &s, const double y[3], const double dydx[3][3], const double rel_tol)
  {
    // M_A = e_A e_A^T, S_AB = sym(e_A e_B^T)
    double M[3][3][3];
    for (unsigned int A = 0; A < 3; ++A)
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = 0; j < 3; ++j)
          M[A][i][j] = s.e[A][i] * s.e[A][j];
    static const unsigned int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    double                    S[3][3][3];
    double                    theta2[3];
    const double              scale = std::max({std::abs(s.x[0]), std::abs(s.x[1]), std::abs(s.x[2])});
    for (unsigned int p = 0; p < 3; ++p)
      {
        const unsigned int A = pairs[p][0], B = pairs[p][1];
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            S[p][i][j] = 0.5 * (s.e[A][i] * s.e[B][j] + s.e[B][i] * s.e[A][j]);
        const double dx = s.x[A] - s.x[B];
        double       th;
        if (std::abs(dx) <= rel_tol * scale)
          th = 0.5 * ((dydx[A][A] - dydx[A][B]) + (dydx[B][B] - dydx[B][A]));
        else
          th = (y[A] - y[B]) / dx;
        theta2[p] = 2.0 * th;
      }
    Tensor4 D;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              double v = 0;
              for (unsigned int A = 0; A < 3; ++A)
                {
                  const double mij = M[A][i][j];
                  if (mij != 0.0)
                    for (unsigned int B = 0; B < 3; ++B)
                      v += dydx[A][B] * mij * M[B][k][l];
                }
              for (unsigned int p = 0; p < 3; ++p)
                v += theta2[p] * S[p][i][j] * S[p][k][l];
              D[i][j][k][l] = v;
            }
    return D;
  }

  Tensor4
  chain_trial_b(const Tensor4 &D, const Tensor2 &dF, const Sym2 &B)
  {
    const Tensor2 G = dF * Tensor2(B);
    Tensor4       r;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            r[i][j][k][l] = 2.0 * (D[i][j][k][0] * G[0][l] + D[i][j][k][1] * G[1][l] + D[i][j][k][2] * G[2][l]);
    return r;
  }

  Tensor4
  lie_tangent_to_dF(const Tensor4 &c, const Sym2 &tau, const Tensor2 &dF)
  {
    const Tensor2 Fi  = invert(dF);
    const Tensor2 T   = tau;
    const Tensor2 FiT = Fi * T;            // (dF^-1 tau)_lj
    const Tensor2 TFt = T * transpose(Fi); // (tau dF^-T)_il
    Tensor4       r;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            {
              double v = c[i][j][k][0] * Fi[l][0] + c[i][j][k][1] * Fi[l][1] + c[i][j][k][2] * Fi[l][2];
              if (i == k)
                v += FiT[l][j];
              if (j == k)
                v += TFt[i][l];
              r[i][j][k][l] = v;
            }
    return r;
  }

  Tensor2
  incremental_deformation_gradient(const Sym2 &d_eps, const Tensor2 &d_omega)
  {
    Tensor2 f = Tensor2(d_eps) + d_omega;
    for (unsigned int i = 0; i < 3; ++i)
      f[i][i] += 1.0;
    return f;
  }
} // namespace talus::materials::fs
