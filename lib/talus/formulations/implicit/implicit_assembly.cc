// talus — the implicit step's linear system (implicit_solver.h): the nodal
// projections, the residual and tangent of an iterate (internal force, loads,
// stiffness-proportional damping, contact on the points, lumped or consistent
// inertia, the force plates' balances), the damping stiffness, the mixed u-p
// pressure predictor, and the linear solves (one right-hand side, several with
// one factorisation, the force plates condensed by superposition).
#include <talus/base/tool.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/formulations/implicit/updated_lagrangian_ops.h>

#include <deal.II/base/mpi.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace talus::implicit_mpm
{
  namespace
  {
    /// The consistent inertia of one point on the displacement components
    /// (`with_matrix`, `with_vector` as the walk's integrand flags):
    /// b_ic += m_p N_i sum_j N_j w_jc (w: the nodal a + alpha_R v, the walk's
    /// field) and A_ic,jc += coef m_p N_i N_j. Summed over the points this is
    /// M w and coef M with M_ij = sum_p m_p N_i N_j (its row sums are the lumped
    /// masses); a pressure component (mixed u-p) carries no mass.
    template <int dim, bool with_matrix, bool with_vector>
    struct ConsistentInertia
    {
      double                coef   = 0;
      static constexpr bool matrix = with_matrix, vector = with_vector;
      template <int d_, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc >= dim && d_ == dim, "ConsistentInertia: the displacement components come first");
        const double m = P[PropertyLayout<dim>::mass];
        if constexpr (with_vector)
          {
            double w[dim] = {};
            for (unsigned int j = 0; j < p.n; ++j)
              for (unsigned int c = 0; c < dim; ++c)
                w[c] += p.N[j] * ls.u[p.local[j] * nc + c];
            for (unsigned int i = 0; i < p.n; ++i)
              for (unsigned int c = 0; c < dim; ++c)
                ls.b[p.local[i] * nc + c] += m * p.N[i] * w[c];
          }
        if constexpr (with_matrix)
          for (unsigned int i = 0; i < p.n; ++i)
            for (unsigned int j = 0; j < p.n; ++j)
              {
                const double v = coef * m * p.N[i] * p.N[j];
                for (unsigned int c = 0; c < dim; ++c)
                  ls.a(p.local[i] * nc + c, p.local[j] * nc + c) += v;
              }
      }
    };
  } // namespace

  template <int dim>
  void
  Solver<dim>::project_to_grid()
  {
    using L                                   = PropertyLayout<dim>;
    std::vector<MaterialPointSet<dim> *> sets = {&points};
    const auto                          &pins = active.constraints(); // inactive DoFs only: walls keep their mass
    mass                                      = 0;
    with_kernel([&](auto k) {
      with_components([&](auto nc) {
        transfer::assemble<dim, decltype(k), decltype(nc)::value>(sets, active, pins, transfer::NodalProjection<dim>{},
                                                                  nullptr, &mass);
      });
    });
    if (!dynamic())
      return;
    v_n = 0;
    a_n = 0;
    // mixed u-p: onto the displacement components of the u-p space (the
    // pressure components get no mass, hence no inertia)
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{L::velocity}, nullptr, &v_n);
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{acceleration_offset}, nullptr,
                                      &a_n);
      });
    });
    for (unsigned int i = 0; i < mass.locally_owned_size(); ++i)
      {
        const double m       = mass.local_element(i);
        v_n.local_element(i) = m > 0 ? v_n.local_element(i) / m : 0.0;
        a_n.local_element(i) = m > 0 ? a_n.local_element(i) / m : 0.0;
      }
  }

  template <int dim>
  void
  Solver<dim>::compute_cell_jbar()
  {
    cell_jbar.assign(grid.tria.n_active_cells(), 1.0);
    transfer::CellMeanJacobian<dim, shape::Q1Box<dim>> mean{grid, space, du, cell_jbar};
    transfer::for_each_active_cell(points, mean);
  }

  template <int dim>
  double
  Solver<dim>::assemble(const bool with_tangent, const dealii::Tensor<1, dim> &g)
  {
    const auto                            start     = Clock::now();
    const double                          start_cpu = thread_cpu_seconds();
    transfer::PointFailure                failure;
    transfer::UpdatedLagrangianForce<dim> force;
    force.materials      = &prm.materials;
    force.history_offset = PropertyLayout<dim>::history;
    force.gravity        = g;
    force.point_forces   = &point_forces;
    force.load_scale     = point_force_scale; // set with g by apply_loads_at
    force.tangent        = with_tangent;
    force.failure        = &failure;
    force.radius_offset  = radius_offset;
    if (prm.fbar)
      {
        compute_cell_jbar();
        force.jbar = &cell_jbar;
      }
    residual = 0;
    if (with_tangent)
      tangent = 0;
    if (prm.mixed_up)
      {
        transfer::MixedUpForce<dim> up;
        up.models         = &split_models;
        up.history_offset = force.history_offset;
        up.gravity        = g;
        up.point_forces   = &point_forces;
        up.load_scale     = force.load_scale;
        up.alpha          = prm.stabilisation;
        up.tangent        = with_tangent;
        up.failure        = &failure;
        with_kernel([&](auto k) {
          transfer::assemble<dim, decltype(k), dim + 1>({&points}, active, constraints, up,
                                                        with_tangent ? &tangent : nullptr, &residual, &du);
        });
      }
    else
      with_kernel([&](auto k) {
        transfer::assemble<dim, decltype(k), dim>({&points}, active, constraints, force,
                                                  with_tangent ? &tangent : nullptr, &residual, &du);
      });
    const bool any_failed = dealii::Utilities::MPI::max(failure.failed ? 1 : 0, comm) > 0;
    if (any_failed)
      throw NewtonFailure(failure.failed ? failure.what : "a material point on another rank failed");
    if (prm.ghost_penalty > 0)
      ghost.assemble(ghost_stiffness, space, constraints, du, with_tangent ? &tangent : nullptr, residual);
    if (carrying_imbalance)
      {
        const auto &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < residual.locally_owned_size(); ++k)
          if (!constraints.is_constrained(owned.nth_index_in_set(k)))
            residual.local_element(k) -= start_imbalance.local_element(k);
      }
    if (assembling_damping)
      return 0.0;
    if (dynamic() && prm.rayleigh_beta > 0)
      {
        // stiffness-proportional damping: r += beta_R K_n v^{n+1}(du) on the free DoFs and
        // tangent += beta_R gamma/(beta h) K_n (K_n held for the step: the tangent is exact)
        Vector v, Kv;
        space.reinit_vector(v);
        space.reinit_vector(Kv);
        const auto &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          v.local_element(k) = constraints.is_constrained(owned.nth_index_in_set(k))
                                 ? 0.0
                                 : newmark.velocity(du.local_element(k), v_n.local_element(k), a_n.local_element(k));
        damping_stiffness.vmult(Kv, v);
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          if (!constraints.is_constrained(owned.nth_index_in_set(k)))
            residual.local_element(k) += prm.rayleigh_beta * Kv.local_element(k);
        if (with_tangent)
          tangent.add(prm.rayleigh_beta * newmark.damping_coefficient(), damping_stiffness);
      }
    if (point_contact) // the penalty walls on the points (point_contact.h)
      point_contact->assemble(points, active, constraints, du, with_tangent ? &tangent : nullptr, residual);
    if (coulomb_nodes()) // the slipping contact nodes' friction forces (external, fixed in the solve)
      {
        const auto &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < contact_friction.locally_owned_size(); ++k)
          if (contact_friction.local_element(k) != 0.0 && !constraints.is_constrained(owned.nth_index_in_set(k)))
            residual.local_element(k) -= contact_friction.local_element(k);
      }
    if (dynamic() && prm.consistent_mass)
      add_consistent_inertia(with_tangent);
    else if (dynamic())
      {
        // lumped inertia and mass-proportional damping at the nodes:
        // r_i += m_i (a_i + alpha v_i), tangent_ii += m_i (1/(beta h^2) + alpha gamma/(beta h))
        const double coef  = newmark.tangent_factors(prm.rayleigh_alpha, 0).mass;
        const auto  &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
          {
            const auto   i = owned.nth_index_in_set(k);
            const double m = mass.local_element(k);
            if (m == 0 || constraints.is_constrained(i))
              continue;
            const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
            residual.local_element(k) +=
              m * (newmark.acceleration(u, v, a) + prm.rayleigh_alpha * newmark.velocity(u, v, a));
            if (with_tangent)
              tangent.add(i, i, m * coef);
          }
        if (with_tangent)
          tangent.compress(dealii::VectorOperation::add);
      }
    seconds_assembly += seconds_since(start);
    cpu_seconds_assembly += thread_cpu_seconds() - start_cpu;
    ++n_assemblies;
    if (!any_force_plate() || plates_held)
      return residual.l2_norm();
    // force plates: their DoFs' equations are the plates' balances, one per
    // plate: sum_{i in P_k} r_i = F_k (the force the plate exerts on the
    // material). The sums are kept and the rows zeroed (the solve's right-hand
    // side there is 0); the norm Newton tests is that of the free rows and the
    // plates' out-of-balance forces.
    const unsigned int  n = prm.rigid_plates.size();
    std::vector<double> sums(n, 0.0);
    for (unsigned int k = 0; k < n; ++k)
      for (const auto i : plate_owned[k])
        {
          sums[k] += residual(i);
          residual(i) = 0.0;
        }
    dealii::Utilities::MPI::sum(sums, comm, sums);
    double norm2 = residual.norm_sqr();
    for (unsigned int k = 0; k < n; ++k)
      if (force_plate(k))
        {
          plate_sum[k] = sums[k];
          norm2 += (sums[k] - plate_target[k]) * (sums[k] - plate_target[k]);
        }
    return std::sqrt(norm2);
  }

  template <int dim>
  void
  Solver<dim>::add_consistent_inertia(const bool with_tangent)
  {
    // The inertia and damping with the consistent mass: r += M (a + alpha_R v),
    // tangent += (1/(beta h^2) + alpha_R gamma/(beta h)) M. As with the lumped
    // mass, only the free DoFs carry inertia: w = 0 at every DoF constrained in
    // this assembly (walls, held contact nodes, prescribed and inactive nodes),
    // so a constrained node neither feels nor exerts an inertial force.
    const auto  &owned = space.locally_owned_dofs();
    const double alpha = prm.rayleigh_alpha;
    for (unsigned int k = 0; k < inertia_field.locally_owned_size(); ++k)
      {
        const auto i = owned.nth_index_in_set(k);
        if (mass.local_element(k) == 0 || constraints.is_constrained(i))
          {
            inertia_field.local_element(k) = 0.0;
            continue;
          }
        const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
        inertia_field.local_element(k) = newmark.acceleration(u, v, a) + alpha * newmark.velocity(u, v, a);
      }
    inertia_field.update_ghost_values();
    const double coef = newmark.tangent_factors(alpha, 0).mass;
    // The matrix and the vector go through the constraints in one call unless
    // the constraints are inhomogeneous (the lifted predictor of prescribed
    // nodes): there the combined call would move -coef M_ij g_j to the residual,
    // an inertia of the prescribed nodes that the residual (w = 0 there) does not have.
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        if (with_tangent && !constraints.has_inhomogeneities())
          transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, true>{coef},
                                        &tangent, &residual, &inertia_field);
        else
          {
            if (with_tangent)
              transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, false>{coef},
                                            &tangent, nullptr);
            transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, false, true>{coef},
                                          nullptr, &residual, &inertia_field);
          }
      });
    });
  }

  template <int dim>
  void
  Solver<dim>::predict_pressure()
  {
    // Eq. 5.20: p_i = sum_p N_i m_p p_p / sum_p N_i m_p (residual and delta as scratch)
    const auto &pins = active.constraints();
    residual         = 0;
    delta            = 0;
    with_kernel([&](auto k) {
      using K = decltype(k);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, true}, nullptr, &residual);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, false}, nullptr, &delta);
    });
    for (unsigned int k = 0; k < du.locally_owned_size(); ++k)
      if (space.component(k) == dim && delta.local_element(k) > 0)
        du.local_element(k) = residual.local_element(k) / delta.local_element(k);
    du.update_ghost_values();
    delta = 0;
  }

  template <int dim>
  void
  Solver<dim>::nodal_acceleration(Vector &a) const
  {
    for (unsigned int k = 0; k < a.locally_owned_size(); ++k)
      a.local_element(k) = mass.local_element(k) > 0
                             ? newmark.acceleration(du.local_element(k), v_n.local_element(k), a_n.local_element(k))
                             : 0.0;
    a.update_ghost_values();
  }

  template <int dim>
  void
  Solver<dim>::assemble_damping_stiffness(const dealii::Tensor<1, dim> &g)
  {
    const Vector saved(du);
    du = 0;
    du.update_ghost_values();
    assembling_damping = true;
    try
      {
        assemble(true, g);
      }
    catch (...)
      {
        assembling_damping = false;
        throw;
      }
    assembling_damping = false;
    damping_stiffness.copy_from(tangent);
    du = saved;
    du.update_ghost_values();
  }

  // ---------------------------------------------------------------- linear solves
  namespace
  {
    /// A singular tangent (a body free to move as a rigid body in a static
    /// analysis, a point set cut loose) gives a direct solve without error but
    /// a solution that does not solve the system: a failed step.
    void
    require_solved(const LinearSolveInfo &info)
    {
      if (!(info.relative_residual <= 1e-6))
        {
          std::ostringstream os;
          os << "the linear system is singular or nearly so (|b - A x| / |b| = " << info.relative_residual
             << " after the " << info.method
             << " solve): are rigid-body motions of every body prevented by boundary conditions?";
          throw NewtonFailure(os.str());
        }
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta()
  {
    return solve_for_delta(residual);
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta(const Vector &r)
  {
    const auto start = Clock::now();
    Vector     rhs(r);
    rhs *= -1.0;
    delta = 0;
    LinearSolveInfo info;
    try
      {
        std::vector<double> coordinates; // the rigid rotations of the u-p block preconditioner's AMG
        if (prm.linear.method == LinearSolverOptions::Method::gmres_block_amg)
          {
            const unsigned int n_owned = space.locally_owned_dofs().n_elements();
            coordinates.resize(std::size_t(n_owned) * dim);
            for (unsigned int l = 0; l < n_owned; ++l)
              for (unsigned int d = 0; d < dim; ++d)
                coordinates[std::size_t(l) * dim + d] = space.position(l)[d];
          }
        info = solve_linear(tangent, delta, rhs, prm.linear, space.constant_modes(), coordinates);
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    ++n_solves;
    require_solved(info);
    return info;
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_several(std::vector<Vector> &r)
  {
    // iterative methods: one solve_for_delta per right-hand side
    if (prm.linear.method != LinearSolverOptions::Method::direct)
      {
        LinearSolveInfo info;
        for (auto &x : r)
          {
            // a zero right-hand side (the first iteration of a step whose only
            // load is a plate's force: the free rows are in balance) has the
            // solution 0; a Krylov solver would stop with a breakdown on it
            if (x.linfty_norm() == 0)
              continue;
            const auto one = solve_for_delta(x);
            info.method    = one.method;
            info.iterations += one.iterations;
            info.relative_residual = std::max(info.relative_residual, one.relative_residual);
            x                      = delta;
          }
        return info;
      }
    // direct: one factorisation for all of them (solvers/linear_solver.h)
    const auto      start = Clock::now();
    LinearSolveInfo info;
    try
      {
        std::vector<Vector> b(r.size()), x;
        for (unsigned int k = 0; k < r.size(); ++k)
          {
            b[k].reinit(r[k], true);
            b[k] = r[k];
            b[k] *= -1.0;
          }
        info = solve_direct(tangent, x, b, prm.linear.direct_package);
        for (unsigned int k = 0; k < r.size(); ++k)
          r[k].copy_locally_owned_data_from(x[k]);
        info.method = "direct (" + prm.linear.direct_package + ", one factorisation for " + std::to_string(r.size()) +
                      " right-hand sides)";
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    n_solves += r.size();
    require_solved(info);
    return info;
  }

  namespace
  {
    /// Zero the rows and columns of the global DoFs `dofs` (sorted, the same
    /// list on every rank) of a filled Trilinos matrix, keeping each row's
    /// diagonal: the matrix of the system with those DoFs prescribed
    /// (symmetric if A is). In place on Epetra's values (the pattern is kept).
    void
    zero_rows_and_columns(dealii::TrilinosWrappers::SparseMatrix             &A,
                          const std::vector<dealii::types::global_dof_index> &dofs)
    {
      auto                      &E    = const_cast<Epetra_CrsMatrix &>(A.trilinos_matrix());
      const Epetra_Map          &rows = E.RowMap(), &cols = E.ColMap();
      std::vector<unsigned char> col_hit(E.NumMyCols(), 0);
      for (const auto g : dofs)
        {
          const int l = cols.LID(static_cast<int>(g));
          if (l >= 0)
            col_hit[l] = 1;
        }
      for (int r = 0; r < E.NumMyRows(); ++r)
        {
          int     n       = 0;
          double *values  = nullptr;
          int    *indices = nullptr;
          E.ExtractMyRowView(r, n, values, indices);
          const int  gid = rows.GID(r);
          const bool hit = std::binary_search(dofs.begin(), dofs.end(), dealii::types::global_dof_index(gid));
          for (int j = 0; j < n; ++j)
            if ((hit && cols.GID(indices[j]) != gid) || (!hit && col_hit[indices[j]]))
              values[j] = 0.0;
        }
      // values changed behind Epetra's back: drop its cached norms
      E.SumIntoMyValues(0, 0, nullptr, nullptr);
    }

    /// Solve the small dense system M c = b (n x n, row-major) by Gaussian
    /// elimination with partial pivoting; the same arithmetic on every rank.
    std::vector<double>
    solve_dense(std::vector<double> M, std::vector<double> b)
    {
      const unsigned int n = b.size();
      for (unsigned int k = 0; k < n; ++k)
        {
          unsigned int p = k;
          for (unsigned int i = k + 1; i < n; ++i)
            if (std::abs(M[i * n + k]) > std::abs(M[p * n + k]))
              p = i;
          for (unsigned int j = 0; j < n; ++j)
            std::swap(M[k * n + j], M[p * n + j]);
          std::swap(b[k], b[p]);
          for (unsigned int i = k + 1; i < n; ++i)
            {
              const double f = M[i * n + k] / M[k * n + k];
              for (unsigned int j = k; j < n; ++j)
                M[i * n + j] -= f * M[k * n + j];
              b[i] -= f * b[k];
            }
        }
      std::vector<double> c(n, 0.0);
      for (unsigned int k = n; k-- > 0;)
        {
          double s = b[k];
          for (unsigned int j = k + 1; j < n; ++j)
            s -= M[k * n + j] * c[j];
          c[k] = s / M[k * n + k];
        }
      return c;
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_with_plates()
  {
    // The plates' DoFs condensed by superposition (docs/implicit.md, "Rigid
    // plate"): exact, the same solution as a master-slave line u_i = u_m per
    // plate node, without couplings of the master in the sparsity or the
    // master as a ghost on every rank.
    const auto                start = Clock::now();
    const unsigned int        n_all = prm.rigid_plates.size();
    std::vector<unsigned int> ks; // the force plates
    for (unsigned int k = 0; k < n_all; ++k)
      if (force_plate(k))
        ks.push_back(k);
    const unsigned int  n = ks.size();
    std::vector<Vector> e(n), v(n), w(n), z(n);
    std::vector<double> size(n, 0.0);
    for (unsigned int a = 0; a < n; ++a)
      {
        for (Vector *x : {&e[a], &v[a], &w[a], &z[a]})
          space.reinit_vector(*x);
        for (const auto i : plate_owned[ks[a]])
          e[a][i] = 1.0;
        size[a] = plate_owned[ks[a]].size();
        tangent.vmult(v[a], e[a]);  // K e: the plate's column sum (K_FP 1 in the free rows)
        tangent.Tvmult(w[a], e[a]); // K^T e: its row sum, sum_{i in P} K_ij
      }
    dealii::Utilities::MPI::sum(size, comm, size);
    zero_rows_and_columns(tangent, plate_all);
    const auto zero_plate_entries = [&](Vector &x) {
      for (const auto &dofs : plate_owned)
        for (const auto i : dofs)
          x[i] = 0.0;
    };
    // z_0 (the plates held) and z_a (the response to a unit displacement of
    // plate a), from one factorisation with the direct solver
    std::vector<Vector> x(1 + n);
    x[0] = residual; // its plate rows are 0 (assemble)
    for (unsigned int a = 0; a < n; ++a)
      {
        x[1 + a] = v[a];
        zero_plate_entries(x[1 + a]);
      }
    seconds_plates += seconds_since(start);
    const auto      start_solve = Clock::now();
    LinearSolveInfo info        = solve_several(x);
    const double    t_solve     = seconds_since(start_solve);
    const auto      start2      = Clock::now();
    Vector          z0(x[0]);
    zero_plate_entries(z0);
    for (unsigned int a = 0; a < n; ++a)
      {
        z[a] = x[1 + a];
        zero_plate_entries(z[a]);
      }
    seconds_plates_solve += t_solve;
    // the linearised balance of plate a: sum_{i in P_a} (r + K delta)_i = F_a,
    // delta = z_0 + sum_b c_b (z_b + e_b): sum_b (w_a . z_b + e_a . v_b) c_b = F_a - R_a - w_a . z_0
    std::vector<double> M(n * n), b(n);
    for (unsigned int a = 0; a < n; ++a)
      {
        const auto k = ks[a];
        if (size[a] == 0)
          {
            // the plate acts on no free node next to material: its force has
            // nothing to act on (said once), its increment is 0
            for (unsigned int c = 0; c < n; ++c)
              M[a * n + c] = c == a ? 1.0 : 0.0;
            b[a] = 0;
            if (!idle_plates[k])
              {
                idle_plates[k] = 1;
                log() << "  WARNING: " << prm.rigid_plates[k].where
                      << " reaches no free grid node next to material at t = " << time
                      << " s: its force acts on nothing from here on" << std::endl;
              }
            continue;
          }
        for (unsigned int c = 0; c < n; ++c)
          M[a * n + c] = (w[a] * z[c]) + (e[a] * v[c]);
        b[a] = plate_target[k] - plate_sum[k] - (w[a] * z0);
      }
    const std::vector<double> c = solve_dense(M, b);
    delta                       = z0;
    for (unsigned int a = 0; a < n; ++a)
      {
        delta.add(c[a], z[a]);
        plate_c[ks[a]] = c[a];
        for (const auto i : plate_owned[ks[a]])
          delta[i] = c[a]; // exactly c: the plate's nodes move as one
      }
    seconds_plates += seconds_since(start2);
    return info;
  }

  template void            Solver<2>::project_to_grid();
  template void            Solver<2>::compute_cell_jbar();
  template double          Solver<2>::assemble(const bool, const dealii::Tensor<1, 2> &);
  template void            Solver<2>::add_consistent_inertia(const bool);
  template void            Solver<2>::predict_pressure();
  template void            Solver<2>::nodal_acceleration(Vector &) const;
  template void            Solver<2>::assemble_damping_stiffness(const dealii::Tensor<1, 2> &);
  template LinearSolveInfo Solver<2>::solve_for_delta();
  template LinearSolveInfo Solver<2>::solve_for_delta(const Vector &);
  template LinearSolveInfo Solver<2>::solve_several(std::vector<Vector> &);
  template LinearSolveInfo Solver<2>::solve_with_plates();
  template void            Solver<3>::project_to_grid();
  template void            Solver<3>::compute_cell_jbar();
  template double          Solver<3>::assemble(const bool, const dealii::Tensor<1, 3> &);
  template void            Solver<3>::add_consistent_inertia(const bool);
  template void            Solver<3>::predict_pressure();
  template void            Solver<3>::nodal_acceleration(Vector &) const;
  template void            Solver<3>::assemble_damping_stiffness(const dealii::Tensor<1, 3> &);
  template LinearSolveInfo Solver<3>::solve_for_delta();
  template LinearSolveInfo Solver<3>::solve_for_delta(const Vector &);
  template LinearSolveInfo Solver<3>::solve_several(std::vector<Vector> &);
  template LinearSolveInfo Solver<3>::solve_with_plates();
} // namespace talus::implicit_mpm
