#include <talus/formulations/implicit/ghost_penalty.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <algorithm>
#include <cmath>

namespace talus
{
  template <int dim>
  void
  GhostPenalty<dim>::face_nodes(const BackgroundGrid<dim> &grid, const Face &f, unsigned int (&nodes)[n_nodes]) const
  {
    const auto &lo = grid.cells[f.lower];
    const auto &up = grid.cells[f.upper];
    for (unsigned int v = 0; v < n_vertices; ++v)
      nodes[v] = lo.dofs[v * dim];
    unsigned int j = n_vertices;
    for (unsigned int w = 0; w < n_vertices; ++w)
      if ((w >> f.direction) & 1u)
        nodes[j++] = up.dofs[w * dim];
  }

  template <int dim>
  void
  GhostPenalty<dim>::find_faces(const ActiveSet<dim> &active, const NodalSpace<dim> &space,
                                dealii::DynamicSparsityPattern &dsp)
  {
    const auto &grid = space.grid;
    // per node (the slot of its x DoF in a grid vector): how many grid cells
    // it belongs to, and how many of them hold points
    Vector holding, adjacent;
    grid.reinit_vector(holding);
    grid.reinit_vector(adjacent);
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cells[c].locally_owned)
        for (unsigned int v = 0; v < n_vertices; ++v)
          adjacent.local_element(grid.cells[c].dofs[v * dim]) += 1;
    for (const unsigned int c : active.cells())
      for (unsigned int v = 0; v < n_vertices; ++v)
        holding.local_element(grid.cells[c].dofs[v * dim]) += 1;
    for (Vector *x : {&holding, &adjacent})
      {
        x->compress(dealii::VectorOperation::add);
        x->update_ghost_values();
      }
    auto covered = [&](const unsigned int c) {
      for (unsigned int v = 0; v < n_vertices; ++v)
        if (!active.node_active(grid.cells[c].dofs[v * dim]))
          return false;
      return true;
    };
    auto cut = [&](const unsigned int c) {
      for (unsigned int v = 0; v < n_vertices; ++v)
        {
          const unsigned int i = grid.cells[c].dofs[v * dim];
          if (holding.local_element(i) < adjacent.local_element(i))
            return true;
        }
      return false;
    };

    faces.clear();
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      {
        if (!grid.cells[c].locally_owned || !covered(c))
          continue;
        const auto &cell = grid.cell_iterator(c);
        for (unsigned int f = 0; f < 2 * dim; ++f)
          {
            if (cell->at_boundary(f))
              continue;
            const auto nb = cell->neighbor(f);
            if (nb->has_children() || nb->is_artificial())
              continue;
            const unsigned int n     = nb->active_cell_index();
            const bool         upper = f % 2 == 1; // the neighbour is on the + side
            // once per face: the lower cell's rank if both are owned, else the smaller subdomain
            if (nb->is_locally_owned() ? !upper : cell->subdomain_id() > nb->subdomain_id())
              continue;
            if (!covered(n) || !(cut(c) || cut(n)))
              continue;
            faces.push_back(upper ? Face{c, n, f / 2} : Face{n, c, f / 2});
          }
      }
    n_global_faces = dealii::Utilities::MPI::sum<unsigned long long>(faces.size(), grid.comm);

    std::vector<dealii::types::global_dof_index> cols(n_nodes);
    unsigned int                                 nodes[n_nodes];
    for (const Face &f : faces)
      {
        face_nodes(grid, f, nodes);
        for (unsigned int k = 0; k < dim; ++k)
          {
            for (unsigned int a = 0; a < n_nodes; ++a)
              cols[a] = space.node_dof(nodes[a], k);
            std::vector<dealii::types::global_dof_index> sorted(cols);
            std::sort(sorted.begin(), sorted.end());
            for (unsigned int a = 0; a < n_nodes; ++a)
              dsp.add_entries(cols[a], sorted.begin(), sorted.end(), true);
          }
      }
  }

  template <int dim>
  void
  GhostPenalty<dim>::assemble(const double stiffness, const NodalSpace<dim> &space,
                              const dealii::AffineConstraints<double> &constraints, const Vector &du,
                              dealii::TrilinosWrappers::SparseMatrix *tangent, Vector &residual) const
  {
    const auto        &grid = space.grid;
    constexpr unsigned m    = n_nodes * dim;
    // two Gauss points per tangential direction on [0, 1]
    const double                                 gp[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
    constexpr unsigned int                       n_q   = 1u << (dim - 1);
    std::vector<double>                          A(m * m), b(m);
    std::vector<dealii::types::global_dof_index> dofs(m);
    unsigned int                                 nodes[n_nodes];
    double                                       G[n_nodes][n_nodes];
    for (const Face &f : faces)
      {
        const unsigned int d  = f.direction;
        const auto        &lo = grid.cells[f.lower];
        const auto        &up = grid.cells[f.upper];
        face_nodes(grid, f, nodes);
        // slot of the upper cell's vertex w among the face's nodes
        unsigned int upper_slot[n_vertices];
        for (unsigned int w = 0, j = n_vertices; w < n_vertices; ++w)
          upper_slot[w] = ((w >> d) & 1u) ? j++ : (w | (1u << d));
        double area = 1;
        for (unsigned int e = 0; e < dim; ++e)
          if (e != d)
            area *= lo.h[e];
        const double scale = stiffness * lo.h[d] * area / n_q; // Gauss weights (1/2)^(dim-1)
        for (auto &row : G)
          for (double &x : row)
            x = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          {
            double t[dim] = {}; // the quadrature point's reference coordinates along the face
            for (unsigned int e = 0, bit = 0; e < dim; ++e)
              if (e != d)
                t[e] = gp[(q >> bit++) & 1u];
            auto normal_derivative = [&](const CellCache<dim> &cell, const unsigned int v) {
              double s = ((v >> d) & 1u) ? cell.inv_h[d] : -cell.inv_h[d];
              for (unsigned int e = 0; e < dim; ++e)
                if (e != d)
                  s *= ((v >> e) & 1u) ? t[e] : 1 - t[e];
              return s;
            };
            double jump[n_nodes] = {};
            for (unsigned int v = 0; v < n_vertices; ++v)
              {
                jump[v] += normal_derivative(lo, v);
                jump[upper_slot[v]] -= normal_derivative(up, v);
              }
            for (unsigned int a = 0; a < n_nodes; ++a)
              for (unsigned int c = 0; c < n_nodes; ++c)
                G[a][c] += scale * jump[a] * jump[c];
          }
        std::fill(A.begin(), A.end(), 0.0);
        for (unsigned int a = 0; a < n_nodes; ++a)
          for (unsigned int k = 0; k < dim; ++k)
            dofs[a * dim + k] = space.node_dof(nodes[a], k);
        for (unsigned int a = 0; a < n_nodes; ++a)
          for (unsigned int k = 0; k < dim; ++k)
            {
              double r = 0;
              for (unsigned int c = 0; c < n_nodes; ++c)
                {
                  A[(a * dim + k) * m + c * dim + k] = G[a][c];
                  r += G[a][c] * du(dofs[c * dim + k]);
                }
              b[a * dim + k] = r;
            }
        transfer::distribute_local(constraints, m, A.data(), b.data(), m, dofs, tangent, &residual);
      }
    if (tangent != nullptr)
      tangent->compress(dealii::VectorOperation::add);
    residual.compress(dealii::VectorOperation::add);
  }

  template class GhostPenalty<2>;
  template class GhostPenalty<3>;
} // namespace talus
