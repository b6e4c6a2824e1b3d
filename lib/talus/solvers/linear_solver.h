// talus — linear solvers for the Trilinos matrices of the implicit families
// (ActiveSet::reinit_matrix + transfer::assemble): a direct solve (Amesos KLU)
// or CG preconditioned with ML algebraic multigrid. Shared by the implicit and
// semi-implicit families, so it lives beside grid/ and transfer/ rather than
// under one formulation.
#pragma once

#include <talus/grid/background_grid.h>

#include <memory>
#include <string>
#include <vector>

namespace dealii::TrilinosWrappers
{
  class SparseMatrix;
  class PreconditionAMG;
} // namespace dealii::TrilinosWrappers

namespace talus
{
  struct LinearSolverOptions
  {
    enum class Method
    {
      direct,         ///< TrilinosWrappers::SolverDirect (Amesos_Klu)
      cg_amg,         ///< TrilinosWrappers::SolverCG + PreconditionAMG (ML): symmetric matrices
      gmres_amg,      ///< TrilinosWrappers::SolverGMRES (restart 100) + PreconditionAMG (ML): non-symmetric ones
      gmres_block_amg ///< mixed u-p: GMRES with a block-triangular preconditioner (solve_block_up)
    };
    Method method = Method::direct;
    /// direct: the Amesos package ("Amesos_Klu" or "Amesos_Mumps"). KLU's
    /// pivoting fills the indefinite mixed u-p tangent: MUMPS solved the 2D
    /// strip footing's 2100-DoF system 9x faster and to 1e-14 instead of 1e-10
    /// (docs/implicit.md, "Rigid strip footing")
    std::string direct_package = "Amesos_Klu";
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
    unsigned int iterations        = 0; ///< CG or GMRES iterations; 1 for the direct solve
    double       relative_residual = 0; ///< |b - A x| / |b| after the solve
  };

  /// Solve A x = b (x: initial guess for CG, overwritten). `constant_modes`
  /// (NodalSpace::constant_modes(): one per component) help AMG on vector
  /// problems; empty: a single mode. `dof_coordinates` (gmres_block_amg only,
  /// optional): dim coordinates per locally owned DoF, for the rigid rotations
  /// of the displacement AMG. Collective. Throws on non-convergence.
  LinearSolveInfo solve_linear(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
                               const LinearSolverOptions            &options,
                               const std::vector<std::vector<bool>> &constant_modes  = {},
                               const std::vector<double>            &dof_coordinates = {});

  /// Mixed u-p: right-preconditioned GMRES (deal.II's, restart 300) to |b - A x|
  /// <= tol |b| with the block upper-triangular preconditioner [A_hat K_up; 0
  /// S_hat]: one ML V-cycle on K_uu (near null space: the translations and,
  /// with `dof_coordinates`, the rotations); S_hat the diagonal of K_pp -
  /// K_pu diag(K_uu)^-1 K_up. The blocks are taken out of A by the component
  /// masks `constant_modes` (dim + 1 of them, the last the pressure; the DoFs
  /// may be interleaved). solvers/block_up_solver.cc. Collective.
  LinearSolveInfo solve_block_up(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
                                 const LinearSolverOptions            &options,
                                 const std::vector<std::vector<bool>> &constant_modes,
                                 const std::vector<double>            &dof_coordinates = {});

  /// The direct solve of solve_linear (one factorisation of A, with its
  /// iterative refinement) for several right-hand sides: xs[k] from bs[k]
  /// (xs resized like bs). `iterations` counts the right-hand sides,
  /// `relative_residual` is the largest of them. Collective.
  LinearSolveInfo solve_direct(const dealii::TrilinosWrappers::SparseMatrix &A, std::vector<Vector> &xs,
                               const std::vector<Vector> &bs, const std::string &direct_package);

  /// CG + ML AMG whose hierarchy is kept from one solve to the next (the ML
  /// set-up has a fixed cost of ~3 ms per call, most of a small system's
  /// solve). A kept hierarchy was built from an older matrix: CG still
  /// converges to the same tolerance, in a few more iterations. It is rebuilt
  /// at the next solve after invalidate() and at every solve whose `step` is a
  /// multiple of the rebuild interval, and after a slow solve: one with a kept
  /// hierarchy that needed more than 2 x + 10 the iterations of the first
  /// solve with that hierarchy (the matrix has drifted too far from it). The
  /// rebuilds so depend only on the step number, on the states since the last
  /// rebuild and on the caller's invalidate() calls: a restarted run rebuilds
  /// where the uninterrupted one does if the caller invalidates at every
  /// checkpoint write (and at its first step, where it builds anyway).
  /// ML's finest level keeps a reference to A's Epetra matrix (not a copy):
  /// refill A's values in place (A = 0, assemble) between rebuilds, and call
  /// invalidate() whenever A is reinit (a new Epetra object) or changes shape.
  class ReusedAMGSolver
  {
  public:
    ReusedAMGSolver();
    ~ReusedAMGSolver();

    /// 1: a new hierarchy at every solve (no reuse). >= 1.
    void set_rebuild_interval(unsigned int n);
    unsigned int
    rebuild_interval() const
    {
      return interval;
    }
    /// The next solve builds a new hierarchy.
    void
    invalidate()
    {
      stale = true;
    }

    /// Solve A x = b as solve_linear with `options.method` cg_amg. When CG
    /// with a kept hierarchy fails (throws), the hierarchy is rebuilt and the
    /// solve repeated once (counted in n_fallbacks()). Collective.
    LinearSolveInfo solve(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
                          const LinearSolverOptions &options, unsigned long long step,
                          const std::vector<std::vector<bool>> &constant_modes = {});

    /// Hierarchies built so far (settable: a checkpoint carries the count).
    unsigned long long
    n_setups() const
    {
      return setups;
    }
    void
    set_n_setups(const unsigned long long n)
    {
      setups = n;
    }
    unsigned long long
    n_fallbacks() const
    {
      return fallbacks;
    }
    /// Solves after which the next one rebuilds because they were slow.
    unsigned long long
    n_slow_solves() const
    {
      return slow_solves;
    }
    /// Wall time spent in the ML set-up [s] and whether the last solve built one.
    double
    setup_seconds() const
    {
      return seconds_setup;
    }
    bool
    last_solve_rebuilt() const
    {
      return rebuilt;
    }

  private:
    void build(const dealii::TrilinosWrappers::SparseMatrix &A, const LinearSolverOptions &options,
               const std::vector<std::vector<bool>> &constant_modes);

    std::unique_ptr<dealii::TrilinosWrappers::PreconditionAMG> amg;
    unsigned int                                               interval = 1;
    bool                                                       stale = true, rebuilt = false;
    unsigned long long                                         setups = 0, fallbacks = 0, slow_solves = 0;
    unsigned int fresh_iterations = 0; ///< of the first solve with the current hierarchy
    double       seconds_setup    = 0;
  };
} // namespace talus
