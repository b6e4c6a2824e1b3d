// talus — the background grid: a distributed quad/hex triangulation, the vector
// Q1 DoFHandler on it, and a flat per-cell cache (box geometry, local DoF indices,
// vertex neighbours) that the particle loops read instead of deal.II iterators.
#pragma once

#include <deal.II/base/index_set.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/base/point.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace talus
{
  namespace io
  {
    struct GridMesh;
  }
  using Vector = dealii::LinearAlgebra::distributed::Vector<double>;

  /// Kinematic boundary condition on every node of a boundary id (seed 000 §5.1):
  /// applied to all nodes of that boundary, active or not, so nodes that become
  /// active later are constrained too.
  struct BoundaryCondition
  {
    enum class Kind
    {
      fixed, ///< all velocity components zero
      roller ///< the component normal to the boundary zero
    };
    dealii::types::boundary_id id;
    Kind                       kind;
  };

  template <int dim>
  class BackgroundGrid;

  template <int dim>
  struct CellCache
  {
    static constexpr unsigned int n_vertices = 1u << dim;
    double                        lower[dim];
    double                        h[dim];
    double                        inv_h[dim];
    /// Local (owned + ghost) index of DoF (vertex v, component c) at [v*dim + c].
    unsigned int dofs[n_vertices * dim];
    /// This cell's vertex neighbours (itself first), built on first use
    /// (BackgroundGrid::neighbours_of): [0] their count, then their active
    /// cell indices; nullptr until then.
    mutable const unsigned int *neighbours    = nullptr;
    bool                        locally_owned = false;
    /// Set when the entry is filled (CellCaches); an artificial cell's entry
    /// is filled with zeros.
    bool filled = false;
  };

  /// The cell caches of all active cells, indexed by active_cell_index(), each
  /// filled from the triangulation and the DoFHandler when first read. The
  /// entries sit in one anonymous mapping (mmap) that the kernel backs page
  /// by page on first write, so a grid much larger than its points holds in
  /// memory only the pages of the cells the points (and their neighbours)
  /// have used: on the 3D bench, whose grid is 4.8 x the block's box, about
  /// a fifth of the 184 bytes per cell (docs/scaling.md). All-zero bytes are an
  /// entry's unfilled state. An entry never moves: references stay valid
  /// until the next BackgroundGrid::setup().
  template <int dim>
  class CellCaches
  {
  public:
    CellCaches()                              = default;
    CellCaches(const CellCaches &)            = delete;
    CellCaches &operator=(const CellCaches &) = delete;
    ~CellCaches() { release(); }

    const CellCache<dim> &
    operator[](const unsigned int c) const
    {
      const CellCache<dim> &e = entries[c];
      if (__builtin_expect(!e.filled, 0))
        fill(c);
      return e;
    }
    /// The entry of cell c, which must be filled already, without the check of
    /// operator[]. The entries of the cells that hold points are filled:
    /// MaterialPointSet::collect_active_cells and update_active_cells fill the
    /// entries of the cells of the set's walk, the relocation the entry of
    /// every cell it puts a point in, before anything walks them; building a
    /// cell's neighbour list fills the entries of the cells in it (the cells
    /// find_cell_near returns). So the walks, the kernels' cell() and
    /// find_cell_near read entries this way: the check, inlined into the hot
    /// loops, changed GCC's inlining of the update pass (+19 instructions per
    /// point-step on the bench, docs/scaling.md). Checked in debug builds.
    const CellCache<dim> &
    filled_entry(const unsigned int c) const
    {
      Assert(entries[c].filled,
             dealii::ExcMessage("CellCaches::filled_entry: the entry of cell " + std::to_string(c) + " is not filled"));
      return entries[c];
    }
    /// Fill cell c's entry if it is not (operator[] without the read).
    void
    ensure_filled(const unsigned int c) const
    {
      if (!entries[c].filled)
        fill(c);
    }
    /// Whether cell c's entry is filled (checks, tests).
    bool
    is_filled(const unsigned int c) const
    {
      return entries[c].filled;
    }
    std::size_t
    size() const
    {
      return n;
    }
    /// Entries filled so far (memory accounting, tests).
    std::size_t
    n_filled() const
    {
      return n_filled_entries;
    }

    class const_iterator
    {
    public:
      const_iterator(const CellCaches *a, const unsigned int i)
          : array(a)
          , index(i)
      {
      }
      const CellCache<dim> &
      operator*() const
      {
        return (*array)[index];
      }
      const_iterator &
      operator++()
      {
        ++index;
        return *this;
      }
      bool
      operator!=(const const_iterator &o) const
      {
        return index != o.index;
      }

    private:
      const CellCaches *array;
      unsigned int      index;
    };
    /// Iterating over all entries fills all of them.
    const_iterator
    begin() const
    {
      return {this, 0};
    }
    const_iterator
    end() const
    {
      return {this, static_cast<unsigned int>(n)};
    }

  private:
    friend class BackgroundGrid<dim>;
    void                   reset(const BackgroundGrid<dim> &grid, std::size_t n_cells);
    void                   release();
    [[gnu::noinline]] void fill(unsigned int c) const;

    CellCache<dim>            *entries          = nullptr;
    std::size_t                n                = 0;
    const BackgroundGrid<dim> *owner            = nullptr;
    mutable std::size_t        n_filled_entries = 0;
  };

  /// Stencil data of the quadratic B-spline kernel (shape/bspline2.h) for one
  /// locally owned cell: its integer position in the uniform box and the local
  /// (owned + ghost) DoF indices of the 4^dim nodes j-1..j+2 per direction.
  template <int dim>
  struct BSplinePatch
  {
    static constexpr unsigned int n_slots = dim == 2 ? 16 : 64;
    /// cell index per direction, 0 <= i_cell[d] < n_cells[d]
    unsigned int i_cell[dim];
    /// Local index of DoF (slot s, component c) at [s*dim + c]; slot s = p_0 + 4 p_1
    /// (+ 16 p_2) is node i_cell[d] - 1 + p_d. numbers::invalid_unsigned_int for
    /// slots outside the grid.
    unsigned int dofs[n_slots * dim];
    /// every slot inside the grid and the dim DoFs of each slot's node consecutive
    /// (dofs[s * dim + d] = dofs[s * dim] + d): the B-spline kernel's gathers and
    /// scatters then read one index per node and move its components as a block
    bool full = false;
  };

  /// The grid as a uniform box (for the B-spline kernel): lower corner, cell size,
  /// cells per direction.
  template <int dim>
  struct UniformBox
  {
    double       lower[dim];
    double       h[dim];
    double       inv_h[dim];
    unsigned int n_cells[dim];
  };

  template <int dim>
  class BackgroundGrid
  {
  public:
    /// `canonical`: rebuild the local mesh from scratch after every repartition,
    /// so that its cell and DoF numbering depend only on the partition, not on
    /// the history of repartitions (load balancing with bitwise restarts).
    explicit BackgroundGrid(MPI_Comm comm, bool canonical = false);

    /// Axis-aligned box with n_cells[d] cells per direction; boundary ids
    /// 0..2dim-1 for the faces x-, x+, y-, y+, z-, z+.
    void make_box(const dealii::Point<dim> &lower, const dealii::Point<dim> &upper,
                  const std::vector<unsigned int> &n_cells);

    /// Grid read from a file (io::read_msh): the cells must be axis-aligned boxes
    /// with lexicographic vertex order (io::normalise_boxes); material ids and
    /// boundary ids as in the mesh (boundary faces not listed keep id 0).
    void make_from_mesh(const io::GridMesh &mesh);

    /// Distribute DoFs and build the cell cache. Throws InputError if a cell is
    /// not an axis-aligned box (the Q1 kernel and MappingCartesian need boxes).
    void setup();

    /// Per local DoF (owned + ghost) a flag: 1 if its velocity component is
    /// prescribed zero by one of the conditions.
    std::vector<unsigned char> constrained_dofs(const std::vector<BoundaryCondition> &bcs) const;

    void
    reinit_vector(Vector &v) const
    {
      v.reinit(partitioner);
    }

    /// Whether cell c is locally owned, and (if so) its box: the lower corner
    /// and the edge lengths, the values its cache entry holds, read from the
    /// triangulation without filling the entry (a loop over all cells, such as
    /// the seeding, would otherwise fill the caches of cells no point uses).
    bool owned_cell_box(unsigned int c, double (&lower)[dim], double (&h)[dim]) const;

    /// Index of the cell (owned, containing x) among cell `c` and its vertex
    /// neighbours; on success also writes the reference coordinates. Returns
    /// numbers::invalid_unsigned_int if x is in none of them or the containing
    /// cell is not locally owned.
    unsigned int find_owned_cell_near(const unsigned int c, const dealii::Point<dim> &x, dealii::Point<dim> &xi) const;
    /// The same for any cached cell (owned or ghost): the index of the cell
    /// among c and its vertex neighbours that contains x, or invalid.
    unsigned int find_cell_near(const unsigned int c, const dealii::Point<dim> &x, dealii::Point<dim> &xi) const;

    /// Reference coordinates of x in cell c (box map).
    dealii::Point<dim>
    reference_point(const unsigned int c, const dealii::Point<dim> &x) const
    {
      const auto        &cc = cells[c];
      dealii::Point<dim> xi;
      for (unsigned int d = 0; d < dim; ++d)
        xi[d] = (x[d] - cc.lower[d]) * cc.inv_h[d];
      return xi;
    }

    /// Partition weight of a locally owned cell (repartition()).
    using CellWeight = std::function<unsigned int(const typename dealii::Triangulation<dim>::cell_iterator &)>;
    /// Repartition the cells among the ranks so that every rank holds about the
    /// same total weight (p4est along its space-filling curve), then rebuild
    /// DoFs and caches (setup()). Collective. Data attached to cells (material
    /// points) must be packed before and unpacked after by the caller.
    void repartition(const CellWeight &weight);
    /// Smallest cell edge over the whole grid (all ranks).
    double
    min_cell_size() const
    {
      return global_min_h;
    }

    /// Build the B-spline stencil (box, patches) after setup(); collective. Only a
    /// B-spline run calls it, so a Q1 run keeps its memory. Throws InputError if
    /// the grid is not a uniform box (equal cells on a lattice filling the
    /// bounding box) or has fewer than 3 cells in a direction.
    void setup_bspline_patches();

    /// Patch of locally owned cell c (active_cell_index); setup_bspline_patches() first.
    const BSplinePatch<dim> &
    patch(const unsigned int c) const
    {
      return patches[patch_of_cell[c]];
    }
    bool
    has_patches() const
    {
      return !patch_of_cell.empty();
    }

    MPI_Comm                                                   comm;
    dealii::parallel::distributed::Triangulation<dim>          tria;
    dealii::FESystem<dim>                                      fe;
    dealii::DoFHandler<dim>                                    dof_handler;
    dealii::MappingCartesian<dim>                              mapping;
    dealii::IndexSet                                           owned_dofs, relevant_dofs;
    std::shared_ptr<const dealii::Utilities::MPI::Partitioner> partitioner;

    /// Indexed by active_cell_index(), filled on first read.
    CellCaches<dim> cells;

    /// The triangulation's iterator of cell c (active_cell_index), tria.end()
    /// for an artificial cell. Made from its level and index on the level,
    /// packed in 4 bytes per cell (a vector of iterators cost 16).
    typename dealii::Triangulation<dim>::active_cell_iterator
    cell_iterator(const unsigned int c) const
    {
      const std::uint32_t li = level_index[c];
      return li == artificial ? tria.end()
                              : typename dealii::Triangulation<dim>::active_cell_iterator(
                                  &tria, static_cast<int>(li >> index_bits), static_cast<int>(li & index_mask));
    }

    /// The vertex neighbours of non-artificial cell c, itself first (on a grid
    /// without hanging nodes the cells reached by at most one face step along
    /// each axis): [0] their count, [1..] their active cell indices (their cache
    /// entries filled). Built on first use and kept until the next setup():
    /// only the cells whose points leave them (and the B-spline patches) ask,
    /// so a grid much larger than its points does not hold the lists of all its
    /// cells (3^dim indices each).
    const unsigned int *
    neighbours_of(const unsigned int c) const
    {
      const unsigned int *nb = cells[c].neighbours;
      return nb != nullptr ? nb : build_neighbours(c);
    }
    /// Number of cells whose neighbour lists are built (memory accounting, tests).
    std::size_t
    n_neighbour_lists() const
    {
      return n_lists;
    }

    /// Filled by setup_bspline_patches(): the box, one patch per locally owned
    /// cell, and per active cell the index of its patch (invalid if not owned).
    UniformBox<dim>                box{};
    std::vector<BSplinePatch<dim>> patches;
    std::vector<unsigned int>      patch_of_cell;

  private:
    friend class CellCaches<dim>;
    /// Per active cell: its level (top 5 bits) and index on the level (27 bits);
    /// `artificial` for an artificial cell.
    static constexpr unsigned int  index_bits = 27;
    static constexpr std::uint32_t index_mask = (std::uint32_t(1) << index_bits) - 1;
    static constexpr std::uint32_t artificial = ~std::uint32_t(0);
    std::vector<std::uint32_t>     level_index;
    /// Fill cell c's cache entry (CellCaches::fill).
    void fill_cache(unsigned int c, CellCache<dim> &cc) const;

    double                                global_min_h = 0;
    [[gnu::noinline]] const unsigned int *build_neighbours(const unsigned int c) const;
    /// Storage of the neighbour lists: fixed-size chunks, so that a list once
    /// built never moves (CellCache::neighbours points into it) and growing
    /// never copies what is there.
    mutable std::vector<std::unique_ptr<unsigned int[]>> neighbour_chunks;
    mutable std::size_t                                  chunk_used = 0, n_lists = 0;
  };
} // namespace talus
