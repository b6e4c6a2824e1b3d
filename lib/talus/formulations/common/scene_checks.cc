#include <talus/base/errors.h>
#include <talus/base/startup.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/io/particle_file.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>

namespace talus
{
  namespace
  {
    std::string
    fmt(const double x)
    {
      std::ostringstream os;
      os << x;
      return os.str();
    }

    template <int dim>
    std::string
    fmt_point(const dealii::Point<dim> &x)
    {
      std::ostringstream os;
      os << "(";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? ", " : "") << x[d];
      os << ")";
      return os.str();
    }

    std::string
    fmt_bytes(const double b)
    {
      std::ostringstream os;
      os.precision(3);
      if (b >= 1e12)
        os << b / 1e12 << " TB";
      else if (b >= 1e9)
        os << b / 1e9 << " GB";
      else
        os << b / 1e6 << " MB";
      return os.str();
    }

    /// Does a box body [lo, hi] contain a seeding position of the grid? The
    /// seeding puts n points per direction at the sub-cell centres
    /// L + (k + 1/2) h / n, k = 0 .. N n - 1 (h = (U - L) / N); a box is a
    /// product of intervals, so it is enough to find one position per direction.
    bool
    interval_has_seed(const double L, const double U, const unsigned int N, const unsigned int n, const double lo,
                      const double hi)
    {
      const double       s  = (U - L) / (double(N) * n);
      const double       k0 = std::ceil((lo - L) / s - 0.5 - 1e-12);
      const double       k  = std::max(0.0, k0);
      const double       x  = L + (k + 0.5) * s;
      const unsigned int nk = N * n;
      return k < nk && x <= hi + 1e-12 * (U - L) && x >= lo - 1e-12 * (U - L);
    }
  } // namespace

  double
  estimated_memory_bytes(const double n_cells, const double n_points, const unsigned int dim,
                         const unsigned int ranks_on_node, const double cell_factor)
  {
    // measured peak resident memory of talus-explicit (docs/reliability.md):
    // a process, a cell (triangulation, p4est, DoFs, cell cache, nodal vectors)
    // and a material point (ParticleHandler entry, properties, scratch)
    const double per_process = 180e6;
    const double per_cell    = (dim == 2 ? 600 : 1200) * cell_factor;
    const double per_point   = dim == 2 ? 650 : 800;
    return per_process * ranks_on_node + per_cell * n_cells + per_point * n_points;
  }

  template <int dim>
  void
  check_scene_consistency(const SceneParameters<dim> &p, const SceneCheckOptions &options)
  {
    // the point sets body k seeds
    const auto sets = [&](const unsigned int k) {
      return k < options.point_sets_of_body.size() ? double(options.point_sets_of_body[k]) : 1.0;
    };
    // the rows of the file bodies (read once; the checks of check_file_body)
    std::vector<double> file_rows(p.bodies.size(), 0.0);
    if (p.grid_mesh)
      {
        const auto  ids = p.grid_mesh->boundary_ids();
        std::string list;
        for (const auto i : ids)
          list += (list.empty() ? "" : ", ") + std::to_string(i);
        for (const auto &bc : p.boundary_conditions)
          require(std::find(ids.begin(), ids.end(), bc.id) != ids.end(),
                  std::string("boundary conditions/") +
                    (bc.kind == BoundaryCondition::Kind::fixed ? "fixed" : "roller"),
                  "boundary id " + std::to_string(bc.id) + " does not exist in the grid file '" + p.grid_file +
                    "' (ids present: " + (list.empty() ? "none" : list) + ")");
        for (const auto &plate : p.rigid_plates)
          if (plate.target == loads::RigidPlate<dim>::Target::boundary)
            require(std::find(ids.begin(), ids.end(), plate.boundary) != ids.end(), plate.where + "/boundary id",
                    "boundary id " + std::to_string(plate.boundary) + " does not exist in the grid file '" +
                      p.grid_file + "' (ids present: " + (list.empty() ? "none" : list) + ")");
      }
    for (const auto &plate : p.rigid_plates)
      if (plate.target == loads::RigidPlate<dim>::Target::region)
        for (unsigned int d = 0; d < dim; ++d)
          require(plate.lower[d] <= p.grid_upper[d] && plate.upper[d] >= p.grid_lower[d],
                  plate.where + "/region lower corner",
                  "the region lies outside the grid (grid extent " + std::to_string(p.grid_lower[d]) + " .. " +
                    std::to_string(p.grid_upper[d]) + " along " + std::string(1, char('x' + d)) + ")");
    // boundary ids of the box grid: 0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+
    for (const auto &bc : p.grid_mesh ? std::vector<BoundaryCondition>() : p.boundary_conditions)
      require(bc.id < 2 * dim,
              std::string("boundary conditions/") + (bc.kind == BoundaryCondition::Kind::fixed ? "fixed" : "roller"),
              "boundary id " + std::to_string(bc.id) + " does not exist in the grid (a " + std::to_string(dim) +
                "D box grid has ids 0.." + std::to_string(2 * dim - 1) + ": 0 = x-, 1 = x+, 2 = y-, 3 = y+" +
                (dim == 3 ? ", 4 = z-, 5 = z+)" : ")"));

    double n_cells = 1, cell_volume = 1;
    for (unsigned int d = 0; d < dim; ++d)
      {
        n_cells *= p.grid_cells[d];
        cell_volume *= (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d];
      }
    if (p.grid_mesh) // mean cell volume of the bounding box (an estimate for the point count)
      {
        const double h = p.grid_mesh->min_edge();
        require(h > 0 && std::isfinite(h), "grid/file", "'" + p.grid_file + "' has a cell with an edge of zero length");
      }
    {
      // points of the shape bodies (as below) and file bodies, for the memory estimate
      double n_points_estimate = 0;
      for (unsigned int k = 0; k < p.bodies.size(); ++k)
        {
          const auto &b = p.bodies[k];
          if (b.shape == BodyDescription<dim>::Shape::file)
            {
              file_rows[k] = double(check_file_body(p, k).rows);
              n_points_estimate += sets(k) * file_rows[k];
              continue;
            }
          dealii::Point<dim> lo, hi;
          b.bounding_box(lo, hi);
          double v = 1, cv = 1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              v *= std::max(0.0, std::min(hi[d], p.grid_upper[d]) - std::max(lo[d], p.grid_lower[d]));
              cv *= (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d];
            }
          n_points_estimate += sets(k) * v / cv * std::pow(double(b.particles_per_direction), dim);
        }
      int size = 1; // a --check without MPI is a singleton (tool.cc)
      if (mpi_started())
        MPI_Comm_size(MPI_COMM_WORLD, &size);
      // ranks sharing this node: Open MPI says; otherwise assume all (the conservative case)
      const char        *local   = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
      const unsigned int on_node = local ? std::max(1, std::atoi(local)) : size;
      const double       need =
        estimated_memory_bytes(n_cells, n_points_estimate, dim, on_node, options.cell_memory_factor) * on_node / size;
      const double avail = available_memory_bytes();
      require(avail < 0 || need <= avail, "grid/cells",
              fmt(n_cells) + " cells and about " + fmt(n_points_estimate) + " material points need about " +
                fmt_bytes(need) + " on this node" + (on_node > 1 ? " (" + std::to_string(on_node) + " ranks)" : "") +
                ", but only " + fmt_bytes(avail) +
                " are available (MemAvailable of /proc/meminfo, or the cgroup limit); use fewer cells or "
                "particles per direction, or a machine with more memory");
    }
    require(n_cells <= max_grid_cells, "grid/cells",
            fmt(n_cells) + " cells in total exceed the limit of " + fmt(max_grid_cells) +
              " (check the numbers per direction)");
    require(cell_volume > 0 && std::isfinite(cell_volume), "grid",
            "the cells have zero or non-finite size (corners " + fmt_point(p.grid_lower) + ", " +
              fmt_point(p.grid_upper) + ")");

    double n_points = 0;
    for (unsigned int k = 0; k < p.bodies.size(); ++k)
      {
        const auto       &b     = p.bodies[k];
        const std::string where = "body " + std::to_string(k) + " ('" + b.name + "')";
        if (b.shape == BodyDescription<dim>::Shape::file)
          {
            n_points += sets(k) * file_rows[k];
            continue;
          }
        // bounding box of the body
        dealii::Point<dim> lo, hi;
        b.bounding_box(lo, hi);
        double overlap = 1;
        for (unsigned int d = 0; d < dim; ++d)
          overlap *= std::max(0.0, std::min(hi[d], p.grid_upper[d]) - std::max(lo[d], p.grid_lower[d]));
        require(overlap > 0, where,
                "contains no material point: it lies entirely outside the grid (body " + fmt_point(lo) + " to " +
                  fmt_point(hi) + ", grid " + fmt_point(p.grid_lower) + " to " + fmt_point(p.grid_upper) + ")");
        if (!b.clip_to_grid)
          {
            // silently clipped bodies were a trap: the grid must hold the whole body
            const std::string out = outside_extent(b, p.grid_lower, p.grid_upper);
            require(out.empty(), where,
                    out +
                      "; a body must lie wholly inside the grid (allowed: move or shrink the body, enlarge "
                      "the grid, or set 'clip to grid = true' in '" +
                      "body " + std::to_string(k) + "' to drop the points outside)");
            if (p.grid_mesh && b.shape == BodyDescription<dim>::Shape::box)
              {
                // a grid file need not fill its bounding box: the cells must cover the box body
                const auto        &m       = *p.grid_mesh;
                const unsigned int nv      = m.n_cell_vertices();
                double             covered = 0, body_volume = 1;
                for (unsigned int d = 0; d < dim; ++d)
                  body_volume *= hi[d] - lo[d];
                for (std::size_t c = 0; c < m.n_cells(); ++c)
                  {
                    const auto &a = m.vertices[m.cells[c * nv]], &z = m.vertices[m.cells[c * nv + nv - 1]];
                    double      v = 1;
                    for (unsigned int d = 0; d < dim; ++d)
                      v *= std::max(0.0, std::min(hi[d], z[d]) - std::max(lo[d], a[d]));
                    covered += v;
                  }
                require(covered >= body_volume * (1 - 1e-9), where,
                        "the box " + fmt_point(lo) + " to " + fmt_point(hi) + " is not covered by the cells of '" +
                          p.grid_file + "' (" + fmt(body_volume - covered) +
                          " of its volume lies over no cell); a body must lie wholly inside the grid (allowed: "
                          "move or shrink the body, or set 'clip to grid = true' to drop the points outside)");
              }
          }
        if (b.shape == BodyDescription<dim>::Shape::box && !p.grid_mesh)
          for (unsigned int d = 0; d < dim; ++d)
            require(interval_has_seed(p.grid_lower[d], p.grid_upper[d], p.grid_cells[d], b.particles_per_direction,
                                      b.lower[d], b.upper[d]),
                    where,
                    "contains no material point: it is thinner than one sub-cell (cell size / particles per "
                    "direction) in direction " +
                      std::to_string(d) + " and holds no seeding position");
        n_points += sets(k) * overlap / cell_volume * std::pow(double(b.particles_per_direction), dim);
      }
    require(n_points <= max_material_points, "bodies",
            "about " + fmt(n_points) + " material points would be seeded, more than the limit of " +
              fmt(max_material_points) + " (check 'cells' and 'particles per direction')");
  }

  template <int dim>
  void
  check_run_files(const RunParameters<dim> &p)
  {
    require_output_directory(p.output_directory, "output/directory");
    const bool        own = p.checkpoint_directory.empty();
    const std::string dir = checkpoint_directory_of(p);
    if (p.checkpoint_interval > 0 || p.checkpoint_wall_interval > 0)
      require_output_directory(dir, own ? "output/directory" : "checkpoint/directory");
    if (p.restart == RunParameters<dim>::Restart::yes)
      {
        // the newest valid one is chosen (and read) later; here at least one must exist
        bool            found = false;
        std::error_code ec;
        if (std::filesystem::is_directory(dir, ec))
          for (const auto &e : std::filesystem::directory_iterator(dir, ec))
            {
              const std::string n = e.path().filename().string();
              if (n.rfind("checkpoint-", 0) == 0 && e.path().extension() == ".h5")
                found = true;
            }
        require(found, "checkpoint/restart",
                "no valid checkpoint: no checkpoint-<step>.h5 in '" + dir +
                  "' to restart from (allowed: 'if available' to start at t = 0 when there is none, or false)");
      }
  }

  template <int dim>
  FileBodyRows
  check_file_body(const SceneParameters<dim> &p, const unsigned int k)
  {
    const auto         &b     = p.bodies[k];
    const std::string   entry = "body " + std::to_string(k);
    const auto          info  = io::particle_file_info(b.particle_file, dim, MPI_COMM_WORLD, entry + "/particle file");
    const std::uint64_t rows  = b.file_body_id < info.rows_per_body.size() ? info.rows_per_body[b.file_body_id] : 0;
    if (rows == 0)
      {
        std::string present;
        for (unsigned int i = 0; i < info.rows_per_body.size(); ++i)
          if (info.rows_per_body[i])
            present += (present.empty() ? "" : ", ") + std::to_string(i);
        throw InputError(entry + "/file body id: particle file '" + b.particle_file +
                         "' has no material point with body id " + std::to_string(b.file_body_id) +
                         " (body ids present: " + (present.empty() ? "none" : present) + ")");
      }
    require(info.max_material < p.materials.size(), entry + "/particle file",
            "'" + b.particle_file + "' uses material id " + std::to_string(info.max_material) +
              ", but number of materials = " + std::to_string(p.materials.size()) + " (allowed 0.." +
              std::to_string(p.materials.size() - 1) + ")");
    for (unsigned int j = 0; j < k; ++j)
      require(p.bodies[j].shape != BodyDescription<dim>::Shape::file || p.bodies[j].particle_file != b.particle_file ||
                p.bodies[j].file_body_id != b.file_body_id,
              entry + "/file body id",
              "body " + std::to_string(j) + " already takes the points of body id " + std::to_string(b.file_body_id) +
                " of '" + b.particle_file + "' (each point once)");
    FileBodyRows r;
    r.rows = rows;
    for (const auto m : info.materials_per_body[b.file_body_id])
      r.materials.push_back(static_cast<unsigned int>(m));
    return r;
  }

  template <int dim>
  double
  smallest_cell_edge(const SceneParameters<dim> &p)
  {
    if (p.grid_mesh)
      return p.grid_mesh->min_edge();
    double h = std::numeric_limits<double>::max();
    for (unsigned int d = 0; d < dim; ++d)
      h = std::min(h, (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d]);
    return h;
  }

  template FileBodyRows check_file_body(const SceneParameters<2> &, unsigned int);
  template FileBodyRows check_file_body(const SceneParameters<3> &, unsigned int);
  template double       smallest_cell_edge(const SceneParameters<2> &);
  template double       smallest_cell_edge(const SceneParameters<3> &);
  template void         check_run_files(const RunParameters<2> &);
  template void         check_run_files(const RunParameters<3> &);
  template void         check_scene_consistency(const SceneParameters<2> &, const SceneCheckOptions &);
  template void         check_scene_consistency(const SceneParameters<3> &, const SceneCheckOptions &);
} // namespace talus
