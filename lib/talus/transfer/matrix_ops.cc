#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.templates.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace talus::transfer
{
  void
  distribute_local(const dealii::AffineConstraints<double> &constraints, const unsigned int m, const double *A_local,
                   const double *b_local, const unsigned int stride,
                   const std::vector<dealii::types::global_dof_index> &dofs, dealii::TrilinosWrappers::SparseMatrix *A,
                   Vector *b)
  {
    // scratch kept between calls (the walk is serial)
    static thread_local dealii::FullMatrix<double> Am;
    static thread_local dealii::Vector<double>     bm;
    if (Am.m() != m)
      Am.reinit(m, m);
    if (bm.size() != m)
      bm.reinit(m);
    if (A_local != nullptr)
      for (unsigned int i = 0; i < m; ++i)
        for (unsigned int j = 0; j < m; ++j)
          Am(i, j) = A_local[i * stride + j];
    else
      Am = 0;
    if (b_local != nullptr)
      for (unsigned int i = 0; i < m; ++i)
        bm(i) = b_local[i];
    else
      bm = 0;
    // Constrained columns with inhomogeneities move to the right-hand side
    // (-A_ij g_j): the vector needs the local matrix in the same call.
    if (A != nullptr && b != nullptr)
      constraints.distribute_local_to_global(Am, bm, dofs, *A, *b);
    else if (A != nullptr)
      constraints.distribute_local_to_global(Am, dofs, *A);
    else if (b != nullptr)
      constraints.distribute_local_to_global(bm, dofs, *b, Am);
  }

  struct FixedValueDistributor::Impl
  {
    const dealii::AffineConstraints<double>   &constraints;
    const dealii::Utilities::MPI::Partitioner &part;
    dealii::TrilinosWrappers::SparseMatrix    *A;
    Vector                                    *b;
    const Epetra_CrsMatrix                    *E      = nullptr;
    bool                                       usable = false, wrote = false;
    /// per partitioner-local index: 0 free, 1 fixed to 0, 2 fixed to value[l]
    std::vector<unsigned char> state;
    std::vector<double>        value;
    // scratch per cell
    std::vector<unsigned int> local, free_rows, fixed_rows, inhomogeneous, order;
    std::vector<int>          column;
    /// position of each local column in the row being filled (-1: not in it)
    std::vector<long> position_in_row;
    /// Epetra local row and column index of each partitioner-local DoF, looked
    /// up at its first use in this assembly (-2: not yet, -1: not in the map):
    /// a map's LID is a hash look-up, and a DoF comes up in every cell of its
    /// support (up to 4^dim B-spline patches)
    std::vector<int> row_lid, col_lid;
    static inline int
    cached_lid(std::vector<int> &cache, const Epetra_Map &map, const unsigned int l,
               const dealii::types::global_dof_index g)
    {
      int &id = cache[l];
      if (id == -2)
        id = map.LID(static_cast<int>(g));
      return id;
    }
    std::vector<dealii::types::global_dof_index> cols;
    std::vector<double>                          vals;

    Impl(const dealii::AffineConstraints<double> &c, const dealii::Utilities::MPI::Partitioner &p,
         dealii::TrilinosWrappers::SparseMatrix *A, Vector *b)
        : constraints(c)
        , part(p)
        , A(A)
        , b(b)
    {
      if (A == nullptr)
        return;
      E = &A->trilinos_matrix();
      if (!E->Filled() || !E->IndicesAreLocal())
        return;
      if (b != nullptr && b->get_partitioner().get() != &part && !b->get_partitioner()->is_compatible(part))
        return;
      const unsigned int n = part.locally_owned_size() + part.n_ghost_indices();
      state.assign(n, 0);
      value.assign(n, 0.0);
      for (const auto &line : constraints.get_lines())
        {
          if (!line.entries.empty())
            return; // a line with entries: deal.II's general path
          const auto g = line.index;
          if (!part.in_local_range(g) && !part.is_ghost_entry(g))
            return;
          const unsigned int l = part.global_to_local(g);
          state[l]             = line.inhomogeneity != 0.0 ? 2 : 1;
          value[l]             = line.inhomogeneity;
        }
      slot.assign(E->ColMap().NumMyElements(), 0);
      row_lid.assign(n, -2);
      col_lid.assign(n, -2);
      usable = true;
    }

    /// Where each local column of an Epetra row sits in the row: `slot` of
    /// column l is valid for the row being filled when its stamp is current
    /// (no clearing between rows). Filled by open_row, read by position.
    std::vector<unsigned long long> slot; // (stamp << 32) | position
    unsigned long long              stamp      = 0;
    double                         *row_values = nullptr;

    inline void
    open_row(const int lr)
    {
      int  n   = 0;
      int *idx = nullptr;
      E->ExtractMyRowView(lr, n, row_values, idx);
      ++stamp;
      for (int q = 0; q < n; ++q)
        slot[idx[q]] = (stamp << 32) | static_cast<unsigned int>(q);
    }
    /// position of local column lc in the open row, or -1
    inline long
    position(const int lc) const
    {
      if (lc < 0)
        return -1;
      const unsigned long long s = slot[lc];
      return (s >> 32) == stamp ? static_cast<long>(s & 0xffffffffULL) : -1;
    }

    /// deal.II's SparseMatrix::add throws (ExcTrilinosError, Epetra's ierr 2)
    /// for a non-zero entry outside the pattern; so does this
    [[noreturn]] static void
    outside_pattern(const dealii::types::global_dof_index row, const dealii::types::global_dof_index col)
    {
      throw std::runtime_error("transfer::FixedValueDistributor: a non-zero matrix entry (" + std::to_string(row) +
                               ", " + std::to_string(col) + ") outside the sparsity pattern");
    }

    /// open row += v at local column lc (global row, col: for the error)
    inline void
    add_in_open_row(const int lc, const double v, const dealii::types::global_dof_index row,
                    const dealii::types::global_dof_index col)
    {
      const long q = position(lc);
      if (q < 0)
        outside_pattern(row, col);
      row_values[q] += v;
    }

    void
    distribute(const unsigned int m, const double *Al, const double *bl, const unsigned int stride,
               const std::vector<dealii::types::global_dof_index> &dofs)
    {
      local.resize(m);
      free_rows.clear();
      fixed_rows.clear();
      for (unsigned int i = 0; i < m; ++i)
        {
          const auto g = dofs[i];
          if (!part.in_local_range(g) && !part.is_ghost_entry(g))
            {
              // a DoF this rank does not hold: deal.II's path for the whole cell
              distribute_local(constraints, m, Al, bl, stride, dofs, A, b);
              return;
            }
          local[i] = part.global_to_local(g);
          (state[local[i]] == 0 ? free_rows : fixed_rows).push_back(i);
        }
      const Epetra_Map &row_map = E->RowMap(), &col_map = E->ColMap();
      const auto        row_of = [&](const unsigned int i) { return cached_lid(row_lid, row_map, local[i], dofs[i]); };

      // Epetra column index of every local DoF (-1: not in the column map, in
      // no pattern row here)
      column.resize(m);
      for (unsigned int i = 0; i < m; ++i)
        column[i] = cached_lid(col_lid, col_map, local[i], dofs[i]);

      // (1) matrix rows of the free DoFs, free columns only (deal.II:
      // resolve_matrix_row, zero entries elided). The rows of one node's
      // components have the same column list (a space couples all components
      // of two nodes): the positions of the cell's columns found in one row
      // serve the next ones after a check of each used position (idx[q] is
      // the column), instead of a new stamp of the whole row.
      position_in_row.resize(m);
      bool have_positions = false;
      for (const unsigned int r : free_rows)
        {
          const double *row = Al + r * stride;
          const int     lr  = row_of(r);
          if (lr >= 0)
            {
              int     n   = 0;
              int    *idx = nullptr;
              double *val = nullptr;
              E->ExtractMyRowView(lr, n, val, idx);
              bool reuse = have_positions;
              for (unsigned int k = 0; reuse && k < free_rows.size(); ++k)
                {
                  const unsigned int c = free_rows[k];
                  const long         q = position_in_row[c];
                  reuse                = q >= 0 ? (q < n && idx[q] == column[c]) : row[c] == 0.0;
                }
              if (reuse)
                row_values = val;
              else
                {
                  open_row(lr);
                  for (const unsigned int c : free_rows)
                    position_in_row[c] = position(column[c]);
                  have_positions = true;
                }
              for (const unsigned int c : free_rows)
                {
                  const double a = row[c];
                  if (a == 0.0)
                    continue;
                  const long q = position_in_row[c];
                  if (q < 0)
                    outside_pattern(dofs[r], dofs[c]);
                  row_values[q] += a;
                }
              wrote = true;
            }
          else
            {
              // another rank's row: as deal.II (columns in ascending global order)
              cols.clear();
              vals.clear();
              order.assign(free_rows.begin(), free_rows.end());
              const unsigned int k = order.size();
              std::sort(order.begin(), order.end(),
                        [&](const unsigned int x, const unsigned int y) { return dofs[x] < dofs[y]; });
              for (unsigned int q = 0; q < k; ++q)
                if (row[order[q]] != 0.0)
                  {
                    cols.push_back(dofs[order[q]]);
                    vals.push_back(row[order[q]]);
                  }
              if (!cols.empty())
                A->add(dofs[r], cols.size(), cols.data(), vals.data(), false, true);
            }
        }

      // (2) the right-hand side of the free rows: b_r - sum_k A_rk g_k over the
      // inhomogeneous constrained k in deal.II's order (descending local index)
      if (b != nullptr && bl != nullptr)
        {
          inhomogeneous.clear();
          for (auto it = fixed_rows.rbegin(); it != fixed_rows.rend(); ++it)
            if (state[local[*it]] == 2)
              inhomogeneous.push_back(*it);
          for (const unsigned int r : free_rows)
            {
              double val = bl[r];
              for (const unsigned int k : inhomogeneous)
                val -= (Al[r * stride + k] * value[local[k]]);
              if (val != 0.0)
                b->local_element(local[r]) += val;
            }
        }

      // (3) constrained rows: their |local diagonal|, or the mean |diagonal| of
      // the local matrix (deal.II: set_matrix_diagonals)
      if (!fixed_rows.empty())
        {
          double average = 0;
          for (unsigned int i = 0; i < m; ++i)
            average += std::abs(Al[i * stride + i]);
          average /= static_cast<double>(m);
          if (average == 0.0)
            {
              double max = 0;
              for (unsigned int j = 0; j < m; ++j)
                {
                  double sum = 0;
                  for (unsigned int i = 0; i < m; ++i)
                    sum += std::abs(Al[i * stride + j]);
                  if (sum > max)
                    max = sum;
                }
              average = max / static_cast<double>(m);
              if (average == 0.0)
                average = 1.0;
            }
          for (const unsigned int i : fixed_rows)
            {
              const double d  = Al[i * stride + i] != 0.0 ? std::abs(Al[i * stride + i]) : average;
              const int    lr = row_of(i);
              if (lr >= 0)
                {
                  open_row(lr);
                  add_in_open_row(column[i], d, dofs[i], dofs[i]);
                  wrote = true;
                }
              else
                A->add(dofs[i], dofs[i], d);
            }
        }
    }

    ~Impl()
    {
      // values changed behind Epetra's back: drop its cached norms (an add of
      // no entries resets them)
      if (wrote && E->NumMyRows() > 0)
        const_cast<Epetra_CrsMatrix *>(E)->SumIntoMyValues(0, 0, nullptr, nullptr);
    }
  };

  FixedValueDistributor::FixedValueDistributor(const dealii::AffineConstraints<double>   &constraints,
                                               const dealii::Utilities::MPI::Partitioner &partitioner,
                                               dealii::TrilinosWrappers::SparseMatrix *A, Vector *b)
      : impl(std::make_unique<Impl>(constraints, partitioner, A, b))
  {
  }
  FixedValueDistributor::~FixedValueDistributor() = default;
  bool
  FixedValueDistributor::usable() const
  {
    return impl->usable;
  }
  void
  FixedValueDistributor::distribute(const unsigned int m, const double *A_local, const double *b_local,
                                    const unsigned int stride, const std::vector<dealii::types::global_dof_index> &dofs)
  {
    impl->distribute(m, A_local, b_local, stride, dofs);
  }

  template <int dim>
  void
  finish_assembly(const ActiveSet<dim> &active, const double diag_sum, const double diag_count,
                  dealii::TrilinosWrappers::SparseMatrix *A, Vector *b)
  {
    const MPI_Comm comm = active.space.grid.comm;
    if (A != nullptr)
      {
        A->compress(dealii::VectorOperation::add);
        const double     s        = dealii::Utilities::MPI::sum(diag_sum, comm);
        const double     n        = dealii::Utilities::MPI::sum(diag_count, comm);
        const double     d        = s > 0 ? s / n : 1.0;
        dealii::IndexSet inactive = active.space.locally_owned_dofs();
        inactive.subtract_set(active.active_owned_dofs());
        for (const auto i : inactive)
          A->set(i, i, d);
        A->compress(dealii::VectorOperation::insert);
      }
    if (b != nullptr)
      b->compress(dealii::VectorOperation::add);
  }

  template void finish_assembly(const ActiveSet<2> &, double, double, dealii::TrilinosWrappers::SparseMatrix *,
                                Vector *);
  template void finish_assembly(const ActiveSet<3> &, double, double, dealii::TrilinosWrappers::SparseMatrix *,
                                Vector *);

  // the common assemblies for both kernels
  template <int dim>
  using ElasticAndGravity = Sum<LinearElasticStiffness, BodyForce<dim>>;
#define TALUS_ASSEMBLE(dim, K, nc, Integrand)                                                                         \
  template void assemble<dim, K, nc, Integrand>(const std::vector<MaterialPointSet<dim> *> &, const ActiveSet<dim> &, \
                                                const dealii::AffineConstraints<double> &, const Integrand &,         \
                                                dealii::TrilinosWrappers::SparseMatrix *, Vector *, const Vector *);
#define TALUS_MATRIX_OPS(dim, K)                                       \
  template struct AssembleSystem<dim, K, dim, ConsistentMass>;         \
  template struct AssembleSystem<dim, K, 1, ConsistentMass>;           \
  template struct AssembleSystem<dim, K, dim, LinearElasticStiffness>; \
  template struct AssembleSystem<dim, K, dim, BodyForce<dim>>;         \
  template struct AssembleSystem<dim, K, dim, ElasticAndGravity<dim>>; \
  TALUS_ASSEMBLE(dim, K, dim, ConsistentMass)                          \
  TALUS_ASSEMBLE(dim, K, 1, ConsistentMass)                            \
  TALUS_ASSEMBLE(dim, K, dim, ElasticAndGravity<dim>)

  TALUS_MATRIX_OPS(2, shape::Q1Box<2>)
  TALUS_MATRIX_OPS(3, shape::Q1Box<3>)
  TALUS_MATRIX_OPS(2, shape::BSpline2Box<2>)
  TALUS_MATRIX_OPS(3, shape::BSpline2Box<3>)
#undef TALUS_MATRIX_OPS
#undef TALUS_ASSEMBLE
} // namespace talus::transfer
