// talus — shared checkpoint pieces (point_checkpoint.h).
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/point_checkpoint.h>

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace talus
{
  namespace
  {
    bool
    is_root(MPI_Comm comm)
    {
      return dealii::Utilities::MPI::this_mpi_process(comm) == 0;
    }

    /// checkpoint-<step>.h5 files in dir, newest first (names carry the
    /// zero-padded step: lexicographic order is chronological).
    std::vector<std::string>
    sorted_checkpoints(const std::string &dir)
    {
      std::vector<std::string> files;
      if (std::filesystem::is_directory(dir))
        for (const auto &e : std::filesystem::directory_iterator(dir))
          {
            const std::string n = e.path().filename().string();
            if (n.rfind("checkpoint-", 0) == 0 && e.path().extension() == ".h5")
              files.push_back(e.path().string());
          }
      std::sort(files.rbegin(), files.rend());
      return files;
    }
  } // namespace

  std::vector<std::string>
  list_checkpoint_files(const std::string &dir, MPI_Comm comm)
  {
    std::vector<std::string> files;
    if (is_root(comm))
      files = sorted_checkpoints(dir);
    return dealii::Utilities::MPI::broadcast(comm, files, 0);
  }

  std::string
  prepare_checkpoint_file(const std::string &dir, const unsigned int step, MPI_Comm comm)
  {
    if (is_root(comm))
      {
        std::filesystem::create_directories(dir);
        for (const auto &e : std::filesystem::directory_iterator(dir))
          if (e.path().extension() == ".part") // left by a killed run
            std::filesystem::remove(e.path());
      }
    MPI_Barrier(comm);
    return dir + "/checkpoint-" + dealii::Utilities::int_to_string(step, 10) + ".h5";
  }

  void
  prune_checkpoint_files(const std::string &dir, const unsigned int keep, MPI_Comm comm)
  {
    if (is_root(comm))
      {
        const auto files = sorted_checkpoints(dir);
        for (std::size_t k = keep; k < files.size(); ++k)
          std::filesystem::remove(files[k]);
      }
  }

  void
  write_checkpoint_header(io::H5File &f, const std::string &format, const int version, const unsigned int dim,
                          MPI_Comm comm)
  {
    f.set_attribute("format", format);
    f.set_attribute("version", std::int64_t(version));
    f.set_attribute("dimension", std::int64_t(dim));
    f.set_attribute("ranks", std::int64_t(dealii::Utilities::MPI::n_mpi_processes(comm)));
  }

  template <int dim>
  std::unique_ptr<io::H5File>
  open_newest_checkpoint(const std::vector<std::string> &files, const std::string &format, const int version,
                         const std::vector<double> &signature, MPI_Comm comm)
  {
    for (const auto &file : files)
      {
        // a file that cannot be read is skipped (the older one is tried);
        // a readable one of another scene is an input error
        std::unique_ptr<io::H5File> fp;
        std::string                 problem;
        try
          {
            fp = std::make_unique<io::H5File>(file, io::H5File::Mode::read, comm);
            if (fp->get_string("format") != format || fp->get_int("version") != version)
              problem = "not a " + format + " of version " + std::to_string(version);
          }
        catch (const std::exception &e)
          {
            problem = e.what();
          }
        // every rank must agree on skipping
        if (dealii::Utilities::MPI::max(problem.empty() ? 0 : 1, comm))
          {
            log() << "  warning: skipping checkpoint " << file << ": "
                  << (problem.empty() ? "unreadable on another rank" : problem) << std::endl;
            continue;
          }
        const std::string where = "checkpoint " + file;
        if (fp->get_int("dimension") != dim)
          throw InputError(where + ": written by a " + std::to_string(fp->get_int("dimension")) +
                           "D run, this .prm is " + std::to_string(dim) + "D");
        const auto sig = fp->read_all("scene/signature");
        if (sig != signature)
          throw InputError(where + ": written for another scene (" + describe_scene_signature<dim>(sig) +
                           "); this .prm has " + describe_scene_signature<dim>(signature));
        return fp;
      }
    return nullptr;
  }

  void
  write_run_state(io::H5File &f, const RunState &s)
  {
    f.set_attribute("step", std::int64_t(s.step_number));
    f.set_attribute("stage", std::int64_t(s.current_stage));
    f.set_attribute("stage start time", s.stage_start_time);
    f.set_attribute("time", s.time);
    f.set_attribute("time step", s.dt);
    f.set_attribute("vtu counter", std::int64_t(s.counters.vtu_counter));
    f.set_attribute("next series", s.counters.next_series);
    f.set_attribute("next vtu", s.counters.next_vtu);
    f.set_attribute("next checkpoint", s.counters.next_checkpoint);
    f.set_attribute("lost reported", std::int64_t(s.counters.lost_reported));
  }

  void
  read_run_state(const io::H5File &f, RunState &s, const double checkpoint_interval)
  {
    s.step_number              = f.get_int("step");
    s.current_stage            = f.get_int("stage");
    s.stage_start_time         = f.has_attribute("stage start time") ? f.get_double("stage start time") : 0.0;
    s.time                     = f.get_double("time");
    s.dt                       = f.get_double("time step");
    s.counters.vtu_counter     = f.get_int("vtu counter");
    s.counters.next_series     = f.get_double("next series");
    s.counters.next_vtu        = f.get_double("next vtu");
    s.counters.next_checkpoint = f.get_double("next checkpoint");
    s.counters.lost_reported   = f.get_int("lost reported");
    // the next interval-driven checkpoint follows the current settings
    if (checkpoint_interval > 0 && s.counters.next_checkpoint <= s.time)
      s.counters.next_checkpoint = s.time + checkpoint_interval;
  }

  template <int dim>
  std::vector<double>
  scene_signature(const SceneParameters<dim> &scene, const unsigned int n_properties)
  {
    std::vector<double> s;
    for (unsigned int d = 0; d < dim; ++d)
      s.push_back(scene.grid_lower[d]);
    for (unsigned int d = 0; d < dim; ++d)
      s.push_back(scene.grid_upper[d]);
    for (unsigned int d = 0; d < dim; ++d)
      s.push_back(scene.grid_cells[d]);
    s.push_back(n_properties);
    s.push_back(scene.materials.size());
    s.push_back(scene.bodies.size());
    return s;
  }

  template <int dim>
  std::string
  describe_scene_signature(const std::vector<double> &s)
  {
    if (s.size() != 3 * dim + 3)
      return "an unreadable scene signature";
    std::ostringstream os;
    os << "grid (";
    for (unsigned int d = 0; d < dim; ++d)
      os << (d ? "," : "") << s[d];
    os << ") to (";
    for (unsigned int d = 0; d < dim; ++d)
      os << (d ? "," : "") << s[dim + d];
    os << "), cells ";
    for (unsigned int d = 0; d < dim; ++d)
      os << (d ? "x" : "") << s[2 * dim + d];
    os << ", " << s[3 * dim] << " properties per point, " << s[3 * dim + 1] << " materials, " << s[3 * dim + 2]
       << " bodies";
    return os.str();
  }

  template <int dim>
  void
  write_points(io::H5File &f, const MaterialPointSet<dim> &points, const std::string &group)
  {
    f.set_attribute(group + " moved locally", std::int64_t(points.relocation_stats.moved_locally));
    f.set_attribute(group + " global sorts", std::int64_t(points.relocation_stats.global_sorts));
    f.set_attribute(group + " storage sorts", std::int64_t(points.relocation_stats.storage_sorts));
    f.set_attribute(group + " lost", std::int64_t(points.relocation_stats.lost));
    const unsigned int         n_props = points.layout.n_properties();
    const std::size_t          n_local = points.handler.n_locally_owned_particles();
    std::vector<std::uint64_t> ids, cells;
    std::vector<double>        loc, ref, props;
    ids.reserve(n_local);
    cells.reserve(n_local);
    loc.reserve(n_local * dim);
    ref.reserve(n_local * dim);
    props.reserve(n_local * n_props);
    for (const auto &pt : points.handler)
      {
        ids.push_back(pt.get_id());
        cells.push_back(pt.get_surrounding_cell()->active_cell_index());
        const auto x = pt.get_location(), xi = pt.get_reference_location();
        for (unsigned int d = 0; d < dim; ++d)
          loc.push_back(x[d]);
        for (unsigned int d = 0; d < dim; ++d)
          ref.push_back(xi[d]);
        const auto P = pt.get_properties();
        props.insert(props.end(), P.begin(), P.end());
      }
    f.write_rows(group + "/id", ids, 1);
    f.write_rows(group + "/cell", cells, 1);
    f.write_rows(group + "/location", loc, dim);
    f.write_rows(group + "/reference", ref, dim);
    f.write_rows(group + "/properties", props, n_props);
    f.write_rows(group + "/ranks_n_particles", std::vector<std::uint64_t>{ids.size()}, 1);
    f.write_rows(group + "/ranks_moves", std::vector<std::uint64_t>{points.relocator().moves_since_sort()}, 1);
  }

  template <int dim>
  void
  read_points(const io::H5File &f, MaterialPointSet<dim> &points, const BackgroundGrid<dim> &grid,
              const std::string &where, const std::string &group)
  {
    MPI_Comm           comm               = grid.comm;
    const auto         n_ranks            = dealii::Utilities::MPI::n_mpi_processes(comm);
    const auto         rank               = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int n_props            = points.layout.n_properties();
    points.relocation_stats.moved_locally = f.get_int(group + " moved locally");
    points.relocation_stats.global_sorts  = f.get_int(group + " global sorts");
    points.relocation_stats.storage_sorts = f.get_int(group + " storage sorts");
    points.relocation_stats.lost          = f.get_int(group + " lost");
    if (f.get_int("ranks") == static_cast<std::int64_t>(n_ranks))
      {
        // my rows: the counts of the ranks before me
        const auto    counts = f.read_rows_u64(group + "/ranks_n_particles", 0, n_ranks);
        std::uint64_t begin  = 0;
        for (unsigned int r = 0; r < rank; ++r)
          begin += counts[r];
        const std::uint64_t end   = begin + counts[rank];
        const auto          ids   = f.read_rows_u64(group + "/id", begin, end);
        const auto          cells = f.read_rows_u64(group + "/cell", begin, end);
        const auto          loc   = f.read_rows(group + "/location", begin, end);
        const auto          ref   = f.read_rows(group + "/reference", begin, end);
        const auto          props = f.read_rows(group + "/properties", begin, end);
        // the points cell group by cell group, in the saved storage order
        std::vector<unsigned int>                                            cell_order;
        std::vector<std::vector<typename MaterialPointSet<dim>::SavedPoint>> groups;
        for (std::size_t i = 0; i < ids.size(); ++i)
          {
            if (cells[i] >= grid.cells.size() || !grid.cell_iterator(cells[i])->is_locally_owned())
              throw InputError(where + ": particle " + std::to_string(ids[i]) +
                               " refers to a cell this rank does not own (grid partition differs)");
            if (i == 0 || cells[i] != cells[i - 1])
              {
                cell_order.push_back(cells[i]);
                groups.emplace_back();
              }
            typename MaterialPointSet<dim>::SavedPoint q;
            for (unsigned int d = 0; d < dim; ++d)
              {
                q.x[d]  = loc[i * dim + d];
                q.xi[d] = ref[i * dim + d];
              }
            q.id         = ids[i];
            q.properties = props.data() + i * n_props;
            groups.back().push_back(q);
          }
        points.handler.reserve(ids.size());
        points.insert_in_order(cell_order, groups);
        points.relocator().moves_since_sort() = f.read_rows_u64(group + "/ranks_moves", rank, rank + 1)[0];
        return;
      }
    // another rank count: read a block, let deal.II send every point to the
    // rank owning its cell. The row index travels as the id; then every
    // cell's points are re-inserted in the saved order with their saved ids
    // and reference coordinates, cells in the order of their first saved row
    // (the storage order of the run, as far as a new partition allows).
    const std::uint64_t n                          = f.shape(group + "/id").first;
    const auto [b, e]                              = io::block_range(n, rank, n_ranks);
    const auto                                 loc = f.read_rows(group + "/location", b, e);
    const auto                                 pr  = f.read_rows(group + "/properties", b, e);
    std::vector<dealii::Point<dim>>            x(e - b);
    std::vector<std::vector<double>>           props(e - b);
    std::vector<dealii::types::particle_index> row(e - b);
    for (std::size_t i = 0; i < x.size(); ++i)
      {
        for (unsigned int d = 0; d < dim; ++d)
          x[i][d] = loc[i * dim + d];
        props[i].assign(pr.begin() + i * n_props, pr.begin() + (i + 1) * n_props);
        row[i] = b + i;
      }
    const auto boxes =
      dealii::GridTools::compute_mesh_predicate_bounding_box(grid.tria, dealii::IteratorFilters::LocallyOwnedCell());
    const auto global_boxes = dealii::Utilities::MPI::all_gather(comm, boxes);
    points.handler.insert_global_particles(x, global_boxes, props, row);
    if (points.handler.n_global_particles() != n)
      throw InputError(where + ": " + std::to_string(n) + " points in the file, " +
                       std::to_string(points.handler.n_global_particles()) + " placed in the grid");

    const auto all_ids = f.read_rows_u64(group + "/id", 0, n);
    const auto all_ref = f.read_rows(group + "/reference", 0, n);
    struct Local
    {
      std::uint64_t       row;
      unsigned int        cell;
      dealii::Point<dim>  x;
      std::vector<double> props;
    };
    std::vector<Local> local;
    local.reserve(points.handler.n_locally_owned_particles());
    for (const auto &pt : points.handler)
      {
        const auto P = pt.get_properties();
        local.push_back({pt.get_id(), pt.get_surrounding_cell()->active_cell_index(), pt.get_location(),
                         std::vector<double>(P.begin(), P.end())});
      }
    std::sort(local.begin(), local.end(), [](const Local &a, const Local &c) { return a.row < c.row; });
    std::vector<unsigned int>              cell_order;
    std::vector<std::vector<unsigned int>> in_cell_rows(grid.cells.size());
    for (unsigned int k = 0; k < local.size(); ++k)
      {
        if (in_cell_rows[local[k].cell].empty())
          cell_order.push_back(local[k].cell);
        in_cell_rows[local[k].cell].push_back(k);
      }
    points.handler.clear_particles();
    std::vector<std::vector<typename MaterialPointSet<dim>::SavedPoint>> groups(cell_order.size());
    for (std::size_t g = 0; g < cell_order.size(); ++g)
      {
        const unsigned int c = cell_order[g];
        for (const unsigned int k : in_cell_rows[c])
          {
            const auto        &q    = local[k];
            dealii::Point<dim> xi   = grid.reference_point(c, q.x), saved;
            double             dist = 0;
            for (unsigned int d = 0; d < dim; ++d)
              {
                saved[d] = all_ref[q.row * dim + d];
                dist     = std::max(dist, std::abs(saved[d] - xi[d]));
              }
            // the saved coordinates unless deal.II put the point into the
            // neighbour of its old cell (a point on a face)
            groups[g].push_back({q.x, dist < 1e-10 ? saved : xi,
                                 static_cast<dealii::types::particle_index>(all_ids[q.row]), q.props.data()});
          }
      }
    points.insert_in_order(cell_order, groups);
    // the memory-order sort counter: this rank's share
    std::uint64_t moves = 0;
    for (const auto m : f.read_all(group + "/ranks_moves"))
      moves += static_cast<std::uint64_t>(m);
    points.relocator().moves_since_sort() = moves / n_ranks;
  }

  void
  write_pvd_times(io::H5File &f, const std::string &name, const std::vector<std::pair<double, std::string>> &records)
  {
    std::vector<double> t;
    for (const auto &r : records)
      t.push_back(r.first);
    f.write_global(name, t, 1);
  }

  std::vector<std::pair<double, std::string>>
  read_pvd_records(const io::H5File &f, const std::string &name, const std::string &prefix)
  {
    std::vector<std::pair<double, std::string>> records;
    unsigned int                                k = 0;
    for (const double t : f.read_all(name))
      records.emplace_back(t, prefix + "_" + dealii::Utilities::int_to_string(k++, 4) + ".pvtu");
    return records;
  }

  template std::unique_ptr<io::H5File> open_newest_checkpoint<2>(const std::vector<std::string> &, const std::string &,
                                                                 int, const std::vector<double> &, MPI_Comm);
  template std::unique_ptr<io::H5File> open_newest_checkpoint<3>(const std::vector<std::string> &, const std::string &,
                                                                 int, const std::vector<double> &, MPI_Comm);
  template std::vector<double>         scene_signature<2>(const SceneParameters<2> &, unsigned int);
  template std::vector<double>         scene_signature<3>(const SceneParameters<3> &, unsigned int);
  template std::string                 describe_scene_signature<2>(const std::vector<double> &);
  template std::string                 describe_scene_signature<3>(const std::vector<double> &);
  template void                        write_points<2>(io::H5File &, const MaterialPointSet<2> &, const std::string &);
  template void                        write_points<3>(io::H5File &, const MaterialPointSet<3> &, const std::string &);
  template void read_points<2>(const io::H5File &, MaterialPointSet<2> &, const BackgroundGrid<2> &,
                               const std::string &, const std::string &);
  template void read_points<3>(const io::H5File &, MaterialPointSet<3> &, const BackgroundGrid<3> &,
                               const std::string &, const std::string &);
} // namespace talus
