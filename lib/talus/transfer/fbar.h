// talus — the F-bar of seed 002 §4.4.2 (Eqs. 79-83), shared by the explicit
// and semi-implicit families (numerics/volumetric stabilisation): a point's volume increment dJ from
// the nodal velocity on its stencil, the stabilised increment its model sees,
// the modified F-bar's b_e scaling and its fixed patch tiling. Kernel-agnostic:
// the stencil is transfer::PointStencil<dim, K> of any shape policy. The node
// map-remap of dJ is a walk of each family (its nodal vectors and fused sums:
// Solver::volume_averages in both), made of volume_increment and
// PointStencil::scatter / value.
#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace talus::transfer
{
  /// 'numerics/volumetric stabilisation' of every family (declared with the
  /// shared scene, formulations/common/scene_parameters.cc); each family refuses
  /// what it does not implement, naming the entry.
  enum class VolumetricStabilisation
  {
    none,          ///< the increment dF as it is
    f_bar,         ///< dF scaled by (smoothed dJ / dJ)^(1/dim) (seed 002 Eqs. 79-80; implicit: cell mean)
    modified_f_bar ///< and b_e^t by (patch mean J^e / J^e)^(2/3) (Eqs. 81-83; semi-implicit only)
  };

  /// The increment dF = I + h grad v of a point (grad v of the nodal velocity
  /// on its stencil, gv[i][j] = d v_i / d x_j; plane strain in 2D: dF_33 = 1).
  template <int dim>
  inline dealii::Tensor<2, 3>
  increment_tensor(const double (&gv)[dim][dim], const double h)
  {
    dealii::Tensor<2, 3> dF;
    for (unsigned int i = 0; i < 3; ++i)
      dF[i][i] = 1;
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int j = 0; j < dim; ++j)
        dF[i][j] += h * gv[i][j];
    return dF;
  }

  /// det(I + g) - 1 of a displacement-gradient increment g (in 2D the in-plane
  /// block) as the sum of g's invariants: no cancellation against the 1. The
  /// rate-form F-bar (explicit family) works with dJ - 1, because a stiff body at
  /// rest has |g| ~ 1e-9, where det(I + g) - 1 keeps only ~7 digits and the
  /// stress E (dJbar - dJ) takes that round-off (1 vs 2 ranks differed by 1e-9
  /// of the stress in a contact scene before this).
  template <int dim>
  inline double
  volume_increment_minus_one(const double (&g)[dim][dim])
  {
    if constexpr (dim == 2)
      return g[0][0] + g[1][1] + (g[0][0] * g[1][1] - g[0][1] * g[1][0]);
    else
      {
        const double minors = g[0][0] * g[1][1] - g[0][1] * g[1][0] + g[0][0] * g[2][2] - g[0][2] * g[2][0] +
                              g[1][1] * g[2][2] - g[1][2] * g[2][1];
        const double det = g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1]) -
                           g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0]) +
                           g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]);
        return g[0][0] + g[1][1] + g[2][2] + minors + det;
      }
  }

  /// The rate-form Eq. 79: dF-bar - I of a displacement-gradient increment g,
  /// given e = dJ - 1 and e_bar = dJbar - 1: (a - 1) I + a g with a = ((1 +
  /// e_bar) / (1 + e))^(1/dim), a - 1 by log1p / expm1 (exact digits for small
  /// e, e_bar; the same value as stabilised_increment(I + g, 1 + e_bar) - I).
  template <int dim>
  inline void
  stabilised_gradient_increment(const double (&g)[dim][dim], const double e, const double e_bar,
                                double (&g_bar)[dim][dim])
  {
    const double a_minus_one = std::expm1((std::log1p(e_bar) - std::log1p(e)) / dim);
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int j = 0; j < dim; ++j)
        g_bar[i][j] = (1 + a_minus_one) * g[i][j] + (i == j ? a_minus_one : 0.0);
  }

  /// dF-bar = (dJbar / dJ)^(1/dim) dF (Eq. 79; in 2D the in-plane block, the
  /// paper's dof = 2): the increment a soil point's model sees with either F-bar.
  template <int dim>
  inline dealii::Tensor<2, 3>
  stabilised_increment(const dealii::Tensor<2, 3> &dF, const double dJ_bar)
  {
    const double         a = std::pow(dJ_bar / dealii::determinant(dF), 1.0 / dim);
    dealii::Tensor<2, 3> f = dF;
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int j = 0; j < dim; ++j)
        f[i][j] *= a;
    return f;
  }

  /// The modified F-bar's b_e-bar = (Jebar / J^e)^(2/3) b_e (Eq. 82), on the six
  /// stored components of a symmetric b_e (xx, yy, zz, xy, yz, xz): afterwards
  /// sqrt(det b_e) = Jebar. It goes into the history, not into the increment:
  /// folding it into the increment would also multiply the model's own total J
  /// by the ratio every step, and those factors pile up (docs/semi-implicit.md,
  /// 'The modified F-bar and the point's J').
  inline void
  scale_elastic_b(double *b_sym, const double elastic_ratio)
  {
    const double c = std::cbrt(elastic_ratio * elastic_ratio);
    for (unsigned int k = 0; k < 6; ++k)
      b_sym[k] *= c;
  }

  /// The modified F-bar patches: a fixed tiling of the grid box by squares
  /// (cubes) of side `patch_size` cells from its lower corner ("defined only
  /// once", §3.3). The last patch of a direction is cut by the grid's upper
  /// face; a position outside the box is counted in the nearest patch.
  template <int dim>
  struct PatchTiling
  {
    dealii::Point<dim>            lower;
    dealii::Tensor<1, dim>        side;
    std::array<unsigned int, dim> count{};

    void
    reinit(const dealii::Point<dim> &grid_lower, const dealii::Point<dim> &grid_upper,
           const std::vector<unsigned int> &cells, const double patch_size)
    {
      lower = grid_lower;
      for (unsigned int d = 0; d < dim; ++d)
        {
          side[d]  = patch_size * (grid_upper[d] - grid_lower[d]) / cells[d];
          count[d] = static_cast<unsigned int>(std::ceil(cells[d] / patch_size - 1e-9));
        }
    }
    unsigned int
    size() const
    {
      unsigned int n = 1;
      for (unsigned int d = 0; d < dim; ++d)
        n *= count[d];
      return n;
    }
    /// the patch of a position, x fastest
    unsigned int
    index(const dealii::Point<dim> &x) const
    {
      unsigned int k = 0;
      for (int d = dim - 1; d >= 0; --d)
        {
          const double r = std::floor((x[d] - lower[d]) / side[d]);
          k              = k * count[d] + static_cast<unsigned int>(std::clamp(r, 0.0, double(count[d] - 1)));
        }
      return k;
    }
  };
} // namespace talus::transfer
