// talus — contact walls on the points' side (point_contact.h).
#include <talus/formulations/implicit/point_contact.h>
#include <talus/shape/with_kernel.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>

#include <cmath>

namespace talus::implicit_mpm
{
  template <int dim>
  PointContact<dim>::PointContact(std::vector<ContactPlane>                                      planes_,
                                  const std::vector<std::shared_ptr<const materials::Material>> &materials,
                                  const bool axisymmetric_, const bool bspline_)
      : planes(std::move(planes_))
      , axisymmetric(axisymmetric_)
      , bspline(bspline_)
  {
    for (const auto &m : materials)
      modulus.push_back(m->constrained_modulus());
  }

  template <int dim>
  void
  PointContact<dim>::set_time(const double t_n, const double t)
  {
    for (auto &c : planes)
      if (c.velocity != 0)
        {
          c.wall_n = c.wall_0 + c.velocity * t_n;
          c.wall   = c.wall_0 + c.velocity * t;
        }
  }

  template <int dim>
  int
  PointContact<dim>::acts_on(const ContactPlane &c, const double *xs_n, const double r) const
  {
    if (!c.footing)
      return 1;
    unsigned int k = 0;
    for (unsigned int t = 0; t < dim; ++t)
      if (t != c.axis)
        {
          if (xs_n[t] < c.lower[k] || xs_n[t] > c.upper[k])
            return 0;
          ++k;
        }
    // the spot at the start of the step no deeper than the point's extent
    // behind the plane's start-of-step position (a stiff penalty keeps the
    // points in contact far shallower; deeper is a point that came round the
    // footing's edge)
    return c.sign * (c.wall_n - xs_n[c.axis]) >= -2 * r ? 1 : -1;
  }

  template <int dim>
  void
  PointContact<dim>::extend_layout(PropertyLayout<dim> &layout)
  {
    offset_ = layout.add_extra("contact", dim + planes.size() * (dim + 1));
  }

  template <int dim>
  void
  PointContact<dim>::initialize_points(MaterialPointSet<dim> &points) const
  {
    for (auto &pt : points.handler)
      {
        auto P = pt.get_properties();
        for (unsigned int k = 0; k < dim + planes.size() * (dim + 1); ++k)
          P[offset_ + k] = 0.0;
      }
  }

  template <int dim>
  void
  PointContact<dim>::start_step(MaterialPointSet<dim> &points) const
  {
    for (auto &pt : points.handler)
      {
        auto        P = pt.get_properties();
        const auto &x = pt.get_location();
        for (unsigned int d = 0; d < dim; ++d)
          P[offset_ + d] = x[d];
      }
  }

  template <int dim>
  void
  PointContact<dim>::extent_and_stiffness(const double *P, const ContactPlane &c, double &r, double &k) const
  {
    using L        = PropertyLayout<dim>;
    const double V = P[L::volume];
    // axisymmetric: V is the ring's volume; the extent is that of the point's area
    const double A = axisymmetric ? V / (2 * M_PI * std::max(P[offset_], 1e-300)) : V;
    r              = 0.5 * std::pow(A, 1.0 / dim);
    k              = c.penalty * modulus[static_cast<unsigned int>(P[L::material])] * V / (c.cell * c.cell);
  }

  template <int dim>
  int
  PointContact<dim>::law(const ContactPlane &c, const double *x, const double *x_n, const double *state, const double r,
                         const double k, Law &out) const
  {
    for (unsigned int i = 0; i < dim; ++i)
      {
        out.f[i]      = 0;
        out.anchor[i] = 0;
        for (unsigned int j = 0; j < dim; ++j)
          out.D[i][j] = 0;
      }
    out.pen          = 0;
    const unsigned a = c.axis;
    const double   g = c.sign * (c.wall - x[a]) - r;
    if (!(g < 0))
      return 0;
    const double pen      = -g; // d pen / d x_a = sign
    out.pen               = pen;
    out.f[a]              = -k * pen * c.sign;
    out.D[a][a]           = -k;
    const double friction = c.friction;
    if (friction == 0)
      return 1;
    // the slip since the point touched the wall
    const bool held = state[dim] != 0.0;
    double     s[dim], s2 = 0;
    for (unsigned int t = 0; t < dim; ++t)
      {
        out.anchor[t] = t == a ? 0.0 : (held ? state[t] : x_n[t]);
        s[t]          = t == a ? 0.0 : x[t] - out.anchor[t];
        s2 += s[t] * s[t];
      }
    const double kt = k, sn = std::sqrt(s2);
    if (friction == std::numeric_limits<double>::infinity() || kt * sn <= friction * k * pen)
      {
        for (unsigned int t = 0; t < dim; ++t)
          if (t != a)
            {
              out.f[t]    = -kt * s[t];
              out.D[t][t] = -kt;
            }
        return 1;
      }
    // Coulomb slip: f_t = -mu k pen s/|s|
    const double fn = friction * k * pen;
    for (unsigned int t = 0; t < dim; ++t)
      if (t != a)
        {
          const double e = s[t] / sn;
          out.f[t]       = -fn * e;
          out.D[t][a]    = -friction * k * c.sign * e;
          for (unsigned int q = 0; q < dim; ++q)
            if (q != a)
              out.D[t][q] += -fn * ((t == q ? 1.0 : 0.0) - e * s[q] / sn) / sn;
          out.anchor[t] = x[t] - fn / kt * e;
        }
    return 2;
  }

