// talus — the iterative solver of the mixed u-p tangent ('linear solver/method =
// gmres block amg'; docs/implicit.md, "Block-preconditioned GMRES for mixed u-p").
//
// The tangent [K_uu K_up; K_pu K_pp] is one Trilinos matrix on the interleaved
// DoFs of the (dim + 1)-component NodalSpace. Right-preconditioned GMRES
// (deal.II's, on Trilinos vectors of the active DoFs: the pinned rows are
// solved directly) with the block upper-triangular preconditioner
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
#include <deal.II/lac/trilinos_vector.h>

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

    using TrilinosVector = dealii::TrilinosWrappers::MPI::Vector;

    /// The active part of the u-p tangent, its blocks and the displacement AMG
    /// hierarchy; vmult is the preconditioner on vectors of the active DoFs.
    ///
    /// The tangent has a row for every DoF of the grid; those no point touches
    /// are pinned (a row holding its diagonal only, ActiveSet). GMRES runs on
    /// the other ("active") DoFs: on a grid much larger than the body its
    /// vectors would otherwise be mostly zeros (the bench block: 62,500 of
    /// 470,596 rows), and the AMG would aggregate the pinned rows too.
    class BlockUpSystem
    {
    public:
      BlockUpSystem(const dealii::TrilinosWrappers::SparseMatrix &A, const LinearSolverOptions &options,
                    const std::vector<std::vector<bool>> &constant_modes, const std::vector<double> &dof_coordinates)
      {
        const Epetra_CrsMatrix &M       = A.trilinos_matrix();
        const Epetra_Map       &rows    = M.RowMap();
        const Epetra_Map       &cols    = M.ColMap();
        const int               n_owned = rows.NumMyElements();
        const unsigned int      n_comp  = constant_modes.size();
        if (n_comp < 2)
          throw std::invalid_argument("gmres block amg needs the mixed u-p system (a pressure component)");
        for (const auto &m : constant_modes)
          if (int(m.size()) != n_owned)
            throw std::invalid_argument("gmres block amg: the component masks do not match the matrix rows");
        const unsigned int dim    = n_comp - 1;
        const auto        &p_mask = constant_modes.back();

        // per row: 0 pinned, 1 displacement, 2 pressure; imported onto the
        // column map for the columns
        Epetra_Vector    row_kind(rows), col_kind(cols);
        std::vector<int> active_gids, u_gids, p_gids, u_rows;
        for (int i = 0; i < n_owned; ++i)
          {
            int     n       = 0;
            double *values  = nullptr;
            int    *indices = nullptr;
            check(M.ExtractMyRowView(i, n, values, indices), "reading a row of the tangent");
            const int g = rows.GID(i);
            if (n == 1 && cols.GID(indices[0]) == g)
              {
                pinned_rows.push_back(i);
                pinned_diagonal.push_back(values[0]);
                continue;
              }
            row_kind[i] = p_mask[i] ? 2.0 : 1.0;
            (p_mask[i] ? p_active : u_active).push_back(int(active_rows.size()));
            (p_mask[i] ? p_gids : u_gids).push_back(g);
            if (!p_mask[i])
              u_rows.push_back(i);
            active_rows.push_back(i);
            active_gids.push_back(g);
          }
        Epetra_Import importer(cols, rows);
        check(col_kind.Import(row_kind, importer, Insert), "importing the DoF kinds");
        active_map = std::make_unique<Epetra_Map>(-1, int(active_gids.size()), active_gids.data(), 0, M.Comm());
        u_map      = std::make_unique<Epetra_Map>(-1, int(u_gids.size()), u_gids.data(), 0, M.Comm());
        p_map      = std::make_unique<Epetra_Map>(-1, int(p_gids.size()), p_gids.data(), 0, M.Comm());
        active_set.set_size(A.m());
        active_set.add_indices(active_gids.begin(), active_gids.end());
        active_set.compress();

        // the active matrix and its four blocks, by global index (the original
        // numbering; Epetra builds each one's column map)
        const int max_row        = M.MaxNumEntries();
        A_active                 = std::make_unique<Epetra_CrsMatrix>(Copy, *active_map, max_row);
        K_uu                     = std::make_unique<Epetra_CrsMatrix>(Copy, *u_map, max_row);
        K_up                     = std::make_unique<Epetra_CrsMatrix>(Copy, *u_map, max_row);
        auto                K_pu = std::make_unique<Epetra_CrsMatrix>(Copy, *p_map, max_row);
        auto                K_pp = std::make_unique<Epetra_CrsMatrix>(Copy, *p_map, max_row);
        std::vector<double> va, vu, vp;
        std::vector<int>    ga, gu, gp;
        for (const int i : active_rows)
          {
            int     n       = 0;
            double *values  = nullptr;
            int    *indices = nullptr;
            check(M.ExtractMyRowView(i, n, values, indices), "reading a row of the tangent");
            va.clear(), vu.clear(), vp.clear(), ga.clear(), gu.clear(), gp.clear();
            for (int j = 0; j < n; ++j)
              {
                const double kind = col_kind[indices[j]];
                if (kind == 0)
                  continue; // a pinned column: its value moves to the right-hand side (solve_block_up)
                va.push_back(values[j]), ga.push_back(cols.GID(indices[j]));
                if (kind == 2)
                  vp.push_back(values[j]), gp.push_back(ga.back());
                else
                  vu.push_back(values[j]), gu.push_back(ga.back());
              }
            const int g = rows.GID(i);
            check(A_active->InsertGlobalValues(g, int(va.size()), va.data(), ga.data()), "the active tangent");
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
        check(A_active->FillComplete(*active_map, *active_map), "active tangent fill");
        check(K_uu->FillComplete(*u_map, *u_map), "K_uu fill");
        check(K_up->FillComplete(*p_map, *u_map), "K_up fill");
        check(K_pu->FillComplete(*u_map, *p_map), "K_pu fill");
        check(K_pp->FillComplete(*p_map, *p_map), "K_pp fill");

        // -S_hat = diag(K_pu diag(K_uu)^-1 K_up - K_pp) (positive: K_pp = -M/K - S_stab)
        Epetra_Vector d(*u_map);
        check(K_uu->ExtractDiagonalCopy(d), "diag(K_uu)");
        for (int i = 0; i < d.MyLength(); ++i)
          d[i] = d[i] != 0 ? 1.0 / d[i] : 0.0;
        Epetra_CrsMatrix D_K_up(*K_up);
        check(D_K_up.LeftScale(d), "diag(K_uu)^-1 K_up");
        Epetra_CrsMatrix product(Copy, *p_map, 0);
        check(EpetraExt::MatrixMatrix::Multiply(*K_pu, false, D_K_up, false, product), "K_pu D^-1 K_up");
        minus_S_diagonal = std::make_unique<Epetra_Vector>(*p_map);
        Epetra_Vector pp(*p_map);
        check(product.ExtractDiagonalCopy(*minus_S_diagonal), "diag(K_pu D^-1 K_up)");
        check(K_pp->ExtractDiagonalCopy(pp), "diag(K_pp)");
        check(minus_S_diagonal->Update(-1.0, pp, 1.0), "diag(-S_hat)");
        for (int i = 0; i < minus_S_diagonal->MyLength(); ++i)
          if ((*minus_S_diagonal)[i] == 0) // not met: an active pressure row has a mass term
            (*minus_S_diagonal)[i] = 1;

        // AMG on K_uu with the rigid-body modes as its near null space
        const bool         rotations = dof_coordinates.size() == std::size_t(n_owned) * dim && dim > 1;
        const unsigned int n_modes   = dim + (rotations ? (dim == 3 ? 3 : 1) : 0);
        u_null_space                 = std::make_unique<Epetra_MultiVector>(*u_map, n_modes);
        for (unsigned int k = 0; k < u_rows.size(); ++k)
          {
            const int i = u_rows[k];
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

      /// dst = A_active src
      struct ActiveMatrix
      {
        const Epetra_CrsMatrix &A;
        void
        vmult(TrilinosVector &dst, const TrilinosVector &src) const
        {
          check(A.Multiply(false, src.trilinos_vector(), dst.trilinos_vector()), "the active tangent's product");
        }
      };
      ActiveMatrix
      active_matrix() const
      {
        return {*A_active};
      }

      /// dst = P^-1 src on the active DoFs
      void
      vmult(TrilinosVector &dst, const TrilinosVector &src) const
      {
        const double *s = src.trilinos_vector()[0];
        double       *t = dst.trilinos_vector()[0];
        Epetra_Vector r_u(*u_map), z_u(*u_map), r_p(*p_map), z_p(*p_map), w_u(*u_map);
        for (unsigned int k = 0; k < p_active.size(); ++k)
          r_p[k] = s[p_active[k]];
        for (unsigned int k = 0; k < u_active.size(); ++k)
          r_u[k] = s[u_active[k]];
        // z_p = S_hat^-1 r_p = -diag(-S_hat)^-1 r_p
        check(z_p.ReciprocalMultiply(-1.0, *minus_S_diagonal, r_p, 0.0), "the pressure diagonal");
        check(K_up->Multiply(false, z_p, w_u), "K_up z_p");
        check(r_u.Update(-1.0, w_u, 1.0), "r_u - K_up z_p");
        check(amg_u.trilinos_operator().ApplyInverse(r_u, z_u), "the displacement V-cycle");
        for (unsigned int k = 0; k < p_active.size(); ++k)
          t[p_active[k]] = z_p[k];
        for (unsigned int k = 0; k < u_active.size(); ++k)
          t[u_active[k]] = z_u[k];
      }

      std::vector<int>    active_rows, pinned_rows; ///< owned rows of the tangent (local indices)
      std::vector<double> pinned_diagonal;
      dealii::IndexSet    active_set;

    private:
      std::vector<int>                          u_active, p_active; ///< positions among the active rows
      std::unique_ptr<Epetra_Map>               active_map, u_map, p_map;
      std::unique_ptr<Epetra_CrsMatrix>         A_active, K_uu, K_up;
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
    LinearSolveInfo     info;
    const BlockUpSystem system(A, options, constant_modes, dof_coordinates);
    info.method = "GMRES + block preconditioner (ML AMG on K_uu, diagonal SIMPLE Schur complement)";
    // the pinned rows are solved at once; their columns move to the right-hand side
    x = 0;
    for (unsigned int k = 0; k < system.pinned_rows.size(); ++k)
      if (system.pinned_diagonal[k] != 0) // a zero one stays 0 (and shows in the residual)
        x.local_element(system.pinned_rows[k]) = b.local_element(system.pinned_rows[k]) / system.pinned_diagonal[k];
    Vector r;
    r.reinit(b, true);
    A.vmult(r, x);
    r.sadd(-1.0, 1.0, b);
    TrilinosVector rhs(system.active_set, A.get_mpi_communicator()), y(rhs);
    for (unsigned int k = 0; k < system.active_rows.size(); ++k)
      rhs.trilinos_vector()[0][k] = r.local_element(system.active_rows[k]);
    y = 0;
    // deal.II's criterion is absolute: |r| <= tol; with right preconditioning
    // GMRES measures the true residual |b - A x| (of the active rows: the
    // pinned ones are solved exactly)
    dealii::SolverControl               control(options.max_iterations, options.relative_tolerance * b.l2_norm());
    dealii::SolverGMRES<TrilinosVector> solver(control, dealii::SolverGMRES<TrilinosVector>::AdditionalData(302, true));
    solver.solve(system.active_matrix(), y, rhs, system);
    info.iterations = control.last_step();
    for (unsigned int k = 0; k < system.active_rows.size(); ++k)
      x.local_element(system.active_rows[k]) = y.trilinos_vector()[0][k];
    // the residual, independent of the solver's own measure
    A.vmult(r, x);
    r.sadd(-1.0, 1.0, b);
    const double b_norm    = b.l2_norm();
    info.relative_residual = b_norm > 0 ? r.l2_norm() / b_norm : r.l2_norm();
    return info;
  }
} // namespace talus
