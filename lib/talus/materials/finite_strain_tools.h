// talus — kinematic helpers shared by the finite-strain (hyperelastic-based)
// models: storage of symmetric tensors in the history, the spectral
// decomposition of the elastic left Cauchy-Green tensor, the derivative of an
// isotropic tensor function of b (robust at repeated eigenvalues) and the chain
// rules that turn it into the consistent tangent d tau / d dF required by
// Material::finite_strain_update().
//
// Internal to talus_materials. Tension positive.
#pragma once

#include <deal.II/base/array_view.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

namespace talus::materials::fs
{
  using Tensor2 = dealii::Tensor<2, 3>;
  using Tensor4 = dealii::Tensor<4, 3>;
  using Sym2    = dealii::SymmetricTensor<2, 3>;

  /// Six history values (xx, yy, zz, xy, yz, xz) starting at `offset`.
  Sym2 load_sym(const dealii::ArrayView<const double> &h, const unsigned int offset);
  void store_sym(const Sym2 &t, const dealii::ArrayView<double> &h, const unsigned int offset);

  /// Eigen-decomposition of a symmetric 3x3 tensor, eigenvalues sorted in
  /// descending order: x[0] >= x[1] >= x[2]; e[A] are orthonormal.
  struct Spectral
  {
    double               x[3];
    dealii::Tensor<1, 3> e[3];
  };
  Spectral spectral_decomposition(const Sym2 &b);

  /// Y = sum_A y_A e_A (x) e_A.
  Sym2 assemble(const Spectral &s, const double y[3]);

  /// Derivative dY/dX of the isotropic tensor function Y(X) = sum_A y_A(x) e_A(x) e_A
  /// given the principal values x_A of X, y_A and dydx[A][B] = d y_A / d x_B.
  /// Result: full 4th-order tensor D_ijkl = dY_ij/dX_kl, symmetrised in (k,l).
  ///
  /// Spin part: the eigenvector rotation contributes theta_AB = (y_A - y_B)/(x_A - x_B)
  /// for every ordered pair A != B. When |x_A - x_B| <= rel_tol * max|x| the
  /// quotient is replaced by its analytic limit for symmetric functions of the
  /// eigenvalues, 1/2 [ (dy_A/dx_A - dy_A/dx_B) + (dy_B/dx_B - dy_B/dx_A) ],
  /// so the tangent is continuous at coincident eigenvalues (error O(rel_tol)).
  Tensor4 isotropic_derivative(const Spectral &s, const double y[3], const double dydx[3][3],
                               const double rel_tol = 1e-8);

  /// For X = dF B dF^T (B fixed, symmetric) and D = dY/dX (symmetric in k,l):
  /// dY_ij / d dF_kl = 2 sum_n D_ijkn (dF B)_nl.
  Tensor4 chain_trial_b(const Tensor4 &D, const Tensor2 &dF, const Sym2 &B);

  /// Convert a spatial (Lie-derivative) tangent c, L_v tau = c : d, of the
  /// Kirchhoff stress tau into d tau / d dF for a step with increment dF:
  /// dtau_ij/ddF_kl = c_ijkn dF^-1_ln + delta_ik (dF^-1 tau)_lj + delta_jk (tau dF^-T)_il.
  Tensor4 lie_tangent_to_dF(const Tensor4 &c, const Sym2 &tau, const Tensor2 &dF);

  /// Cauchy stress tau / J.
  inline Sym2
  kirchhoff_to_cauchy(const Sym2 &tau, const double J)
  {
    return tau / J;
  }

  /// dF = I + d_eps + d_omega: the incremental deformation gradient used by the
  /// rate-form update_stress() of the finite-strain models.
  Tensor2 incremental_deformation_gradient(const Sym2 &d_eps, const Tensor2 &d_omega);
} // namespace talus::materials::fs
