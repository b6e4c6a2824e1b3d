// talus — the material point diagnostics every family reports: mass, momentum,
// kinetic energy, strain energy, gravity potential and the mass moment (for a
// centre of mass), summed over the points of a rank and then over all ranks in
// one reduction; and the search for a point holding a non-finite value, named
// with its id, position and field.
//
// PointSums::add is inline: the explicit update passes call it for every point
// while they update it (no second walk over the points). sum_points walks a
// MaterialPointSet for the same sums at any other time.
#pragma once

#include <deal.II/base/mpi.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace talus
{
  template <int dim>
  class MaterialPointSet;
  namespace materials
  {
    class Material;
  }
} // namespace talus

namespace talus::diagnostics
{
  /// Sums of point quantities. A point may carry a second phase (the pore
  /// liquid of a two-phase point): its mass and velocity enter the momentum,
  /// the kinetic energy and the gravity potential; its mass is summed apart.
  template <int dim>
  struct PointSums
  {
    double mass              = 0;  ///< sum m_p (the first phase)
    double second_mass       = 0;  ///< sum m_L,p (the second phase; 0 for one-phase points)
    double momentum[dim]     = {}; ///< sum m_p v_p + m_L,p v_L,p
    double mass_moment[dim]  = {}; ///< sum (m_p + m_L,p) x_p
    double kinetic           = 0;  ///< sum 1/2 m_p |v_p|^2 + 1/2 m_L,p |v_L,p|^2
    double strain            = 0;  ///< sum of what add_strain received
    double gravity_potential = 0;  ///< -sum (m_p + m_L,p) g . x_p
    double n_points          = 0;

    /// A one-phase point: mass m, velocity v (dim values), position x, under
    /// gravity g. Returns |v|^2 (for the caller's finiteness check).
    double
    add(const double m, const double *v, const dealii::Point<dim> &x, const dealii::Tensor<1, dim> &g)
    {
      double v2 = 0, gx = 0;
      for (unsigned int d = 0; d < dim; ++d)
        {
          v2 += v[d] * v[d];
          gx += g[d] * x[d];
        }
      mass += m;
      kinetic += 0.5 * m * v2;
      for (unsigned int d = 0; d < dim; ++d)
        {
          momentum[d] += m * v[d];
          mass_moment[d] += m * x[d];
        }
      gravity_potential -= m * gx;
      n_points += 1;
      return v2;
    }

    /// A point carrying a second phase: mass mL with velocity vL besides m, v.
    /// Returns |v|^2 (of the first phase).
    double
    add(const double m, const double *v, const double mL, const double *vL, const dealii::Point<dim> &x,
        const dealii::Tensor<1, dim> &g)
    {
      double v2 = 0, vl2 = 0, gx = 0;
      for (unsigned int d = 0; d < dim; ++d)
        {
          v2 += v[d] * v[d];
          vl2 += vL[d] * vL[d];
          gx += g[d] * x[d];
        }
      mass += m;
      second_mass += mL;
      kinetic += 0.5 * m * v2 + 0.5 * mL * vl2;
      for (unsigned int d = 0; d < dim; ++d)
        {
          momentum[d] += m * v[d] + mL * vL[d];
          mass_moment[d] += (m + mL) * x[d];
        }
      gravity_potential -= (m + mL) * gx;
      n_points += 1;
      return v2;
    }

    /// Strain energy of a point (V_p times its energy density, computed by the caller).
    void
    add_strain(const double e)
    {
      strain += e;
    }

    /// Replace every field by its sum over the ranks of comm (one reduction).
    void sum_over_ranks(MPI_Comm comm);

    dealii::Tensor<1, dim>
    total_momentum() const
    {
      dealii::Tensor<1, dim> p;
      for (unsigned int d = 0; d < dim; ++d)
        p[d] = momentum[d];
      return p;
    }
  };

  /// sum_over_ranks of several sums (of several point sets) in one reduction.
  template <int dim>
  void sum_over_ranks(const std::vector<PointSums<dim> *> &sums, MPI_Comm comm);

  /// What sum_points adds for each point besides mass, velocity and position.
  template <int dim>
  struct SumOptions
  {
    /// for the gravity potential (zero: none)
    dealii::Tensor<1, dim> gravity;
    /// the position is the location plus the displacement (points kept at their
    /// Gauss points: the FEM)
    bool add_displacement = false;
    /// strain energy V_p psi(sigma_p) with the point's material (by material id);
    /// null: no strain energy
    const std::vector<std::shared_ptr<const materials::Material>> *materials = nullptr;
    /// the second phase of a point with properties P: its mass (0: none) and,
    /// through the pointer, its velocity (dim values); empty: one-phase points
    std::function<double(const double *P, const double *&velocity)> second_phase;
    /// strain energy a point stores besides the elastic one (e.g. that of its
    /// pore pressure), added after it; empty: none
    std::function<double(const double *P)> extra_strain;
  };

  /// The sums over the locally owned points of `set`, in storage order (not
  /// reduced: call sum_over_ranks).
  template <int dim>
  PointSums<dim> sum_points(const MaterialPointSet<dim> &set, const SumOptions<dim> &options = {});

  /// The first point holding a non-finite value among its first `n_checked`
  /// properties (all when larger than their count) or in its location, or
  /// (with `positive_volume`) a volume that is not positive, on the lowest rank
  /// that has one, described as "point 17 of 'soil' at (0.1, 2.5): stress_xx =
  /// nan"; empty when every point is valid. Collective.
  template <int dim>
  std::string find_invalid_point(const MaterialPointSet<dim> &set, MPI_Comm comm, unsigned int n_checked = ~0u,
                                 bool positive_volume = true);
} // namespace talus::diagnostics
