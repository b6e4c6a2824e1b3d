#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/input_checks.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/io/output.h>
#include <talus/io/vtu.h>
#include <talus/io/png_snapshots.h>
#include <talus/loads/load_control.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/transfer/point_ops.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/particles/data_out.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

namespace talus::explicit_mpm
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::List;
  using dealii::Patterns::Selection;

  namespace
  {
    using Clock = std::chrono::steady_clock;
    double
    seconds_since(const Clock::time_point &t0)
    {
      return std::chrono::duration<double>(Clock::now() - t0).count();
    }

    std::string
    zeros(const unsigned int dim, const std::string &last = "0")
    {
      std::string s;
      for (unsigned int d = 0; d + 1 < dim; ++d)
        s += "0, ";
      return s + last;
    }



    std::vector<unsigned int>
    parse_ids(const std::string &text, const std::string &where)
    {
      std::vector<unsigned int> r;
      for (const auto &s : dealii::Utilities::split_string_list(text, ','))
        {
          const auto v = parse_doubles(s, where);
          require(v.size() == 1 && v[0] >= 0 && v[0] == std::floor(v[0]) && v[0] < 65535,
                  where,
                  "'" + s + "' is not a non-negative integer id");
          r.push_back(static_cast<unsigned int>(v[0]));
        }
      return r;
    }
  } // namespace

  // ================================================================ parameters
  void
  declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file)
  {
    declare_parameters_with_integration(prm, prm_file, "mpm");
  }

  void
  declare_parameters_with_integration(dealii::ParameterHandler &prm, const std::string &prm_file,
                                      const std::string &default_integration)
  {
    const unsigned int dim = dealii::Utilities::string_to_int(
      peek_entry(prm_file, "", "dimension", "2", Selection("2|3")));
    const unsigned int n_materials = dealii::Utilities::string_to_int(
      peek_entry(prm_file, "", "number of materials", "1", Integer(1, 64)));
    const unsigned int n_bodies = dealii::Utilities::string_to_int(
      peek_entry(prm_file, "", "number of bodies", "1", Integer(1, 64)));

    prm.declare_entry("dimension", "2", Selection("2|3"),
                      "Spatial dimension: 2 (plane strain, per unit thickness) or 3.");
    prm.enter_subsection("time");
    {
      prm.declare_entry("end time", "1.0", Double(0), "Simulated duration [s], > 0 (must be set).", /*has_to_be_set=*/true);
      prm.declare_entry("courant number", "0.5", Double(0, 1),
                        "Time step as a fraction of the critical time step L_min/c (seed 000 Eq. 4.120), "
                        "used when 'time step' is 0. Range (0, 1].");
      prm.declare_entry("time step", "0", Double(0),
                        "Fixed time step [s]; 0 = courant number x critical time step. A value above the "
                        "critical time step is refused unless 'force time step' is true.");
      prm.declare_entry("force time step", "false", Bool(),
                        "Accept a 'time step' above the critical one (stability studies).");
      prm.declare_entry("maximum steps", "0", Integer(0), "Stop after this many steps; 0 = no limit.");
    }
    prm.leave_subsection();

    prm.enter_subsection("grid");
    {
      prm.declare_entry("source", "box", Selection("box|file"),
                        "Background grid: 'box' (lower corner, upper corner, cells below) or 'file' (the grid "
                        "file written by talus-mesh, entry 'file'; see docs/mesh.md). A grid from a file must "
                        "consist of axis-aligned rectangles/boxes (MPM limitation); its boundary ids and "
                        "material ids come from the file.");
      prm.declare_entry("file", "", Anything(),
                        "grid/source = file: grid file (gmsh MSH 2.2 ASCII as written by talus-mesh).");
      prm.declare_entry("lower corner", zeros(dim), Anything(),
                        "Lower corner of the box background grid [m], dim comma-separated numbers.");
      prm.declare_entry("upper corner", (dim == 2 ? "1, 1" : "1, 1, 1"), Anything(),
                        "Upper corner of the box background grid [m].");
      prm.declare_entry("cells", dim == 2 ? "10, 10" : "10, 10, 10", Anything(),
                        "Number of cells per direction (dim positive integers). Boundary ids: "
                        "0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+.");
    }
    prm.leave_subsection();

    prm.enter_subsection("boundary conditions");
    {
      prm.declare_entry("fixed", "", Anything(),
                        "Boundary ids (comma-separated) on which every velocity component is zero.");
      prm.declare_entry("roller", "", Anything(),
                        "Boundary ids on which the velocity component normal to the boundary is zero.");
    }
    prm.leave_subsection();

    prm.enter_subsection("gravity");
    prm.declare_entry("acceleration", zeros(dim, "-9.81"), Anything(),
                      "Gravitational acceleration vector [m/s^2].");
    prm.leave_subsection();

    prm.enter_subsection("stability");
    prm.declare_entry("energy growth limit", "10", Double(1),
                      "The run is stopped as unstable when kinetic + strain energy exceed this factor times "
                      "the energy available (initial kinetic + strain energy + released potential energy + "
                      "external work), or when any state becomes non-finite.");
    prm.declare_entry("lost particles", "remove", Selection("remove|stop"),
                      "Material points that leave the grid: 'remove' them (counted in the log and in "
                      "series.csv, column lost_particles) and go on, or 'stop' the run with an error (exit 3).");
    prm.leave_subsection();

    prm.enter_subsection("output");
    {
      prm.declare_entry("directory", "output", Anything(), "Output directory (created if missing).");
      prm.declare_entry("vtu interval", "0", Double(0),
                        "Simulated time between particle VTU/PVTU outputs (PVD series); 0 = first and last only.");
      prm.declare_entry("series interval", "0", Double(0),
                        "Simulated time between rows of series.csv (energies, momentum, probes); 0 = every step.");
      prm.declare_entry("write grid", "false", Bool(), "Also write the background grid with nodal mass and velocity.");
      prm.declare_entry("final particles csv", "false", Bool(),
                        "Write particles_final.csv (id, position, displacement, velocity, stress, volume), "
                        "gathered on rank 0 and sorted by id: for tests and comparisons of small runs.");
      prm.declare_entry("progress", "true", Bool(), "Print progress with an ETA every few seconds.");
      prm.declare_entry("probes", "", Anything(),
                        "Points 'x,y[,z]; x,y[,z]; ...': the material point nearest to each at t = 0 is tracked; "
                        "its displacement, velocity and stress go to series.csv (and the results file).");
      prm.declare_entry("results file", "", Anything(),
                        "HDF5 results written at the end of the run (for talus-compare and post-processing), "
                        "relative to the output directory unless absolute; empty = none. Holds the columns of "
                        "series.csv (energies, momentum, probes over time), the probe displacements, velocities "
                        "and stresses over time, the final material point fields and the final fields mapped to "
                        "the grid nodes (lumped projection). Layout in docs/fem.md.");
      io::declare_png_snapshot_parameters(prm);
    }
    prm.leave_subsection();

    declare_numerics_parameters(prm, default_integration);
    prm.enter_subsection("checkpoint");
    {
      prm.declare_entry("interval", "0", Double(0),
                        "Simulated time between checkpoints (HDF5, complete state); 0 = off.");
      prm.declare_entry("wall clock interval", "0", Double(0),
                        "Wall-clock seconds between checkpoints (for batch time limits); 0 = off.");
      prm.declare_entry("keep", "2", Integer(1, 1000), "Number of newest checkpoints kept.");
      prm.declare_entry("directory", "", Anything(), "Checkpoint directory; empty = <output directory>/checkpoints.");
      prm.declare_entry("restart", "false", Selection("false|true|if available"),
                        "Resume from the newest valid checkpoint in the directory: 'true' (an error if there is "
                        "none), 'if available' (else start at t = 0), 'false'. The command-line option --restart "
                        "means 'true'. The .prm must describe the same scene (grid, materials, bodies); the end "
                        "time and output settings may change.");
    }
    prm.leave_subsection();
    declare_liquid_output(prm);

    prm.declare_entry("number of materials", "1", Integer(1, 64),
                      "Number of 'material k' subsections (k = 0..n-1).");
    for (unsigned int k = 0; k < n_materials; ++k)
      {
        prm.enter_subsection("material " + std::to_string(k));
        materials::declare_material_parameters(prm);
        declare_pore_liquid(prm);
        prm.leave_subsection();
      }

    prm.declare_entry("number of bodies", "1", Integer(1, 64), "Number of 'body k' subsections (k = 0..n-1).");
    loads::declare_parameters(prm, prm_file, dim, n_bodies);
    for (unsigned int k = 0; k < n_bodies; ++k)
      {
        prm.enter_subsection("body " + std::to_string(k));
        prm.declare_entry("name", "body " + std::to_string(k), Anything(), "Name used in messages.");
        prm.declare_entry("material", "0", Integer(0), "Material id (index of a 'material k' subsection).");
        prm.declare_entry("shape", "box", Selection("box|ball|polygon|file"),
                          "Region filled with material points: box (lower/upper corner), ball (disk in 2D, "
                          "sphere in 3D: center, radius), polygon (2D: vertices), or file: the material points "
                          "of a particle file written by talus-mesh ('particle file', 'file body id'), with "
                          "their positions, volumes, material ids (the entry 'material' is then not used) and "
                          "initial stresses if the file has them.");
        prm.declare_entry("particle file", "", Anything(), "shape = file: the particle file (HDF5, talus-mesh).");
        prm.declare_entry("file body id", "-1", Integer(-1, 65535),
                          "shape = file: take the rows of the file with this body id; -1 = the index k of this "
                          "'body k' subsection.");
        prm.declare_entry("lower corner", zeros(dim), Anything(), "Box: lower corner [m].");
        prm.declare_entry("upper corner", (dim == 2 ? "1, 1" : "1, 1, 1"), Anything(), "Box: upper corner [m].");
        prm.declare_entry("center", zeros(dim), Anything(), "Ball: center [m].");
        prm.declare_entry("radius", "0", Double(0), "Ball: radius [m].");
        prm.declare_entry("vertices", "", Anything(), "Polygon: 'x,y; x,y; ...' [m], at least 3 vertices.");
        prm.declare_entry("particles per direction", "2", Integer(1, 10),
                          "Material points per cell and direction (n^dim per filled cell, regular positions).");
        declare_clip_to_grid(prm);
        prm.declare_entry("initial velocity", zeros(dim), Anything(), "Uniform initial velocity [m/s].");
        prm.declare_entry("initial velocity function", "", Anything(),
                          "Optional initial velocity field, dim expressions separated by ';' in x, y, z "
                          "(muparser syntax, e.g. '0.1*sin(pi*x/2); 0'); overrides 'initial velocity'.");
        prm.declare_entry("function constants", "", Anything(),
                          "Constants for the function, 'name=value, name=value'.");
        declare_body_traction(prm, dim);
        prm.leave_subsection();
      }
  }

  template <int dim>
  Parameters<dim>
  parse_parameters(dealii::ParameterHandler &prm)
  {
    Parameters<dim> p;
    prm.enter_subsection("time");
    p.end_time        = prm.get_double("end time");
    p.courant         = prm.get_double("courant number");
    p.time_step       = prm.get_double("time step");
    p.force_time_step = prm.get_bool("force time step");
    p.max_steps       = prm.get_integer("maximum steps");
    require(p.courant > 0, "time/courant number", "must be > 0");
    require(p.end_time > 0, "time/end time", "must be > 0");
    prm.leave_subsection();

    prm.enter_subsection("grid");
    if (prm.get("source") == "file")
      {
        p.grid_file = prm.get("file");
        require_input_file(p.grid_file, "grid/file");
        auto mesh = std::make_shared<io::GridMesh>(io::read_msh(p.grid_file, dim));
        io::normalise_boxes(*mesh, "grid/file '" + p.grid_file + "'");
        io::check_faces(*mesh, "grid/file '" + p.grid_file + "'");
        double lo[3], hi[3];
        mesh->bounding_box(lo, hi);
        p.grid_cells.assign(dim, 1);
        p.grid_cells[0] = mesh->n_cells();
        for (unsigned int d = 0; d < dim; ++d)
          p.grid_lower[d] = lo[d], p.grid_upper[d] = hi[d];
        p.grid_mesh = mesh;
      }
    else
      {
        p.grid_lower = parse_point<dim>(prm.get("lower corner"), "grid/lower corner");
        p.grid_upper = parse_point<dim>(prm.get("upper corner"), "grid/upper corner");
        p.grid_cells = parse_cell_counts(prm.get("cells"), "grid/cells");
        require(p.grid_cells.size() == dim, "grid/cells", "needs exactly " + std::to_string(dim) + " integers");
        for (unsigned int d = 0; d < dim; ++d)
          {
            require(p.grid_cells[d] > 0, "grid/cells", "every entry must be > 0");
            require(p.grid_upper[d] > p.grid_lower[d], "grid/upper corner",
                    "must exceed 'lower corner' in every direction");
          }
      }
    prm.leave_subsection();

    prm.enter_subsection("boundary conditions");
    for (const auto id : parse_ids(prm.get("fixed"), "boundary conditions/fixed"))
      p.boundary_conditions.push_back({static_cast<dealii::types::boundary_id>(id), BoundaryCondition::Kind::fixed});
    for (const auto id : parse_ids(prm.get("roller"), "boundary conditions/roller"))
      p.boundary_conditions.push_back({static_cast<dealii::types::boundary_id>(id), BoundaryCondition::Kind::roller});
    prm.leave_subsection();

    prm.enter_subsection("gravity");
    p.gravity = parse_point<dim>(prm.get("acceleration"), "gravity/acceleration");
    prm.leave_subsection();

    prm.enter_subsection("stability");
    p.energy_growth_limit    = prm.get_double("energy growth limit");
    p.stop_on_lost_particles = prm.get("lost particles") == "stop";
    prm.leave_subsection();

    prm.enter_subsection("output");
    p.output_directory    = prm.get("directory");
    p.vtu_interval        = prm.get_double("vtu interval");
    p.series_interval     = prm.get_double("series interval");
    p.write_grid          = prm.get_bool("write grid");
    p.final_particles_csv = prm.get_bool("final particles csv");
    p.progress            = prm.get_bool("progress");
    require(!p.output_directory.empty(), "output/directory", "must not be empty");
    for (const auto &s : dealii::Utilities::split_string_list(prm.get("probes"), ';'))
      p.probes.push_back(parse_point<dim>(s, "output/probes"));
    p.results_file = prm.get("results file");
    if (!p.results_file.empty() && p.results_file.front() != '/')
      p.results_file = p.output_directory + "/" + p.results_file;
    io::check_png_snapshot_parameters(prm);
    prm.leave_subsection();

    prm.enter_subsection("checkpoint");
    p.checkpoint_interval      = prm.get_double("interval");
    p.checkpoint_wall_interval = prm.get_double("wall clock interval");
    p.checkpoint_keep          = prm.get_integer("keep");
    p.checkpoint_directory     = prm.get("directory");
    {
      const std::string r = prm.get("restart");
      p.restart = r == "true" ? Parameters<dim>::Restart::yes :
                  r == "if available" ? Parameters<dim>::Restart::if_available :
                                        Parameters<dim>::Restart::no;
    }
    if (tool_option_given("--restart"))
      p.restart = Parameters<dim>::Restart::yes;
    prm.leave_subsection();
    parse_liquid_output(prm, p.liquid);

    const unsigned int n_materials = prm.get_integer("number of materials");
    for (unsigned int k = 0; k < n_materials; ++k)
      {
        const std::string where = "material " + std::to_string(k);
        prm.enter_subsection(where);
        std::shared_ptr<const materials::Material> m = materials::create_material(prm, where, k);
        p.liquid.pore_liquid.push_back(parse_pore_liquid(prm, where, m));
        p.materials.push_back(m);
        prm.leave_subsection();
      }

    const unsigned int n_bodies = prm.get_integer("number of bodies");
    for (unsigned int k = 0; k < n_bodies; ++k)
      {
        const std::string where = "body " + std::to_string(k);
        prm.enter_subsection(where);
        BodyDescription<dim> b;
        b.name        = prm.get("name");
        b.material_id = prm.get_integer("material");
        require(b.material_id < n_materials, where + "/material",
                "material " + std::to_string(b.material_id) + " is not defined (number of materials = " +
                  std::to_string(n_materials) + ", allowed 0.." + std::to_string(n_materials - 1) + ")");
        const std::string shape = prm.get("shape");
        if (shape == "box")
          {
            b.shape = BodyDescription<dim>::Shape::box;
            b.lower = parse_point<dim>(prm.get("lower corner"), where + "/lower corner");
            b.upper = parse_point<dim>(prm.get("upper corner"), where + "/upper corner");
            for (unsigned int d = 0; d < dim; ++d)
              require(b.upper[d] > b.lower[d], where + "/upper corner", "must exceed 'lower corner' in every direction");
          }
        else if (shape == "ball")
          {
            b.shape  = BodyDescription<dim>::Shape::ball;
            b.center = parse_point<dim>(prm.get("center"), where + "/center");
            b.radius = prm.get_double("radius");
            require(b.radius > 0, where + "/radius", "must be > 0 for shape = ball");
          }
        else if (shape == "file")
          {
            b.shape         = BodyDescription<dim>::Shape::file;
            b.particle_file = prm.get("particle file");
            require_input_file(b.particle_file, where + "/particle file");
            const int id    = prm.get_integer("file body id");
            b.file_body_id  = id < 0 ? k : static_cast<unsigned int>(id);
          }
        else
          {
            require(dim == 2, where + "/shape", "polygon bodies exist in 2D only (allowed in 3D: box|ball|file)");
            b.shape = BodyDescription<dim>::Shape::polygon;
            for (const auto &s : dealii::Utilities::split_string_list(prm.get("vertices"), ';'))
              b.polygon.push_back(parse_point<2>(s, where + "/vertices"));
            require(b.polygon.size() >= 3, where + "/vertices", "a polygon needs at least 3 vertices");
          }
        b.particles_per_direction = prm.get_integer("particles per direction");
        b.clip_to_grid            = prm.get_bool("clip to grid");
        b.initial_velocity        = parse_point<dim>(prm.get("initial velocity"), where + "/initial velocity");
        const std::string expr    = prm.get("initial velocity function");
        if (!expr.empty())
          {
            std::map<std::string, double> constants = {{"pi", M_PI}, {"Pi", M_PI}};
            for (const auto &c : dealii::Utilities::split_string_list(prm.get("function constants"), ','))
              {
                const auto kv = dealii::Utilities::split_string_list(c, '=');
                const auto v = kv.size() == 2 ? parse_doubles(kv[1], where + "/function constants") : std::vector<double>();
                require(v.size() == 1, where + "/function constants", "'" + c + "' is not of the form name=value");
                constants[kv[0]] = v[0];
              }
            auto fp = std::make_shared<dealii::FunctionParser<dim>>(dim);
            try
              {
                fp->initialize(dealii::FunctionParser<dim>::default_variable_names(), expr, constants);
                fp->value(dealii::Point<dim>(), 0); // force a parse of every component
                for (unsigned int d = 0; d < dim; ++d)
                  fp->value(dealii::Point<dim>(), d);
              }
            catch (const std::exception &e)
              {
                throw InputError(where + "/initial velocity function: cannot parse '" + expr + "' (need " +
                                 std::to_string(dim) + " expressions separated by ';'): " + exception_text(e));
              }
            b.velocity_field = [fp](const dealii::Point<dim> &x) {
              dealii::Tensor<1, dim> v;
              for (unsigned int d = 0; d < dim; ++d)
                v[d] = fp->value(x, d);
              return v;
            };
          }
        p.liquid.tractions.push_back(parse_body_traction<dim>(prm, where));
        prm.leave_subsection();
        p.bodies.push_back(b);
      }
    p.loads = loads::parse_parameters<dim>(prm, p.end_time, p.gravity, p.boundary_conditions, p.bodies);
    if (p.loads.staged)
      {
        p.end_time = 0; // the sum of the stage durations
        for (const auto &st : p.loads.stages)
          p.end_time += st.duration;
      }
    p.numerics = parse_numerics_parameters(prm, n_bodies);
    if (p.numerics.bspline())
      {
        // the passes that are not yet kernel templates (transfer/) walk with Q1
        const std::string why = " is not available with numerics/shape function = quadratic bspline yet "
                                "(its particle passes use linear shape functions); allowed: ";
        require(p.numerics.integration == NumericsOptions::Integration::mpm, "numerics/integration",
                std::string(p.numerics.integration == NumericsOptions::Integration::mpm_mixed ? "mpm-mixed" :
                            p.numerics.integration == NumericsOptions::Integration::fem     ? "fem" :
                                                                                              "ul-fem") +
                  why + "mpm");
        require(p.numerics.smoothing == NumericsOptions::Smoothing::none, "numerics/strain smoothing",
                "strain smoothing" + why + "none");
        require(!p.numerics.contact(), "contact/pairs", "contact" + why + "empty");
        require(!p.liquid.any_coupled() && !p.liquid.any_traction(), "numerics/shape function",
                "coupled 2-phase materials and body tractions" + why + "1-phase materials without tractions");
        for (const auto &st : p.loads.stages)
          require(st.tractions.empty() && st.velocities.empty() && st.friction_ids.empty(), "numerics/shape function",
                  "tractions, prescribed velocities and boundary friction (loads sections)" + why +
                    "damping, mass scaling, quasi-static convergence, K0 and stages");
        require(!p.grid_mesh, "grid/source",
                "a grid file with quadratic B-splines: they need a uniform box grid; allowed: box");
        for (unsigned int d = 0; d < dim; ++d)
          require(p.grid_cells[d] >= shape::BSpline2<dim>::min_cells, "grid/cells",
                  "quadratic B-splines need at least 3 cells per direction (the wall treatment)");
      }
    if (p.numerics.fem())
      {
        const std::string mode = p.numerics.integration == NumericsOptions::Integration::fem ? "fem" : "ul-fem";
        require(!p.numerics.contact(), "contact/pairs",
                "contact is not available with numerics/integration = " + mode +
                  " (the Gauss points of one mesh share one velocity field); allowed: empty");
        require(p.numerics.smoothing == NumericsOptions::Smoothing::none, "numerics/strain smoothing",
                "strain smoothing is not available with numerics/integration = " + mode + "; allowed: none");
        require(!p.liquid.any_coupled() && !p.liquid.any_traction(), "numerics/integration",
                "'" + mode + "' runs the 1-phase step only: coupled 2-phase materials and body tractions are "
                "refused (allowed with them: mpm)");
        require(p.numerics.integration == NumericsOptions::Integration::fem ||
                  (p.checkpoint_interval == 0 && p.checkpoint_wall_interval == 0 &&
                   p.restart == Parameters<dim>::Restart::no),
                "checkpoint",
                "checkpoints and restarts are not available with numerics/integration = ul-fem (the moved "
                "mesh is not saved); allowed: interval = 0, wall clock interval = 0, restart = false");
      }
    check_consistency(p);
    return p;
  }

  // ================================================================ solver
  template <int dim>
  Solver<dim>::Solver(const Parameters<dim> &p, MPI_Comm c)
    : prm(p)
    , comm(c)
    , grid(c)
    , points(grid, "points")
    , gravity(p.gravity)
  {}

  template <int dim>
  Solver<dim>::~Solver() = default;

  template <int dim>
  double
  Solver<dim>::critical_time_step() const
  {
    // seed 000 Eq. 4.120 (solids), 4.121 (liquids, with the viscous limit), 4.129
    // (coupled 2-phase); for quads/hexes L_min is the smallest cell edge.
    double dt_min = std::numeric_limits<double>::max();
    for (const auto &c : critical_time_steps())
      dt_min = std::min(dt_min, c.dt);
    return dt_min;
  }

  template <int dim>
  std::vector<CriticalStep>
  Solver<dim>::critical_time_steps() const
  {
    auto r = explicit_mpm::critical_time_steps(prm.materials, prm.liquid.pore_liquid, grid.min_cell_size());
    // mass scaling (seed 000 Eq. 6.31, 1-phase solid): c / sqrt(beta), dt_cr x sqrt(beta)
    if (mass_scaling != 1.0)
      for (auto &c : r)
        {
          const double f = std::sqrt(mass_scaling);
          c.wave_speed /= f;
          c.dt *= f;
          c.dt_wave *= f;
          c.dt_other *= f;
          c.dt_4_122 *= f;
        }
    return r;
  }

  template <int dim>
  void
  Solver<dim>::setup()
  {
    if (prm.grid_mesh)
      grid.make_from_mesh(*prm.grid_mesh);
    else
      grid.make_box(prm.grid_lower, prm.grid_upper, prm.grid_cells);
    grid.setup();
    if (prm.numerics.bspline())
      grid.setup_bspline_patches(); // the 4^dim node patch of every owned cell
    constrained = grid.constrained_dofs(prm.boundary_conditions);
    grid.reinit_vector(nodal_mass);
    grid.reinit_vector(nodal_a);
    grid.reinit_vector(nodal_p);

    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    points.layout.n_history = n_history;
    if (prm.loads.active())
      {
        control                    = std::make_unique<loads::LoadControl<dim>>(prm.loads);
        control->extend_layout(points.layout);
      }
    // 2-phase / traction properties and the free-surface flag: only when used
    if (prm.liquid.any_coupled() || prm.liquid.any_traction())
      {
        two_phase = std::make_unique<TwoPhase<dim>>(*this);
        two_phase->extend_layout(points.layout);
      }
    if (prm.liquid.free_surface_factor > 0)
      {
        free_surface = std::make_unique<FreeSurface<dim>>(*this, prm.liquid.free_surface_factor);
        free_surface->extend_layout(points.layout);
      }
    points.initialize();
    if (prm.numerics.fem())
      fem = std::make_unique<FemIntegration<dim>>(*this, prm.numerics.integration ==
                                                           NumericsOptions::Integration::ul_fem);
    require(!two_phase || (!prm.numerics.extended_p2g() && prm.numerics.smoothing == NumericsOptions::Smoothing::none),
            "numerics/integration, numerics/strain smoothing, contact/pairs",
            "MPM-MIXED, strain smoothing and contact are available in the 1-phase step only (not with coupled "
            "2-phase materials or tractions); use integration = mpm, strain smoothing = none, no contact pairs");
    if (prm.numerics.contact())
      contact = std::make_unique<Contact<dim>>(grid, prm.numerics, prm.bodies.size());
    if (prm.numerics.smoothing != NumericsOptions::Smoothing::none)
      smoothing = std::make_unique<StrainSmoothing<dim>>(grid, prm.numerics.smoothing);

    bool restored = false;
    if (prm.restart != Parameters<dim>::Restart::no)
      {
        restored = restore_checkpoint();
        if (!restored && prm.restart == Parameters<dim>::Restart::yes)
          throw InputError("checkpoint/restart: no valid checkpoint (checkpoint-<step>.h5) in '" +
                           checkpoint_directory() + "'");
        if (!restored)
          log() << "  no checkpoint in " << checkpoint_directory() << ": starting at t = 0" << std::endl;
      }
    if (!restored)
      {
      std::vector<double> density;
      for (const auto &m : prm.materials)
        density.push_back(m->density());
      auto       seeded = seed_bodies(grid, prm.bodies, density, points.layout, points.handler);
      const auto filed  = insert_file_bodies(grid, prm.bodies, density, points.layout, points.handler, seeded.n_particles);
      for (unsigned int b = 0; b < prm.bodies.size(); ++b)
        seeded.volume_per_body[b] += filed.volume_per_body[b];
      log_clipping(prm, seeded, filed); // what 'clip to grid' left out (input_checks.h)
      if (fem) // the cells these points occupy get Gauss points instead (fem.h)
        seeded = fem->seed(density);
      for (unsigned int b = 0; b < prm.bodies.size(); ++b)
        require(seeded.volume_per_body[b] > 0, "body " + std::to_string(b) + " ('" + prm.bodies[b].name + "')",
                "contains no material point: it lies outside the grid or is smaller than one sub-cell");
      if (control)
        control->initial_state(*this); // K0 stresses, stage 0 (gravity, boundaries, mass scaling)

      // history initialisation
      for (auto &pt : points.handler)
        {
          auto        P = pt.get_properties();
          const auto &m = *prm.materials[static_cast<unsigned int>(P[PropertyLayout<dim>::material])];
          if (points.layout.n_history)
            m.initialize_history(PropertyLayout<dim>::get_stress(P.data()),
                                 dealii::ArrayView<double>(P.data() + points.layout.history, m.n_history()));
        }
      if (two_phase)
        two_phase->initialize_particles(); // restored points carry their 2-phase state
      }

    const double dt_cr = critical_time_step();
    if (restored)
      ; // the time step of the checkpointed run (bitwise continuation)
    else if (prm.time_step > 0)
      {
        if (prm.time_step > dt_cr && !prm.force_time_step)
          {
            std::ostringstream os;
            os << "time/time step: " << prm.time_step << " s exceeds the critical time step " << dt_cr
               << " s (L_min = " << grid.min_cell_size()
               << " m); lower it, or set 'force time step = true' to run anyway";
            throw InputError(os.str());
          }
        dt = prm.time_step;
      }
    else
      dt = prm.courant * dt_cr;

    // probes: nearest particle at t = 0 (ties: lowest id); restored: saved ids
    for (const auto &q : restored ? std::vector<dealii::Point<dim>>() : prm.probes)
      {
        std::pair<double, dealii::types::particle_index> best{std::numeric_limits<double>::max(), 0};
        for (const auto &pt : points.handler)
          best = std::min(best, std::make_pair(pt.get_location().distance(q), pt.get_id()));
        const auto all = dealii::Utilities::MPI::all_gather(comm, best);
        probe_ids.push_back(std::min_element(all.begin(), all.end())->second);
      }
    probe_values.assign(probe_ids.size() * 2 * dim, 0.0);
    probe_stress.assign(probe_ids.size() * PropertyLayout<dim>::n_stress, 0.0);

    // energy scale for the instability floor: sum m c^2
    double local_scale = 0;
    for (const auto &pt : points.handler)
      {
        const auto  P = pt.get_properties();
        const auto &m = *prm.materials[static_cast<unsigned int>(P[PropertyLayout<dim>::material])];
        local_scale += P[PropertyLayout<dim>::mass] * m.constrained_modulus() / m.density();
      }
    total_mass_setup = total_mass();
    if (!restored)
      {
        energy_scale     = dealii::Utilities::MPI::sum(local_scale, comm);
        initial_energies = energies();
      }
    collect_active_cells();
  }

  template <int dim>
  void
  Solver<dim>::collect_active_cells()
  {
    points.collect_active_cells();
    collect_active_dofs();
  }

  template <int dim>
  void
  Solver<dim>::collect_active_dofs()
  {
    // owned DoFs that can carry mass this step: those of active cells, plus the
    // owned DoFs other ranks contribute to (their particles' ghost nodes)
    const unsigned int n_owned = nodal_mass.locally_owned_size();
    if (dof_marker.size() != n_owned)
      dof_marker.assign(n_owned, 0);
    active_dofs.clear();
    const auto add = [&](const unsigned int i) {
      if (i < n_owned && !dof_marker[i])
        {
          dof_marker[i] = 1;
          active_dofs.push_back(i);
        }
    };
    if (prm.numerics.bspline()) // the nodes of the cells' patches (invalid outside the grid: skipped)
      for (const auto &ac : points.active_cells())
        {
          const unsigned int *dofs = grid.patch(ac.cell).dofs;
          for (unsigned int n = 0; n < BSplinePatch<dim>::n_slots; ++n)
            if (dofs[n * dim] < n_owned && !dof_marker[dofs[n * dim]]) // a node's components: all or none new
              for (unsigned int d = 0; d < dim; ++d)
                add(dofs[n * dim + d]);
        }
    else
      for (const auto &ac : points.active_cells())
        for (const unsigned int i : grid.cells[ac.cell].dofs)
          add(i);
    for (const auto &range : grid.partitioner->import_indices())
      for (unsigned int i = range.first; i < range.second; ++i)
        if (!dof_marker[i])
          {
            dof_marker[i] = 1;
            active_dofs.push_back(i);
          }
    for (const unsigned int i : active_dofs)
      dof_marker[i] = 0;
  }

  template <int dim>
  void
  Solver<dim>::zero_on_active(Vector &v) const
  {
    // only entries of active cells (and ghosts) can be non-zero: clear those
    // instead of the whole vector, so empty regions of the grid cost nothing
    v.zero_out_ghost_values();
    double *x = v.begin();
    for (const unsigned int i : active_dofs)
      x[i] = 0.0;
  }

  // ---------------------------------------------------------------- P2G (A)
  template <int dim>
  void
  Solver<dim>::p2g_mass_and_force()
  {
    if (fem)
      {
        fem->p2g_mass_and_force(); // Gauss points, current cell geometry (fem.cc)
        p2g_ready = true;
        return;
      }
    if (prm.numerics.extended_p2g())
      {
        p2g_extended(*this); // MPM-MIXED and/or per-body contact fields
        p2g_ready = true;
        return;
      }
    if (prm.numerics.bspline())
      p2g_mass_and_force_with<shape::BSpline2Box<dim>>();
    else
      p2g_mass_and_force_with<shape::Q1Box<dim>>();
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::p2g_mass_and_force_with()
  {
    zero_on_active(nodal_mass);
    zero_on_active(nodal_a);
    transfer::ScatterMassForce<dim, K> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
    transfer::for_each_active_cell(points, p2g);
    p2g_ready = true;
  }

  // ---------------------------------------------------------------- nodal a
  template <int dim>
  void
  Solver<dim>::nodal_acceleration()
  {
    nodal_mass.compress(dealii::VectorOperation::add);
    nodal_a.compress(dealii::VectorOperation::add);
    if (control)
      control->nodal_forces(*this); // tractions, convergence ratios, damping, mass scaling
    const double *M = nodal_mass.begin();
    double *      A = nodal_a.begin();
    for (const unsigned int i : active_dofs)
      A[i] = (M[i] > 0 && !constrained[i]) ? A[i] / M[i] : 0.0;
    if (control)
      control->nodal_accelerations(*this); // prescribed velocities, boundary friction
    nodal_a.update_ghost_values();
  }

  // ---------------------------------------------------------------- G2P + P2G (B)
  template <int dim>
  void
  Solver<dim>::g2p_velocity_p2g_momentum(const double h)
  {
    if (prm.numerics.bspline())
      g2p_velocity_p2g_momentum_with<shape::BSpline2Box<dim>>(h);
    else
      g2p_velocity_p2g_momentum_with<shape::Q1Box<dim>>(h);
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::g2p_velocity_p2g_momentum_with(const double h)
  {
    zero_on_active(nodal_p);
    transfer::UpdateVelocityScatterMomentum<dim, K> op{grid, nodal_a.begin(), nodal_p.begin(), h};
    transfer::for_each_active_cell(points, op);
    nodal_p.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Solver<dim>::scatter_point_momentum(Vector &v)
  {
    zero_on_active(v);
    const auto walk = [&](auto kernel) {
      using K = decltype(kernel);
      transfer::ScatterMomentum<dim, K> op(grid, v.begin());
      transfer::for_each_active_cell(points, op);
    };
    if (prm.numerics.bspline())
      walk(shape::BSpline2Box<dim>());
    else
      walk(shape::Q1Box<dim>());
    v.compress(dealii::VectorOperation::add);
  }

  template <int dim>
  void
  Solver<dim>::nodal_velocity()
  {
    const double *M = nodal_mass.begin();
    double *      V = nodal_p.begin();
    for (const unsigned int i : active_dofs)
      V[i] = (M[i] > 0 && !constrained[i]) ? V[i] / M[i] : 0.0; // Eq. 4.48
    if (control)
      control->nodal_velocities(*this);
    nodal_p.update_ghost_values();
  }

  // ---------------------------------------------------------------- G2P update (C)
  namespace
  {
    /// The explicit point physics of the update pass (seed 000 §4.3.7): strain
    /// and spin increments from the gradient of the displacement increment,
    /// the constitutive update, the volume update, and the sums of energies,
    /// momentum, finiteness and probes at the new position.
    template <int dim, class K>
    struct ExplicitPointUpdate
    {
      using L = PropertyLayout<dim>;
      const std::vector<std::shared_ptr<const materials::Material>> &materials;
      const unsigned int                                             history;
      const double                                                   h;
      const dealii::Tensor<1, dim>                                   g;
      Contact<dim> *                                                 contact;
      const StrainSmoothing<dim> *                                   smoothing;
      const bool                                                     need_strain_energy;
      const std::vector<dealii::types::particle_index> &             probe_ids;
      std::vector<double> &                                          probe_values;
      std::vector<double> &                                          probe_stress;

      Energies               e        = {};
      dealii::Tensor<1, dim> momentum = {};
      bool                   bad      = false;
      /// from update() to moved() of one point
      struct PointState
      {
        dealii::SymmetricTensor<2, 3> sigma;
        const materials::Material *   material;
      };

      inline void
      increments(const typename K::Cell & cell,
                 const typename K::Eval & ev,
                 const typename K::Field &du,
                 const double *           P,
                 double (&gu)[dim][dim],
                 double (&dx)[dim])
      {
        if constexpr (std::is_same_v<K, shape::Q1Box<dim>>)
          if (contact) // the body's own nodal velocities (§6.2)
            {
              typename K::Field dub;
              contact->body_increments(*cell.cc, static_cast<unsigned int>(P[L::body]), h, dub.u);
              shape::Q1Factorised<dim>::differences(dub.u, dub.D);
              transfer::default_increments<dim, K>(cell, ev, dub, gu, dx);
              return;
            }
        transfer::default_increments<dim, K>(cell, ev, du, gu, dx);
      }

      inline void
      update(const unsigned int c, const typename K::Cell &cell, double *P, const double (&gu)[dim][dim],
             PointState &state)
      {
        materials::Strain d_eps;
        materials::Spin   d_omega;
        for (unsigned int d = 0; d < dim; ++d)
          for (unsigned int k = 0; k < dim; ++k)
            {
              if (k >= d)
                d_eps[d][k] = 0.5 * (gu[d][k] + gu[k][d]);
              d_omega[d][k] = 0.5 * (gu[d][k] - gu[k][d]);
            }
        if (smoothing) // §6.7.1: smoothed volumetric part
          smoothing->apply(c, d_eps);
        const materials::Material &m     = *materials[static_cast<unsigned int>(P[L::material])];
        auto                       sigma = L::get_stress(P);
        m.update_stress(d_eps, d_omega, h, sigma, dealii::ArrayView<double>(P + history, m.n_history()));
        L::set_stress(sigma, P);
        state.sigma    = sigma;
        state.material = &m;
        const double dvol = trace(d_eps);
        P[L::volume] *= (1.0 + dvol); // Eq. 4.50 (density follows as m / V)
        // A point never integrates more than the volume of its cell. Without
        // this bound, points that separate from the mass at a free surface
        // (cohesionless material at the apex, sigma = 0) dilate without limit
        // under the grid's velocity gradient (1e6 x measured in the demo
        // column collapse) and blow the run up when they land again.
        double cell_volume = 1.0;
        for (unsigned int d = 0; d < dim; ++d)
          cell_volume *= cell.cc->h[d];
        if (P[L::volume] > cell_volume)
          P[L::volume] = cell_volume;
      }

      inline void
      moved(const transfer::PointIterator<dim> &it,
            const double *                      P,
            const dealii::Point<dim> &          x,
            const PointState &                  state)
      {
        const double mass = P[L::mass];
        double       v2 = 0, gx = 0;
        for (unsigned int d = 0; d < dim; ++d)
          {
            v2 += P[L::velocity + d] * P[L::velocity + d];
            gx += g[d] * x[d];
          }
        e.kinetic += 0.5 * mass * v2;
        for (unsigned int d = 0; d < dim; ++d)
          momentum[d] += mass * P[L::velocity + d];
        e.gravity_potential -= mass * gx;
        if (need_strain_energy)
          e.strain += P[L::volume] * state.material->elastic_energy_density(state.sigma);
        const auto &sigma = state.sigma;
        if (!std::isfinite(sigma[0][0] + sigma[1][1] + sigma[0][1] + x[0] + x[1] + v2 + P[L::volume]) ||
            !(P[L::volume] > 0))
          bad = true;
        if (!probe_ids.empty())
          for (unsigned int k = 0; k < probe_ids.size(); ++k)
            if (it->get_id() == probe_ids[k])
              {
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    probe_values[k * 2 * dim + d]       = P[L::displacement + d];
                    probe_values[k * 2 * dim + dim + d] = P[L::velocity + d];
                  }
                for (unsigned int q = 0; q < L::n_stress; ++q)
                  probe_stress[k * L::n_stress + q] = P[L::stress + q];
              }
      }
    };
  } // namespace

  template <int dim>
  void
  Solver<dim>::g2p_update(const double h)
  {
    if (prm.numerics.bspline())
      g2p_update_with<shape::BSpline2Box<dim>>(h);
    else
      g2p_update_with<shape::Q1Box<dim>>(h);
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::g2p_update_with(const double h)
  {
    std::fill(probe_values.begin(), probe_values.end(), 0.0);
    std::fill(probe_stress.begin(), probe_stress.end(), 0.0);
    ExplicitPointUpdate<dim, K> physics{prm.materials, points.layout.history, h, gravity,
                                        contact.get(), smoothing.get(), need_strain_energy,
                                        probe_ids, probe_values, probe_stress};
    // the mass and force of the next step are accumulated here, at the updated
    // state, for every particle that stays in its cell (seed 000 §4.3.7 step 1 of
    // the next cycle fused into this pass); moved particles are added by the
    // relocation, and any deal.II sort falls back to a full P2G pass.
    // Every non-zero entry of the mass/force vectors belongs to a cell that
    // holds particles now (writes go only to cells that hold particles after
    // the relocation), so clearing the active DoFs clears everything, and the
    // cells that receive moved particles below start from zero.
    zero_on_active(nodal_mass);
    zero_on_active(nodal_a);
    transfer::UpdateAndMove<dim, K, ExplicitPointUpdate<dim, K>> update{grid, points, nodal_p.begin(), h,
                                                                         physics};
    if (prm.numerics.extended_p2g()) // a full P2G pass follows
      transfer::for_each_active_cell(points, update);
    else
      {
        transfer::ScatterMassForce<dim, K> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
        transfer::Fused                    fused{update, p2g};
        transfer::for_each_active_cell(points, fused);
      }
    local_energies = physics.e;
    local_momentum = physics.momentum;
    local_bad      = physics.bad;
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::relocate_with()
  {
    // moved points add their mass and force to the next step's sums; a deal.II
    // sort recomputes reference locations and may move points to other ranks:
    // the fused P2G is then redone from scratch
    transfer::ScatterMassForce<dim, K> p2g{grid, gravity, nodal_mass.begin(), nodal_a.begin()};
    const bool                         sorted =
      points.relocate([&](const unsigned int c, const dealii::Point<dim> &xi, const double *P) {
        p2g.scatter_one(c, xi, P);
      });
    p2g_ready = !sorted && !prm.numerics.extended_p2g();
    // with B-splines a cell's stencil is 4^dim nodes: recompute the active DoFs
    // only when the set of cells with points changed (Q1: every step, as the
    // order of the list follows the cells and bitwise restarts rely on it)
    if (!prm.numerics.bspline() || points.cell_set_changed())
      collect_active_dofs();
  }

  template <int dim>
  void
  Solver<dim>::step(const double h)
  {
    if (two_phase)
      {
        two_phase->step(h); // separate passes (explicit_two_phase.cc)
        return;
      }
    auto t0 = Clock::now();
    if (!p2g_ready)
      p2g_mass_and_force();
    if (control)
      control->before_nodal_solve(*this, h); // traction point forces, nodal v^t
    timings.p2g += seconds_since(t0);
    t0 = Clock::now();
    nodal_acceleration();
    if (contact)
      contact->correct_accelerations(*this, h);
    timings.grid += seconds_since(t0);
    t0 = Clock::now();
    if (contact)
      contact->g2p_velocity_p2g_momentum(*this, h);
    else
      g2p_velocity_p2g_momentum(h);
    if (control)
      control->particle_velocities(*this); // prescribed material point velocities
    timings.p2g += seconds_since(t0);
    t0 = Clock::now();
    nodal_velocity();
    if (contact)
      contact->correct_velocities(*this, h);
    if (smoothing)
      smoothing->compute(*this, h);
    timings.grid += seconds_since(t0);
    t0 = Clock::now();
    if (fem)
      {
        // FEM / UL-FEM: points stay in their cells, no relocation; the update
        // pass accumulates the next step's mass and force (fem.cc)
        fem->update(h);
        p2g_ready = true;
        timings.g2p += seconds_since(t0);
        return;
      }
    g2p_update(h);
    timings.g2p += seconds_since(t0);
    t0 = Clock::now();
    if (prm.numerics.bspline())
      relocate_with<shape::BSpline2Box<dim>>();
    else
      relocate_with<shape::Q1Box<dim>>();
    timings.relocation += seconds_since(t0);
  }

  template <int dim>
  void
  Solver<dim>::advance(const unsigned int n_steps)
  {
    TimeLoop(*this, loop_settings(prm), comm).advance_steps(n_steps);
  }

  template <int dim>
  Energies
  Solver<dim>::energies() const
  {
    if (two_phase)
      return two_phase->energies();
    using L = PropertyLayout<dim>;
    Energies   e;
    const bool fixed_points = fem && !fem->updated_lagrangian(); // at their Gauss points: x = X + u
    for (const auto &pt : points.handler)
      {
        const auto  P = pt.get_properties();
        const auto &m = *prm.materials[static_cast<unsigned int>(P[L::material])];
        double      v2 = 0, gx = 0;
        for (unsigned int d = 0; d < dim; ++d)
          {
            v2 += P[L::velocity + d] * P[L::velocity + d];
            gx += gravity[d] * (pt.get_location()[d] + (fixed_points ? P[L::displacement + d] : 0.0));
          }
        e.kinetic += 0.5 * P[L::mass] * v2;
        e.gravity_potential -= P[L::mass] * gx;
        e.strain += P[L::volume] * m.elastic_energy_density(L::get_stress(P.data()));
      }
    double v[3] = {e.kinetic, e.strain, e.gravity_potential};
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 3), comm, dealii::ArrayView<double>(v, 3));
    return {v[0], v[1], v[2], external_work};
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::total_momentum() const
  {
    if (two_phase)
      return two_phase->total_momentum();
    dealii::Tensor<1, dim> p;
    for (const auto &pt : points.handler)
      for (unsigned int d = 0; d < dim; ++d)
        p[d] += pt.get_properties()[PropertyLayout<dim>::mass] *
                pt.get_properties()[PropertyLayout<dim>::velocity + d];
    return dealii::Utilities::MPI::sum(p, comm);
  }

  template <int dim>
  double
  Solver<dim>::total_mass() const
  {
    double m = 0;
    for (const auto &pt : points.handler)
      m += pt.get_properties()[PropertyLayout<dim>::mass];
    return dealii::Utilities::MPI::sum(m, comm);
  }

  template <int dim>
  std::pair<double, bool>
  Solver<dim>::check_incremental_state()
  {
    const bool same = points.check_active_cells();
    collect_active_dofs();
    if (!p2g_ready)
      return {0.0, same};
    const unsigned int  n = nodal_mass.locally_owned_size() + grid.partitioner->n_ghost_indices();
    std::vector<double> m0(nodal_mass.begin(), nodal_mass.begin() + n), f0(nodal_a.begin(), nodal_a.begin() + n);
    p2g_mass_and_force();
    double scale_m = 0, scale_f = 0, dm = 0, df = 0;
    std::vector<unsigned char> check(n, 0);
    for (const unsigned int i : active_dofs)
      check[i] = 1;
    for (unsigned int i = nodal_mass.locally_owned_size(); i < n; ++i)
      check[i] = 1;
    for (unsigned int i = 0; i < n; ++i)
      if (check[i])
        {
          scale_m = std::max(scale_m, std::abs(nodal_mass.local_element(i)));
          scale_f = std::max(scale_f, std::abs(nodal_a.local_element(i)));
          dm      = std::max(dm, std::abs(nodal_mass.local_element(i) - m0[i]));
          df      = std::max(df, std::abs(nodal_a.local_element(i) - f0[i]));
        }
    const double err = std::max(dm / std::max(scale_m, 1e-300), df / std::max(scale_f, 1e-300));
    return {dealii::Utilities::MPI::max(err, comm), !dealii::Utilities::MPI::logical_or(!same, comm)};
  }

  template <int dim>
  std::pair<double, dealii::Tensor<1, dim>>
  Solver<dim>::grid_mass_and_momentum()
  {
    // P2G of mass and of momentum of the current particle velocities (a = 0)
    p2g_mass_and_force();
    nodal_mass.compress(dealii::VectorOperation::add);
    nodal_a = 0.0;
    p2g_ready = false;
    g2p_velocity_p2g_momentum(0.0);
    double                 m = 0;
    dealii::Tensor<1, dim> p;
    const unsigned int     n = nodal_mass.locally_owned_size();
    // component of each owned DoF from the cell cache
    std::vector<int> component(n + grid.partitioner->n_ghost_indices(), -1);
    for (const auto &cc : grid.cells)
      for (unsigned int v = 0; v < shape::Q1<dim>::n_vertices; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          if (cc.h[0] > 0) // skip artificial cells (never filled)
            component[cc.dofs[v * dim + d]] = d;
    for (unsigned int i = 0; i < n; ++i)
      {
        if (component[i] == 0)
          m += nodal_mass.local_element(i);
        if (component[i] >= 0)
          p[component[i]] += nodal_p.local_element(i);
      }
    return {dealii::Utilities::MPI::sum(m, comm), dealii::Utilities::MPI::sum(p, comm)};
  }

  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    double v[5] = {local_energies.kinetic, need_strain_energy ? local_energies.strain : 0.0,
                   local_energies.gravity_potential,
                   local_bad ? 1.0 : 0.0, 0.0};
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 5), comm, dealii::ArrayView<double>(v, 5));
    std::ostringstream os;
    os << std::setprecision(4);
    if (v[3] > 0 || !std::isfinite(v[0] + v[1] + v[2]))
      {
        os << "step " << step_number << " (t = " << time << " s, dt = " << dt
           << " s): the state became non-finite or a material point volume became non-positive "
              "(velocity, stress or position). Reduce the time step (courant number) or check the material data.";
        throw InstabilityError(os.str());
      }
    const double available = initial_energies.kinetic + initial_energies.strain +
                             std::max(0.0, initial_energies.gravity_potential - v[2]) + std::abs(external_work);
    const double now = v[0] + v[1];
    // floor: 1e-4 of the potential energy of the mass over the grid's diagonal,
    // so that an undamped oscillation returning to its start (released
    // potential ~0) with a round-off-sized energy error is not taken for growth
    double diagonal = 0;
    for (unsigned int d = 0; d < dim; ++d)
      diagonal += (prm.grid_upper[d] - prm.grid_lower[d]) * (prm.grid_upper[d] - prm.grid_lower[d]);
    const double floor = 1e-12 * energy_scale + 1e-4 * total_mass_setup * gravity.norm() * std::sqrt(diagonal);
    if (now > prm.energy_growth_limit * available + floor)
      {
        os << "step " << step_number << " (t = " << time << " s, dt = " << dt
           << " s): kinetic + strain energy grew to " << now << " J, more than " << prm.energy_growth_limit
           << " x the energy available (" << available
           << " J: initial kinetic + strain, released potential, external work). "
              "The time step is above the stability limit or the material data are inconsistent.";
        throw InstabilityError(os.str());
      }
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    if (free_surface)
      free_surface->update();
    dealii::Particles::DataOut<dim> out;
    out.build_patches(points.handler, points.layout.names(), points.layout.interpretations());
    dealii::DataOutBase::VtkFlags flags;
    flags.time              = time;
    flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
    out.set_flags(flags);
    const std::string name = io::write_vtu_atomic(out, prm.output_directory, "particles", counter, comm);
    pvd_records.emplace_back(time, name);
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      io::write_pvd(prm.output_directory + "/particles.pvd", pvd_records);
    if (prm.write_grid)
      {
        dealii::DataOut<dim> dout;
        dout.attach_dof_handler(grid.dof_handler);
        std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> interp(
          dim, dealii::DataComponentInterpretation::component_is_part_of_vector);
        dout.add_data_vector(nodal_mass, std::vector<std::string>(dim, "nodal_mass"), dealii::DataOut<dim>::type_dof_data, interp);
        dout.add_data_vector(nodal_p, std::vector<std::string>(dim, "nodal_velocity"), dealii::DataOut<dim>::type_dof_data, interp);
        dout.build_patches();
        const std::string gname = io::write_vtu_atomic(dout, prm.output_directory, "grid", counter, comm);
        grid_pvd_records.emplace_back(time, gname);
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          io::write_pvd(prm.output_directory + "/grid.pvd", grid_pvd_records);
      }
  }

  template <int dim>
  void
  Solver<dim>::write_final_particles() const
  {
    using L = PropertyLayout<dim>;
    std::vector<std::vector<double>> rows;
    for (const auto &pt : points.handler)
      {
        std::vector<double> r = {static_cast<double>(pt.get_id())};
        const auto          P = pt.get_properties();
        // fem: the point stays at its Gauss point; its position is that plus u
        const bool fixed = fem && !fem->updated_lagrangian();
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(pt.get_location()[d] + (fixed ? P[L::displacement + d] : 0.0));
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(P[L::displacement + d]);
        for (unsigned int d = 0; d < dim; ++d)
          r.push_back(P[L::velocity + d]);
        for (unsigned int k = 0; k < L::n_stress; ++k)
          r.push_back(P[L::stress + k]);
        r.push_back(P[L::volume]);
        for (const auto &e : points.layout.extras)
          for (unsigned int i = 0; i < e.size; ++i)
            r.push_back(P[e.offset + i]);
        rows.push_back(r);
      }
    const auto all = dealii::Utilities::MPI::gather(comm, rows, 0);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::vector<std::vector<double>> merged;
    for (const auto &r : all)
      merged.insert(merged.end(), r.begin(), r.end());
    std::sort(merged.begin(), merged.end());
    std::vector<std::string> header = {"id"};
    const char *             ax[]   = {"x", "y", "z"};
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("pos_") + ax[d]);
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("u_") + ax[d]);
    for (unsigned int d = 0; d < dim; ++d)
      header.push_back(std::string("v_") + ax[d]);
    const auto names = points.layout.names();
    for (unsigned int k = 0; k < L::n_stress; ++k)
      header.push_back(names[L::stress + k]);
    header.push_back("volume");
    for (const auto &e : points.layout.extras)
      for (unsigned int i = 0; i < e.size; ++i)
        header.push_back(e.size == 1 ? e.name : e.name + "_" + std::string(ax[i < 3 ? i : 0]));
    io::AtomicFile f(prm.output_directory + "/particles_final.csv");
    for (unsigned int k = 0; k < header.size(); ++k)
      f.stream() << (k ? "," : "") << header[k];
    f.stream() << "\n" << std::setprecision(17);
    for (const auto &r : merged)
      {
        f.stream() << static_cast<unsigned long long>(r[0]);
        for (unsigned int k = 1; k < r.size(); ++k)
          f.stream() << "," << r[k];
        f.stream() << "\n";
      }
    f.commit();
  }

  template <int dim>
  LoopSettings
  loop_settings(const Parameters<dim> &prm)
  {
    LoopSettings s;
    s.end_time                 = prm.end_time;
    s.max_steps                = prm.max_steps;
    s.output_directory         = prm.output_directory;
    s.series_interval          = prm.series_interval;
    s.vtu_interval             = prm.vtu_interval;
    s.checkpoint_interval      = prm.checkpoint_interval;
    s.checkpoint_wall_interval = prm.checkpoint_wall_interval;
    s.progress                 = prm.progress;
    s.stop_on_lost_points      = prm.stop_on_lost_particles;
    s.max_cut_backs            = 0; // an explicit step always completes
    return s;
  }

  template <int dim>
  void
  Solver<dim>::run()
  {
    TimeLoop(*this, loop_settings(prm), comm).run();
  }

  // ================================================================ Formulation interface

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    const double dt_cr = critical_time_step();
    out << "talus-explicit: " << dim << "D, " << grid.tria.n_global_active_cells() << " cells, "
        << grid.dof_handler.n_dofs() << " DoFs, " << n_particles()
        << (fem ? (fem->updated_lagrangian() ? " Gauss points (ul-fem), " : " Gauss points (fem), ") :
                  " material points, ")
        << dealii::Utilities::MPI::n_mpi_processes(comm) << " rank(s)\n"
        << "  critical time step " << dt_cr << " s (L_min " << grid.min_cell_size() << " m), dt = " << dt
        << " s (" << dt / dt_cr << " x critical), end time " << prm.end_time << " s\n";
  }

  template <int dim>
  unsigned int
  Solver<dim>::n_stages() const
  {
    return control ? control->n_stages() : 1;
  }

  template <int dim>
  double
  Solver<dim>::begin_stage(const unsigned int k, const bool first, const bool resumed)
  {
    if (!control)
      return prm.end_time;
    // stage 0 of a fresh run was begun by setup()
    if (first && !resumed && k == 0)
      return stage_start_time + control->stage(0).duration;
    return control->begin_stage(*this, k, resumed);
  }

  template <int dim>
  bool
  Solver<dim>::stage_converged(std::string &message)
  {
    if (!control || !control->stage_converged())
      return false;
    std::ostringstream os;
    os << std::setprecision(6) << "force ratio " << control->force_ratio << ", energy ratio "
       << control->energy_ratio;
    message = os.str();
    return true;
  }

  template <int dim>
  void
  Solver<dim>::before_step(const double, const bool diagnostics_due)
  {
    // the stability check uses KE (+ SE when summed), a series row needs SE
    need_strain_energy = diagnostics_due || step_number % 10 == 0;
  }

  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    step(h);
    return StepOutcome::done;
  }

  template <int dim>
  void
  Solver<dim>::prepare_output()
  {
    // probe values at the start (after a step, the update pass fills them)
    using L = PropertyLayout<dim>;
    if (!probe_ids.empty())
      for (const auto &pt : points.handler)
        for (unsigned int k = 0; k < probe_ids.size(); ++k)
          if (pt.get_id() == probe_ids[k])
            {
              for (unsigned int d = 0; d < dim; ++d)
                {
                  probe_values[k * 2 * dim + d]       = pt.get_properties()[L::displacement + d];
                  probe_values[k * 2 * dim + dim + d] = pt.get_properties()[L::velocity + d];
                }
              for (unsigned int q = 0; q < L::n_stress; ++q)
                probe_stress[k * L::n_stress + q] = pt.get_properties()[L::stress + q];
            }
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    const char *             ax[] = {"x", "y", "z"};
    std::vector<std::string> c    = {"kinetic_energy", "strain_energy", "gravity_potential_energy",
                                     "external_work",  "total_energy"};
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("momentum_") + ax[d]);
    c.push_back("n_particles");
    c.push_back("lost_particles");
    if (control && control->has_convergence())
      {
        c.push_back("force_ratio");
        c.push_back("energy_ratio");
      }
    if (free_surface)
      {
        c.push_back("free_surface_points");
        for (unsigned int d = 0; d < dim; ++d)
          {
            c.push_back(std::string("extent_") + ax[d] + "_min");
            c.push_back(std::string("extent_") + ax[d] + "_max");
          }
      }
    for (unsigned int k = 0; k < probe_ids.size(); ++k)
      {
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back("probe" + std::to_string(k) + "_u" + ax[d]);
        for (unsigned int d = 0; d < dim; ++d)
          c.push_back("probe" + std::to_string(k) + "_v" + ax[d]);
      }
    // probe stresses after all displacement/velocity columns
    const auto names = points.layout.names();
    for (unsigned int k = 0; k < probe_ids.size(); ++k)
      for (unsigned int q = 0; q < PropertyLayout<dim>::n_stress; ++q)
        c.push_back("probe" + std::to_string(k) + "_" + names[PropertyLayout<dim>::stress + q]);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool after_step)
  {
    // After a step, the update pass has already summed the energies and the
    // momentum of the new state (strain energy when need_strain_energy was
    // set); only at the start and after a deal.II sort (points may have been
    // lost) are they summed by separate passes.
    Energies               e;
    dealii::Tensor<1, dim> p;
    if (after_step && !points.relocator().sorted_last)
      {
        double v[3 + dim] = {local_energies.kinetic, local_energies.strain, local_energies.gravity_potential};
        for (unsigned int d = 0; d < dim; ++d)
          v[3 + d] = local_momentum[d];
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(v, 3 + dim), comm,
                                    dealii::ArrayView<double>(v, 3 + dim));
        e = {v[0], v[1], v[2], external_work};
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = v[3 + d];
      }
    else
      {
        e = energies();
        p = total_momentum();
      }
    if (free_surface)
      free_surface->update();
    std::vector<double> probes(probe_values.size()), probe_sigma(probe_stress.size());
    if (!probe_values.empty())
      {
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(probe_values), comm,
                                    dealii::ArrayView<double>(probes));
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(probe_stress), comm,
                                    dealii::ArrayView<double>(probe_sigma));
      }
    std::vector<double> r = {e.kinetic, e.strain, e.gravity_potential, e.external_work, e.total()};
    for (unsigned int d = 0; d < dim; ++d)
      r.push_back(p[d]);
    r.push_back(static_cast<double>(n_particles()));
    r.push_back(static_cast<double>(points.relocation_stats.lost));
    if (control && control->has_convergence())
      {
        r.push_back(control->force_ratio);
        r.push_back(control->energy_ratio);
      }
    if (free_surface)
      {
        r.push_back(free_surface->count);
        for (const double x : free_surface->extent)
          r.push_back(x);
      }
    r.insert(r.end(), probes.begin(), probes.end());
    r.insert(r.end(), probe_sigma.begin(), probe_sigma.end());
    return r;
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    io::write_pvd(prm.output_directory + "/particles.pvd", pvd_records);
    if (prm.write_grid)
      io::write_pvd(prm.output_directory + "/grid.pvd", grid_pvd_records);
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &series_csv)
  {
    if (prm.final_particles_csv)
      write_final_particles();
    if (!prm.results_file.empty())
      write_results(series_csv);
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &loop_timings)
  {
    timings.output = loop_timings.output;
    timings.total  = loop_timings.total;
    const double ns = 1e9 * timings.total / std::max(1.0, double(step_number) * double(n_particles()));
    const auto & rs = points.relocation_stats;
    log() << std::setprecision(4) << "  breakdown [s]: P2G " << timings.p2g << ", grid " << timings.grid
          << ", G2P+stress " << timings.g2p << ", relocation " << timings.relocation << " (moves "
          << rs.seconds_moves << ", sorts " << rs.seconds_sorts << "), output " << timings.output
          << "; particles moved cell " << rs.moved_locally << ", full sorts " << rs.global_sorts
          << ", memory-order sorts " << rs.storage_sorts << ", lost " << rs.lost << "\n";
    log() << "talus-explicit: done: " << step_number << " steps, " << n_particles() << " particles, wall "
          << timings.total << " s, " << std::setprecision(3) << ns << " ns/particle-step, output in "
          << prm.output_directory << "/ (particles.pvd, series.csv)" << std::endl;
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    const unsigned int dim = prm.get_integer("dimension");
    if (dim == 2)
      {
        auto       p = parse_parameters<2>(prm);
        Solver<2>  s(p, MPI_COMM_WORLD);
        s.setup();
        s.run();
      }
    else
      {
        auto       p = parse_parameters<3>(prm);
        Solver<3>  s(p, MPI_COMM_WORLD);
        s.setup();
        s.run();
      }
    io::draw_png_snapshots(prm, MPI_COMM_WORLD); // after every output file is complete
    return exit_ok;
  }

  template struct Parameters<2>;
  template struct Parameters<3>;
  template Parameters<2> parse_parameters<2>(dealii::ParameterHandler &);
  template Parameters<3> parse_parameters<3>(dealii::ParameterHandler &);
  template LoopSettings loop_settings<2>(const Parameters<2> &);
  template LoopSettings loop_settings<3>(const Parameters<3> &);
  template class Solver<2>;
  template class Solver<3>;
} // namespace talus::explicit_mpm
