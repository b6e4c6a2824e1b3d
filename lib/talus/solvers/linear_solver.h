// talus — linear solvers for the Trilinos matrices of the implicit families
// (ActiveSet::reinit_matrix + transfer::assemble): a direct solve (Amesos KLU)
// or CG preconditioned with ML algebraic multigrid. Shared by the implicit and
// semi-implicit families, so it lives beside grid/ and transfer/ rather than
// under one formulation.
#pragma once

#include <talus/grid/background_grid.h>

#include <string>
#include <vector>

namespace dealii::TrilinosWrappers
{
  class SparseMatrix;
}

namespace talus
{
  struct LinearSolverOptions
  {
    enum class Method
    {
      direct, ///< TrilinosWrappers::SolverDirect (Amesos_Klu)
      cg_amg  ///< TrilinosWrappers::SolverCG + PreconditionAMG (ML)
    };
    Method method = Method::direct;
    /// CG: stop when |b - A x| <= relative_tolerance |b|. AztecOO throws "loss of
    /// precision" (error -3) when this nears round-off x condition number
    /// (1e-12 on a 3300-DoF column did): keep it well above.
    double       relative_tolerance = 1e-10;
    unsigned int max_iterations     = 1000;
    /// AMG: ML's aggregation threshold and the smoother sweeps per level
    double       aggregation_threshold = 1e-4;
    unsigned int smoother_sweeps       = 2;
  };

  struct LinearSolveInfo
  {
    std::string  method;
    unsigned int iterations = 0; ///< CG iterations; 1 for the direct solve
    double       relative_residual = 0; ///< |b - A x| / |b| after the solve
  };

  /// Solve A x = b (x: initial guess for CG, overwritten). `constant_modes`
  /// (NodalSpace::constant_modes(): one per component) help AMG on vector
  /// problems; empty: a single mode. Collective. Throws on non-convergence.
  LinearSolveInfo solve_linear(const dealii::TrilinosWrappers::SparseMatrix &A,
                               Vector &                                      x,
                               const Vector &                                b,
                               const LinearSolverOptions &                   options,
                               const std::vector<std::vector<bool>> &        constant_modes = {});
} // namespace talus
