// talus — traction point forces, the solver-independent part of surface loads
// (seed 000 Eqs. 4.28-4.29, 5.1-5.3; seed 001 §4.4 f_ext): which boundary
// material points of a body face or a region carry which traction slot and
// their share of the loaded area, the time factors of the tractions, and the
// force of one point f_p = sum_j factor_j(t) t_j A_p. A family scatters
// f_i += sum_p N_i(x_p) f_p in its own pass (explicit: loads::LoadControl,
// implicit: the residual integrand of talus-implicit).
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/loads/settings.h>
#include <talus/particles/material_point_set.h>
#include <talus/particles/material_points.h>

#include <mpi.h>

#include <limits>
#include <vector>

namespace talus::loads
{
  template <int dim>
  class PointForces
  {
  public:
    /// Add `n_slots` blocks of dim doubles (point_force_j) to the layout;
    /// before the ParticleHandler is initialised.
    void extend_layout(PropertyLayout<dim> &layout, const unsigned int n_slots);
    unsigned int
    n_slots() const
    {
      return slots;
    }
    /// Offset of the first block (slot j at + j dim).
    unsigned int
    offset() const
    {
      return force_offset;
    }

    /// Select the points of every traction by their initial position X = x - u
    /// (the outermost layer of a box body on the face, or the points in a
    /// region), give each its area share A_p (V_p / the sub-cell spacing normal
    /// to the face; for a body face normalised to the box face, so the total is
    /// exactly traction x area) and store t_j A_p in slot j; other slots 0.
    /// A traction on a grid boundary id (nodal forces) selects no point: its
    /// slot stays 0. A point load (Target::point) puts its whole force on the
    /// one point nearest its position (assign_point_load); a point that
    /// carries exactly that force in its slot already keeps it, so a later
    /// stage or a restart does not move the load to another point.
    /// Logs one line per traction; a traction selecting no point is an
    /// InputError. Collective.
    void assign(const std::vector<Traction<dim>> &tractions, MaterialPointSet<dim> &points,
                const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies, MPI_Comm comm);

    /// Time factors: traction j < n_global at the absolute time t, the others
    /// at the stage time t - stage_t0.
    void update_factors(const std::vector<Traction<dim>> &tractions, const unsigned int n_global, const double t,
                        const double stage_t0);

    /// Time factors given by the caller, one per slot (a family that keeps the
    /// tractions of every stage in slots of their own and sets the others to 0).
    void
    set_factors(std::vector<double> f)
    {
      factor = std::move(f);
    }

    /// A restart within a stage: the points' force slots come from the checkpoint
    /// (what assign() gave at the stage's start); only the switch is set again.
    void
    resume(const std::vector<Traction<dim>> &tractions)
    {
      have_tractions = !tractions.empty();
    }
    /// Whether the tractions of the last assign() were not empty.
    bool
    any() const
    {
      return have_tractions;
    }
    const std::vector<double> &
    factors() const
    {
      return factor;
    }

    /// f_p at the time of the last update_factors (0 without tractions).
    void
    force(const double *P, double (&f)[dim]) const
    {
      for (unsigned int d = 0; d < dim; ++d)
        f[d] = 0;
      if (!have_tractions)
        return;
      for (unsigned int j = 0; j < factor.size(); ++j)
        for (unsigned int d = 0; d < dim; ++d)
          f[d] += factor[j] * P[force_offset + j * dim + d];
    }
    /// The same sum over the non-zero entries only; returns whether the point
    /// carries any (the scatter skips unloaded points).
    bool
    force_if_loaded(const double *P, double (&f)[dim]) const
    {
      bool any_entry = false;
      for (unsigned int d = 0; d < dim; ++d)
        f[d] = 0;
      for (unsigned int j = 0; j < factor.size(); ++j)
        for (unsigned int d = 0; d < dim; ++d)
          if (P[force_offset + j * dim + d] != 0.0)
            {
              f[d] += factor[j] * P[force_offset + j * dim + d];
              any_entry = true;
            }
      return any_entry;
    }

  private:
    static constexpr dealii::types::particle_index invalid_particle =
      std::numeric_limits<dealii::types::particle_index>::max();
    /// The particle id of the one point of all ranks that carries point load
    /// `t` in slot j already (a later stage, a restart), else invalid_particle.
    /// Collective.
    dealii::types::particle_index carrier(const Traction<dim> &t, unsigned int j, const MaterialPointSet<dim> &points,
                                          MPI_Comm comm) const;
    /// Point load `t` into slot j of one point: `kept`, or the point of its body
    /// (any body) nearest its position by initial position, ties to the smaller
    /// initial position (x, then y, then z), then to the smaller particle id,
    /// over all ranks; logs the choice. Collective.
    void assign_point_load(const Traction<dim> &t, unsigned int j, dealii::types::particle_index kept,
                           MaterialPointSet<dim> &points, MPI_Comm comm);

    unsigned int        slots = 0, force_offset = 0;
    bool                have_tractions = false;
    std::vector<double> factor; ///< time factors of the tractions at t
  };
} // namespace talus::loads
