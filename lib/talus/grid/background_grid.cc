#include <talus/base/errors.h>
#include <talus/grid/background_grid.h>
#include <talus/io/grid_mesh.h>
#include <talus/shape/bspline2.h>

#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sys/mman.h>
#include <type_traits>
#include <map>
#include <set>

namespace talus
{
  template <int dim>
  BackgroundGrid<dim>::BackgroundGrid(MPI_Comm comm_, const bool canonical)
      : comm(comm_)
      , tria(comm_, dealii::Triangulation<dim>::none,
             canonical ? dealii::parallel::distributed::Triangulation<dim>::mesh_reconstruction_after_repartitioning
                       : dealii::parallel::distributed::Triangulation<dim>::default_setting)
      , fe(dealii::FE_Q<dim>(1), dim)
      , dof_handler(tria)
  {
  }

  template <int dim>
  void
  BackgroundGrid<dim>::make_box(const dealii::Point<dim> &lower, const dealii::Point<dim> &upper,
                                const std::vector<unsigned int> &n_cells)
  {
    require(n_cells.size() == dim, "grid/cells", "needs " + std::to_string(dim) + " entries");
    for (unsigned int d = 0; d < dim; ++d)
      {
        require(upper[d] > lower[d], "grid", "upper corner must exceed lower corner in every direction");
        require(n_cells[d] > 0, "grid/cells", "every entry must be > 0");
      }
    // p4est keeps one tree per coarse cell and deal.II 9.4 reorders the coarse
    // cells with an O(n log n) set-based algorithm: a 786k-cell coarse grid took
    // ~45 s to create. Build the largest power-of-two coarsening of the requested
    // grid and refine it globally instead (same cells, z-ordered within trees).
    unsigned int k = 0;
    while (true)
      {
        bool ok = true;
        for (unsigned int d = 0; d < dim; ++d)
          ok = ok && n_cells[d] % (1u << (k + 1)) == 0;
        if (!ok)
          break;
        ++k;
      }
    std::vector<unsigned int> coarse(dim);
    for (unsigned int d = 0; d < dim; ++d)
      coarse[d] = n_cells[d] >> k;
    dealii::GridGenerator::subdivided_hyper_rectangle(tria, coarse, lower, upper, true);
    if (k > 0)
      tria.refine_global(k);
  }

