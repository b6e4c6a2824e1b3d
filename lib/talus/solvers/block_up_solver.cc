// talus — the iterative solver of the mixed u-p tangent ('linear solver/method =
// gmres block amg'; docs/implicit.md, "Block-preconditioned GMRES for mixed u-p").
//
// The tangent [K_uu K_up; K_pu K_pp] is one Trilinos matrix on the interleaved
// DoFs of the (dim + 1)-component NodalSpace. Right-preconditioned GMRES
// (deal.II's, on the NodalSpace's vectors) with the block upper-triangular
// preconditioner
//
//     P = [ A_hat  K_up  ]      P^-1 r:  z_p = S_hat^-1 r_p,
//         [ 0      S_hat ]               z_u = A_hat^-1 (r_u - K_up z_p)
//
// A_hat^-1: one V-cycle of ML smoothed-aggregation AMG on K_uu (with the rigid
// translations, and the rotations when the DoF positions are given, as its near
// null space); S_hat = diag(K_pp - K_pu diag(K_uu)^-1 K_up), the diagonal of
// the "SIMPLE" Schur complement approximation (formed by a sparse product: no
// material data needed). ML AMG on the whole SIMPLE matrix instead of its
// diagonal took as many GMRES iterations (docs/implicit.md).
#include <talus/solvers/linear_solver.h>

#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <EpetraExt_MatrixMatrix.h>
#include <Epetra_CrsMatrix.h>
#include <Epetra_Import.h>
#include <Epetra_Map.h>
#include <Epetra_MultiVector.h>
#include <Epetra_Vector.h>
#include <Teuchos_ParameterList.hpp>

#include <memory>
#include <stdexcept>
#include <string>

namespace talus
{
  namespace
  {
    void
    check(const int code, const char *what)
    {
      if (code != 0)
        throw std::runtime_error(std::string("gmres block amg: ") + what + " failed (Epetra code " +
                                 std::to_string(code) + ")");
    }

