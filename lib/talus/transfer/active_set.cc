#include <talus/particles/material_point_set.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/active_set.h>
#include <talus/transfer/matrix_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <algorithm>
#include <type_traits>

namespace talus
{
  namespace
  {
    /// The bits of a node's recorded neighbours: 2 words per node, one bit per
    /// lattice offset of a neighbour within one point stencil.
    constexpr unsigned int offset_words = 2;

    /// For kernel K: the bit naming the lattice offset from stencil slot a to
    /// slot b. A cell's stencil slots are a lattice of B^dim nodes (B = 2: the
    /// Q1 vertices; B = 4: the B-spline patch, slot = p_0 + 4 p_1 + 16 p_2);
    /// one point's slots lie within W per direction (W = 2 or 3), so an
    /// offset per direction is in [-(W - 1), W - 1]: (2W - 1)^dim <= 125 bits.
    template <int dim, class K>
    struct PairOffsets
    {
      static constexpr unsigned int
      root(const unsigned int n)
      {
        unsigned int r = 1;
        while (dim == 1 ? r < n : dim == 2 ? r * r < n : r * r * r < n)
          ++r;
        return r;
      }
      static constexpr unsigned int B = root(K::n_nodes), W = root(K::n_point_nodes), span = 2 * W - 1;
      static_assert(dim == 1   ? span <= 128
                    : dim == 2 ? span * span <= 128
                               : span * span * span <= 128,
                    "ActiveSet: a stencil's offsets must fit 128 bits");
      static constexpr unsigned char far = 255; // never within one point's stencil
      unsigned char                  bit[K::n_nodes][K::n_nodes];

      PairOffsets()
      {
        for (unsigned int a = 0; a < K::n_nodes; ++a)
          for (unsigned int b = 0; b < K::n_nodes; ++b)
            {
              unsigned int index = 0, scale = 1, pa = a, pb = b;
              bool         near = true;
              for (unsigned int d = 0; d < dim; ++d, scale *= span, pa /= B, pb /= B)
                {
                  const int o = int(pb % B) - int(pa % B);
                  near        = near && o >= -int(W - 1) && o <= int(W - 1);
                  index += unsigned(o + int(W - 1)) * scale;
                }
              bit[a][b] = near ? static_cast<unsigned char>(index) : far;
            }
      }
      static const PairOffsets &
      table()
      {
        static const PairOffsets t;
        return t;
      }
      inline void
      set(std::uint64_t *bits, const unsigned int a, const unsigned int b) const
      {
        const unsigned int i = bit[a][b];
        if (i != far)
          bits[i / 64] |= std::uint64_t(1) << (i % 64);
      }
      inline bool
      is_set(const std::uint64_t *bits, const unsigned int a, const unsigned int b) const
      {
        const unsigned int i = bit[a][b];
        return i != far && (bits[i / 64] >> (i % 64) & 1) != 0;
      }
    };

