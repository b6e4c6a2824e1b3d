// talus — return mapping onto a set of planar yield surfaces in principal stress
// space (shared by Tresca and Mohr-Coulomb with tension cut-off).
//
// With isotropic linear elasticity and perfectly plastic yield and potential
// functions that are linear in the principal stresses, the implicit (backward
// Euler) return is exact: for an active set A the plastic multipliers solve the
// small linear system
//     sum_{k in A} (a_j . D b_k) dgamma_k = f_j(sigma_trial),   j in A,
// and sigma = sigma_trial - sum_k dgamma_k D b_k. The active set is the smallest
// one whose multipliers are non-negative and whose returned stress violates no
// surface (all faces first, then edges, then corners). This treats faces, edges
// and apexes of the yield surface in one piece of code.
// Internal to talus_materials; tension positive.
#pragma once

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <array>

namespace talus::materials::internal
{
  using Vec3 = std::array<double, 3>;

  /// f(sigma) = a . sigma - k <= 0 with plastic flow direction b (dF/dsigma of
  /// the potential), all in principal stress space.
  struct PlanarSurface
  {
    Vec3   a;
    double k;
    Vec3   b;
  };

  struct PrincipalReturnResult
  {
    bool         converged = false; ///< false: no admissible active set found
    Vec3         sigma{};           ///< returned principal stresses
    Vec3         dep{};             ///< plastic strain increment (principal)
    unsigned int active_mask = 0;   ///< bit k set: candidate surface k active
    unsigned int n_active    = 0;
  };

  /// Return the trial principal stresses onto the candidate surfaces. `check`
  /// surfaces are only tested for admissibility (they include the candidates).
  /// lambda, G: Lame constants. tol: absolute tolerance on f [Pa].
  PrincipalReturnResult return_to_planar_surfaces(const Vec3 &trial, const double lambda, const double G,
                                                  const PlanarSurface *candidates, const unsigned int n_candidates,
                                                  const PlanarSurface *check, const unsigned int n_check,
                                                  const double tol);

  /// Spectral decomposition, eigenvalues in descending order.
  struct Spectral
  {
    Vec3                                values;
    std::array<dealii::Tensor<1, 3>, 3> vectors;
  };
  Spectral spectral_decomposition(const dealii::SymmetricTensor<2, 3> &s);

  /// sum_i v_i n_i (x) n_i
  dealii::SymmetricTensor<2, 3> compose(const Vec3 &v, const Spectral &sd);

  /// Largest and smallest eigenvalue of a symmetric 3x3 tensor (closed form, cheap),
  /// used for the elastic pre-check.
  Vec3 principal_values(const dealii::SymmetricTensor<2, 3> &s);
} // namespace talus::materials::internal