  namespace
  {
    template <int dim>
    struct ContactIntegrand
    {
      const PointContact<dim> *pc;
      PointContactStats       *stats;
      static constexpr bool    matrix = true, vector = true;

      template <int d_, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        const double *x_n    = P + pc->offset();
        const auto   &planes = pc->walls();
        for (unsigned int w = 0; w < planes.size(); ++w)
          {
            double r, k;
            pc->extent_and_stiffness(P, planes[w], r, k);
            // the contact spot: the material at the point's extent towards the
            // wall, x_n + s r_p e_a; its shape values (Q1 is linear along an
            // axis, so exactly) N_i + s r_p dN_i/dx_a
            const unsigned int a = planes[w].axis;
            const double       o = planes[w].sign * r;
            double             Ns[PN::capacity], xs_n[dim], x[dim];
            for (unsigned int i = 0; i < p.n; ++i)
              Ns[i] = p.N[i] + o * p.G[i][a];
            for (unsigned int c = 0; c < dim; ++c)
              {
                xs_n[c] = x_n[c] + (c == a ? o : 0.0);
                x[c]    = xs_n[c];
                for (unsigned int i = 0; i < p.n; ++i)
                  x[c] += Ns[i] * ls.u[p.local[i] * nc + c];
              }
            if (const int on = pc->acts_on(planes[w], xs_n, r); on != 1)
              {
                stats->behind_footing += on == -1;
                continue;
              }
            typename PointContact<dim>::Law law;
            const int state = pc->law(planes[w], x, xs_n, P + pc->offset() + dim + w * (dim + 1), 0.0, k, law);
            if (state == 0)
              continue;
            ++stats->in_contact;
            stats->slipping += state == 2;
            double ft2 = 0;
            for (unsigned int c = 0; c < dim; ++c)
              if (c != planes[w].axis)
                ft2 += law.f[c] * law.f[c];
            stats->normal_force += std::abs(law.f[planes[w].axis]);
            if (planes[w].footing)
              stats->footing_force -= planes[w].sign * law.f[planes[w].axis];
            stats->tangential_force += std::sqrt(ft2);
            stats->max_penetration_ratio = std::max(stats->max_penetration_ratio, law.pen / r);
            // the force acts at the spot: r_i -= N_i f; K_ij -= N_i N_j df/dx
            // (x = x_n + sum_j N_j Du_j, N the spot's shape values)
            for (unsigned int i = 0; i < p.n; ++i)
              {
                for (unsigned int c = 0; c < dim; ++c)
                  ls.b[p.local[i] * nc + c] -= Ns[i] * law.f[c];
                for (unsigned int j = 0; j < p.n; ++j)
                  {
                    const double NN = Ns[i] * Ns[j];
                    if (NN == 0)
                      continue;
                    for (unsigned int c = 0; c < dim; ++c)
                      for (unsigned int e = 0; e < dim; ++e)
                        if (law.D[c][e] != 0)
                          ls.a(p.local[i] * nc + c, p.local[j] * nc + e) -= NN * law.D[c][e];
                  }
              }
          }
      }
    };