  template <int dim>
  void
  BackgroundGrid<dim>::make_from_mesh(const io::GridMesh &mesh)
  {
    require(mesh.dim == dim, "grid/file",
            "the grid file is " + std::to_string(mesh.dim) + "D, the scene " + std::to_string(dim) + "D");
    constexpr unsigned int nv = dealii::GeometryInfo<dim>::vertices_per_cell;
    constexpr unsigned int nf = dealii::GeometryInfo<dim>::vertices_per_face;
    // keep only the vertices the cells use (deal.II refuses unused ones)
    std::vector<unsigned int>       new_index(mesh.vertices.size(), dealii::numbers::invalid_unsigned_int);
    std::vector<dealii::Point<dim>> vertices;
    for (const unsigned int v : mesh.cells)
      if (new_index[v] == dealii::numbers::invalid_unsigned_int)
        {
          new_index[v] = vertices.size();
          dealii::Point<dim> x;
          for (unsigned int d = 0; d < dim; ++d)
            x[d] = mesh.vertices[v][d];
          vertices.push_back(x);
        }
    std::vector<dealii::CellData<dim>> cells(mesh.n_cells());
    for (std::size_t c = 0; c < mesh.n_cells(); ++c)
      {
        for (unsigned int v = 0; v < nv; ++v)
          cells[c].vertices[v] = new_index[mesh.cells[c * nv + v]];
        cells[c].material_id = mesh.cell_material[c];
      }
    tria.create_triangulation(vertices, cells, dealii::SubCellData());
    // boundary ids: match faces by their sorted vertex indices
    std::map<std::array<unsigned int, nf>, unsigned int> face_id;
    for (std::size_t k = 0; k < mesh.n_faces(); ++k)
      {
        std::array<unsigned int, nf> key;
        bool                         known = true;
        for (unsigned int v = 0; v < nf; ++v)
          {
            key[v] = new_index[mesh.faces[k * nf + v]];
            known  = known && key[v] != dealii::numbers::invalid_unsigned_int;
          }
        require(known, "grid/file", "boundary face " + std::to_string(k) + " uses a vertex that no cell has");
        std::sort(key.begin(), key.end());
        face_id[key] = mesh.face_boundary[k];
      }
    std::size_t matched = 0;
    for (const auto &cell : tria.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          {
            std::array<unsigned int, nf> key;
            for (unsigned int v = 0; v < nf; ++v)
              key[v] = cell->face(f)->vertex_index(v);
            std::sort(key.begin(), key.end());
            const auto it = face_id.find(key);
            cell->face(f)->set_boundary_id(it == face_id.end() ? 0 : it->second);
            matched += it != face_id.end();
          }
    // (a listed face that is interior, or not a face at all, is refused by talus-mesh)
    (void)matched;
  }

  template <int dim>
  void
  BackgroundGrid<dim>::setup()
  {
    dof_handler.distribute_dofs(fe);
    owned_dofs = dof_handler.locally_owned_dofs();
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant_dofs);
    partitioner = std::make_shared<dealii::Utilities::MPI::Partitioner>(owned_dofs, relevant_dofs, comm);

    // the cache entries are filled on first read (CellCaches::fill); here only
    // the level and index of every cell, and the check that every cell is a box
    constexpr unsigned int nv = CellCache<dim>::n_vertices;
    cells.reset(*this, tria.n_active_cells());
    level_index.assign(tria.n_active_cells(), artificial);
    double min_h = std::numeric_limits<double>::max();
    for (const auto &cell : tria.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        const unsigned int c = cell->active_cell_index();
        AssertThrow(cell->level() < 31 && std::uint32_t(cell->index()) <= index_mask,
                    dealii::ExcMessage("grid: more than 30 levels or 2^27 cells on a level"));
        level_index[c]   = (std::uint32_t(cell->level()) << index_bits) | std::uint32_t(cell->index());
        const auto p0    = cell->vertex(0);
        const bool owned = cell->is_locally_owned();
        double     h[dim];
        for (unsigned int d = 0; d < dim; ++d)
          {
            h[d] = cell->vertex(nv - 1)[d] - p0[d];
            if (owned)
              min_h = std::min(min_h, h[d]);
          }
        // every vertex must sit at its box corner
        for (unsigned int v = 0; v < nv; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              const double expected = p0[d] + (((v >> d) & 1u) ? h[d] : 0.0);
              if (std::abs(cell->vertex(v)[d] - expected) > 1e-10 * std::abs(h[d]) || !(h[d] > 0))
                throw InputError("grid: cell " + cell->id().to_string() + " at " + std::to_string(p0[0]) +
                                 ",... is not an axis-aligned box with lexicographic "
                                 "vertex order; the MPM background grid must consist of axis-aligned quads/hexes");
            }
      }
    global_min_h = dealii::Utilities::MPI::min(min_h, comm);

    // the vertex neighbour lists are built on first use (neighbours_of)
    neighbour_chunks.clear();
    chunk_used = 0;
    n_lists    = 0;

    // a rebuilt grid (repartition, restart) keeps a requested B-spline stencil valid
    if (!patch_of_cell.empty())
      setup_bspline_patches();
  }