    /// The blocks of the u-p tangent and the two AMG hierarchies, and the
    /// preconditioner's vmult on the NodalSpace's vectors.
    class BlockUpPreconditioner
    {
    public:
      BlockUpPreconditioner(const dealii::TrilinosWrappers::SparseMatrix &A, const LinearSolverOptions &options,
                            const std::vector<std::vector<bool>> &constant_modes,
                            const std::vector<double>            &dof_coordinates)
      {
        const Epetra_CrsMatrix &M = A.trilinos_matrix();
        const Epetra_Map       &rows = M.RowMap();
        const Epetra_Map       &cols = M.ColMap();
        const int               n_owned = rows.NumMyElements();
        const unsigned int      n_comp  = constant_modes.size();
        if (n_comp < 2)
          throw std::invalid_argument("gmres block amg needs the mixed u-p system (a pressure component)");
        for (const auto &m : constant_modes)
          if (int(m.size()) != n_owned)
            throw std::invalid_argument("gmres block amg: the component masks do not match the matrix rows");
        const unsigned int dim = n_comp - 1;
        const auto        &p_mask = constant_modes.back();

        // which columns are pressures: the row flags imported onto the column map
        Epetra_Vector row_is_p(rows), col_is_p(cols);
        std::vector<int> u_gids, p_gids;
        for (int i = 0; i < n_owned; ++i)
          {
            row_is_p[i] = p_mask[i] ? 1.0 : 0.0;
            (p_mask[i] ? p_lids : u_lids).push_back(i);
            (p_mask[i] ? p_gids : u_gids).push_back(rows.GID(i));
          }
        Epetra_Import importer(cols, rows);
        check(col_is_p.Import(row_is_p, importer, Insert), "importing the pressure flags");
        u_map = std::make_unique<Epetra_Map>(-1, int(u_gids.size()), u_gids.data(), 0, M.Comm());
        p_map = std::make_unique<Epetra_Map>(-1, int(p_gids.size()), p_gids.data(), 0, M.Comm());

        // the four blocks by global index (the original numbering; Epetra builds
        // each block's column map)
        const int max_row = M.MaxNumEntries();
        K_uu              = std::make_unique<Epetra_CrsMatrix>(Copy, *u_map, max_row);
        K_up              = std::make_unique<Epetra_CrsMatrix>(Copy, *u_map, max_row);
        auto K_pu         = std::make_unique<Epetra_CrsMatrix>(Copy, *p_map, max_row);
        auto K_pp         = std::make_unique<Epetra_CrsMatrix>(Copy, *p_map, max_row);
        std::vector<double> vu, vp;
        std::vector<int>    gu, gp;
        for (int i = 0; i < n_owned; ++i)
          {
            int     n       = 0;
            double *values  = nullptr;
            int    *indices = nullptr;
            check(M.ExtractMyRowView(i, n, values, indices), "reading a row of the tangent");
            vu.clear(), vp.clear(), gu.clear(), gp.clear();
            for (int j = 0; j < n; ++j)
              if (col_is_p[indices[j]] != 0)
                vp.push_back(values[j]), gp.push_back(cols.GID(indices[j]));
              else
                vu.push_back(values[j]), gu.push_back(cols.GID(indices[j]));
            const int g = rows.GID(i);
            if (p_mask[i])
              {
                check(K_pu->InsertGlobalValues(g, int(vu.size()), vu.data(), gu.data()), "K_pu");
                check(K_pp->InsertGlobalValues(g, int(vp.size()), vp.data(), gp.data()), "K_pp");
              }
            else
              {
                check(K_uu->InsertGlobalValues(g, int(vu.size()), vu.data(), gu.data()), "K_uu");
                check(K_up->InsertGlobalValues(g, int(vp.size()), vp.data(), gp.data()), "K_up");
              }
          }
        check(K_uu->FillComplete(*u_map, *u_map), "K_uu fill");
        check(K_up->FillComplete(*p_map, *u_map), "K_up fill");
        check(K_pu->FillComplete(*u_map, *p_map), "K_pu fill");
        check(K_pp->FillComplete(*p_map, *p_map), "K_pp fill");

        // -S_hat = K_pu diag(K_uu)^-1 K_up - K_pp (positive: K_pp = -M/K - S_stab)
        Epetra_Vector d(*u_map);
        check(K_uu->ExtractDiagonalCopy(d), "diag(K_uu)");
        for (int i = 0; i < d.MyLength(); ++i)
          d[i] = d[i] != 0 ? 1.0 / d[i] : 0.0;
        Epetra_CrsMatrix D_K_up(*K_up);
        check(D_K_up.LeftScale(d), "diag(K_uu)^-1 K_up");
        Epetra_CrsMatrix product(Copy, *p_map, 0);
        check(EpetraExt::MatrixMatrix::Multiply(*K_pu, false, D_K_up, false, product), "K_pu D^-1 K_up");
        Epetra_CrsMatrix *sum = nullptr;
        check(EpetraExt::MatrixMatrix::Add(product, false, 1.0, *K_pp, false, -1.0, sum), "-S_hat");
        std::unique_ptr<Epetra_CrsMatrix> minus_S(sum);
        check(minus_S->FillComplete(*p_map, *p_map), "-S_hat fill");
        minus_S_diagonal = std::make_unique<Epetra_Vector>(*p_map);
        check(minus_S->ExtractDiagonalCopy(*minus_S_diagonal), "diag(-S_hat)");
        // a pressure row without any coupling (cannot occur: the inactive pins
        // have a diagonal) would divide by zero
        for (int i = 0; i < minus_S_diagonal->MyLength(); ++i)
          if ((*minus_S_diagonal)[i] == 0)
            (*minus_S_diagonal)[i] = 1;

        // AMG on K_uu with the rigid-body modes as its near null space
        const unsigned int n_u       = u_lids.size();
        const bool         rotations = dof_coordinates.size() == std::size_t(n_owned) * dim && dim > 1;
        const unsigned int n_modes   = dim + (rotations ? (dim == 3 ? 3 : 1) : 0);
        u_null_space                 = std::make_unique<Epetra_MultiVector>(*u_map, n_modes);
        for (unsigned int k = 0; k < n_u; ++k)
          {
            const int i = u_lids[k];
            int       c = 0;
            while (c < int(dim) && !constant_modes[c][i])
              ++c;
            (*u_null_space)[c][k] = 1.0;
            if (rotations)
              {
                const double *x = &dof_coordinates[std::size_t(i) * dim];
                if (dim == 2)
                  (*u_null_space)[2][k] = c == 0 ? -x[1] : x[0];
                else
                  {
                    // rotations about the x, y, z axes: omega x X
                    if (c == 0)
                      (*u_null_space)[4][k] = x[2], (*u_null_space)[5][k] = -x[1];
                    else if (c == 1)
                      (*u_null_space)[3][k] = -x[2], (*u_null_space)[5][k] = x[0];
                    else
                      (*u_null_space)[3][k] = x[1], (*u_null_space)[4][k] = -x[0];
                  }
              }
          }
        dealii::TrilinosWrappers::PreconditionAMG::AdditionalData data;
        data.elliptic              = true;
        data.higher_order_elements = false;
        data.aggregation_threshold = options.aggregation_threshold;
        data.smoother_sweeps       = options.smoother_sweeps;
        Teuchos::ParameterList              list;
        std::unique_ptr<Epetra_MultiVector> unused;
        data.set_parameters(list, unused, *K_uu);
        list.set("null space: type", "pre-computed");
        list.set("null space: dimension", int(n_modes));
        list.set("null space: vectors", u_null_space->Values());
        amg_u.initialize(*K_uu, list);
      }

