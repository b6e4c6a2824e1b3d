// talus — the one-set single-point variant of the semi-implicit step
// ('semi implicit/point sets = one set'; semi_implicit_solver.h,
// docs/semi-implicit.md 'The single-point variants'): one point set whose
// points carry the soil and its pore water (water velocity, water mass, pore
// pressure and its gradient; the water's porosity is the point's own), so each
// point pass of the step walks one set once for both phases. The phases of
// semi_implicit_step.cc call these in place of their two walks; the nodal
// work between the walks is theirs, unchanged (the water set is empty, so
// their walks of it do nothing).
#include <talus/formulations/semi_implicit/semi_implicit_solver.h>
#include <talus/materials/material.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/stencil_ops.h>

#include <algorithm>

namespace talus::semi_implicit
{
  namespace
  {
    /// the local (owned, then ghost) values of a grid vector
    inline double *
    at_local(Vector &v)
    {
      return v.begin();
    }
  } // namespace

  // The water of a one-set point: mass m_w = n0 rho_w V0 (Eq. 37, constant; 0
  // on the points of a soil body), the volume it stands for V_w = m_w / (rho_w
  // n) with n the point's porosity (Eq. 36 with n_wp = n_p: the two-set
  // variants interpolate n_wp from the nodes, which needs the soil's nodal sums
  // first, i.e. a second P2N walk), its velocity weights rho_w V0 (Eq. 51).
  // Every sum below is the two-set pass's with the water point's values taken
  // from the point itself.

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_to_nodes(const StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;

    const bool   initial_stage = this_step.initial_stage;
    const auto  &g             = this_step.g;
    const double rw            = prm.water_density;
    const bool   linear        = prm.linear_smoothing;
    cell_water_volume.assign(grid.cells.size(), 0.0);
    const SoilSums to{at_local(Ms), at_local(Ps), at_local(Mn), at_local(Mk), at_local(Fs)};
    double *ww = at_local(Ww), *pw0 = at_local(Pw0), *ww0 = at_local(Ww0), *mwp = at_local(Mwp), *mw = at_local(Mw),
           *mwg = at_local(Mwg);
    Stencil surface; // a loaded point's stencil at its share of the face
    transfer::for_each_point_stencil<dim, K>(
      grid, soil, stencils<K>(soil), [&](unsigned int c, It &it, const Stencil &s) {
        const double *P = it->get_properties().data();
        // the soil: soil_to_nodes' sums
        scatter_soil_point(P, s, to, initial_stage, g);
        bloads.template scatter_point_traction<K>(c, it->get_location(), P, s, surface, to.fs);
        // its water: water_to_nodes' sums
        const double mwp_ = P[fs.water_mass];
        if (!(mwp_ > 0)) // a point of a soil body
          return;
        const double Vw = water_volume(P), w0 = rw * P[fs.initial_volume];
        s.scatter(ww, rw * Vw);
        s.scatter_vector(pw0, w0, P + fs.water_velocity);
        s.scatter(ww0, w0);
        if (linear) // sum N m (p - grad p . x_p); the node adds (sum N m grad p) . x_I
          {
            const auto x  = it->get_location();
            double     px = P[fs.pressure];
            for (unsigned int d = 0; d < dim; ++d)
              px -= P[fs.pressure_gradient + d] * x[d];
            s.scatter(mwp, mwp_ * px);
            s.scatter_vector(mwg, mwp_, P + fs.pressure_gradient);
          }
        else
          s.scatter(mwp, mwp_ * P[fs.pressure]);
        s.scatter(mw, mwp_);
        cell_water_volume[c] += Vw;
      });
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_pressure_forces()
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // pore_pressure_forces: the smoothed p of the points (77), sum_s V N grad p^t
    // and sum_w V_w N grad p^t from the nodal p^t
    const double *pn  = at_local(p_node);
    double       *gpw = at_local(Gpw), *gps = at_local(Gps);
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               double    *P   = it->get_properties().data();
                                               const bool wet = P[fs.water_mass] > 0;
                                               if (wet && prm.pressure_smoothing)
                                                 smooth_pressure(s, pn, P, P[fs.pressure]);
                                               double gp[dim];
                                               s.gradient(pn, gp);
                                               s.scatter_vector(gps, P[L::volume], gp);
                                               if (wet)
                                                 s.scatter_vector(gpw, water_volume(P), gp);
                                             });
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_weak_gradients(const double *phi, double *fs_out, double *fw_out)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               const double *P = it->get_properties().data();
                                               double        gp[dim];
                                               s.gradient(phi, gp);
                                               s.scatter_vector(fs_out, P[L::volume], gp);
                                               if (P[fs.water_mass] > 0)
                                                 s.scatter_vector(fw_out, water_volume(P), gp);
                                             });
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_poisson_terms(const StepState &this_step)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // point_poisson_terms with both phases on one point: the Poisson integrand
    // weighs the point's coefficient and flux by its volume V, so the water's
    // terms (on V_w) enter as V_w / V times theirs
    const double  h = this_step.h, rw = prm.water_density;
    const double *vss = at_local(vs_star), *vws = at_local(vw_star);
    transfer::for_each_point_stencil<dim, K>(
      grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
        double      *P      = it->get_properties().data();
        const double n      = P[fs.porosity];
        const double rs     = prm.materials[static_cast<unsigned int>(P[L::material])]->density();
        const double r      = P[fs.water_mass] > 0 ? water_volume(P) / P[L::volume] : 0.0; // V_w / V
        double       c      = prm.rigid_skeleton ? 0.0 : h * (1 - n) / rs;
        double       q[dim] = {};
        if (!prm.rigid_skeleton)
          {
            double v[dim];
            s.vector_value(vss, v);
            for (unsigned int d = 0; d < dim; ++d)
              q[d] = (1 - n) * v[d];
          }
        if (r > 0)
          {
            double v[dim];
            s.vector_value(vws, v);
            c += r * h * n / rw;
            for (unsigned int d = 0; d < dim; ++d)
              q[d] += r * n * v[d];
          }
        P[fs.poisson_coefficient] = c;
        for (unsigned int d = 0; d < dim; ++d)
          P[fs.poisson_flux + d] = q[d];
      });
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_plate_flux(const double *ew)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // a force plate's unit response: the water's flux n e_w added on the soil's
    // (1 - n) e_s, weighed by V_w / V as in one_set_poisson_terms
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               double *P = it->get_properties().data();
                                               if (!(P[fs.water_mass] > 0))
                                                 return;
                                               const double r = water_volume(P) / P[L::volume];
                                               double       v[dim];
                                               s.vector_value(ew, v);
                                               for (unsigned int d = 0; d < dim; ++d)
                                                 P[fs.plate_flux + d] += r * P[fs.porosity] * v[d];
                                             });
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::one_set_to_particles()
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // nodes_to_particles for both phases: FLIP of the soil and the water
    // velocity, the pore pressure increment and gradient, the MUSL scatter of
    // the soil's momentum
    Ps                = 0;
    const double *vsn = at_local(vs_new), *vst = at_local(vs_t), *vwn = at_local(vw_new), *vwt = at_local(vw_t),
                 *dpn = at_local(dp_node), *pn = at_local(p_node);
    double *ps = at_local(Ps);
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               double *P = it->get_properties().data();
                                               flip_update(s, vsn, vst, P + L::velocity);
                                               s.scatter_vector(ps, P[L::mass], P + L::velocity);
                                               if (!(P[fs.water_mass] > 0))
                                                 return;
                                               flip_update(s, vwn, vwt, P + fs.water_velocity);
                                               pressure_update(s, pn, dpn, fs, P);
                                             });
  }

#define TALUS_ONE_SET_INSTANTIATE(dim, K)                                                   \
  template void Solver<dim>::one_set_to_nodes<K>(const StepState &);                        \
  template void Solver<dim>::one_set_pressure_forces<K>();                                  \
  template void Solver<dim>::one_set_weak_gradients<K>(const double *, double *, double *); \
  template void Solver<dim>::one_set_poisson_terms<K>(const StepState &);                   \
  template void Solver<dim>::one_set_plate_flux<K>(const double *);                         \
  template void Solver<dim>::one_set_to_particles<K>();
  TALUS_ONE_SET_INSTANTIATE(2, shape::BSpline2Box<2>)
  TALUS_ONE_SET_INSTANTIATE(2, shape::Q1Box<2>)
  TALUS_ONE_SET_INSTANTIATE(3, shape::BSpline2Box<3>)
  TALUS_ONE_SET_INSTANTIATE(3, shape::Q1Box<3>)
#undef TALUS_ONE_SET_INSTANTIATE
} // namespace talus::semi_implicit
