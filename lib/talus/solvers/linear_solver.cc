#include <talus/solvers/linear_solver.h>

#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <chrono>
#include <stdexcept>

namespace talus
{
  namespace
  {
    dealii::TrilinosWrappers::PreconditionAMG::AdditionalData
    amg_data(const LinearSolverOptions &options, const std::vector<std::vector<bool>> &constant_modes)
    {
      dealii::TrilinosWrappers::PreconditionAMG::AdditionalData amg;
      amg.elliptic              = true;
      amg.higher_order_elements = false;
      amg.aggregation_threshold = options.aggregation_threshold;
      amg.smoother_sweeps       = options.smoother_sweeps;
      amg.constant_modes        = constant_modes;
      return amg;
    }

    /// A Krylov solve (TrilinosWrappers::SolverCG or SolverGMRES) to |b - A x| <=
    /// tol |b|; returns the iterations
    template <class KrylovSolver>
    unsigned int
    krylov(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
           const LinearSolverOptions &options, const dealii::TrilinosWrappers::PreconditionAMG &preconditioner,
           const typename KrylovSolver::AdditionalData &data = typename KrylovSolver::AdditionalData())
    {
      // AztecOO's criterion is absolute (|r| <= tol, unscaled)
      dealii::SolverControl control(options.max_iterations, options.relative_tolerance * b.l2_norm());
      KrylovSolver          solver(control, data);
      solver.solve(A, x, b, preconditioner);
      return control.last_step();
    }

    unsigned int
    cg(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b, const LinearSolverOptions &options,
       const dealii::TrilinosWrappers::PreconditionAMG &preconditioner)
    {
      return krylov<dealii::TrilinosWrappers::SolverCG>(A, x, b, options, preconditioner);
    }

    double
    relative_residual(const dealii::TrilinosWrappers::SparseMatrix &A, const Vector &x, const Vector &b)
    {
      // the residual, independent of the solver's own measure
      Vector r;
      r.reinit(b, true);
      A.vmult(r, x);
      r.sadd(-1.0, 1.0, b);
      const double b_norm = b.l2_norm();
      return b_norm > 0 ? r.l2_norm() / b_norm : r.l2_norm();
    }
  } // namespace

  LinearSolveInfo
  solve_direct(const dealii::TrilinosWrappers::SparseMatrix &A, std::vector<Vector> &xs, const std::vector<Vector> &bs,
               const std::string &direct_package)
  {
    LinearSolveInfo info;
    info.method = "direct (" + direct_package + ")";
    dealii::SolverControl                                  control(1, 0);
    dealii::TrilinosWrappers::SolverDirect::AdditionalData data(false, direct_package);
    dealii::TrilinosWrappers::SolverDirect                 solver(control, data);
    solver.initialize(A);
    xs.resize(bs.size());
    for (unsigned int k = 0; k < bs.size(); ++k)
      {
        const Vector &b = bs[k];
        Vector       &x = xs[k];
        x.reinit(b, true);
        x = 0;
        solver.solve(x, b);
        ++info.iterations;
        // Iterative refinement with the same factorisation when the direct
        // solve leaves a visible round-off residual: badly scaled systems (the
        // mixed u-p tangent of a stiff material, E = 1e7 Pa: u rows ~ E, the
        // 1/K-scaled p rows ~ V / G ~ 1e-8) lose digits in KLU's pivoting;
        // a few refinement steps bring |b - A x| / |b| back to round-off. Not
        // entered (results unchanged) when the first solve is already clean.
        const double b_norm = b.l2_norm();
        Vector       r, d;
        r.reinit(b, true);
        d.reinit(x, true);
        const auto residual_norm = [&]() {
          A.vmult(r, x);
          r.sadd(-1.0, 1.0, b);
          return r.l2_norm();
        };
        double rn = residual_norm();
        for (unsigned int i = 0; i < 3 && rn > 1e-9 * b_norm; ++i)
          {
            d = 0;
            solver.solve(d, r);
            x += d;
            const double rn_new = residual_norm();
            if (!(rn_new < rn))
              {
                x -= d; // no gain: keep the better iterate
                break;
              }
            rn = rn_new;
          }
        info.relative_residual = std::max(info.relative_residual, b_norm > 0 ? rn / b_norm : rn);
      }
    return info;
  }

