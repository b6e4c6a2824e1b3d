// talus — FEM on the same grid from the same explicit time loop
// (`numerics/integration = fem | ul-fem`; Anura3D's FEM / UL-FEM modes).
//
// The integration points are the 2^dim Gauss points of every cell covered by a
// body (volume = JxW, mass = density x JxW), stored as material points of the
// ParticleHandler, so the solver's nodal solve, G2P/P2G of velocities and
// momentum, loads, damping, convergence, output and checkpoints are the MPM
// code. Only the update pass differs (one branch per step in Solver::step):
//
//  * fem:    small strain on the fixed mesh. Points never move and keep their
//            cell and reference coordinates; the displacement accumulates
//            u_p += sum_i N_i du_i; strains from the gradients of the fixed
//            cell; no spin (no Jaumann rotation); volumes stay JxW.
//  * ul-fem: the mesh follows the material. Nodal coordinates x_i += du_i;
//            strains and spins from the gradients of the current (deformed)
//            cell, evaluated isoparametrically (general Q1 map, not the
//            box-cell kernel); points keep their reference coordinates and
//            cell, x_p = sum_i N_i(xi_p) x_i, V_p = det J(xi_p) w_p.
//
// In both, the mass and internal force of the next step are accumulated in
// the same pass (no relocation ever happens).
#pragma once

#include <talus/formulations/explicit/forward.h>
#include <talus/grid/background_grid.h>
#include <talus/particles/material_points.h>
#include <talus/shape/q1_iso.h>

#include <vector>

namespace talus::explicit_mpm
{
  template <int dim>
  class FemIntegration
  {
  public:
    /// `updated_lagrangian`: ul-fem (the mesh follows the material).
    FemIntegration(Solver<dim> &solver, bool updated_lagrangian);

    /// Replace the material points of the MPM seeding (primitives and particle
    /// files, already in the particle handler) by the Gauss points of the cells
    /// they occupy: a cell is covered by the lowest body id among its points and
    /// takes that body's (first point's) material; volume = det J w, mass =
    /// density x volume, velocity from the body. Ids global and contiguous.
    /// Collective.
    SeedingResult seed(const std::vector<double> &density_of_material);

    /// Full pass: nodal mass and internal + gravity force of the current state.
    void p2g_mass_and_force();
    /// Update pass after the nodal velocities are known: strains, stresses,
    /// volumes, displacements (positions for ul-fem), energies, probes; then the
    /// next step's mass and force (fused). Moves the nodes for ul-fem.
    void update(double dt);

    /// After a repartition (load balancing, fem only: ul-fem is refused with
    /// it): the vertex table of the new active cells. The state of fem is on
    /// the Gauss points, which moved with their cells.
    void grid_changed();

    bool
    updated_lagrangian() const
    {
      return ul;
    }
    /// ul-fem: accumulated nodal displacements (owned + ghost entries of the
    /// cells that hold points are kept current without communication).
    const Vector &
    nodal_displacement() const
    {
      return nodal_u;
    }

  private:
    Solver<dim>                  &s;
    const bool                    ul;
    static constexpr unsigned int nv = 1u << dim;
    using Kernel                     = shape::Q1Iso<dim>; ///< the cells may be deformed (ul-fem)
    /// reference vertex coordinates per active cell index: [c][v][d]
    std::vector<double> vertices;
    Vector              nodal_u;
    /// local DoF indices (owned + ghost) of the cells that hold points
    std::vector<unsigned int> moving_dofs;
    void                      collect_moving_dofs();
    /// the reference vertex table from the triangulation
    void collect_vertices();
    /// current vertex coordinates of cell c
    void current_vertices(unsigned int c, double (&X)[nv][dim]) const;
  };
} // namespace talus::explicit_mpm