    /// OR `words` 64-bit words per local index (owned + ghost of `part`) over
    /// the ranks that hold the index: the owner ORs in its ghosts' words, then
    /// every ghost gets the owner's result. Collective.
    void
    or_over_ranks(const dealii::Utilities::MPI::Partitioner &part, const MPI_Comm comm, const unsigned int words,
                  std::vector<std::uint64_t> &data)
    {
      if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1)
        return;
      const unsigned int    n_owned = part.locally_owned_size();
      std::vector<unsigned> imports;
      imports.reserve(part.n_import_indices());
      for (const auto &[first, end] : part.import_indices())
        for (unsigned int i = first; i < end; ++i)
          imports.push_back(i);
      const int                  tag = 4711;
      std::vector<std::uint64_t> buffer(imports.size() * words);
      std::vector<MPI_Request>   requests;
      const auto                 wait = [&]() {
        MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
        requests.clear();
      };
      // ghosts -> owners
      unsigned int offset = 0;
      for (const auto &[rank, count] : part.import_targets())
        {
          requests.emplace_back();
          MPI_Irecv(buffer.data() + std::size_t(offset) * words, int(count * words), MPI_UINT64_T, int(rank), tag, comm,
                    &requests.back());
          offset += count;
        }
      offset = n_owned;
      for (const auto &[rank, count] : part.ghost_targets())
        {
          requests.emplace_back();
          MPI_Isend(data.data() + std::size_t(offset) * words, int(count * words), MPI_UINT64_T, int(rank), tag, comm,
                    &requests.back());
          offset += count;
        }
      wait();
      for (std::size_t k = 0; k < imports.size(); ++k)
        for (unsigned int w = 0; w < words; ++w)
          data[std::size_t(imports[k]) * words + w] |= buffer[k * words + w];
      // owners -> ghosts
      for (std::size_t k = 0; k < imports.size(); ++k)
        for (unsigned int w = 0; w < words; ++w)
          buffer[k * words + w] = data[std::size_t(imports[k]) * words + w];
      offset = n_owned;
      for (const auto &[rank, count] : part.ghost_targets())
        {
          requests.emplace_back();
          MPI_Irecv(data.data() + std::size_t(offset) * words, int(count * words), MPI_UINT64_T, int(rank), tag + 1,
                    comm, &requests.back());
          offset += count;
        }
      offset = 0;
      for (const auto &[rank, count] : part.import_targets())
        {
          requests.emplace_back();
          MPI_Isend(buffer.data() + std::size_t(offset) * words, int(count * words), MPI_UINT64_T, int(rank), tag + 1,
                    comm, &requests.back());
          offset += count;
        }
      wait();
    }
  } // namespace

  template <int dim>
  ActiveSet<dim>::ActiveSet(const NodalSpace<dim> &space_)
      : space(space_)
      , pattern(std::make_unique<dealii::TrilinosWrappers::SparsityPattern>())
  {
  }

  template <int dim>
  ActiveSet<dim>::~ActiveSet() = default;

  template <int dim>
  template <class K>
  void
  ActiveSet<dim>::reinit(const std::vector<MaterialPointSet<dim> *> &sets, const Couplings couplings, const Reach reach,
                         const ExtraCouplings &extra)
  {
    const auto        &grid     = space.grid;
    const unsigned int nc       = space.n_components();
    const auto        &relevant = space.locally_relevant_dofs();
    const auto        &owned    = space.locally_owned_dofs();

    // rows of all relevant DoFs: a point near the partition touches ghost nodes,
    // whose rows go to their owners (distribute_sparsity_pattern below)
    dealii::DynamicSparsityPattern dsp(relevant);
    Vector                         touched_dofs;
    space.reinit_vector(touched_dofs);
    std::vector<dealii::types::global_dof_index> cols;
    const PairOffsets<dim, K>                   &offsets = PairOffsets<dim, K>::table();
    const bool                                   record  = couplings == Couplings::record;
    cell_holds_points.assign(grid.cells.size(), 0);
    recorded_kernel_nodes           = record ? K::n_nodes : 0;
    const unsigned int n_grid_nodes = grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    node_neighbours.assign(record ? std::size_t(n_grid_nodes) * offset_words : 0, 0);

    auto sink = [&](const unsigned int c, const typename K::Cell &cell, const auto &touched, const auto &pairs) {
      cell_holds_points[c] = 1;
      for (unsigned int a = 0; a < K::n_nodes; ++a)
        {
          if (!touched[a])
            continue;
          const unsigned int ga   = cell.dofs[a * dim];
          std::uint64_t     *bits = record ? node_neighbours.data() + std::size_t(ga) * offset_words : nullptr;
          cols.clear();
          for (unsigned int b = 0; b < K::n_nodes; ++b)
            if (reach == Reach::cell ? touched[b] : pairs[a * K::n_nodes + b])
              {
                if (record)
                  offsets.set(bits, a, b);
                for (unsigned int k = 0; k < nc; ++k)
                  cols.push_back(space.node_dof(cell.dofs[b * dim], k));
              }
          std::sort(cols.begin(), cols.end());
          for (unsigned int k = 0; k < nc; ++k)
            {
              const auto row    = space.node_dof(ga, k);
              touched_dofs(row) = 1.0;
              dsp.add_entries(row, cols.begin(), cols.end(), true);
            }
        }
    };
    for (auto *set : sets)
      {
        transfer::CollectCouplings<dim, K, decltype(sink)> op(grid, sink);
        transfer::for_each_active_cell(*set, op);
      }
    // every rank that holds a node knows all of its couplings: the check of a
    // later step is then exact on any number of ranks
    if (record)
      or_over_ranks(*grid.partitioner, grid.comm, offset_words, node_neighbours);

    // a DoF is active if a point of any rank touches it
    touched_dofs.compress(dealii::VectorOperation::add);
    touched_dofs.update_ghost_values();
    std::vector<dealii::types::global_dof_index> act;
    const unsigned int n_local = space.partitioner()->locally_owned_size() + space.partitioner()->n_ghost_indices();
    for (unsigned int l = 0; l < n_local; ++l)
      if (touched_dofs.local_element(l) > 0)
        act.push_back(space.partitioner()->local_to_global(l));
    std::sort(act.begin(), act.end());
    active_relevant = dealii::IndexSet(space.dof_handler().n_dofs());
    active_relevant.add_indices(act.begin(), act.end());
    active_relevant.compress();
    active_owned    = active_relevant & owned;
    n_active_global = dealii::Utilities::MPI::sum<unsigned long long>(active_owned.n_elements(), grid.comm);

    active_cells.clear();
    for (unsigned int c = 0; c < cell_holds_points.size(); ++c)
      if (cell_holds_points[c])
        active_cells.push_back(c);

    const unsigned int n_grid_local = grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    active_node.assign(n_grid_local, 0);
    for (unsigned int i = 0; i < n_grid_local; ++i)
      {
        const auto g = space.node_dof(i, 0);
        if (g != dealii::numbers::invalid_dof_index && active_relevant.is_element(g))
          active_node[i] = 1;
      }

    inactive.clear();
    inactive.reinit(relevant);
    for (const auto i : relevant)
      if (!active_relevant.is_element(i))
        inactive.add_line(i);
    inactive.close();

    if (extra)
      extra(dsp);
    // every owned row has its diagonal (an inactive row nothing else)
    for (const auto i : owned)
      dsp.add(i, i);
    dealii::SparsityTools::distribute_sparsity_pattern(dsp, owned, grid.comm, relevant);
    pattern->reinit(owned, owned, dsp, grid.comm);
  }

  namespace
  {
    /// The walk of ActiveSet::couplings_covered: per point, every pair of the
    /// stencil slots it touches (as CollectCouplings) must be recorded at the
    /// first node of the pair. For the B-spline the touched slots come from the
    /// 1D factors alone (transfer::touched_window_slots, no products), and the
    /// pairs of a node are tested as one mask (WindowMasks). The check with the
    /// full stencil and a bit test per pair was 5.5 % of a landslide step
    /// (docs/semi-implicit.md).
    template <int dim, class K>
    struct CheckCouplings
    {
      CheckCouplings(const BackgroundGrid<dim> &grid, const std::vector<unsigned char> &cell_recorded,
                     const std::vector<std::uint64_t> &node_neighbours, const PairOffsets<dim, K> &offsets)
          : grid(grid)
          , cell_recorded(cell_recorded)
          , node_neighbours(node_neighbours)
          , offsets(offsets)
      {
      }
      const BackgroundGrid<dim>        &grid;
      const std::vector<unsigned char> &cell_recorded;
      const std::vector<std::uint64_t> &node_neighbours;
      const PairOffsets<dim, K>        &offsets;
      static constexpr bool             prefetch_location = false;
      typename K::Cell                  cell;
      bool                              recorded = false, covered = true;

      static constexpr bool bspline = std::is_same_v<K, shape::BSpline2Box<dim>>;

      inline void
      begin_cell(const unsigned int c)
      {
        recorded = cell_recorded[c] != 0;
        covered  = covered && recorded;
        if (recorded)
          cell = K::cell(grid, c);
      }

      /// B-spline: what a window's zero factors imply, the same in every cell
      /// and for either first slot (a pair's offset bit is a difference of
      /// window digits): the touched window nodes and, per touched node, the
      /// bits of its offsets to all touched nodes, which its recorded bits must
      /// contain. A point then costs one word test per node instead of one bit
      /// test per pair.
      struct WindowMasks
      {
        std::uint32_t zeros;                    ///< window_zeros of the windows it describes
        unsigned int  n;                        ///< touched window nodes
        unsigned int  offset[K::n_point_nodes]; ///< their patch slots from the first window slot
        std::uint64_t mask[K::n_point_nodes][offset_words];
      };
      std::vector<WindowMasks> windows; ///< the kinds met in this walk (a handful)
      unsigned int             last = 0;

      /// Per direction which of the window's 3 values and 3 derivatives are 0:
      /// all that decides its touched nodes (transfer::touched_window_slots).
      template <class Eval>
      static std::uint32_t
      window_zeros(const Eval &e)
      {
        std::uint32_t z = 0;
        for (unsigned int d = 0; d < dim; ++d)
          for (unsigned int a = 0; a < 3; ++a)
            z |=
              (std::uint32_t(e.N[d][a] == 0.0) << (6 * d + a)) | (std::uint32_t(e.dN[d][a] == 0.0) << (6 * d + 3 + a));
        return z;
      }
      template <class Eval>
      const WindowMasks &
      masks_of(const Eval &e)
      {
        const std::uint32_t zeros = window_zeros(e);
        if (last < windows.size() && windows[last].zeros == zeros)
          return windows[last];
        for (last = 0; last < windows.size(); ++last)
          if (windows[last].zeros == zeros)
            return windows[last];
        Eval at_corner = e; // the same window from the patch's first slot
        for (unsigned int d = 0; d < dim; ++d)
          at_corner.first[d] = 0;
        WindowMasks m{};
        m.zeros = zeros;
        m.n     = transfer::touched_window_slots<dim>(at_corner, m.offset);
        for (unsigned int a = 0; a < m.n; ++a)
          for (unsigned int b = 0; b < m.n; ++b)
            offsets.set(m.mask[a], m.offset[a], m.offset[b]);
        windows.push_back(m);
        return windows.back(); // last == windows.size() - 1
      }

      inline bool
      point(const unsigned int, transfer::PointIterator<dim> &it)
      {
        if (!recorded || !covered)
          return true;
        if constexpr (bspline)
          {
            typename K::Eval e;
            K::evaluate(cell, it->get_reference_location(), e);
            const WindowMasks &m     = masks_of(e);
            const unsigned int first = shape::Window3<dim>::first_slot(e);
            for (unsigned int a = 0; a < m.n; ++a)
              {
                const std::uint64_t *bits =
                  node_neighbours.data() + std::size_t(cell.dofs[(first + m.offset[a]) * dim]) * offset_words;
                for (unsigned int w = 0; w < offset_words; ++w)
                  covered = covered && (bits[w] & m.mask[a][w]) == m.mask[a][w];
              }
          }
        else
          {
            unsigned int slot[K::n_point_nodes], t[K::n_point_nodes], n = 0;
            double       N[K::n_point_nodes], G[K::n_point_nodes][dim];
            K::point_stencil(cell, it->get_reference_location(), slot, N, G);
            for (unsigned int w = 0; w < K::n_point_nodes; ++w)
              if (transfer::touches<dim>(N[w], G[w]))
                t[n++] = slot[w];
            for (unsigned int a = 0; a < n; ++a)
              {
                const std::uint64_t *bits = node_neighbours.data() + std::size_t(cell.dofs[t[a] * dim]) * offset_words;
                for (unsigned int b = 0; b < n; ++b)
                  covered = covered && offsets.is_set(bits, t[a], t[b]);
              }
          }
        return true;
      }
      inline void
      end_cell(const unsigned int)
      {
      }
    };
  } // namespace

  template <int dim>
  template <class K>
  bool
  ActiveSet<dim>::couplings_covered(const std::vector<MaterialPointSet<dim> *> &sets) const
  {
    if (recorded_kernel_nodes != K::n_nodes || cell_holds_points.size() != space.grid.cells.size())
      return false; // not recorded (with this kernel), or the grid changed since
    CheckCouplings<dim, K> op(space.grid, cell_holds_points, node_neighbours, PairOffsets<dim, K>::table());
    for (auto *set : sets)
      {
        transfer::for_each_active_cell(*set, op);
        if (!op.covered)
          return false;
      }
    return true;
  }

  template <int dim>
  dealii::AffineConstraints<double>
  ActiveSet<dim>::constraints_with(const dealii::AffineConstraints<double> &dirichlet) const
  {
    dealii::AffineConstraints<double> c;
    c.reinit(space.locally_relevant_dofs());
    for (const auto i : space.locally_relevant_dofs())
      if (!active_relevant.is_element(i))
        c.add_line(i);
      else if (dirichlet.is_constrained(i))
        {
          c.add_line(i);
          if (const auto *entries = dirichlet.get_constraint_entries(i))
            c.add_entries(i, *entries);
          c.set_inhomogeneity(i, dirichlet.get_inhomogeneity(i));
        }
    c.close();
    return c;
  }

  template <int dim>
  void
  ActiveSet<dim>::reinit_matrix(dealii::TrilinosWrappers::SparseMatrix &A) const
  {
    A.reinit(*pattern);
  }

  template class ActiveSet<2>;
  template class ActiveSet<3>;
  template void ActiveSet<2>::reinit<shape::Q1Box<2>>(const std::vector<MaterialPointSet<2> *> &,
                                                      ActiveSet<2>::Couplings, ActiveSet<2>::Reach,
                                                      const ActiveSet<2>::ExtraCouplings &);
  template void ActiveSet<3>::reinit<shape::Q1Box<3>>(const std::vector<MaterialPointSet<3> *> &,
                                                      ActiveSet<3>::Couplings, ActiveSet<3>::Reach,
                                                      const ActiveSet<3>::ExtraCouplings &);
  template void ActiveSet<2>::reinit<shape::BSpline2Box<2>>(const std::vector<MaterialPointSet<2> *> &,
                                                            ActiveSet<2>::Couplings, ActiveSet<2>::Reach,
                                                            const ActiveSet<2>::ExtraCouplings &);
  template void ActiveSet<3>::reinit<shape::BSpline2Box<3>>(const std::vector<MaterialPointSet<3> *> &,
                                                            ActiveSet<3>::Couplings, ActiveSet<3>::Reach,
                                                            const ActiveSet<3>::ExtraCouplings &);
  template bool ActiveSet<2>::couplings_covered<shape::Q1Box<2>>(const std::vector<MaterialPointSet<2> *> &) const;
  template bool ActiveSet<3>::couplings_covered<shape::Q1Box<3>>(const std::vector<MaterialPointSet<3> *> &) const;
  template bool
  ActiveSet<2>::couplings_covered<shape::BSpline2Box<2>>(const std::vector<MaterialPointSet<2> *> &) const;
  template bool
  ActiveSet<3>::couplings_covered<shape::BSpline2Box<3>>(const std::vector<MaterialPointSet<3> *> &) const;
} // namespace talus
