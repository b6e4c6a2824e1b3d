#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.templates.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector.h>

namespace talus::transfer
{
  void
  distribute_local(const dealii::AffineConstraints<double> &           constraints,
                   const unsigned int                                  m,
                   const double *                                      A_local,
                   const double *                                      b_local,
                   const unsigned int                                  stride,
                   const std::vector<dealii::types::global_dof_index> &dofs,
                   dealii::TrilinosWrappers::SparseMatrix *            A,
                   Vector *                                            b)
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

  template <int dim>
  void
  finish_assembly(const ActiveSet<dim> &                  active,
                  const double                            diag_sum,
                  const double                            diag_count,
                  dealii::TrilinosWrappers::SparseMatrix *A,
                  Vector *                                b)
  {
    const MPI_Comm comm = active.space.grid.comm;
    if (A != nullptr)
      {
        A->compress(dealii::VectorOperation::add);
        const double s = dealii::Utilities::MPI::sum(diag_sum, comm);
        const double n = dealii::Utilities::MPI::sum(diag_count, comm);
        const double d = s > 0 ? s / n : 1.0;
        dealii::IndexSet inactive = active.space.locally_owned_dofs();
        inactive.subtract_set(active.active_owned_dofs());
        for (const auto i : inactive)
          A->set(i, i, d);
        A->compress(dealii::VectorOperation::insert);
      }
    if (b != nullptr)
      b->compress(dealii::VectorOperation::add);
  }

  template void finish_assembly(const ActiveSet<2> &, double, double, dealii::TrilinosWrappers::SparseMatrix *, Vector *);
  template void finish_assembly(const ActiveSet<3> &, double, double, dealii::TrilinosWrappers::SparseMatrix *, Vector *);

  // the common assemblies for both kernels
  template <int dim>
  using ElasticAndGravity = Sum<LinearElasticStiffness, BodyForce<dim>>;
#define TALUS_ASSEMBLE(dim, K, nc, Integrand)                                                                   \
  template void assemble<dim, K, nc, Integrand>(const std::vector<MaterialPointSet<dim> *> &,                  \
                                                const ActiveSet<dim> &,                                         \
                                                const dealii::AffineConstraints<double> &,                      \
                                                const Integrand &,                                              \
                                                dealii::TrilinosWrappers::SparseMatrix *,                       \
                                                Vector *,                                                       \
                                                const Vector *);
#define TALUS_MATRIX_OPS(dim, K)                                                                                \
  template struct AssembleSystem<dim, K, dim, ConsistentMass>;                                                \
  template struct AssembleSystem<dim, K, 1, ConsistentMass>;                                                  \
  template struct AssembleSystem<dim, K, dim, LinearElasticStiffness>;                                        \
  template struct AssembleSystem<dim, K, dim, BodyForce<dim>>;                                                \
  template struct AssembleSystem<dim, K, dim, ElasticAndGravity<dim>>;                                        \
  TALUS_ASSEMBLE(dim, K, dim, ConsistentMass)                                                                 \
  TALUS_ASSEMBLE(dim, K, 1, ConsistentMass)                                                                   \
  TALUS_ASSEMBLE(dim, K, dim, ElasticAndGravity<dim>)

  TALUS_MATRIX_OPS(2, shape::Q1Box<2>)
  TALUS_MATRIX_OPS(3, shape::Q1Box<3>)
  TALUS_MATRIX_OPS(2, shape::BSpline2Box<2>)
  TALUS_MATRIX_OPS(3, shape::BSpline2Box<3>)
#undef TALUS_MATRIX_OPS
#undef TALUS_ASSEMBLE
} // namespace talus::transfer