      /// dst = P^-1 src (locally owned entries; the ghosts are not read)
      void
      vmult(Vector &dst, const Vector &src) const
      {
        Epetra_Vector r_u(*u_map), z_u(*u_map), r_p(*p_map), z_p(*p_map), w_u(*u_map);
        for (unsigned int k = 0; k < p_lids.size(); ++k)
          r_p[k] = src.local_element(p_lids[k]);
        for (unsigned int k = 0; k < u_lids.size(); ++k)
          r_u[k] = src.local_element(u_lids[k]);
        // z_p = S_hat^-1 r_p = -diag(-S_hat)^-1 r_p
        check(z_p.ReciprocalMultiply(-1.0, *minus_S_diagonal, r_p, 0.0), "the pressure diagonal");
        check(K_up->Multiply(false, z_p, w_u), "K_up z_p");
        check(r_u.Update(-1.0, w_u, 1.0), "r_u - K_up z_p");
        check(amg_u.trilinos_operator().ApplyInverse(r_u, z_u), "the displacement V-cycle");
        for (unsigned int k = 0; k < p_lids.size(); ++k)
          dst.local_element(p_lids[k]) = z_p[k];
        for (unsigned int k = 0; k < u_lids.size(); ++k)
          dst.local_element(u_lids[k]) = z_u[k];
      }

    private:
      std::vector<int>                          u_lids, p_lids; // local rows of each block
      std::unique_ptr<Epetra_Map>               u_map, p_map;
      std::unique_ptr<Epetra_CrsMatrix>         K_uu, K_up;
      std::unique_ptr<Epetra_Vector>            minus_S_diagonal;
      std::unique_ptr<Epetra_MultiVector>       u_null_space; // referenced by ML
      dealii::TrilinosWrappers::PreconditionAMG amg_u;
    };
  } // namespace

  LinearSolveInfo
  solve_block_up(const dealii::TrilinosWrappers::SparseMatrix &A, Vector &x, const Vector &b,
                 const LinearSolverOptions &options, const std::vector<std::vector<bool>> &constant_modes,
                 const std::vector<double> &dof_coordinates)
  {
    LinearSolveInfo             info;
    const BlockUpPreconditioner preconditioner(A, options, constant_modes, dof_coordinates);
    info.method = "GMRES + block preconditioner (ML AMG on K_uu, diagonal SIMPLE Schur complement)";
    // deal.II's criterion is absolute: |r| <= tol; with right preconditioning
    // GMRES measures the true residual |b - A x|
    dealii::SolverControl control(options.max_iterations, options.relative_tolerance * b.l2_norm());
    dealii::SolverGMRES<Vector> solver(control, dealii::SolverGMRES<Vector>::AdditionalData(302, true));
    solver.solve(A, x, b, preconditioner);
    info.iterations = control.last_step();
    // the residual, independent of the solver's own measure
    Vector r;
    r.reinit(b, true);
    A.vmult(r, x);
    r.sadd(-1.0, 1.0, b);
    const double b_norm    = b.l2_norm();
    info.relative_residual = b_norm > 0 ? r.l2_norm() / b_norm : r.l2_norm();
    return info;
  }
} // namespace talus
