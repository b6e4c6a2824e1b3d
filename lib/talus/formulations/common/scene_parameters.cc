#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/io/png_snapshots.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <iostream>
#include <sstream>
#include <cmath>
#include <map>

namespace talus
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  std::vector<unsigned int>
  parse_ids(const std::string &text, const std::string &where)
  {
    std::vector<unsigned int> r;
    for (const auto &s : dealii::Utilities::split_string_list(text, ','))
      {
        const auto v = parse_doubles(s, where);
        require(v.size() == 1 && v[0] >= 0 && v[0] == std::floor(v[0]) && v[0] < 65535, where,
                "'" + s + "' is not a non-negative integer id");
        r.push_back(static_cast<unsigned int>(v[0]));
      }
    return r;
  }

  std::vector<unsigned int>
  parse_cell_counts(const std::string &text, const std::string &where)
  {
    std::vector<unsigned int> r;
    for (const auto &s : dealii::Utilities::split_string_list(text, ','))
      {
        const bool digits = !s.empty() && s.size() <= 10 &&
                            std::all_of(s.begin(), s.end(), [](const char c) { return c >= '0' && c <= '9'; });
        const double v = digits ? std::stod(s) : -1;
        require(digits && v >= 1 && v <= 2147483647.0, where,
                "'" + s + "' is not a positive integer (cells per direction, 1 to 2147483647; got '" + text + "')");
        r.push_back(static_cast<unsigned int>(v));
      }
    return r;
  }

  void
  declare_clip_to_grid(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("clip to grid", "false", Bool(),
                      "false: a body not wholly inside the grid is refused (naming the coordinate outside and "
                      "the grid extent); true: its points outside the grid are dropped and the log states how "
                      "many and the volume lost.");
  }

  SceneCounts
  peek_scene_counts(const std::string &prm_file)
  {
    SceneCounts c;
    c.dim = dealii::Utilities::string_to_int(peek_entry(prm_file, "", "dimension", "2", Selection("2|3")));
    c.n_materials =
      dealii::Utilities::string_to_int(peek_entry(prm_file, "", "number of materials", "1", Integer(1, 64)));
    c.n_bodies = dealii::Utilities::string_to_int(peek_entry(prm_file, "", "number of bodies", "1", Integer(1, 64)));
    c.n_rigid_plates = loads::peek_rigid_plates(prm_file);
    return c;
  }

  void
  declare_scene_parameters(dealii::ParameterHandler &prm, const SceneCounts &counts)
  {
    const unsigned int dim = counts.dim;
    prm.declare_entry("dimension", "2", Selection("2|3"),
                      "Spatial dimension: 2 (plane strain, per unit thickness) or 3.");
    prm.enter_subsection("grid");
    {
      prm.declare_entry("source", "box", Selection("box|file"),
                        "Background grid: 'box' (lower corner, upper corner, cells below) or 'file' (the grid "
                        "file written by talus-mesh, entry 'file'; see docs/mesh.md). A grid from a file must "
                        "consist of axis-aligned rectangles/boxes (MPM limitation); its boundary ids and "
                        "material ids come from the file.");
      prm.declare_entry("file", "", Anything(),
                        "grid/source = file: grid file (gmsh MSH 2.2 ASCII as written by talus-mesh).");
      prm.declare_entry("lower corner", zeros_text(dim), Anything(),
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
      loads::declare_rigid_plate_parameters(prm, dim, counts.n_rigid_plates);
    }
    prm.leave_subsection();

    prm.enter_subsection("numerics");
    prm.declare_entry("shape function", "linear", Selection("linear|quadratic bspline"),
                      "Shape functions of every particle-grid transfer, in every family: 'linear' (Q1 on the grid "
                      "cells) or 'quadratic bspline' (uniform quadratic B-splines on the grid nodes, 3 nodes per "
                      "direction per point: no cell-crossing noise; at the grid walls the outside node is a ghost "
                      "carrying the linear extrapolation, so fixed and roller walls hold exactly at the wall; "
                      "needs a uniform box grid with at least 3 cells per direction; docs/shape-functions.md). A "
                      "family refuses the combinations with its own options that it cannot honour, naming them.");
    prm.declare_entry(
      "volumetric stabilisation", "none", Selection("none|f-bar|modified f-bar"),
      "Volumetric-locking stabilisation of the point update, in every family (transfer/fbar.h). none: the "
      "increment dF as computed. f-bar: the model sees dF scaled by (dJbar / dJ)^(1/dim) (in plane in 2D), "
      "dJbar a smoothed volume change: talus-explicit and talus-semi-implicit the mass-weighted map of the "
      "points' dJ to the nodes and back (seed 002 Eqs. 79-80, linear and quadratic B-spline shape functions; "
      "docs/explicit.md, docs/semi-implicit.md), talus-implicit the volume-weighted mean of det dF over the "
      "points of a grid cell with its exact tangent (irreducible form, linear shape functions; "
      "docs/implicit.md). modified f-bar (talus-semi-implicit only): in addition the elastic b_e of the "
      "last step scaled by (Jebar / J^e)^(2/3), Jebar the mass-weighted mean of J^e = sqrt(det b_e) over "
      "the soil points of a fixed square patch (Eqs. 81-83; 'semi implicit/patch size'); needs a model "
      "that keeps b_e (hencky mohr coulomb, nor sand, neo hookean).");
    prm.leave_subsection();

    prm.enter_subsection("gravity");
    prm.declare_entry("acceleration", zeros_text(dim, "-9.81"), Anything(),
                      "Gravitational acceleration vector [m/s^2].");
    prm.leave_subsection();

    prm.declare_entry("number of materials", "1", Integer(1, 64), "Number of 'material k' subsections (k = 0..n-1).");
    for (unsigned int k = 0; k < counts.n_materials; ++k)
      {
        prm.enter_subsection("material " + std::to_string(k));
        materials::declare_material_parameters(prm);
        prm.leave_subsection();
      }

    prm.declare_entry("number of bodies", "1", Integer(1, 64), "Number of 'body k' subsections (k = 0..n-1).");
    for (unsigned int k = 0; k < counts.n_bodies; ++k)
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
        prm.declare_entry("lower corner", zeros_text(dim), Anything(), "Box: lower corner [m].");
        prm.declare_entry("upper corner", (dim == 2 ? "1, 1" : "1, 1, 1"), Anything(), "Box: upper corner [m].");
        prm.declare_entry("center", zeros_text(dim), Anything(), "Ball: center [m].");
        prm.declare_entry("radius", "0", Double(0), "Ball: radius [m].");
        prm.declare_entry("vertices", "", Anything(), "Polygon: 'x,y; x,y; ...' [m], at least 3 vertices.");
        prm.declare_entry("particles per direction", "2", Integer(1, 10),
                          "Material points per cell and direction (n^dim per filled cell, regular positions).");
        declare_clip_to_grid(prm);
        prm.declare_entry("initial velocity", zeros_text(dim), Anything(), "Uniform initial velocity [m/s].");
        prm.declare_entry("initial velocity function", "", Anything(),
                          "Optional initial velocity field, dim expressions separated by ';' in x, y, z "
                          "(muparser syntax, e.g. '0.1*sin(pi*x/2); 0'); overrides 'initial velocity'.");
        prm.declare_entry("function constants", "", Anything(),
                          "Constants for the function, 'name=value, name=value'.");
        declare_initial_stress(prm);
        prm.leave_subsection();
      }
  }

  SceneCounts
  declare_common_parameters(dealii::ParameterHandler &prm, const std::string &prm_file,
                            const std::string &time_step_doc, const std::vector<std::string> &png_fields_not_written)
  {
    const SceneCounts counts = peek_scene_counts(prm_file);
    declare_scene_parameters(prm, counts);
    declare_run_parameters(prm, counts.dim, png_fields_not_written);
    prm.enter_subsection("time");
    prm.declare_entry("time step", "0", Double(0), time_step_doc);
    prm.leave_subsection();
    return counts;
  }

  void
  declare_run_parameters(dealii::ParameterHandler &prm, const unsigned int dim,
                         const std::vector<std::string> &png_fields_not_written)
  {
    prm.enter_subsection("time");
    {
      prm.declare_entry("end time", "1.0", Double(0), "Simulated duration [s], > 0 (must be set).",
                        /*has_to_be_set=*/true);
      prm.declare_entry("maximum steps", "0", Integer(0), "Stop after this many steps; 0 = no limit.");
    }
    prm.leave_subsection();

    prm.enter_subsection("stability");
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
      prm.declare_entry("write grid", "false", Bool(),
                        "Also write the background grid with nodal mass and velocity (talus-explicit and "
                        "talus-fem; refused by talus-implicit and talus-semi-implicit).");
      prm.declare_entry("final particles csv", "false", Bool(),
                        "Write particles_final.csv (id, position, displacement, velocity, stress, volume), "
                        "gathered on rank 0 and sorted by id: for tests and comparisons of small runs.");
      prm.declare_entry("progress", "true", Bool(), "Print progress with an ETA every few seconds.");
      prm.declare_entry("probes", "", Anything(),
                        "Points 'x,y[,z]; x,y[,z]; ...': the material point nearest to each at t = 0 is tracked; "
                        "its displacement, velocity and stress go to series.csv (and the results file); "
                        "talus-semi-implicit: the nearest soil point, and the pore pressure of the nearest water "
                        "point.");
      prm.declare_entry("results file", "", Anything(),
                        "HDF5 results written at the end of the run (for talus-compare and post-processing), "
                        "relative to the output directory unless absolute; empty = none. Holds the columns of "
                        "series.csv (energies, momentum, probes over time), the probe displacements, velocities "
                        "and stresses over time, the final material point fields and the final fields mapped to "
                        "the grid nodes (lumped projection). Layout in docs/fem.md.");
      io::declare_png_snapshot_parameters(prm, dim, png_fields_not_written);
    }
    prm.leave_subsection();

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

    prm.enter_subsection("load balancing");
    {
      prm.declare_entry("interval", "0", Integer(0),
                        "Steps between checks of the load balance of a parallel run; 0 = off. When on, the "
                        "cells are partitioned by weight (cell weight + point weight x material points in the "
                        "cell) at the start, and again whenever the imbalance (largest number of material "
                        "points on a rank over the mean) exceeds 'imbalance threshold' at a check. The "
                        "imbalance is written to series.csv (column imbalance) and each rebalance to the log.");
      prm.declare_entry("imbalance threshold", "1.1", Double(1),
                        "Rebalance when max/mean material points per rank exceeds this (>= 1).");
      prm.declare_entry("point weight", "100", Integer(1, 100000), "Partition weight of one material point.");
      prm.declare_entry("cell weight", "1", Integer(0, 100000),
                        "Partition weight of a cell, with or without points (the memory and grid work it costs).");
    }
    prm.leave_subsection();
  }

  template <int dim>
  void
  parse_scene_parameters(dealii::ParameterHandler &prm, SceneParameters<dim> &p)
  {
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
    p.rigid_plates = loads::parse_rigid_plate_parameters<dim>(prm, !p.grid_mesh);
    prm.leave_subsection();

    prm.enter_subsection("gravity");
    p.gravity = parse_point<dim>(prm.get("acceleration"), "gravity/acceleration");
    prm.leave_subsection();

    prm.enter_subsection("numerics");
    p.shape_function =
      prm.get("shape function") == "quadratic bspline" ? ShapeFunction::quadratic_bspline : ShapeFunction::linear;
    {
      using VS                   = transfer::VolumetricStabilisation;
      const std::string vs       = prm.get("volumetric stabilisation");
      p.volumetric_stabilisation = vs == "f-bar" ? VS::f_bar : vs == "modified f-bar" ? VS::modified_f_bar : VS::none;
    }
    prm.leave_subsection();

    const unsigned int n_materials = prm.get_integer("number of materials");
    for (unsigned int k = 0; k < n_materials; ++k)
      {
        const std::string where = "material " + std::to_string(k);
        prm.enter_subsection(where);
        p.materials.push_back(materials::create_material(prm, where, k));
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
              require(b.upper[d] > b.lower[d], where + "/upper corner",
                      "must exceed 'lower corner' in every direction");
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
            const int id   = prm.get_integer("file body id");
            b.file_body_id = id < 0 ? k : static_cast<unsigned int>(id);
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
                const auto v =
                  kv.size() == 2 ? parse_doubles(kv[1], where + "/function constants") : std::vector<double>();
                require(v.size() == 1, where + "/function constants", "'" + c + "' is not of the form name=value");
                constants[kv[0]] = v[0];
              }
            auto fp = std::make_shared<dealii::FunctionParser<dim>>(dim);
            // deal.II 9.4 prints muparser's diagnosis to std::cerr before it
            // throws: keep it out of the tool's stderr (the InputError below
            // carries the same text, naming the entry)
            std::ostringstream    parser_noise;
            std::streambuf *const cerr_buffer = std::cerr.rdbuf(parser_noise.rdbuf());
            try
              {
                fp->initialize(dealii::FunctionParser<dim>::default_variable_names(), expr, constants);
                fp->value(dealii::Point<dim>(), 0); // force a parse of every component
                for (unsigned int d = 0; d < dim; ++d)
                  fp->value(dealii::Point<dim>(), d);
                std::cerr.rdbuf(cerr_buffer);
              }
            catch (const std::exception &e)
              {
                std::cerr.rdbuf(cerr_buffer);
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
        prm.leave_subsection();
        p.bodies.push_back(b);
      }
    p.initial_stress = parse_initial_stress<dim>(prm, p.bodies, p.gravity);
  }

  template <int dim>
  void
  parse_run_parameters(dealii::ParameterHandler &prm, RunParameters<dim> &p)
  {
    prm.enter_subsection("time");
    p.end_time  = prm.get_double("end time");
    p.max_steps = prm.get_integer("maximum steps");
    require(p.end_time > 0, "time/end time", "must be > 0");
    prm.leave_subsection();

    prm.enter_subsection("stability");
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

    using Restart = typename RunParameters<dim>::Restart;
    prm.enter_subsection("checkpoint");
    p.checkpoint_interval      = prm.get_double("interval");
    p.checkpoint_wall_interval = prm.get_double("wall clock interval");
    p.checkpoint_keep          = prm.get_integer("keep");
    p.checkpoint_directory     = prm.get("directory");
    {
      const std::string r = prm.get("restart");
      p.restart           = r == "true" ? Restart::yes : r == "if available" ? Restart::if_available : Restart::no;
    }
    if (tool_option_given("--restart"))
      p.restart = Restart::yes;
    prm.leave_subsection();

    prm.enter_subsection("load balancing");
    p.balance.interval     = prm.get_integer("interval");
    p.balance.threshold    = prm.get_double("imbalance threshold");
    p.balance.point_weight = prm.get_integer("point weight");
    p.balance.cell_weight  = prm.get_integer("cell weight");
    prm.leave_subsection();
  }

  template <int dim>
  LoopSettings
  loop_settings(const RunParameters<dim> &p)
  {
    LoopSettings s;
    s.end_time                 = p.end_time;
    s.max_steps                = p.max_steps;
    s.output_directory         = p.output_directory;
    s.series_interval          = p.series_interval;
    s.vtu_interval             = p.vtu_interval;
    s.checkpoint_interval      = p.checkpoint_interval;
    s.checkpoint_wall_interval = p.checkpoint_wall_interval;
    s.progress                 = p.progress;
    s.stop_on_lost_points      = p.stop_on_lost_particles;
    return s;
  }

  template struct SceneParameters<2>;
  template struct SceneParameters<3>;
  template struct RunParameters<2>;
  template struct RunParameters<3>;
  template void         parse_scene_parameters<2>(dealii::ParameterHandler &, SceneParameters<2> &);
  template void         parse_scene_parameters<3>(dealii::ParameterHandler &, SceneParameters<3> &);
  template void         parse_run_parameters<2>(dealii::ParameterHandler &, RunParameters<2> &);
  template void         parse_run_parameters<3>(dealii::ParameterHandler &, RunParameters<3> &);
  template LoopSettings loop_settings<2>(const RunParameters<2> &);
  template LoopSettings loop_settings<3>(const RunParameters<3> &);
} // namespace talus
