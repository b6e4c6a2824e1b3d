// talus-mesh: mesh preparation. Background grid (structured box, or a gmsh
// .geo/.msh recombined into quads/hexes) -> grid file (MSH 2.2 ASCII) and the
// material points of the bodies -> particle file (HDF5). See docs/mesh.md.
#include <talus/base/errors.h>
#include <talus/base/startup.h>
#include <talus/base/tool.h>
#include <talus/mesh/prepare.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace
{
  using namespace talus;
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  std::string
  zeros(const unsigned int dim)
  {
    return dim == 2 ? "0, 0" : "0, 0, 0";
  }


  /// Peak memory of talus-mesh for a box grid of n cells (docs/reliability.md:
  /// measured in 2D, 170 MB + 156 B per cell; 3D scaled by the vertices per cell).
  double
  mesh_memory_bytes(const double n_cells, const unsigned int dim)
  {
    return 170e6 + (dim == 2 ? 160.0 : 320.0) * n_cells;
  }

  /// "name = id, name = id" -> normalised name -> id
  std::map<std::string, unsigned int>
  parse_map(const std::string &text, const std::string &where)
  {
    std::map<std::string, unsigned int> m;
    for (const auto &item : dealii::Utilities::split_string_list(text, ','))
      {
        const auto kv = dealii::Utilities::split_string_list(item, '=');
        const auto v  = kv.size() == 2 ? parse_doubles(kv[1], where) : std::vector<double>();
        require(kv.size() == 2 && !kv[0].empty() && v.size() == 1 && v[0] >= 0 && v[0] <= 65535 &&
                  v[0] == std::floor(v[0]),
                where, "'" + item + "' is not of the form 'group name = id' (id an integer 0..65535)");
        m[mesh::normalise_name(kv[0])] = static_cast<unsigned int>(v[0]);
      }
    return m;
  }

  void
  declare(dealii::ParameterHandler &prm, const std::string &prm_file)
  {
    const unsigned int dim =
      dealii::Utilities::string_to_int(peek_entry(prm_file, "", "dimension", "2", Selection("2|3")));
    const unsigned int n_bodies =
      dealii::Utilities::string_to_int(peek_entry(prm_file, "", "number of bodies", "1", Integer(0, 64)));
    prm.declare_entry("dimension", "2", Selection("2|3"), "Spatial dimension.");
    prm.enter_subsection("grid");
    {
      prm.declare_entry("source", "box", Selection("box|gmsh"),
                        "Background grid: 'box' (lower corner, upper corner, cells; boundary ids 0 = x-, 1 = x+, "
                        "2 = y-, 3 = y+, 4 = z-, 5 = z+, material id 0) or 'gmsh' (entry 'file').");
      prm.declare_entry("lower corner", zeros(dim), Anything(), "box: lower corner [m].");
      prm.declare_entry("upper corner", dim == 2 ? "1, 1" : "1, 1, 1", Anything(), "box: upper corner [m].");
      prm.declare_entry("cells", dim == 2 ? "10, 10" : "10, 10, 10", Anything(), "box: cells per direction.");
      prm.declare_entry("file", "", Anything(),
                        "gmsh: a .geo (meshed here through the gmsh API) or a .msh (any version gmsh reads). "
                        "Boundary ids come from the physical groups of dimension dim-1, material ids from those "
                        "of dimension dim: names 'boundary <id> [label]' / 'material <id> [label]', unnamed "
                        "groups by their tag, other names through 'boundary groups' / 'material groups'.");
      prm.declare_entry("recombine", "true", Bool(),
                        "gmsh .geo: recombine triangles into quadrangles (Mesh.RecombineAll).");
      prm.declare_entry("subdivide", "false", Bool(),
                        "gmsh .geo: split every element into quadrangles/hexahedra (Mesh.SubdivisionAlgorithm).");
      prm.declare_entry("round coordinates", "true", Bool(),
                        "Round the node coordinates of gmsh meshes (grid and bodies) to 10 decimal digits below "
                        "the mesh extent: gmsh places transfinite nodes with errors of ~1e-12 of the extent, which "
                        "would make cells and volumes differ from the intended ones in the 12th digit.");
      prm.declare_entry("boundary groups", "", Anything(),
                        "Boundary ids of named groups that do not follow the convention: 'name = id, name = id'.");
      prm.declare_entry("material groups", "", Anything(), "Material ids of named groups: 'name = id, ...'.");
      prm.declare_entry("allow distorted cells", "false", Bool(),
                        "false: every cell must be an axis-aligned rectangle/box (what the MPM solvers need); "
                        "true: any valid quad/hex is written (for other uses of the grid).");
    }
    prm.leave_subsection();
    prm.enter_subsection("output");
    {
      prm.declare_entry("grid file", "grid.msh", Anything(), "Grid file to write (gmsh MSH 2.2 ASCII).", true);
      prm.declare_entry("particle file", "particles.h5", Anything(), "Particle file to write (HDF5).", true);
      prm.declare_entry("particle csv", "", Anything(),
                        "Optional CSV of the material points (x, y[, z], volume, material_id, body_id, and the initial "
                        "stress if any); empty = none.");
    }
    prm.leave_subsection();
    prm.declare_entry("number of bodies", "1", Integer(0, 64), "Number of 'body k' subsections.");
    for (unsigned int k = 0; k < n_bodies; ++k)
      {
        prm.enter_subsection("body " + std::to_string(k));
        prm.declare_entry("name", "body " + std::to_string(k), Anything(), "Name used in messages.");
        prm.declare_entry("source", "box", Selection("box|ball|polygon|grid|gmsh"),
                          "Where the material points go: a .prm shape (box, ball = disk/sphere, polygon) or "
                          "'grid' (the grid cells of 'groups', every cell if empty) -- n^dim points per grid "
                          "cell; or 'gmsh': the elements of a body mesh ('file', 'groups'; triangles/quadrangles, "
                          "tetrahedra/hexahedra), n per direction per element. Earlier bodies win where "
                          "grid-seeded bodies overlap.");
        prm.declare_entry(
          "material", "0", Anything(),
          "Material id (integer 0..65535), or 'groups': from the material groups of the mesh "
          "(the grid cell's material id; for gmsh bodies the 'material <id>' groups of the body mesh).");
        prm.declare_entry("lower corner", zeros(dim), Anything(), "box: lower corner [m].");
        prm.declare_entry("upper corner", dim == 2 ? "1, 1" : "1, 1, 1", Anything(), "box: upper corner [m].");
        prm.declare_entry("center", zeros(dim), Anything(), "ball: center [m].");
        prm.declare_entry("radius", "0", Double(0), "ball: radius [m].");
        prm.declare_entry("vertices", "", Anything(), "polygon (2D): 'x,y; x,y; ...' [m].");
        prm.declare_entry("file", "", Anything(), "gmsh: body mesh (.geo meshed here, or .msh).");
        prm.declare_entry("groups", "", Anything(),
                          "grid / gmsh: physical groups of dimension dim (names or numeric tags, comma-separated) "
                          "whose cells/elements form the body; empty = all.");
        prm.declare_entry("points per direction", "2", Integer(1, 10),
                          "Material points per cell/element and direction.");
        prm.declare_entry("clip to grid", "false", Bool(),
                          "box/ball/polygon: false = a body not wholly inside the grid is refused (naming the "
                          "coordinate outside and the grid extent); true = its points outside the grid are "
                          "dropped and the summary states how many and the volume lost.");
        prm.declare_entry("positions", "regular", Selection("regular|gauss"),
                          "regular: centres of n^dim equal sub-cells (triangles: of n^2 sub-triangles; not on "
                          "tetrahedra); gauss: Gauss points. Volumes are |det J| x weight, so they sum to the "
                          "cell/element volumes.");
        prm.declare_entry("k0", "0", Double(0),
                          "> 0: write the initial stress sigma_v = -density g (surface level - z), sigma_h = k0 "
                          "sigma_v (vertical = last axis; tension positive); 0: no initial stress.");
        prm.declare_entry("k0 density", "0", Double(0), "Density for the K0 stress [kg/m^3].");
        prm.declare_entry("k0 gravity", "9.81", Double(0), "Gravity for the K0 stress [m/s^2].");
        prm.declare_entry("surface level", "top", Anything(),
                          "Vertical coordinate of the ground surface for K0 [m]; 'top' = highest point of the "
                          "body + half a point spacing.");
        prm.leave_subsection();
      }
  }

  template <int dim>
  mesh::Settings<dim>
  parse(dealii::ParameterHandler &prm)
  {
    mesh::Settings<dim> s;
    prm.enter_subsection("grid");
    s.grid_from_gmsh = prm.get("source") == "gmsh";
    if (s.grid_from_gmsh)
      {
        s.grid_file = prm.get("file");
        require_input_file(s.grid_file, "grid/file");
      }
    else
      {
        const auto lo = parse_point<dim>(prm.get("lower corner"), "grid/lower corner");
        const auto hi = parse_point<dim>(prm.get("upper corner"), "grid/upper corner");
        for (unsigned int d = 0; d < dim; ++d)
          {
            s.lower[d] = lo[d], s.upper[d] = hi[d];
            require(hi[d] > lo[d], "grid/upper corner", "must exceed 'lower corner' in every direction");
          }
        const auto c = parse_doubles(prm.get("cells"), "grid/cells");
        require(c.size() == dim, "grid/cells", "needs exactly " + std::to_string(dim) + " integers");
        double total = 1;
        for (const double x : c)
          {
            require(x >= 1 && x == std::floor(x) && x < 1e8, "grid/cells", "every entry must be a positive integer");
            s.cells.push_back(static_cast<unsigned int>(x));
            total *= x;
          }
        const double need = mesh_memory_bytes(total, dim), avail = available_memory_bytes();
        require(avail < 0 || need <= avail, "grid/cells",
                std::to_string(static_cast<unsigned long long>(total)) + " cells need about " +
                  std::to_string(static_cast<unsigned long long>(need / 1e6)) + " MB for the grid, but only " +
                  std::to_string(static_cast<unsigned long long>(avail / 1e6)) +
                  " MB are available (MemAvailable of /proc/meminfo, or the cgroup limit)");
        require(total <= 1e8, "grid/cells", "more than 1e8 cells in total");
      }
    s.grid_options.recombine         = prm.get_bool("recombine");
    s.grid_options.subdivide         = prm.get_bool("subdivide");
    s.grid_options.round_coordinates = prm.get_bool("round coordinates");
    s.boundary_map                   = parse_map(prm.get("boundary groups"), "grid/boundary groups");
    s.material_map                   = parse_map(prm.get("material groups"), "grid/material groups");
    s.allow_distorted                = prm.get_bool("allow distorted cells");
    prm.leave_subsection();

    const unsigned int n = prm.get_integer("number of bodies");
    for (unsigned int k = 0; k < n; ++k)
      {
        const std::string where = "body " + std::to_string(k);
        prm.enter_subsection(where);
        mesh::BodySpec<dim> b;
        b.name                = prm.get("name");
        const std::string src = prm.get("source");
        using S               = typename mesh::BodySpec<dim>::Source;
        b.source              = src == "box"       ? S::box
                                : src == "ball"    ? S::ball
                                : src == "polygon" ? S::polygon
                                : src == "grid"    ? S::grid
                                                   : S::gmsh;
        const std::string mat = prm.get("material");
        if (mesh::normalise_name(mat) == "groups")
          b.material = -1;
        else
          {
            const auto v = parse_doubles(mat, where + "/material");
            require(v.size() == 1 && v[0] >= 0 && v[0] <= 65535 && v[0] == std::floor(v[0]), where + "/material",
                    "'" + mat + "' is not a material id (an integer 0..65535) or 'groups'");
            b.material = static_cast<int>(v[0]);
          }
        if (b.source == S::box)
          {
            b.shape.shape = BodyDescription<dim>::Shape::box;
            b.shape.lower = parse_point<dim>(prm.get("lower corner"), where + "/lower corner");
            b.shape.upper = parse_point<dim>(prm.get("upper corner"), where + "/upper corner");
            for (unsigned int d = 0; d < dim; ++d)
              require(b.shape.upper[d] > b.shape.lower[d], where + "/upper corner",
                      "must exceed 'lower corner' in every direction");
          }
        else if (b.source == S::ball)
          {
            b.shape.shape  = BodyDescription<dim>::Shape::ball;
            b.shape.center = parse_point<dim>(prm.get("center"), where + "/center");
            b.shape.radius = prm.get_double("radius");
            require(b.shape.radius > 0, where + "/radius", "must be > 0 for source = ball");
          }
        else if (b.source == S::polygon)
          {
            require(dim == 2, where + "/source", "polygon bodies exist in 2D only");
            b.shape.shape = BodyDescription<dim>::Shape::polygon;
            for (const auto &p : dealii::Utilities::split_string_list(prm.get("vertices"), ';'))
              b.shape.polygon.push_back(parse_point<2>(p, where + "/vertices"));
            require(b.shape.polygon.size() >= 3, where + "/vertices", "a polygon needs at least 3 vertices");
          }
        else if (b.source == S::gmsh)
          {
            b.file = prm.get("file");
            require_input_file(b.file, where + "/file");
          }
        if (b.source == S::grid || b.source == S::gmsh)
          b.groups = dealii::Utilities::split_string_list(prm.get("groups"), ',');
        else
          require(prm.get("groups").empty(), where + "/groups", "only for source = grid or gmsh");
        b.n                             = prm.get_integer("points per direction");
        b.shape.clip_to_grid            = prm.get_bool("clip to grid");
        b.shape.particles_per_direction = b.n;
        b.shape.name                    = b.name;
        if (!s.grid_from_gmsh && !b.shape.clip_to_grid &&
            (b.source == S::box || b.source == S::ball || b.source == S::polygon))
          {
            // a box grid is known here: refuse at --check (a gmsh grid: in mesh::prepare)
            dealii::Point<dim> glo, ghi;
            for (unsigned int d = 0; d < dim; ++d)
              glo[d] = s.lower[d], ghi[d] = s.upper[d];
            const std::string out = outside_extent(b.shape, glo, ghi);
            require(out.empty(), where + " ('" + b.name + "')",
                    out + "; a body must lie wholly inside the grid (allowed: move or shrink the body, enlarge "
                          "the grid, or set 'clip to grid = true' to drop the points outside)");
          }
        b.gauss      = prm.get("positions") == "gauss";
        b.k0         = prm.get_double("k0");
        b.k0_density = prm.get_double("k0 density");
        b.k0_gravity = prm.get_double("k0 gravity");
        if (b.k0 > 0)
          require(b.k0_density > 0, where + "/k0 density", "must be > 0 when k0 > 0");
        const std::string level = prm.get("surface level");
        if (mesh::normalise_name(level) != "top")
          {
            const auto v = parse_doubles(level, where + "/surface level");
            require(v.size() == 1, where + "/surface level", "one number or 'top'");
            b.surface_level = v[0];
          }
        s.bodies.push_back(b);
        prm.leave_subsection();
      }
    return s;
  }

  struct Outputs
  {
    std::string grid, particles, csv;
  };

  Outputs
  parse_outputs(dealii::ParameterHandler &prm)
  {
    Outputs o;
    prm.enter_subsection("output");
    o.grid      = prm.get("grid file");
    o.particles = prm.get("particle file");
    o.csv       = prm.get("particle csv");
    prm.leave_subsection();
    require_output_file(o.grid, "output/grid file");
    require_output_file(o.particles, "output/particle file");
    if (!o.csv.empty())
      require_output_file(o.csv, "output/particle csv");
    require(o.grid != o.particles && o.grid != o.csv && o.particles != o.csv, "output",
            "the grid file, particle file and particle csv must be different files");
    return o;
  }

  /// Run f on rank 0; an InputError there is rethrown on every rank (so that all
  /// ranks leave with the same message and exit status 2).
  template <typename F>
  void
  on_root(MPI_Comm comm, F &&f)
  {
    if (!mpi_started()) // --check of a singleton (no MPI, base/startup.h)
      {
        f();
        return;
      }
    const bool  root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
    std::string message;
    int         failed = 0;
    if (root)
      try
        {
          f();
        }
      catch (const InputError &e)
        {
          message = e.what();
          failed  = 1;
        }
    MPI_Bcast(&failed, 1, MPI_INT, 0, comm);
    if (failed)
      {
        int len = message.size();
        MPI_Bcast(&len, 1, MPI_INT, 0, comm);
        message.resize(len);
        MPI_Bcast(message.data(), len, MPI_CHAR, 0, comm);
        throw InputError(message);
      }
  }

  void
  make_parent(const std::string &file)
  {
    const auto parent = std::filesystem::path(file).parent_path();
    if (!parent.empty())
      std::filesystem::create_directories(parent);
  }

  template <int dim>
  int
  run_dim(dealii::ParameterHandler &prm)
  {
    const MPI_Comm    comm = MPI_COMM_WORLD;
    const auto        s    = parse<dim>(prm);
    const auto        out  = parse_outputs(prm);
    mesh::Result<dim> r;
    on_root(comm, [&]() { r = mesh::prepare(s); });
    const bool root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
    if (root)
      {
        for (const auto &f : {out.grid, out.particles, out.csv})
          if (!f.empty())
            make_parent(f);
      }
    MPI_Barrier(comm);
    // the particle file first (collective), the grid file last: a make rule on
    // the grid file sees both complete
    r.particles.dim = dim;
    io::write_particle_file(out.particles, r.particles, comm);
    if (root)
      {
        if (!out.csv.empty())
          {
            std::ofstream f(out.csv + ".part");
            const auto   &t      = r.particles;
            const bool    stress = !t.stress.empty();
            f << (dim == 2 ? "x,y" : "x,y,z") << ",volume,material_id,body_id"
              << (!stress    ? ""
                  : dim == 2 ? ",stress_xx,stress_yy,stress_zz,stress_xy"
                             : ",stress_xx,stress_yy,stress_zz,stress_xy,stress_yz,stress_xz")
              << "\n"
              << std::setprecision(17);
            for (std::size_t i = 0; i < t.size(); ++i)
              {
                for (unsigned int d = 0; d < dim; ++d)
                  f << t.position[i * dim + d] << ",";
                f << t.volume[i] << "," << t.material[i] << "," << t.body[i];
                if (stress)
                  for (unsigned int k = 0; k < t.n_stress(); ++k)
                    f << "," << t.stress[i * t.n_stress() + k];
                f << "\n";
              }
            f.close();
            std::filesystem::rename(out.csv + ".part", out.csv);
          }
        io::write_msh(r.grid, out.grid);
        auto       &os = log();
        const auto &sm = r.summary;
        os << "talus-mesh: grid: " << r.grid.n_cells() << " cells, " << r.grid.vertices.size() << " vertices, min edge "
           << r.grid.min_edge() << " m\n  boundary ids (faces):";
        for (const auto &[id, n] : sm.faces_per_boundary)
          os << " " << id << " (" << n << ")";
        os << "\n  material ids (cells):";
        for (const auto &[id, n] : sm.cells_per_material)
          os << " " << id << " (" << n << ")";
        os << "\n";
        for (const auto &note : sm.notes)
          os << "  note: " << note << "\n";
        for (std::size_t b = 0; b < s.bodies.size(); ++b)
          os << "  body " << b << " ('" << s.bodies[b].name << "'): " << sm.points_per_body[b]
             << " material points, volume " << std::setprecision(15) << sm.volume_per_body[b] << "\n";
        os << "  wrote " << out.grid << ", " << out.particles << (out.csv.empty() ? "" : ", " + out.csv) << std::endl;
      }
    MPI_Barrier(comm);
    return exit_ok;
  }

  void
  check(dealii::ParameterHandler &prm, const std::string &)
  {
    const MPI_Comm comm = MPI_COMM_WORLD;
    if (prm.get_integer("dimension") == 2)
      {
        const auto s = parse<2>(prm);
        parse_outputs(prm);
        on_root(comm, [&]() { mesh::check_groups(s); });
      }
    else
      {
        const auto s = parse<3>(prm);
        parse_outputs(prm);
        on_root(comm, [&]() { mesh::check_groups(s); });
      }
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return prm.get_integer("dimension") == 2 ? run_dim<2>(prm) : run_dim<3>(prm);
  }
} // namespace

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-mesh";
  tool.summary = "Mesh preparation: writes the background grid (a structured box, or a gmsh .geo/.msh\n"
                 "recombined into quadrangles/hexahedra, boundary and material ids from its physical groups)\n"
                 "as a gmsh MSH 2.2 ASCII file, and the material points of the bodies (.prm shapes, grid\n"
                 "regions, or gmsh body meshes of any first-order elements) as an HDF5 particle file, which\n"
                 "talus-explicit reads (grid/source = file, body shape = file). Refuses inverted or\n"
                 "degenerate cells, second-order elements, zero-volume, duplicated or outside points and\n"
                 "missing physical groups with exit status 2. See docs/mesh.md.";
  tool.declare = &declare;
  tool.check   = &check;
  tool.run     = &run;
  return talus::run_tool(argc, argv, tool);
}
