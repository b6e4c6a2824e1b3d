// Shared helpers for the finite-strain material tests (header only; not a test).
#pragma once

#include <talus/materials/material.h>

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <cmath>
#include <vector>

namespace talus_test
{
  using namespace talus::materials;
  using T2 = dealii::Tensor<2, 3>;
  using T4 = dealii::Tensor<4, 3>;

  inline T2
  identity2()
  {
    T2 I;
    for (unsigned int i = 0; i < 3; ++i)
      I[i][i] = 1.0;
    return I;
  }

  inline T2
  diag(const double a, const double b, const double c)
  {
    T2 F;
    F[0][0] = a;
    F[1][1] = b;
    F[2][2] = c;
    return F;
  }

  /// Rotation by angle t about the (normalised) axis (x, y, z), Rodrigues.
  inline T2
  rotation(const double x, const double y, const double z, const double t)
  {
    const double n    = std::sqrt(x * x + y * y + z * z);
    const double a[3] = {x / n, y / n, z / n};
    T2           K;
    K[0][1] = -a[2];
    K[0][2] = a[1];
    K[1][0] = a[2];
    K[1][2] = -a[0];
    K[2][0] = -a[1];
    K[2][1] = a[0];
    return identity2() + std::sin(t) * K + (1 - std::cos(t)) * K * K;
  }

  struct Step
  {
    Stress              tau;
    std::vector<double> hist;
    T4                  tangent;
  };

  inline Step
  step(const Material &m, const T2 &dF, const std::vector<double> &h_old, const bool tangent = true)
  {
    Step s;
    s.hist.resize(h_old.size());
    m.finite_strain_update(dF, dealii::ArrayView<const double>(h_old.data(), h_old.size()),
                           dealii::ArrayView<double>(s.hist.data(), s.hist.size()), s.tau,
                           tangent ? &s.tangent : nullptr);
    return s;
  }

  /// Central finite difference of tau w.r.t. dF.
  inline T4
  fd_tangent(const Material &m, const T2 &dF, const std::vector<double> &h_old, const double h = 1e-6)
  {
    T4 r;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int l = 0; l < 3; ++l)
        {
          T2 p = dF, q = dF;
          p[k][l] += h;
          q[k][l] -= h;
          const Stress tp = step(m, p, h_old, false).tau;
          const Stress tq = step(m, q, h_old, false).tau;
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
              r[i][j][k][l] = (tp[i][j] - tq[i][j]) / (2 * h);
        }
    return r;
  }

  inline double
  norm4(const T4 &t)
  {
    double s = 0;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int l = 0; l < 3; ++l)
            s += t[i][j][k][l] * t[i][j][k][l];
    return std::sqrt(s);
  }

  /// || analytic - FD ||_F / max(|| FD ||_F, floor).
  inline double
  tangent_error(const Material &m, const T2 &dF, const std::vector<double> &h_old, const double floor = 0.0,
                const double h = 1e-6)
  {
    const T4 a  = step(m, dF, h_old, true).tangent;
    const T4 fd = fd_tangent(m, dF, h_old, h);
    return norm4(a - fd) / std::max(norm4(fd), floor);
  }

  inline std::vector<double>
  init_history(const Material &m, const Stress &sigma = Stress())
  {
    std::vector<double> h(m.n_history(), 0.0);
    m.initialize_history(sigma, dealii::ArrayView<double>(h.data(), h.size()));
    return h;
  }

  inline Stress
  rotate(const Stress &s, const T2 &Q)
  {
    return dealii::symmetrize(Q * T2(s) * dealii::transpose(Q));
  }
} // namespace talus_test
