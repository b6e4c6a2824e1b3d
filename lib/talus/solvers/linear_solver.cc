#include <talus/solvers/linear_solver.h>

#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

namespace talus
{
  LinearSolveInfo
  solve_linear(const dealii::TrilinosWrappers::SparseMatrix &A,
               Vector &                                      x,
               const Vector &                                b,
               const LinearSolverOptions &                   options,
               const std::vector<std::vector<bool>> &        constant_modes)
  {
    LinearSolveInfo info;
    const double    b_norm = b.l2_norm();
    if (options.method == LinearSolverOptions::Method::direct)
      {
        info.method = "direct (Amesos_Klu)";
        dealii::SolverControl                           control(1, 0);
        dealii::TrilinosWrappers::SolverDirect::AdditionalData data(false, "Amesos_Klu");
        dealii::TrilinosWrappers::SolverDirect          solver(control, data);
        solver.solve(A, x, b);
        info.iterations = 1;
      }
    else
      {
        info.method = "CG + AMG (ML)";
        dealii::TrilinosWrappers::PreconditionAMG::AdditionalData amg;
        amg.elliptic              = true;
        amg.higher_order_elements = false;
        amg.aggregation_threshold = options.aggregation_threshold;
        amg.smoother_sweeps       = options.smoother_sweeps;
        amg.constant_modes        = constant_modes;
        dealii::TrilinosWrappers::PreconditionAMG amg_preconditioner;
        amg_preconditioner.initialize(A, amg);
        // AztecOO's criterion is absolute (|r| <= tol, unscaled)
        dealii::SolverControl control(options.max_iterations, options.relative_tolerance * b_norm);
        dealii::TrilinosWrappers::SolverCG solver(control);
        solver.solve(A, x, b, amg_preconditioner);
        info.iterations = control.last_step();
      }
    // the residual, independent of the solver's own measure
    Vector r;
    r.reinit(b, true);
    A.vmult(r, x);
    r.sadd(-1.0, 1.0, b);
    info.relative_residual = b_norm > 0 ? r.l2_norm() / b_norm : r.l2_norm();
    return info;
  }
} // namespace talus