  LinearSolveInfo
  solve_linear(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
               const LinearSolverOptions &options, const std::vector<std::vector<bool>> &constant_modes,
               const std::vector<double> &dof_coordinates)
  {
    LinearSolveInfo info;
    if (options.method == LinearSolverOptions::Method::gmres_block_amg)
      return solve_block_up(A, x, b, options, constant_modes, dof_coordinates);
    if (options.method == LinearSolverOptions::Method::direct)
      {
        std::vector<Vector> xs;
        info = solve_direct(A, xs, {b}, options.direct_package);
        x.copy_locally_owned_data_from(xs[0]);
        return info;
      }
    else
      {
        dealii::TrilinosWrappers::PreconditionAMG amg_preconditioner;
        amg_preconditioner.initialize(A, amg_data(options, constant_modes));
        if (options.method == LinearSolverOptions::Method::gmres_amg)
          {
            using GMRES     = dealii::TrilinosWrappers::SolverGMRES;
            info.method     = "GMRES + AMG (ML)";
            info.iterations = krylov<GMRES>(A, x, b, options, amg_preconditioner, GMRES::AdditionalData(false, 100));
          }
        else
          {
            info.method     = "CG + AMG (ML)";
            info.iterations = cg(A, x, b, options, amg_preconditioner);
          }
      }
    info.relative_residual = relative_residual(A, x, b);
    return info;
  }

  ReusedAMGSolver::ReusedAMGSolver()  = default;
  ReusedAMGSolver::~ReusedAMGSolver() = default;

  void
  ReusedAMGSolver::set_rebuild_interval(const unsigned int n)
  {
    if (n == 0)
      throw std::invalid_argument("ReusedAMGSolver: the rebuild interval must be >= 1");
    interval = n;
  }

  void
  ReusedAMGSolver::build(const dealii::TrilinosWrappers::SparseMatrix &A, const LinearSolverOptions &options,
                         const std::vector<std::vector<bool>> &constant_modes)
  {
    const auto t0 = std::chrono::steady_clock::now();
    amg.reset(); // free the old hierarchy first (it references A's Epetra matrix)
    amg = std::make_unique<dealii::TrilinosWrappers::PreconditionAMG>();
    amg->initialize(A, amg_data(options, constant_modes));
    stale   = false;
    rebuilt = true;
    ++setups;
    seconds_setup += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  LinearSolveInfo
  ReusedAMGSolver::solve(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
                         const LinearSolverOptions &options, const unsigned long long step,
                         const std::vector<std::vector<bool>> &constant_modes)
  {
    rebuilt = false;
    if (stale || !amg || step % interval == 0)
      build(A, options, constant_modes);
    LinearSolveInfo info;
    info.method = "CG + AMG (ML)";
    if (rebuilt)
      {
        info.iterations  = cg(A, x, b, options, *amg);
        fresh_iterations = info.iterations;
      }
    else
      {
        // a kept hierarchy: if CG fails with it (a preconditioner too far from
        // A), start again from the same guess with a fresh one. Deterministic:
        // a restarted run meets the same failure at the same step.
        Vector x0(x);
        try
          {
            info.iterations = cg(A, x, b, options, *amg);
          }
        catch (const std::exception &)
          {
            ++fallbacks;
            x = x0;
            build(A, options, constant_modes);
            info.iterations  = cg(A, x, b, options, *amg);
            fresh_iterations = info.iterations;
          }
        // the matrix has drifted far from the hierarchy's: a new one next time
        if (!rebuilt && info.iterations > 2 * fresh_iterations + 10)
          {
            stale = true;
            ++slow_solves;
          }
      }
    info.relative_residual = relative_residual(A, x, b);
    return info;
  }
} // namespace talus