    void
    sum_stats(PointContactStats &s, const MPI_Comm comm)
    {
      double v[5] = {double(s.in_contact), double(s.slipping), double(s.new_contacts), double(s.released),
                     double(s.behind_footing)};
      dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 5), comm, dealii::ArrayView<double>(v, 5));
      s.behind_footing        = static_cast<unsigned long long>(v[4]);
      s.footing_force         = dealii::Utilities::MPI::sum(s.footing_force, comm);
      s.in_contact            = static_cast<unsigned long long>(v[0]);
      s.slipping              = static_cast<unsigned long long>(v[1]);
      s.new_contacts          = static_cast<unsigned long long>(v[2]);
      s.released              = static_cast<unsigned long long>(v[3]);
      s.normal_force          = dealii::Utilities::MPI::sum(s.normal_force, comm);
      s.tangential_force      = dealii::Utilities::MPI::sum(s.tangential_force, comm);
      s.max_penetration_ratio = dealii::Utilities::MPI::max(s.max_penetration_ratio, comm);
    }
  } // namespace

  template <int dim>
  PointContactStats
  PointContact<dim>::assemble(MaterialPointSet<dim> &points, const ActiveSet<dim> &active,
                              const dealii::AffineConstraints<double> &constraints, const Vector &du,
                              dealii::TrilinosWrappers::SparseMatrix *A, Vector &b) const
  {
    PointContactStats           stats;
    const ContactIntegrand<dim> integrand{this, &stats};
    const auto                  run = [&](auto nc) {
      shape::with_kernel<dim>(bspline, [&](auto k) {
        transfer::AssembleSystem<dim, decltype(k), decltype(nc)::value, ContactIntegrand<dim>> op(
                           active, constraints, integrand, A, &b, &du);
        transfer::for_each_active_cell(points, op);
      });
    };
    if (active.space.n_components() == dim)
      run(std::integral_constant<unsigned int, dim>());
    else
      run(std::integral_constant<unsigned int, dim + 1>());
    if (A != nullptr)
      A->compress(dealii::VectorOperation::add);
    b.compress(dealii::VectorOperation::add);
    sum_stats(stats, active.space.grid.comm);
    return stats;
  }

  template <int dim>
  PointContactStats
  PointContact<dim>::commit(MaterialPointSet<dim> &points, const NodalSpace<dim> &space, const Vector &du) const
  {
    PointContactStats stats;
    // val[c], grad[c][d]: Du and its gradient at the point
    const auto update = [&](transfer::PointIterator<dim> &it, const double *val, const auto &grad) {
      auto          P   = it->get_properties();
      const double *x_n = P.data() + offset_;
      for (unsigned int w = 0; w < planes.size(); ++w)
        {
          double *state = P.data() + offset_ + dim + w * (dim + 1);
          double  r, k;
          extent_and_stiffness(P.data(), planes[w], r, k);
          // the contact spot x_n + s r_p e_a and its increment Du + s r_p dDu/dx_a
          const unsigned int a = planes[w].axis;
          const double       o = planes[w].sign * r;
          double             xs_n[dim], x[dim];
          for (unsigned int c = 0; c < dim; ++c)
            {
              xs_n[c] = x_n[c] + (c == a ? o : 0.0);
              x[c]    = xs_n[c] + val[c] + o * grad[c][a];
            }
          Law       law;
          const int on = acts_on(planes[w], xs_n, r);
          stats.behind_footing += on == -1;
          const int s = on == 1 ? this->law(planes[w], x, xs_n, state, 0.0, k, law) : 0;
          if (s == 0)
            {
              stats.released += state[dim] != 0.0;
              for (unsigned int c = 0; c <= dim; ++c)
                state[c] = 0.0;
              continue;
            }
          stats.new_contacts += state[dim] == 0.0;
          ++stats.in_contact;
          stats.slipping += s == 2;
          stats.normal_force += std::abs(law.f[planes[w].axis]);
          if (planes[w].footing)
            stats.footing_force -= planes[w].sign * law.f[planes[w].axis];
          double ft2 = 0;
          for (unsigned int c = 0; c < dim; ++c)
            if (c != planes[w].axis)
              ft2 += law.f[c] * law.f[c];
          stats.tangential_force += std::sqrt(ft2);
          stats.max_penetration_ratio = std::max(stats.max_penetration_ratio, law.pen / r);
          for (unsigned int c = 0; c < dim; ++c)
            state[c] = law.anchor[c];
          state[dim] = 1.0;
        }
    };
    const auto run = [&](auto nc) {
      constexpr unsigned int n = decltype(nc)::value;
      auto cb = [&](transfer::PointIterator<dim> &it, const double *val, const auto &grad) { update(it, val, grad); };
      shape::with_kernel<dim>(bspline, [&](auto k) {
        transfer::InterpolateField<dim, decltype(k), n, decltype(cb)> op(space, du, cb);
        transfer::for_each_active_cell(points, op);
      });
    };
    if (space.n_components() == dim)
      run(std::integral_constant<unsigned int, dim>());
    else
      run(std::integral_constant<unsigned int, dim + 1>());
    sum_stats(stats, space.grid.comm);
    return stats;
  }

  template class PointContact<2>;
  template class PointContact<3>;
} // namespace talus::implicit_mpm