  template <int dim>
  void
  CellCaches<dim>::reset(const BackgroundGrid<dim> &grid, const std::size_t n_cells)
  {
    static_assert(std::is_trivially_copyable_v<CellCache<dim>>, "entries start as zero bytes");
    release();
    // an anonymous mapping: zero pages that become resident one by one when an
    // entry on them is first filled (calloc would do the same only when it
    // happens to take fresh memory from the system, not recycled heap)
    const std::size_t bytes = std::max<std::size_t>(n_cells, 1) * sizeof(CellCache<dim>);
    void *p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED)
      throw std::bad_alloc();
    entries          = static_cast<CellCache<dim> *>(p);
    n                = n_cells;
    owner            = &grid;
    n_filled_entries = 0;
  }

  template <int dim>
  void
  CellCaches<dim>::release()
  {
    if (entries != nullptr)
      munmap(entries, std::max<std::size_t>(n, 1) * sizeof(CellCache<dim>));
    entries = nullptr;
    n       = 0;
  }

  template <int dim>
  void
  CellCaches<dim>::fill(const unsigned int c) const
  {
    CellCache<dim> &cc = entries[c];
    owner->fill_cache(c, cc);
    cc.filled = true;
    ++n_filled_entries;
  }

  template <int dim>
  void
  BackgroundGrid<dim>::fill_cache(const unsigned int c, CellCache<dim> &cc) const
  {
    const std::uint32_t li = level_index[c];
    if (li == artificial)
      return; // zeros
    constexpr unsigned int                                       nv = CellCache<dim>::n_vertices;
    const typename dealii::DoFHandler<dim>::active_cell_iterator cell(&tria, static_cast<int>(li >> index_bits),
                                                                      static_cast<int>(li & index_mask), &dof_handler);
    cc.locally_owned = cell->is_locally_owned();
    const auto p0    = cell->vertex(0);
    for (unsigned int d = 0; d < dim; ++d)
      {
        cc.lower[d] = p0[d];
        cc.h[d]     = cell->vertex(nv - 1)[d] - p0[d];
        cc.inv_h[d] = 1.0 / cc.h[d];
      }
    static thread_local std::vector<dealii::types::global_dof_index> dof_indices; // no allocation per entry
    dof_indices.resize(fe.n_dofs_per_cell());
    cell->get_dof_indices(dof_indices);
    for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
      {
        const auto [comp, base] = fe.system_to_component_index(i);
        const unsigned int v    = base; // Q1: base index == vertex
        cc.dofs[v * dim + comp] = partitioner->global_to_local(dof_indices[i]);
      }
  }

  template <int dim>
  bool
  BackgroundGrid<dim>::owned_cell_box(const unsigned int c, double (&lower)[dim], double (&h)[dim]) const
  {
    const auto cell = cell_iterator(c);
    if (cell == tria.end() || !cell->is_locally_owned())
      return false;
    constexpr unsigned int nv = CellCache<dim>::n_vertices;
    const auto             p0 = cell->vertex(0);
    for (unsigned int d = 0; d < dim; ++d)
      {
        lower[d] = p0[d];
        h[d]     = cell->vertex(nv - 1)[d] - p0[d];
      }
    return true;
  }

  template <int dim>
  const unsigned int *
  BackgroundGrid<dim>::build_neighbours(const unsigned int c) const
  {
    // the cells reached from c by at most one face step along each axis, in the
    // order x, then y, then z (GridTools::vertex_to_cell_map with its std::sets
    // took ~40 s on a 786k-cell grid for all cells at once)
    // Each step along an axis adds at most two cells per cell found so far: at
    // most 3^dim cells. All on c's level: the cells of a lattice, each reached
    // once; else (hanging nodes) a coarser cell may be reached twice.
    AssertThrow(cell_iterator(c) != tria.end(), dealii::ExcMessage("neighbours of an artificial cell"));
    constexpr unsigned int                                    max_set = dim == 2 ? 9 : 27;
    typename dealii::Triangulation<dim>::active_cell_iterator set[max_set];
    unsigned int                                              n_set = 0;
    set[n_set++]                                                    = cell_iterator(c);
    const int level                                                 = set[0]->level();
    bool      one_level                                             = true;
    for (unsigned int d = 0; d < dim; ++d)
      {
        const unsigned int n = n_set;
        for (unsigned int k = 0; k < n; ++k)
          for (const unsigned int f : {2 * d, 2 * d + 1})
            {
              if (set[k]->at_boundary(f))
                continue;
              const auto nbc = set[k]->neighbor(f);
              if (nbc->has_children() || nbc->is_artificial())
                continue;
              one_level    = one_level && nbc->level() == level;
              set[n_set++] = nbc;
            }
      }
    unsigned int nb[max_set];
    unsigned int count = 0;
    for (unsigned int k = 0; k < n_set; ++k)
      {
        const unsigned int i = set[k]->active_cell_index();
        if (one_level || std::find(nb, nb + count, i) == nb + count)
          nb[count++] = i;
      }
    // find_cell_near reads the entries of the listed cells unchecked
    for (unsigned int k = 0; k < count; ++k)
      cells.ensure_filled(nb[k]);
    constexpr std::size_t chunk_size = 1u << 16; // entries: 256 KB
    if (neighbour_chunks.empty() || chunk_used + count + 1 > chunk_size)
      {
        neighbour_chunks.emplace_back(new unsigned int[chunk_size]);
        chunk_used = 0;
      }
    unsigned int *list = neighbour_chunks.back().get() + chunk_used;
    chunk_used += count + 1;
    list[0] = count;
    std::copy(nb, nb + count, list + 1);
    cells[c].neighbours = list;
    ++n_lists;
    return list;
  }

  template <int dim>
  void
  BackgroundGrid<dim>::setup_bspline_patches()
  {
    const std::string  where   = "grid";
    const std::string  reason  = ": quadratic B-spline shape functions need a uniform box grid (equal "
                                 "axis-aligned cells filling the box; every face of the box is a wall)";
    const char         axis[]  = "xyz";
    const unsigned int invalid = dealii::numbers::invalid_unsigned_int;

    // the box from the owned cells of all ranks
    double lo[dim], hi[dim], hmin[dim], hmax[dim];
    for (unsigned int d = 0; d < dim; ++d)
      {
        lo[d] = hmin[d] = std::numeric_limits<double>::max();
        hi[d] = hmax[d] = -std::numeric_limits<double>::max();
      }
    for (const auto &cc : cells)
      if (cc.locally_owned)
        for (unsigned int d = 0; d < dim; ++d)
          {
            lo[d]   = std::min(lo[d], cc.lower[d]);
            hi[d]   = std::max(hi[d], cc.lower[d] + cc.h[d]);
            hmin[d] = std::min(hmin[d], cc.h[d]);
            hmax[d] = std::max(hmax[d], cc.h[d]);
          }
    std::size_t n_box = 1;
    for (unsigned int d = 0; d < dim; ++d)
      {
        lo[d]   = dealii::Utilities::MPI::min(lo[d], comm);
        hmin[d] = dealii::Utilities::MPI::min(hmin[d], comm);
        hi[d]   = dealii::Utilities::MPI::max(hi[d], comm);
        hmax[d] = dealii::Utilities::MPI::max(hmax[d], comm);
        // 1e-6: grid files carry node coordinates rounded to ~1e-10 of the extent
        // (talus-mesh), i.e. cell sizes differing by up to ~1e-10 n relative
        if (hmax[d] - hmin[d] > 1e-6 * hmax[d])
          throw InputError(where + reason + "; the cell size in " + axis[d] + " varies from " +
                           std::to_string(hmin[d]) + " to " + std::to_string(hmax[d]));
        const double       extent = hi[d] - lo[d];
        const unsigned int n      = static_cast<unsigned int>(std::lround(extent / hmax[d]));
        box.lower[d]              = lo[d];
        box.n_cells[d]            = n;
        box.h[d]                  = extent / n;
        box.inv_h[d]              = n / extent;
        if (n < shape::BSpline2<dim>::min_cells)
          throw InputError(where + ": quadratic B-spline shape functions need at least " +
                           std::to_string(shape::BSpline2<dim>::min_cells) +
                           " cells in every direction; the grid has " + std::to_string(n) + " in " + axis[d]);
        n_box *= n;
      }
    if (n_box != tria.n_global_active_cells())
      throw InputError(where + reason + "; the grid has " + std::to_string(tria.n_global_active_cells()) +
                       " cells, its bounding box holds " + std::to_string(n_box));

    patch_of_cell.assign(cells.size(), invalid);
    patches.clear();
    std::vector<std::array<unsigned int, dim>> index(cells.size());
    bool                                       on_lattice = true;
    for (unsigned int c = 0; c < cells.size(); ++c)
      if (cell_iterator(c) != tria.end())
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double r = (cells[c].lower[d] - box.lower[d]) * box.inv_h[d];
            const long   k = std::lround(r);
            on_lattice     = on_lattice && std::abs(r - k) < 1e-6 && k >= 0 && k < long(box.n_cells[d]);
            index[c][d]    = static_cast<unsigned int>(std::max(k, 0l));
          }
    if (dealii::Utilities::MPI::min(on_lattice ? 1 : 0, comm) == 0)
      throw InputError(where + reason + "; a cell corner is off the lattice of the box");

    constexpr unsigned int nv = CellCache<dim>::n_vertices;
    for (unsigned int c = 0; c < cells.size(); ++c)
      {
        if (!cells[c].locally_owned)
          continue;
        patch_of_cell[c] = patches.size();
        BSplinePatch<dim> p;
        std::fill(std::begin(p.dofs), std::end(p.dofs), invalid);
        for (unsigned int d = 0; d < dim; ++d)
          p.i_cell[d] = index[c][d];
        // the patch nodes are the vertices of the cell and its vertex neighbours
        const unsigned int *nbs = neighbours_of(c);
        for (unsigned int k = 1; k <= nbs[0]; ++k)
          {
            const unsigned int n = nbs[k];
            for (unsigned int v = 0; v < nv; ++v)
              {
                unsigned int slot = 0, m = 1;
                for (unsigned int d = 0; d < dim; ++d, m *= 4)
                  slot += (index[n][d] + ((v >> d) & 1u) + 1 - index[c][d]) * m;
                for (unsigned int comp = 0; comp < dim; ++comp)
                  {
                    unsigned int      &dst = p.dofs[slot * dim + comp];
                    const unsigned int src = cells[n].dofs[v * dim + comp];
                    if (dst != invalid && dst != src)
                      throw std::logic_error("BackgroundGrid::setup_bspline_patches: two DoFs for one node");
                    dst = src;
                  }
              }
          }
        // every slot inside the grid must be found (the ghost layer holds them)
        for (unsigned int slot = 0; slot < BSplinePatch<dim>::n_slots; ++slot)
          {
            bool inside = true;
            for (unsigned int d = 0, s = slot; d < dim; ++d, s /= 4)
              {
                const long node = long(index[c][d]) - 1 + long(s % 4);
                inside          = inside && node >= 0 && node <= long(box.n_cells[d]);
              }
            if (inside != (p.dofs[slot * dim] != invalid))
              throw std::logic_error("BackgroundGrid::setup_bspline_patches: patch node of cell " +
                                     cell_iterator(c)->id().to_string() +
                                     (inside ? " missing from the ghost layer" : " outside the grid"));
          }
        p.full = true;
        for (unsigned int slot = 0; slot < BSplinePatch<dim>::n_slots; ++slot)
          for (unsigned int d = 0; d < dim; ++d)
            p.full = p.full && p.dofs[slot * dim] != invalid && p.dofs[slot * dim + d] == p.dofs[slot * dim] + d;
        patches.push_back(p);
      }
  }

  template <int dim>
  std::vector<unsigned char>
  BackgroundGrid<dim>::constrained_dofs(const std::vector<BoundaryCondition> &bcs) const
  {
    std::vector<unsigned char>           flag(partitioner->locally_owned_size() + partitioner->n_ghost_indices(), 0);
    std::set<dealii::types::boundary_id> used;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_artificial())
          continue;
        for (const unsigned int f : cell->face_indices())
          {
            if (!cell->face(f)->at_boundary())
              continue;
            const auto bid = cell->face(f)->boundary_id();
            for (const auto &bc : bcs)
              if (bc.id == bid)
                {
                  used.insert(bid);
                  const unsigned int normal_dir = f / 2; // box: faces 2d, 2d+1 normal to d
                  for (unsigned int v = 0; v < dealii::GeometryInfo<dim>::vertices_per_face; ++v)
                    for (unsigned int comp = 0; comp < dim; ++comp)
                      if (bc.kind == BoundaryCondition::Kind::fixed || comp == normal_dir)
                        {
                          const auto gi                          = cell->face(f)->vertex_dof_index(v, comp);
                          flag[partitioner->global_to_local(gi)] = 1;
                        }
                }
          }
      }
    // every boundary id named must exist somewhere in the grid
    std::vector<dealii::types::boundary_id> all_ids = tria.get_boundary_ids();
    for (const auto &bc : bcs)
      if (std::find(all_ids.begin(), all_ids.end(), bc.id) == all_ids.end())
        {
          std::string ids;
          for (const auto i : all_ids)
            ids += (ids.empty() ? "" : ", ") + std::to_string(i);
          throw InputError("boundary conditions: boundary id " + std::to_string(bc.id) +
                           " does not exist in the grid (ids present: " + ids + ")");
        }
    return flag;
  }

  template <int dim>
  unsigned int
  BackgroundGrid<dim>::find_cell_near(const unsigned int c, const dealii::Point<dim> &x, dealii::Point<dim> &xi) const
  {
    const unsigned int *nbs = neighbours_of(c);
    for (unsigned int k = 1; k <= nbs[0]; ++k)
      {
        const unsigned int n  = nbs[k];
        const auto        &nc = cells.filled_entry(n); // build_neighbours filled them
        // the first axis outside ends the test (xi is only meaningful for the
        // cell returned: the callers do not read it when none is found)
        unsigned int d = 0;
        for (; d < dim; ++d)
          {
            const double r = (x[d] - nc.lower[d]) * nc.inv_h[d];
            if (!((r >= 0.0) && (r <= 1.0)))
              break;
            xi[d] = r;
          }
        if (d == dim)
          return n;
      }
    return dealii::numbers::invalid_unsigned_int;
  }

  template <int dim>
  unsigned int
  BackgroundGrid<dim>::find_owned_cell_near(const unsigned int c, const dealii::Point<dim> &x,
                                            dealii::Point<dim> &xi) const
  {
    const unsigned int n = find_cell_near(c, x, xi);
    return n != dealii::numbers::invalid_unsigned_int && cells[n].locally_owned ? n
                                                                                : dealii::numbers::invalid_unsigned_int;
  }

  template <int dim>
  void
  BackgroundGrid<dim>::repartition(const CellWeight &weight)
  {
    // the 9.4 'weight' signal: the sum of the connected functions is a cell's
    // whole weight (no implicit base weight)
    const auto connection = tria.signals.weight.connect(
      [&](const typename dealii::Triangulation<dim>::cell_iterator &cell,
          const typename dealii::Triangulation<dim>::CellStatus) -> unsigned int { return weight(cell); });
    tria.repartition();
    connection.disconnect();
    setup();
  }

  template class CellCaches<2>;
  template class CellCaches<3>;
  template class BackgroundGrid<2>;
  template class BackgroundGrid<3>;
} // namespace talus
