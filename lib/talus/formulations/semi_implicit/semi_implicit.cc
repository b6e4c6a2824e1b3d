// talus — the semi-implicit two-phase double-point step (seed 002 §4.5) over
// the shared core: two MaterialPointSets, the kernels' point stencils
// (transfer/stencil_ops.h), a scalar NodalSpace + ActiveSet for the pressure
// increment, CG + ML AMG (solvers/linear_solver.h), the one TimeLoop.
//
// Signs: tension positive for the effective stress and the pore pressure (the
// paper's §2), so the hydrostatic pore pressure is negative.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/load_balance.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/formulations/semi_implicit/boundary_loads.h>
#include <talus/formulations/semi_implicit/fbar.h>
#include <talus/formulations/semi_implicit/semi_implicit.h>
#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/io/output.h>
#include <talus/io/particle_file.h>
#include <talus/io/vtu.h>
#include <talus/loads/k0.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/rigid_plate.h>
#include <talus/particles/material_point_set.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>
#include <talus/solvers/linear_solver.h>
#include <talus/transfer/active_set.h>
#include <talus/transfer/cell_walk.h>
#include <talus/transfer/matrix_ops.h>
#include <talus/transfer/point_ops.h>
#include <talus/transfer/stencil_ops.h>
#include <talus/materials/hencky_mohr_coulomb.h>
#include <talus/materials/neo_hookean.h>
#include <talus/materials/nor_sand.h>
#include <talus/materials/strain_increments.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/particles/data_out.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>
#include <type_traits>

namespace talus::semi_implicit
{
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Selection;

  // ================================================================ parameters
  void
  declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file)
  {
    const SceneCounts counts =
      declare_common_parameters(prm, prm_file,
                                "Fixed time step [s]; 0 = courant number x the soil skeleton's critical step "
                                "h_min / sqrt(E_c / ((1 - n) rho_s)). The step does not depend on the hydraulic "
                                "conductivity (seed 002 §5.3).",
                                /*png fields not written:*/ {"free surface"});
    prm.enter_subsection("time");
    {
      prm.declare_entry("courant number", "0.5", Double(0, 1),
                        "Fraction of the soil skeleton's critical step used when 'time step' is 0.");
    }
    prm.leave_subsection();
    prm.enter_subsection("semi implicit");
    {
      prm.declare_entry("water density", "1000", Double(0), "rho_w [kg/m^3], > 0.");
      prm.declare_entry("unit weight gravity", "9.81", Double(0),
                        "g of the Darcy drag n^2 rho_w g / k (Eq. 15) [m/s^2], > 0; kept when the body force "
                        "is zero (it converts the hydraulic conductivity, it is not a load).");
      prm.declare_entry("free surface volume fraction", "0.5", Double(0, 1),
                        "A cell is wet when the volume of its water points divided by the cell volume is at "
                        "least this; a node touched by water points that is a vertex of a wet and of a dry "
                        "cell is on the free water surface and gets p = 0. In (0, 1).");
      prm.declare_entry("pressure solver tolerance", "1e-10", Double(0, 1e-2),
                        "Relative residual |b - A x| / |b| at which CG + ML AMG stops on the pressure-"
                        "increment Poisson equation.");
      prm.declare_entry("pressure preconditioner rebuild interval", "100", dealii::Patterns::Integer(1),
                        "The ML AMG hierarchy of the pressure solve is kept between steps and rebuilt at "
                        "every step whose number is a multiple of this, whenever the pressure DoF set (the "
                        "active nodes) changes, after a checkpoint is written, at a restart and after a "
                        "solve that needed more than 2 x + 10 the CG iterations of the hierarchy's first; CG reaches "
                        "the same tolerance with a kept hierarchy in a few more iterations. 1 = rebuilt at "
                        "every step. An integer >= 1.");
      prm.declare_entry("pressure smoothing", "linear", Selection("linear|mass weighted|none"),
                        "mass weighted: the water points' pore pressure is replaced by the mass-weighted "
                        "map and remap through the nodes at every step (Eq. 77); it is biased by O(h grad p) "
                        "where a node's support is cut by a wall or the free surface. linear: the same map "
                        "with each point's value carried to the node by its pressure gradient, "
                        "p_I = sum N m (p + grad p . (x_I - x_p)) / sum N m, exact for linear fields "
                        "(docs/semi-implicit.md). none: the pressure changes only by the interpolated "
                        "increments (p += sum N dp).");
      prm.declare_entry("flip fraction", "1", Double(0, 1),
                        "Point velocity update: this fraction of FLIP (v_p + sum N (v^{t+1} - v^t)), the rest "
                        "PIC (sum N v^{t+1}). 1 = pure FLIP as in the paper.");
      prm.declare_entry("volumetric stabilisation", "none", Selection("none|f-bar|modified f-bar"),
                        "Soil volumetric-locking stabilisation (seed 002 §4.4.2). none: the increment dF as "
                        "computed. f-bar: dF scaled by (dJbar / dJ)^(1/dim), dJbar the mass-weighted node map "
                        "and remap of the points' dJ (Eqs. 79-80). modified f-bar: in addition the elastic b_e "
                        "of the last step scaled by (Jebar / J^e)^(2/3), Jebar the mass-weighted mean of "
                        "J^e = sqrt(det b_e) over the soil points of a fixed square patch (Eqs. 81-83); needs a "
                        "model that keeps b_e (hencky mohr coulomb, nor sand, neo hookean).");
      prm.declare_entry("point sets", "double", Selection("double|single"),
                        "double: soil and water are two sets of material points, each moving with its own "
                        "velocity (the paper's double-point method). single: the water is carried on the soil "
                        "points: the water points are seeded on the soil points and move with the soil's "
                        "velocity, so they stay on them; the water keeps its own velocity, mass, pressure and "
                        "the same equations and basis (the single-point comparison). single needs every body "
                        "to be saturated or soil.");
      prm.declare_entry("nor sand specific volume", "node-smoothed", Selection("node-smoothed|point"),
                        "The specific volume v of nor sand soil points. node-smoothed: v = v0 Jbar, Jbar the "
                        "mass-weighted node map and remap of the points' total J (seed 002 Eqs. 96-97). point: "
                        "v = v0 J of the point itself (Borja & Andrade, Eq. 95).");
      prm.declare_entry("patch size", "1.5", Double(0),
                        "Side of the modified F-bar patches in cells (1.5 for quadratic B-splines, 1 = the "
                        "cell-wise average); the patches tile the grid from its lower corner and stay fixed.");
      prm.declare_entry("rigid skeleton", "false", Bool(),
                        "true: the soil skeleton does not move (v_s = 0 at every node, no deformation, the "
                        "soil's terms dropped from the pressure equation): seepage through a fixed soil. The "
                        "water keeps its equations, drag and boundary conditions.");
      prm.declare_entry("drained boundaries", "", dealii::Patterns::Anything(),
                        "Comma-separated boundary ids of the box grid (0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, "
                        "5 = z+) where the water drains: the pore pressure is 0 on their nodes that carry water "
                        "and the water's velocity is not held by the wall condition there (the water can leave "
                        "the grid; the soil keeps its wall condition). Empty: none. An alias of "
                        "'boundary conditions/drainage k' with apply to = boundary, condition = drained "
                        "(docs/boundary-conditions.md).");
      prm.declare_entry("kozeny carman", "false", Bool(),
                        "Update the soil points' conductivity k = C1 n^3 / (1 - n)^2 with C1 from k0, n0 "
                        "(Alg. 8(g)); false: k stays k0.");
    }
    prm.leave_subsection();
    prm.enter_subsection("initial state");
    {
      prm.declare_entry("geostatic", "false", Bool(),
                        "Start from the geostatic state of a horizontally layered scene: pore pressure "
                        "-rho_w g (water level - y) at water points below the water level, effective "
                        "vertical stress -(1-n)(rho_s - rho_w) g depth (buoyant below the water level, "
                        "(1-n) rho_s g above) and horizontal K0 times it at soil points (g = |gravity|).");
      prm.declare_entry("water level", "0", Double(-1e300, 1e300),
                        "Vertical coordinate of the free water surface [m].");
      prm.declare_entry("soil surface", "0", Double(-1e300, 1e300), "Vertical coordinate of the soil surface [m].");
      prm.declare_entry("K0", "1", Double(0), "Horizontal / vertical effective stress ratio.");
      prm.declare_entry("initialisation time", "0", Double(-1e300, 1e300),
                        "Seed 002 App. B.4 (0: none). For t below this time [s] gravity grows linearly from 0 "
                        "to full, the soil models are elastic (nor sand without plasticity; linear elastic and "
                        "neo hookean as they are; other models are refused), the water points move with the "
                        "soil velocity (no seepage of the points) and every soil point has the 'initialisation "
                        "conductivity'. At its end each nor sand point takes its current pressure and elastic "
                        "volumetric strain as the reference, its image pressure from the OCR (Eq. 113) and "
                        "v0 <- J v0 (Eq. 114); then plasticity is on. The time continues: the end time includes "
                        "this stage (an end time equal to it ends the run on the initialised state).");
      prm.declare_entry("initialisation conductivity", "1", Double(-1e300, 1e300),
                        "Hydraulic conductivity [m/s] of every soil point during the App. B.4 initialisation "
                        "(the paper: 1 m/s), > 0.");
    }
    prm.leave_subsection();
    // issue 37 hook: the shared 'loads' (tractions, velocity conditions), the
    // drainage conditions and 'semi implicit/traction acts at' (boundary_loads.cc)
    declare_boundary_load_parameters(prm, prm_file, counts.dim);
    for (unsigned int k = 0; k < counts.n_materials; ++k)
      {
        prm.enter_subsection("material " + std::to_string(k));
        prm.enter_subsection("soil");
        prm.declare_entry("porosity", "0.3", Double(-1e300, 1e300), "Initial porosity n0 of the soil, in (0, 1).");
        prm.declare_entry("hydraulic conductivity", "1e-3", Double(-1e300, 1e300),
                          "Hydraulic conductivity k0 [m/s], > 0.");
        prm.leave_subsection();
        prm.leave_subsection();
      }
    for (unsigned int k = 0; k < counts.n_bodies; ++k)
      {
        prm.enter_subsection("body " + std::to_string(k));
        // must be set: it makes a .prm this family's (an explicit scene is not
        // silently read as a saturated two-phase one)
        prm.declare_entry("phase", "saturated", Selection("saturated|soil|water"),
                          "What the body seeds (must be set): saturated: soil and water points over the region "
                          "(the material is the soil's); soil: soil points only; water: water points only "
                          "(density 'semi implicit/water density'; the material entry is unused).",
                          /*has_to_be_set=*/true);
        prm.leave_subsection();
      }
  }

  namespace
  {
    /// J^e = sqrt(det b_e) of a soil point for the modified F-bar (Eq. 82), or
    /// 0 when its model keeps no b_e. The models that do keep it in history[0..5].
    double
    elastic_jacobian(const materials::Material &m, const double *history)
    {
      const dealii::ArrayView<const double> h(history, m.n_history());
      if (const auto *hmc = dynamic_cast<const materials::HenckyMohrCoulomb *>(&m))
        return hmc->elastic_jacobian(h);
      if (const auto *ns = dynamic_cast<const materials::NorSand *>(&m))
        return ns->elastic_jacobian(h);
      if (const auto *nh = dynamic_cast<const materials::NeoHookean *>(&m))
        return nh->elastic_jacobian(h);
      return 0.0;
    }
    bool
    keeps_elastic_b(const materials::Material &m)
    {
      return dynamic_cast<const materials::HenckyMohrCoulomb *>(&m) || dynamic_cast<const materials::NorSand *>(&m) ||
             dynamic_cast<const materials::NeoHookean *>(&m);
    }

    std::string
    number_text(const double x)
    {
      std::ostringstream os;
      os << std::setprecision(4) << x;
      return os.str();
    }

    /// The checks of a scene that need no grid: every body wholly inside the
    /// grid (or clipped), the memory the grid and points need, the time step.
    template <int dim>
    void
    check_scene(const Parameters<dim> &p)
    {
      double n_cells = 1, cell_volume = 1, h_min = std::numeric_limits<double>::max();
      for (unsigned int d = 0; d < dim; ++d)
        {
          const double h = (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d];
          n_cells *= p.grid_cells[d];
          cell_volume *= h;
          h_min = std::min(h_min, h);
        }
      // boundary ids of the box grid: 0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+
      for (const auto &bc : p.boundary_conditions)
        require(bc.id < 2 * dim,
                std::string("boundary conditions/") + (bc.kind == BoundaryCondition::Kind::fixed ? "fixed" : "roller"),
                "boundary id " + std::to_string(bc.id) + " does not exist in the grid (a " + std::to_string(dim) +
                  "D box has the ids 0 to " + std::to_string(2 * dim - 1) + ": x-, x+, y-, y+" +
                  (dim == 3 ? ", z-, z+)" : ")"));
      if (p.bspline())
        for (unsigned int d = 0; d < dim; ++d)
          require(p.grid_cells[d] >= 3, "grid/cells",
                  "quadratic B-splines need at least 3 cells in every direction (a point's 3-node window)");
      double n_points = 0;
      for (unsigned int k = 0; k < p.bodies.size(); ++k)
        {
          const auto       &b     = p.bodies[k];
          const std::string where = "body " + std::to_string(k) + " ('" + b.name + "')";
          if (b.shape == BodyDescription<dim>::Shape::file) // its rows; the seeding checks their positions
            {
              n_points += (p.phase_of_body[k] == Phase::saturated ? 2 : 1) * double(check_file_body(p, k).rows);
              continue;
            }
          dealii::Point<dim> lo, hi;
          b.bounding_box(lo, hi);
          double overlap = 1;
          for (unsigned int d = 0; d < dim; ++d)
            overlap *= std::max(0.0, std::min(hi[d], p.grid_upper[d]) - std::max(lo[d], p.grid_lower[d]));
          require(overlap > 0, where, "contains no material point: it lies entirely outside the grid");
          if (!b.clip_to_grid)
            {
              const std::string out = outside_extent(b, p.grid_lower, p.grid_upper);
              require(out.empty(), where,
                      out +
                        "; a body must lie wholly inside the grid (allowed: move or shrink the body, enlarge "
                        "the grid, or set 'clip to grid = true' in 'body " +
                        std::to_string(k) + "')");
            }
          // both sets for a saturated body
          n_points += (p.phase_of_body[k] == Phase::saturated ? 2 : 1) * overlap / cell_volume *
                      std::pow(double(b.particles_per_direction), dim);
        }
      // rough peak memory: the explicit family's measured figures per cell and
      // point (docs/reliability.md) doubled for the pressure space, its matrix
      // and the two-phase nodal vectors
      int size = 1;
      MPI_Comm_size(MPI_COMM_WORLD, &size);
      const double per_cell = dim == 2 ? 1200 : 2400, per_point = dim == 2 ? 650 : 800;
      const double need  = 180e6 * size + per_cell * n_cells + per_point * n_points;
      const double avail = available_memory_bytes();
      require(avail < 0 || need <= avail * size, "grid/cells",
              number_text(n_cells) + " cells and about " + number_text(n_points) + " material points need about " +
                number_text(need / 1e9) + " GB, but only " + number_text(avail / 1e9) +
                " GB are available; use fewer cells or particles per direction");
      const double dt_cr = soil_critical_time_step(p, h_min);
      require(p.time_step <= dt_cr, "time/time step",
              "is " + number_text(p.time_step) + " s, above the soil skeleton's critical step " + number_text(dt_cr) +
                " s (h_min / sqrt(E_c / ((1 - n) rho_s))); the semi-implicit step is limited by it");
    }
  } // namespace

  template <int dim>
  Parameters<dim>
  parse_parameters(dealii::ParameterHandler &prm)
  {
    Parameters<dim> p;
    parse_run_parameters<dim>(prm, p);
    parse_scene_parameters<dim>(prm, p);
    prm.enter_subsection("time");
    p.time_step = prm.get_double("time step");
    p.courant   = prm.get_double("courant number");
    require(p.courant > 0, "time/courant number", "must be > 0");
    prm.leave_subsection();
    prm.enter_subsection("semi implicit");
    p.water_density             = prm.get_double("water density");
    p.unit_weight_gravity       = prm.get_double("unit weight gravity");
    p.free_surface_fraction     = prm.get_double("free surface volume fraction");
    p.pressure_tolerance        = prm.get_double("pressure solver tolerance");
    p.pressure_rebuild_interval = prm.get_integer("pressure preconditioner rebuild interval");
    p.kozeny_carman             = prm.get_bool("kozeny carman");
    p.pressure_smoothing        = prm.get("pressure smoothing") != "none";
    p.linear_smoothing          = prm.get("pressure smoothing") == "linear";
    p.flip_fraction             = prm.get_double("flip fraction");
    p.rigid_skeleton            = prm.get_bool("rigid skeleton");
    // rigid plates (issue 37): a rigid skeleton holds every soil node, so no
    // plate can move it (a physical impossibility, not a missing feature)
    if (p.grid_mesh == nullptr) // (a grid file is refused below)
      loads::check_rigid_plates_on_box(p.rigid_plates, p.grid_lower, p.grid_upper, p.grid_cells, p.boundary_conditions);
    if (p.rigid_skeleton)
      loads::refuse_rigid_plates(p.rigid_plates, "talus-semi-implicit",
                                 "'semi implicit/rigid skeleton = true' holds every soil node at rest, so no plate "
                                 "can move the soil (allowed: rigid skeleton = false, or no plate)");
    {
      const std::string text = prm.get("drained boundaries");
      for (const auto &item : dealii::Utilities::split_string_list(text, ','))
        {
          bool ok = !item.empty() && item.find_first_not_of("0123456789") == std::string::npos && item.size() < 3;
          unsigned int id = ok ? static_cast<unsigned int>(std::stoul(item)) : 0;
          ok              = ok && id < 2 * dim;
          require(ok, "semi implicit/drained boundaries",
                  "is '" + text + "'; allowed: empty or comma-separated boundary ids of the " + std::to_string(dim) +
                    "D box, 0 to " + std::to_string(2 * dim - 1) + " (x-, x+, y-, y+" + (dim == 3 ? ", z-, z+)" : ")"));
          // issue 37: an alias of 'boundary conditions/drainage k' (drained boundary)
          p.drainage.push_back(loads::drained_boundary<dim>(static_cast<dealii::types::boundary_id>(id),
                                                            "semi implicit/drained boundaries"));
        }
    }
    {
      const std::string st       = prm.get("volumetric stabilisation");
      p.stabilisation            = st == "f-bar"            ? VolumetricStabilisation::f_bar
                                   : st == "modified f-bar" ? VolumetricStabilisation::modified_f_bar
                                                            : VolumetricStabilisation::none;
      p.patch_size               = prm.get_double("patch size");
      p.single_point             = prm.get("point sets") == "single";
      p.smoothed_specific_volume = prm.get("nor sand specific volume") == "node-smoothed";
      require(p.patch_size >= 0.5 && p.patch_size <= 10, "semi implicit/patch size", "must lie in [0.5, 10] cells");
    }
    require(p.water_density > 0, "semi implicit/water density", "must be > 0 kg/m^3");
    require(p.unit_weight_gravity > 0, "semi implicit/unit weight gravity", "must be > 0 m/s^2");
    require(p.free_surface_fraction > 0 && p.free_surface_fraction < 1, "semi implicit/free surface volume fraction",
            "must lie in (0, 1)");
    require(p.pressure_tolerance > 0, "semi implicit/pressure solver tolerance", "must be > 0");
    prm.leave_subsection();
    prm.enter_subsection("initial state");
    p.geostatic                   = prm.get_bool("geostatic");
    p.water_level                 = prm.get_double("water level");
    p.soil_surface                = prm.get_double("soil surface");
    p.K0                          = prm.get_double("K0");
    p.initialisation_time         = prm.get_double("initialisation time");
    p.initialisation_conductivity = prm.get_double("initialisation conductivity");
    require(std::isfinite(p.initialisation_time) && p.initialisation_time >= 0 && p.initialisation_time <= p.end_time,
            "initial state/initialisation time",
            "is " + number_text(p.initialisation_time) + "; allowed: 0 (none) up to the end time " +
              number_text(p.end_time) + " s");
    require(std::isfinite(p.initialisation_conductivity) && p.initialisation_conductivity > 0,
            "initial state/initialisation conductivity",
            "is " + number_text(p.initialisation_conductivity) + "; must be > 0 m/s");
    if (p.initialisation_time > 0)
      for (unsigned int m = 0; m < p.materials.size(); ++m)
        {
          const std::string model = p.materials[m]->model_name();
          require(model == "nor sand" || model == "linear elastic" || model == "neo hookean",
                  "material " + std::to_string(m) + "/model",
                  "is " + model +
                    ", which has no elastic-only mode for 'initial state/initialisation time'; "
                    "allowed with an initialisation: nor sand, linear elastic, neo hookean");
        }
    prm.leave_subsection();
    for (unsigned int k = 0; k < p.materials.size(); ++k)
      {
        const std::string where = "material " + std::to_string(k) + "/soil/";
        prm.enter_subsection("material " + std::to_string(k));
        prm.enter_subsection("soil");
        SoilData s;
        s.porosity     = prm.get_double("porosity");
        s.conductivity = prm.get_double("hydraulic conductivity");
        prm.leave_subsection();
        prm.leave_subsection();
        std::ostringstream n0, k0;
        n0 << s.porosity;
        k0 << s.conductivity;
        require(s.porosity > 0 && s.porosity < 1, where + "porosity", "is " + n0.str() + "; must lie in (0, 1)");
        require(s.conductivity > 0, where + "hydraulic conductivity", "is " + k0.str() + "; must be > 0 m/s");
        p.soil_of_material.push_back(s);
      }
    bool any_soil = false, any_water = false;
    for (unsigned int k = 0; k < p.bodies.size(); ++k)
      {
        prm.enter_subsection("body " + std::to_string(k));
        const std::string ph = prm.get("phase");
        prm.leave_subsection();
        p.phase_of_body.push_back(ph == "soil" ? Phase::soil : ph == "water" ? Phase::water : Phase::saturated);
        any_soil  = any_soil || p.phase_of_body.back() != Phase::water;
        any_water = any_water || p.phase_of_body.back() != Phase::soil;
        // the material ids of the body's points: its entry, or those of its rows
        // (checked: rows of its body id exist, their material ids too)
        if (p.bodies[k].shape == BodyDescription<dim>::Shape::file)
          p.materials_of_body.push_back(check_file_body(p, k).materials);
        else
          p.materials_of_body.push_back({p.bodies[k].material_id});
      }
    std::string phases; // e.g. "body 0/phase = water": the entries that left a phase out
    for (unsigned int k = 0; k < p.bodies.size(); ++k)
      phases += (k ? ", body " : "body ") + std::to_string(k) + "/phase = " +
                (p.phase_of_body[k] == Phase::soil    ? "soil"
                 : p.phase_of_body[k] == Phase::water ? "water"
                                                      : "saturated");
    if (p.single_point)
      for (unsigned int b = 0; b < p.bodies.size(); ++b)
        require(p.phase_of_body[b] != Phase::water, "semi implicit/point sets",
                "single needs every body to carry soil points (the water rides on them), but body " +
                  std::to_string(b) + " has phase = water; allowed: point sets = double, or phase = saturated");
    // a dry scene (soil points only) is a single-phase solid: allowed
    (void)any_water;
    require(any_soil, phases,
            "the scene has no soil points (free water needs a skeleton for the drag and the mixture): give a "
            "body phase = saturated or soil");
    if (p.stabilisation == VolumetricStabilisation::modified_f_bar)
      for (unsigned int b = 0; b < p.bodies.size(); ++b)
        if (p.phase_of_body[b] != Phase::water)
          for (const unsigned int mid : p.materials_of_body[b])
            {
              const auto &m = *p.materials[mid];
              require(
                keeps_elastic_b(m), "semi implicit/volumetric stabilisation",
                "modified f-bar needs a model that keeps the elastic left Cauchy-Green tensor b_e, but material " +
                  std::to_string(mid) + " (of body " + std::to_string(b) + ") is '" + m.model_name() +
                  "'; allowed: hencky mohr coulomb, nor sand, neo hookean (or volumetric stabilisation = none | "
                  "f-bar)");
            }
    require(p.grid_mesh == nullptr, "grid/source", "talus-semi-implicit needs a box grid (source = box)");
    parse_boundary_load_parameters(prm, p); // issue 37 hook: tractions, velocity and drainage conditions
    check_scene(p);
    return p;
  }

  template <int dim>
  double
  soil_critical_time_step(const Parameters<dim> &p, const double h_min)
  {
    double dt = std::numeric_limits<double>::max();
    for (unsigned int b = 0; b < p.bodies.size(); ++b)
      if (p.phase_of_body[b] != Phase::water)
        for (const unsigned int m : p.materials_of_body[b])
          {
            const double rho = (1 - p.soil_of_material[m].porosity) * p.materials[m]->density();
            dt               = std::min(dt, h_min / std::sqrt(p.materials[m]->constrained_modulus() / rho));
          }
    return dt;
  }

  // ================================================================ the formulation
  namespace
  {
    /// Property offsets of the extras of both sets.
    struct Fields
    {
      unsigned int porosity = 0, initial_porosity = 0, initial_volume = 0, conductivity = 0, pressure = 0;
      unsigned int pressure_gradient   = 0;
      unsigned int surface_offset      = 0; // dim values: from the point to its share of the loaded face
      unsigned int poisson_coefficient = 0, poisson_flux = 0;                 // poisson_flux: dim values, phi v*
      unsigned int smoothed_volume_increment = 0, patch_elastic_jacobian = 0; // F-bar: dJbar, Jebar
      unsigned int smoothed_jacobian = 0;                                     // Nor-Sand (96)-(97): Jbar^{t+1}
      unsigned int plate_flux = 0; // rigid plates with force control: dim values, phi v* of a unit plate velocity
    };

    /// The pressure-increment Poisson terms of one point: K += V c grad N grad N,
    /// f -= V (phi v*) . grad N (the weak form of div(phi v*), integrated by
    /// parts: it keeps the phi jump of a free-water / soil interface, which the
    /// point form phi div v* drops; docs/semi-implicit.md)
    struct PoissonWithFlux
    {
      unsigned int          coefficient = 0, flux = 0; ///< property offsets (flux: dim values)
      static constexpr bool matrix = true, vector = true;
      template <int dim, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc == 1, "PoissonWithFlux: a scalar space");
        const double V = P[PropertyLayout<dim>::volume];
        const double a = P[coefficient] * V;
        // symmetric: each product once, added at (i, j) and (j, i) (the same
        // value either way: bitwise the full loop)
        for (unsigned int i = 0; i < p.n; ++i)
          {
            double fg = 0;
            {
              double gg = 0;
              for (unsigned int d = 0; d < dim; ++d)
                gg += p.G[i][d] * p.G[i][d];
              ls.a(p.local[i], p.local[i]) += a * gg;
            }
            for (unsigned int j = i + 1; j < p.n; ++j)
              {
                double gg = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  gg += p.G[i][d] * p.G[j][d];
                const double v = a * gg;
                ls.a(p.local[i], p.local[j]) += v;
                ls.a(p.local[j], p.local[i]) += v;
              }
            for (unsigned int d = 0; d < dim; ++d)
              fg += P[flux + d] * p.G[i][d];
            ls.b[p.local[i]] -= V * fg;
          }
      }
    };

    /// The source part of PoissonWithFlux alone (f -= V flux . grad N): the
    /// right-hand side of a force-controlled rigid plate's unit velocity, on
    /// the matrix already assembled (rigid plates, docs/semi-implicit.md)
    struct PoissonFluxSource
    {
      unsigned int          flux   = 0;
      static constexpr bool matrix = false, vector = true;
      template <int dim, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        const double V = P[PropertyLayout<dim>::volume];
        for (unsigned int i = 0; i < p.n; ++i)
          {
            double fg = 0;
            for (unsigned int d = 0; d < dim; ++d)
              fg += P[flux + d] * p.G[i][d];
            ls.b[p.local[i]] -= V * fg;
          }
      }
    };

    /// Nodal masses below this fraction of the largest nodal mass count as
    /// empty (decision A3: no division by the tiny masses at a support's edge).
    constexpr double relative_mass_cutoff = 1e-10;
  } // namespace

  template <int dim>
  class Solver : public Formulation
  {
  public:
    using L = PropertyLayout<dim>;

    Solver(const Parameters<dim> &p, MPI_Comm comm)
        : prm(p)
        , comm(comm)
        , grid(comm, p.balance.enabled())
        , soil(grid, "soil")
        , water(grid, "water")
        , balance(grid, p.balance, {&soil, &water},
                  [this] {
                    grid_changed();
                    soil.collect_active_cells();
                    water.collect_active_cells();
                  })
        , bloads(p, grid, comm)
        , pspace(grid, 1)
        , active(pspace)
    {
    }

    void setup();
    std::string
    tool_name() const override
    {
      return "talus-semi-implicit";
    }
    void describe(std::ostream &out) const override;
    double
    begin_stage(const unsigned int, const bool, const bool) override
    {
      return prm.end_time;
    }
    StepOutcome
    advance_by(const double h) override
    {
      if (prm.bspline())
        step<shape::BSpline2Box<dim>>(h);
      else
        step<shape::Q1Box<dim>>(h);
      return StepOutcome::done;
    }
    void check_stability() const override;
    unsigned long long
    lost_points() const override
    {
      return soil.relocation_stats.lost + water.relocation_stats.lost;
    }
    std::vector<std::string> series_columns() const override;
    std::vector<double>      series_values(const bool after_step) override;
    void                     write_vtu(const unsigned int counter) override;
    void                     rewrite_records() override;
    std::string              write_checkpoint() override;
    void                     finish(const std::string &series_csv) override;
    void                     summary(const LoopTimings &timings) override;
    void
    after_step() override
    {
      balance.after_step(step_number, prm.progress);
    } ///< the load-balance check

  private:
    template <class K>
    void step(const double h);
    /// The newest valid checkpoint into the state (false: none). Collective.
    bool restore_checkpoint();
    /// The node-smoothed volume measures of the soil points, one map and
    /// remap: F-bar's increment dJbar (80) and, for the modified F-bar, the
    /// patch mean Jebar (83); Nor-Sand's total Jbar^{t+1} (97)
    template <class K>
    void volume_averages(const double h, const double ms_cut);
    /// whether the soil points need Jbar (a nor sand material, smoothing on)
    bool smooth_jacobian = false;
    void seed();
    void geostatic_state();
    /// compress(add) then update ghosts, for every vector given
    void exchange(std::initializer_list<Vector *> vs) const;
    /// local (owned + ghost) size of a grid vector
    unsigned int
    n_local() const
    {
      return grid.partitioner->locally_owned_size() + grid.partitioner->n_ghost_indices();
    }

    const Parameters<dim> &prm;
    MPI_Comm               comm;
    BackgroundGrid<dim>    grid;
    MaterialPointSet<dim>  soil, water;
    /// Load balancing by material points of both sets (formulations/common/
    /// load_balance.h); its repartitions call grid_changed().
    LoadBalance<dim> balance;
    /// issue 37: the shared tractions, prescribed velocities and drainage
    /// conditions (boundary_loads.h); its hooks are called from the step
    BoundaryLoads<dim> bloads;
    /// Everything of the grid's partition that lives across steps: the
    /// pressure space, the per-DoF node maps and wall/drained flags, the nodal
    /// vectors; the next step rebuilds the active set and the pressure matrix.
    void grid_changed();
    /// the next step rebuilds the pressure DoF set (after a repartition and
    /// after a checkpoint write)
    bool                                   partition_changed = true;
    Fields                                 fs, fw; ///< offsets in the soil and the water layout
    NodalSpace<dim>                        pspace; ///< the scalar pressure space
    ActiveSet<dim>                         active;
    dealii::TrilinosWrappers::SparseMatrix A;
    /// CG + ML AMG with the hierarchy kept between steps (solvers/linear_solver.h);
    /// invalidated when A is reinit and at every checkpoint write
    ReusedAMGSolver pressure_solver;
    /// steps of this run (not of a checkpoint's past: a restart rebuilds once
    /// more) that built a new pressure DoF set, sparsity and matrix
    unsigned long long n_pattern_changes = 0;
    /// of which: the cells were the same, but a point's stencil left the kept pattern
    unsigned long long n_pattern_window_changes = 0;
    Vector             rhs, dp_solution;

    // per grid local DoF: the node's component-0 DoF, component, prescribed zero
    std::vector<unsigned int>  node_of;
    std::vector<unsigned char> component, constrained;
    std::vector<unsigned char> water_constrained, drained; // per DoF; per node (component-0 DoF): on a drained face
    std::vector<dealii::Point<dim>> node_x;                // position of the node of a local DoF
    // nodal fields (grid vectors; scalars at the component-0 DoF)
    Vector Ms, Ps, Mn, Mk,
      Fs; // soil mass, momentum, sum m n, sum N n^2 rho_w g V / k (drag), force (internal + gravity)
    Vector Ww, Pw0, Ww0, Mwp, Mw; // sum N rho_w V, sum N rho_w V0 v, sum N rho_w V0, sum N m p, sum N m
    Vector Gpw, Gps; // sum V N grad p^t over the water / the soil points (times n_I, 1 - n_I: the pore pressure forces)
    Vector Mwg;      // sum N m grad p (linear pressure map)
    Vector n_node, Q_node, Mw_node; // nodal porosity n_I, drag Q_I, water mass M_wI
    Vector vs_t, vw_t, vs_star, vw_star, vs_new, vw_new;
    Vector p_node, dp_node, gs, gw, wet, dry, near_wet;
    std::vector<double> cell_water_volume;
    Vector              Mdj; // F-bar: sum N m dJ of the soil points
    Vector              Mjt; // Nor-Sand: sum N m J^{t+1} of the soil points
    // modified F-bar patches: a fixed square tiling from the grid's lower corner
    PatchTiling<dim>                            patches;
    std::vector<double>                         patch_mass, patch_mass_Je;
    std::vector<std::pair<double, std::string>> pvd_records[2]; // soil, water

    // rigid plates (issue 37; docs/semi-implicit.md 'Rigid plate'): per local
    // grid DoF the plate whose axis component it is (none: not a plate DoF or
    // held by a wall, which keeps it), and the plate of a rough plate's
    // tangential DoF (held at zero like a wall; its reaction is summed)
    static constexpr unsigned int no_plate = static_cast<unsigned int>(-1);
    std::vector<unsigned int>     plate_of, plate_tangential_of;
    /// per node (component-0 DoF): a node of an impermeable plate, which covers
    /// the surface there: no free-surface p = 0 at it (the pressure is solved)
    std::vector<unsigned char> plate_sealed;
    /// per node (component-0 DoF): the plate that holds it, or no_plate
    std::vector<unsigned int> plate_node_of;
    /// per plate: the state between steps (checkpointed) and the last step's answer
    struct PlateState
    {
      double displacement = 0; ///< along the axis [m] (the unknown of force control)
      double velocity     = 0; ///< of the last step [m/s]
      double force        = 0; ///< the force the plate exerted on the material along its axis [N]
      double tangential   = 0; ///< |tangential reaction| of a rough plate [N]
      /// sum over the steps of h x (the largest difference between the velocity
      /// a plate node moves the soil with and the plate's: the axis component,
      /// and a rough plate's tangential ones against 0), in v^{t+1} and in the
      /// remapped velocity: a bound on how far the plate's nodes moved apart [m]
      double node_spread = 0;
      /// sum over the steps of h x the largest tangential velocity of a plate
      /// node in v^{t+1} (components no wall holds): 0 for a rough plate [m]
      double node_slip = 0;
    };
    std::vector<PlateState>   plate_state;
    std::vector<unsigned int> force_plates; ///< indices of the force-controlled plates
    /// per plate: grid nodes (global count) and axis DoFs it moves (not held by a wall)
    std::vector<unsigned long long> plate_nodes, plate_axis_dofs;
    /// per force plate k: the step's response to a unit plate velocity (its
    /// predictor velocities of soil and water, nodal pressure increment, the
    /// weak gradients of that increment, corrected velocities)
    struct PlateResponse
    {
      Vector es, ew, dp, gs, gw, vs, vw;
    };
    std::vector<PlateResponse> plate_response;
    /// Check the plates against the grid (collective; InputError naming the plate).
    void check_plates();
    // App. B.4 initialisation: the models of the elastic stage (nor sand
    // without plasticity, the others as they are), per material
    std::vector<std::shared_ptr<const materials::Material>> initialisation_models;
    bool
    initialising(const double t) const
    {
      return t < prm.initialisation_time - 1e-9 * dt;
    } // as the loop's end test
    /// End of the App. B.4 stage: every nor sand point's references from its
    /// current state (Eqs. 111-114). Logs one line.
    void end_initialisation();

    // diagnostics
    LinearSolveInfo    last_solve;
    unsigned long long solver_iterations = 0, n_solves = 0;
    double             seconds_solve    = 0; ///< CG + AMG set-ups
    double             dt_soil_critical = 0;
    // wall-clock phases of the step (a few clock reads per step; the solve is
    // seconds_solve): P2N, nodal updates, Poisson set-up and assembly, N2P
    // (FLIP + MUSL remap), soil update and stress (with F-bar), water move
    // and the relocation of both sets
    struct PhaseTimes
    {
      double p2n = 0, grid = 0, poisson = 0, n2p = 0, stress = 0, relocation = 0;
    } phase;
    template <class K>
    double shape_walk_seconds(); // one stencil walk over both sets (summary)
    /// Each set's point stencils, kept between the walks of a step (the
    /// positions change only at the move): transfer::StencilCache checks every
    /// entry against its point at each use; cleared when the grid changes.
    struct StencilCaches
    {
      transfer::StencilCache<dim, shape::BSpline2Box<dim>> bspline;
      transfer::StencilCache<dim, shape::Q1Box<dim>>       linear;
      void
      clear()
      {
        bspline.clear();
        linear.clear();
      }
    } soil_stencils, water_stencils;
    template <class K>
    transfer::StencilCache<dim, K> &
    stencils(const MaterialPointSet<dim> &set)
    {
      StencilCaches &c = &set == &soil ? soil_stencils : water_stencils;
      if constexpr (std::is_same_v<K, shape::BSpline2Box<dim>>)
        return c.bspline;
      else
        return c.linear;
    }
  };

  template <int dim>
  void
  Solver<dim>::exchange(std::initializer_list<Vector *> vs) const
  {
    for (auto *v : vs)
      v->compress(dealii::VectorOperation::add);
    for (auto *v : vs)
      v->update_ghost_values();
  }

  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    pspace.setup();
    soil_stencils.clear(); // their DoF indices are of the old partition
    water_stencils.clear();
    constrained = loads::wall_dof_flags(grid, prm.boundary_conditions);

    // node and component of every local grid DoF (from the cells' vertex DoFs)
    const unsigned int nl = n_local();
    node_of.assign(nl, 0);
    component.assign(nl, 0);
    node_x.assign(nl, dealii::Point<dim>());
    for (unsigned int c = 0; c < grid.cells.size(); ++c)
      if (grid.cell_iterators[c] != grid.tria.end()) // artificial cells carry no DoFs (their cache is zero)
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          for (unsigned int d = 0; d < dim; ++d)
            {
              const auto        &cc = grid.cells[c];
              const unsigned int i  = cc.dofs[v * dim + d];
              if (i < nl)
                {
                  node_of[i]   = cc.dofs[v * dim];
                  component[i] = d;
                  for (unsigned int e = 0; e < dim; ++e) // vertex v: bit e set = upper side in direction e
                    node_x[i][e] = cc.lower[e] + ((v >> e) & 1u) * cc.h[e];
                }
            }
    // rigid plates: the axis DoFs they move (a wall keeps what it holds), the
    // tangential DoFs of a rough plate held at zero for both phases (as a
    // wall), p = 0 at a permeable plate's nodes (with the drained faces below)
    plate_of.assign(nl, no_plate);
    plate_tangential_of.assign(nl, no_plate);
    std::vector<unsigned char> plate_drained(nl, 0);
    plate_sealed.assign(nl, 0);
    plate_node_of.assign(nl, no_plate);
    for (const auto &e : loads::rigid_plate_node_dofs(grid, prm.rigid_plates, false))
      {
        const auto &pl        = prm.rigid_plates[e.condition];
        plate_node_of[e.node] = e.condition;
        if (pl.permeable)
          plate_drained[e.node] = 1;
        else
          plate_sealed[e.node] = 1;
        if (constrained[e.dof] && plate_tangential_of[e.dof] == no_plate)
          continue; // a fixed/roller wall holds this component: it keeps it
        if (e.component == pl.axis)
          {
            if (plate_of[e.dof] == no_plate) // a DoF of two plates: refused by check_plates
              plate_of[e.dof] = e.condition;
          }
        else
          {
            plate_tangential_of[e.dof] = e.condition;
            constrained[e.dof]         = 1;
          }
      }
    // drained faces (issue 37 hook): the drainage conditions' node flags and
    // the water's wall hold freed at a draining boundary (boundary_loads.cc);
    // drained[]: the permeable plates' nodes (p = 0)
    water_constrained = constrained;
    drained.assign(nl, 0);
    for (unsigned int i = 0; i < nl; ++i)
      if (plate_drained[i])
        drained[i] = 1;
    bloads.grid_changed(node_of, component, node_x, water_constrained);
    patches.reinit(prm.grid_lower, prm.grid_upper, prm.grid_cells, prm.patch_size);
    for (Vector *v :
         {&Mdj,    &Mjt,    &Ms,     &Ps,      &Mn,     &Mk,     &Fs,      &Ww,   &Pw0,     &Ww0,     &Mwp,
          &Mw,     &Gpw,    &Gps,    &Mwg,     &n_node, &Q_node, &Mw_node, &vs_t, &vw_t,    &vs_star, &vw_star,
          &vs_new, &vw_new, &p_node, &dp_node, &gs,     &gw,     &wet,     &dry,  &near_wet})
      grid.reinit_vector(*v);
    plate_response.resize(force_plates.size());
    for (auto &r : plate_response)
      for (Vector *v : {&r.es, &r.ew, &r.dp, &r.gs, &r.gw, &r.vs, &r.vw})
        grid.reinit_vector(*v);
    partition_changed = true; // the next step rebuilds the active set and the matrix
  }

  template <int dim>
  void
  Solver<dim>::setup()
  {
    grid.make_box(prm.grid_lower, prm.grid_upper, prm.grid_cells);
    grid.setup();
    if (prm.bspline())
      grid.setup_bspline_patches();
    plate_state.assign(prm.rigid_plates.size(), PlateState());
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      if (prm.rigid_plates[k].control == loads::RigidPlate<dim>::Control::force)
        force_plates.push_back(k);
    grid_changed();
    check_plates();

    // layouts: soil points carry the solid model's history; both carry porosity
    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    soil.layout.n_history = n_history;
    fs.porosity           = soil.layout.add_extra("porosity", 1);
    fs.initial_porosity   = soil.layout.add_extra("initial_porosity", 1);
    fs.initial_volume     = soil.layout.add_extra("initial_volume", 1);
    fs.conductivity       = soil.layout.add_extra("conductivity", 1);
    fs.surface_offset     = soil.layout.add_extra("surface_offset", dim, true);
    bloads.extend_layout(soil.layout, fs.surface_offset); // issue 37 hook: the point tractions' slots
    fs.poisson_coefficient = soil.layout.add_extra("poisson_coefficient", 1);
    fs.poisson_flux        = soil.layout.add_extra("poisson_flux", dim, true);
    if (prm.stabilisation != VolumetricStabilisation::none)
      fs.smoothed_volume_increment = soil.layout.add_extra("smoothed_volume_increment", 1);
    if (prm.stabilisation == VolumetricStabilisation::modified_f_bar)
      fs.patch_elastic_jacobian = soil.layout.add_extra("patch_elastic_jacobian", 1);
    for (const auto &m : prm.materials)
      smooth_jacobian = smooth_jacobian || (prm.smoothed_specific_volume && m->model_name() == "nor sand");
    if (smooth_jacobian)
      fs.smoothed_jacobian = soil.layout.add_extra("smoothed_jacobian", 1);
    if (!force_plates.empty())
      {
        fs.plate_flux = soil.layout.add_extra("plate_flux", dim, true);
        fw.plate_flux = water.layout.add_extra("plate_flux", dim, true);
      }
    fw.pressure            = water.layout.add_extra("pore_pressure", 1);
    fw.pressure_gradient   = water.layout.add_extra("pore_pressure_gradient", dim, true);
    fw.porosity            = water.layout.add_extra("porosity", 1);
    fw.initial_porosity    = water.layout.add_extra("initial_porosity", 1);
    fw.initial_volume      = water.layout.add_extra("initial_volume", 1);
    fw.poisson_coefficient = water.layout.add_extra("poisson_coefficient", 1);
    fw.poisson_flux        = water.layout.add_extra("poisson_flux", dim, true);
    soil.initialize();
    water.initialize();
    initialisation_models = prm.materials;
    for (auto &m : initialisation_models)
      if (const auto *ns = dynamic_cast<const materials::NorSand *>(m.get()))
        {
          auto elastic = std::make_shared<materials::NorSand>(ns->parameters());
          elastic->set_plasticity(false);
          m = elastic;
        }
    dt_soil_critical = soil_critical_time_step(prm, grid.min_cell_size());
    if (restore_if_asked(prm, [this] { return restore_checkpoint(); }))
      {
        balance.initial(); // on another number of ranks: partition by points
        return;            // the points, the step and the loop's state as saved
      }
    seed();
    bloads.assign(soil, prm.bodies); // issue 37 hook: the loaded points' forces and face offsets
    if (prm.geostatic)
      geostatic_state();
    initialize_point_histories(prm.materials, soil, soil.layout.history);
    dt = prm.time_step > 0 ? prm.time_step : prm.courant * dt_soil_critical;
    // load balancing: partition by the points of both sets from the start
    balance.initial();
  }

  template <int dim>
  void
  Solver<dim>::check_plates()
  {
    const unsigned int n = prm.rigid_plates.size();
    plate_nodes.assign(n, 0);
    plate_axis_dofs.assign(n, 0);
    if (n == 0)
      return;
    // the shared node checks (exit 2 naming the plate) with the scene's walls
    const auto counts = loads::check_rigid_plate_nodes(grid, prm.rigid_plates, {prm.boundary_conditions}, {""}, comm);
    for (unsigned int k = 0; k < n; ++k)
      plate_nodes[k] = counts[k].nodes;
    const unsigned int owned = grid.partitioner->locally_owned_size();
    for (unsigned int i = 0; i < owned; ++i)
      if (plate_of[i] != no_plate)
        ++plate_axis_dofs[plate_of[i]];
    MPI_Allreduce(MPI_IN_PLACE, plate_axis_dofs.data(), n, MPI_UNSIGNED_LONG_LONG, MPI_SUM, comm);
    // the wall check above counts a node held if a wall holds its axis
    // component; plate_of[] leaves out the same DoFs, so no plate is left
    // without an axis DoF here
    for (unsigned int k = 0; k < n; ++k)
      AssertThrow(plate_axis_dofs[k] > 0, dealii::ExcInternalError());
  }

  // ---------------------------------------------------------------- checkpoints
  // The state between two steps is the two point sets with everything they
  // carry (soil: velocity, stress, the model's history with b_e, volume,
  // porosity, conductivity, its share of the surface load; water: velocity,
  // pore pressure and its gradient, porosity, volume) and the loop's state:
  // every nodal field of a step (masses, p^t, n_I, the drag, the F-bar dJ and
  // patch means, the free-surface flags, the pressure system) is rebuilt from
  // the points at its start, and the patch tiling is fixed by the .prm. Same
  // rank count: bitwise continuation (docs/semi-implicit.md).
  namespace
  {
    const char *const checkpoint_format  = "talus-semi-implicit-checkpoint";
    const int         checkpoint_version = 1;
  } // namespace

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    // the run restarted from this checkpoint builds a new hierarchy at its first
    // solve: so does this one, so that both go on bitwise alike. The same for
    // the pressure DoF set: a kept one remembers the couplings of its build
    // step, which decide later rebuilds (ActiveSet::couplings_covered)
    pressure_solver.invalidate();
    partition_changed = true;
    return write_checkpoint_file(prm, *this, checkpoint_format, checkpoint_version,
                                 scene_signature(prm, soil.layout.n_properties()), comm, [&](io::H5File &f) {
                                   f.set_attribute("pressure solves", std::int64_t(n_solves));
                                   f.set_attribute("pressure cg iterations", std::int64_t(solver_iterations));
                                   f.set_attribute("pressure amg setups", std::int64_t(pressure_solver.n_setups()));
                                   for (unsigned int k = 0; k < plate_state.size(); ++k) // the plates' state
                                     {
                                       const std::string a = "rigid plate " + std::to_string(k) + " ";
                                       f.set_attribute(a + "displacement", plate_state[k].displacement);
                                       f.set_attribute(a + "velocity", plate_state[k].velocity);
                                       f.set_attribute(a + "force", plate_state[k].force);
                                       f.set_attribute(a + "tangential force", plate_state[k].tangential);
                                       f.set_attribute(a + "node spread", plate_state[k].node_spread);
                                       f.set_attribute(a + "node slip", plate_state[k].node_slip);
                                     }
                                   write_points(f, soil, "soil");
                                   write_points(f, water, "water");
                                   write_pvd_times(f, "output/soil_pvd", pvd_records[0]);
                                   write_pvd_times(f, "output/water_pvd", pvd_records[1]);
                                   balance.write(f); // the partition of the last rebalance
                                 });
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto fp = open_checkpoint_to_restore(prm, *this, checkpoint_format, checkpoint_version,
                                               scene_signature(prm, soil.layout.n_properties()), comm);
    if (!fp)
      return false;
    n_solves          = fp->get_int("pressure solves");
    solver_iterations = fp->get_int("pressure cg iterations");
    // (absent in checkpoints written before the AMG reuse)
    if (fp->has_attribute("pressure amg setups"))
      pressure_solver.set_n_setups(fp->get_int("pressure amg setups"));
    const std::string where = "checkpoint " + fp->path();
    for (unsigned int k = 0; k < plate_state.size(); ++k)
      {
        const std::string a = "rigid plate " + std::to_string(k) + " ";
        require(fp->has_attribute(a + "displacement"), where,
                "has no state of 'boundary conditions/rigid plate " + std::to_string(k) +
                  "' (written by a run without it); allowed: a checkpoint of the same scene");
        plate_state[k].displacement = fp->get_double(a + "displacement");
        plate_state[k].velocity     = fp->get_double(a + "velocity");
        plate_state[k].force        = fp->get_double(a + "force");
        plate_state[k].tangential   = fp->get_double(a + "tangential force");
        plate_state[k].node_spread  = fp->get_double(a + "node spread");
        plate_state[k].node_slip    = fp->get_double(a + "node slip");
      }
    balance.restore(*fp); // same ranks: the saved partition, before the points go in
    read_points(*fp, soil, grid, where, "soil");
    read_points(*fp, water, grid, where, "water");
    pvd_records[0] = read_pvd_records(*fp, "output/soil_pvd", soil.name());
    pvd_records[1] = read_pvd_records(*fp, "output/water_pvd", water.name());
    return true;
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      for (const bool is_soil : {true, false})
        io::write_pvd(prm.output_directory + "/" + (is_soil ? soil : water).name() + ".pvd",
                      pvd_records[is_soil ? 0 : 1]);
  }

  template <int dim>
  void
  Solver<dim>::seed()
  {
    // each set is seeded from the bodies of its phase; the body property keeps
    // the index of the .prm body
    for (const bool is_soil : {true, false})
      {
        MaterialPointSet<dim>            &set = is_soil ? soil : water;
        std::vector<BodyDescription<dim>> bodies;
        std::vector<unsigned int>         body_index;
        for (unsigned int b = 0; b < prm.bodies.size(); ++b)
          if (prm.phase_of_body[b] == Phase::saturated || (prm.phase_of_body[b] == Phase::soil) == is_soil)
            {
              bodies.push_back(prm.bodies[b]);
              body_index.push_back(b);
            }
        std::vector<double> unit_density(prm.materials.size(), 1.0); // masses set below
        // file bodies: the rows of their particle files, the same rows for both
        // sets of a saturated body (the single-point variant relies on it)
        seed_scene_bodies(grid, bodies, unit_density, set, is_soil ? "soil point" : "water point",
                          is_soil ? &prm : nullptr, body_index);
        const Fields &f = is_soil ? fs : fw;
        for (auto &pt : set.handler)
          {
            auto               P = pt.get_properties();
            const unsigned int b = body_index[static_cast<unsigned int>(P[L::body])];
            P[L::body]           = b;
            const unsigned int m = static_cast<unsigned int>(P[L::material]); // a file body's: its row's
            // a water body's points take the porosity 1 (free water)
            const double n0       = prm.phase_of_body[b] == Phase::water ? 1.0 : prm.soil_of_material[m].porosity;
            const double V0       = P[L::volume];
            P[f.porosity]         = n0;
            P[f.initial_porosity] = n0;
            P[f.initial_volume]   = V0;
            if (is_soil)
              {
                P[L::mass]        = (1 - n0) * prm.materials[m]->density() * V0; // Eq. 35
                P[f.conductivity] = prm.soil_of_material[m].conductivity;
                for (unsigned int d = 0; d < dim; ++d) // its share of a loaded face: BoundaryLoads::assign
                  P[f.surface_offset + d] = 0;
              }
            else
              {
                P[L::mass] = n0 * prm.water_density * V0;     // Eq. 37
                L::set_stress(materials::Stress(), P.data()); // a particle file's stress is the soil's
                P[f.pressure] = 0;
                for (unsigned int d = 0; d < dim; ++d)
                  P[f.pressure_gradient + d] = 0;
              }
          }
        set.collect_active_cells();
      }
  }

  template <int dim>
  void
  Solver<dim>::geostatic_state()
  {
    const double g = prm.gravity.norm();
    for (auto &pt : water.handler)
      {
        auto         P                    = pt.get_properties();
        const double y                    = pt.get_location()[dim - 1];
        P[fw.pressure]                    = -prm.water_density * g * std::max(0.0, prm.water_level - y);
        P[fw.pressure_gradient + dim - 1] = y < prm.water_level ? prm.water_density * g : 0.0;
      }
    for (auto &pt : soil.handler)
      {
        auto               P  = pt.get_properties();
        const double       y  = pt.get_location()[dim - 1];
        const unsigned int m  = static_cast<unsigned int>(P[L::material]);
        const double       n  = P[fs.porosity];
        const double       rs = prm.materials[m]->density();
        // dry unit weight above the water level, buoyant below
        const double                  above = std::max(0.0, prm.soil_surface - std::max(y, prm.water_level));
        const double                  below = std::max(0.0, std::min(prm.soil_surface, prm.water_level) - y);
        const double                  sv    = -(1 - n) * g * (rs * above + (rs - prm.water_density) * below);
        dealii::SymmetricTensor<2, 3> s;
        for (unsigned int d = 0; d < 3; ++d)
          s[d][d] = prm.K0 * sv;
        s[dim - 1][dim - 1] = sv;
        L::set_stress(s, P.data());
      }
  }

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    const auto ns = soil.handler.n_global_particles(), nw = water.handler.n_global_particles();
    out << "talus-semi-implicit: " << dim << "D, grid " << grid.tria.n_global_active_cells() << " cells (h_min "
        << grid.min_cell_size() << " m), " << (prm.bspline() ? "quadratic B-splines" : "linear shape functions") << ", "
        << ns << " soil + " << nw << " water points\n"
        << "  time step " << dt << " s (soil skeleton critical step " << dt_soil_critical << " s"
        << (prm.time_step > 0 ? ", fixed" : ", courant " + std::to_string(prm.courant))
        << "), pressure: CG + ML AMG to " << prm.pressure_tolerance << " relative residual, AMG rebuilt every "
        << prm.pressure_rebuild_interval << " steps" << std::endl;
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &pl = prm.rigid_plates[k];
        out << "  " << pl.where << ": "
            << (pl.target == loads::RigidPlate<dim>::Target::boundary ? "boundary id " + std::to_string(pl.boundary)
                                                                      : std::string("region"))
            << ", " << plate_nodes[k] << " nodes"
            << (plate_axis_dofs[k] < plate_nodes[k]
                  ? " (" + std::to_string(plate_axis_dofs[k]) + " move along " + "xyz"[pl.axis] + ", the others' " +
                      "xyz"[pl.axis] + " is held by a wall)"
                  : std::string(" moving along ") + "xyz"[pl.axis])
            << ", " << (pl.rough ? "rough" : "frictionless") << ", " << (pl.permeable ? "permeable" : "impermeable")
            << ", "
            << (pl.control == loads::RigidPlate<dim>::Control::force
                  ? "force control: " + number_text(pl.force) + " N x f(t), displacement unknown"
                  : "displacement control: " + number_text(pl.displacement) + " m x f(t), reaction reported")
            << std::endl;
      }
    bloads.describe(out); // issue 37 hook
  }

  // ---------------------------------------------------------------- the step
  template <int dim>
  template <class K>
  void
  Solver<dim>::step(const double h)
  {
    using Stencil = transfer::PointStencil<dim, K>;
    using It      = transfer::PointIterator<dim>;
    // App. B.4 stage: gravity ramped over it (the factor at mid-step), elastic
    // models, the water on the soil, the initialisation conductivity
    const bool   initial_stage = initialising(time);
    const auto   g  = (initial_stage ? std::min(1.0, (time + 0.5 * h) / prm.initialisation_time) : 1.0) * prm.gravity;
    const double rw = prm.water_density;
    const unsigned int nl      = n_local();
    auto               lap     = Clock::now(); // phase timers: add_lap(x) adds the time since the last lap to x
    auto               add_lap = [&lap](double &x) {
      const auto now = Clock::now();
      x += std::chrono::duration<double>(now - lap).count();
      lap = now;
    };

    for (Vector *v :
         {&Ms, &Ps, &Mn, &Mk, &Fs, &Ww, &Pw0, &Ww0, &Mwp, &Mw, &Gpw, &Gps, &Mwg, &gs, &gw, &wet, &dry, &near_wet})
      *v = 0;
    bloads.begin_step(time, h);                    // issue 37 hook: the loads' time factors over [t, t + h]
    auto at = [](Vector &v) { return v.begin(); }; // local (owned, then ghost) values

    // (1)-(2) P2N of the soil: mass (44), momentum (45), porosity (46), the
    // drag coefficient integrated over the soil points (in place of (47) and
    // (58), see below); effective-stress internal force and soil gravity (54)-(55)
    {
      double *ms = at(Ms), *ps = at(Ps), *mn = at(Mn), *mk = at(Mk), *fsv = at(Fs);
      Stencil surface; // a loaded point's stencil at its share of the face
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int c, It &it, const Stencil &s) {
          const double *P = it->get_properties().data();
          const double  m = P[L::mass];
          s.scatter(ms, m);
          s.scatter_vector(ps, m, P + L::velocity);
          s.scatter(mn, m * P[fs.porosity]);
          const double k = initial_stage ? prm.initialisation_conductivity : P[fs.conductivity];
          s.scatter(mk, P[fs.porosity] * P[fs.porosity] * rw * prm.unit_weight_gravity * P[L::volume] / k);
          double gm[dim];
          for (unsigned int d = 0; d < dim; ++d)
            gm[d] = g[d];
          s.scatter_vector(fsv, m, gm);
          double t[dim][dim];
          minus_V_sigma<dim>(P, P[L::volume], t);
          s.scatter_divergence(fsv, t);
          // issue 37 hook: a loaded point's traction force (at the body surface)
          bloads.template scatter_point_traction<K>(c, it->get_location(), P, s, surface, fsv);
        });
    }
    exchange({&Ms, &Ps, &Mn, &Mk, &Fs});
    double ms_max = 0;
    for (unsigned int i = 0; i < nl; ++i)
      ms_max = std::max(ms_max, Ms.local_element(i));
    const double ms_cut = relative_mass_cutoff * dealii::Utilities::MPI::max(ms_max, comm);
    bloads.add_boundary_tractions(Fs, Ms, ms_cut); // issue 37 hook: tractions on grid boundary ids
    // nodal porosity; nodes without soil: n = 1, no drag (A1)
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        {
          const double m          = Ms.local_element(i);
          n_node.local_element(i) = m > ms_cut ? Mn.local_element(i) / m : 1.0;
        }
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double m        = Ms.local_element(node_of[i]);
        vs_t.local_element(i) = m > ms_cut ? Ps.local_element(i) / m : 0.0;
      }

    // (2)(e)-(f) P2N of the water: porosity at the water points from the nodes
    // (48, Alg. 8(h)) and their volume (36); water mass with the nodal porosity
    // (50), velocity with the weights rho_w V0 (51); the mass-weighted nodal
    // pore pressure (77 / A5); the water volume of each cell (free surface)
    cell_water_volume.assign(grid.cells.size(), 0.0);
    {
      const double *nn = at(n_node);
      double       *ww = at(Ww), *pw0 = at(Pw0), *ww0 = at(Ww0), *mwp = at(Mwp), *mw = at(Mw), *mwg = at(Mwg);
      const bool    linear = prm.linear_smoothing;
      transfer::for_each_point_stencil<dim, K>(
        grid, water, stencils<K>(water), [&](unsigned int c, It &it, const Stencil &s) {
          double      *P  = it->get_properties().data();
          const double n  = std::clamp(s.value(nn), 1e-6, 1.0);
          const double V0 = P[fw.initial_volume];
          P[fw.porosity]  = n;
          P[L::volume]    = P[fw.initial_porosity] / n * V0; // Eq. 36
          s.scatter(ww, rw * P[L::volume]);
          s.scatter_vector(pw0, rw * V0, P + L::velocity);
          s.scatter(ww0, rw * V0);
          if (linear) // sum N m (p - grad p . x_p); the node adds (sum N m grad p) . x_I
            {
              const auto x  = it->get_location();
              double     px = P[fw.pressure];
              for (unsigned int d = 0; d < dim; ++d)
                px -= P[fw.pressure_gradient + d] * x[d];
              s.scatter(mwp, P[L::mass] * px);
              s.scatter_vector(mwg, P[L::mass], P + fw.pressure_gradient);
            }
          else
            s.scatter(mwp, P[L::mass] * P[fw.pressure]);
          s.scatter(mw, P[L::mass]);
          cell_water_volume[c] += P[L::volume];
        });
    }
    exchange({&Ww, &Pw0, &Ww0, &Mwp, &Mw, &Mwg});
    if (prm.linear_smoothing) // the node's share (sum N m grad p) . x_I, component by component
      for (unsigned int i = 0; i < nl; ++i)
        Mwp.local_element(node_of[i]) += Mwg.local_element(i) * node_x[i][component[i]];
    double mw_max = 0;
    for (unsigned int i = 0; i < nl; ++i)
      mw_max = std::max(mw_max, Mw.local_element(i));
    const double mw_cut = relative_mass_cutoff * dealii::Utilities::MPI::max(mw_max, comm);
    for (unsigned int i = 0; i < nl; ++i)
      if (component[i] == 0)
        {
          const bool has_water     = Mw.local_element(i) > mw_cut;
          p_node.local_element(i)  = has_water ? Mwp.local_element(i) / Mw.local_element(i) : 0.0;
          Mw_node.local_element(i) = has_water ? n_node.local_element(i) * Ww.local_element(i) : 0.0; // Eq. 50
          // the drag Q_I = sum_s N n^2 rho_w g V / k over the soil points: Eq. 58
          // (g n_I M_wI / k_I) integrates the drag over the node's whole water
          // volume, which at a free-water interface includes the free water
          // (docs/semi-implicit.md: 2.7 % less Darcy flux through a 1 m column)
          Q_node.local_element(i) = has_water && Ms.local_element(i) > ms_cut ? Mk.local_element(i) : 0.0;
        }
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double w        = Ww0.local_element(node_of[i]);
        vw_t.local_element(i) = Mw.local_element(node_of[i]) > mw_cut && w > 0 ? Pw0.local_element(i) / w : 0.0;
      }

    // (3a)/(4a) smoothed pore pressure at the water points (77); the pore
    // pressure force in the form of the correction (66)-(67): the water's
    // n_I sum_w V N grad p^t, the soil's (1 - n_I) sum_s V N grad p^t, from the
    // nodal p^t (decision 'pressure force form' in docs/semi-implicit.md: the
    // printed mixture form -sum_w V p grad N split by n_I gives the soil of a
    // node at a free-water interface the buoyancy of the whole support)
    {
      const double *pn  = at(p_node);
      double       *gpw = at(Gpw), *gps = at(Gps);
      transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), pn, L::volume, gpw,
                                              [&](It &it, const Stencil &s) {
                                                if (prm.pressure_smoothing)
                                                  it->get_properties()[fw.pressure] = s.value(pn);
                                              });
      transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), pn, L::volume, gps);
    }
    exchange({&Gpw, &Gps});
    add_lap(phase.p2n);

    // (3) water predictor (53, 59) and (4) mixture predictor (52), the drag
    // implicit in both velocities: the 2 x 2 system per node and component
    //   (M_s + Q h) v_s* - Q h v_w*         = M_s v_s^t + h (F_s + (1 - n) G_s p)
    //   -Q h v_s*         + (M_w + Q h) v_w* = M_w v_w^t + h (M_w b + n G_w p)
    // whose sum is the mixture equation (52); the printed sequence takes v_s^t
    // in the drag of (53), which amplifies v_s - v_w by about M_w / M_s per step
    // where M_w > M_s (the nodes at a free-water interface; docs/semi-implicit.md)
    // Rigid plates (docs/semi-implicit.md 'Rigid plate'): at a plate's axis
    // DoFs the soil moves with the plate, v_s* = V; the water too when the
    // plate is impermeable (v_w* = V), else its own row with v_s = V. V is the
    // history's for displacement control; for force control the step is
    // solved for V = 0 and, per force plate, for a unit V (es, ew here, the
    // pressure increment and correction below); V follows from the plate's
    // momentum balance at the end of the step.
    const unsigned int  n_plates = prm.rigid_plates.size();
    std::vector<double> plate_v(n_plates, 0.0);
    for (unsigned int k = 0; k < n_plates; ++k)
      if (prm.rigid_plates[k].control == loads::RigidPlate<dim>::Control::displacement)
        plate_v[k] = (prm.rigid_plates[k].displacement_at(time + h) - plate_state[k].displacement) / h;
    for (auto &r : plate_response)
      for (Vector *v : {&r.es, &r.ew, &r.dp, &r.gs, &r.gw})
        *v = 0;
    for (unsigned int i = 0; i < nl; ++i)
      {
        const unsigned int j   = node_of[i];
        const double       Mwi = Mw_node.local_element(j), Msi = Ms.local_element(j);
        const double       Q = Q_node.local_element(j), n = n_node.local_element(j);
        const double       b = g[component[i]];
        const double rs      = Msi * vs_t.local_element(i) + h * (Fs.local_element(i) + (1 - n) * Gps.local_element(i));
        const double rwv     = Mwi * vw_t.local_element(i) + h * (Mwi * b + n * Gpw.local_element(i));
        double       vw = 0, vs = 0;
        const bool   has_soil = Msi > ms_cut, has_water = Mwi > 0;
        if (prm.rigid_skeleton) // v_s = 0: the water alone, its drag implicit
          vw = has_water ? rwv / (Mwi + h * Q) : 0.0;
        else if (has_soil && has_water)
          {
            const double a = Msi + h * Q, c = Mwi + h * Q, o = h * Q, det = a * c - o * o;
            vs = (c * rs + o * rwv) / det;
            vw = (o * rs + a * rwv) / det;
          }
        else if (has_soil)
          vs = rs / Msi;
        else if (has_water)
          vw = rwv / Mwi;
        if (constrained[i]) // same conditions on both phases (A10), except the water at a drained face
          vs = 0;
        if (water_constrained[i])
          vw = 0;
        bloads.predictor(i, has_soil, has_water, Mwi, Q, h, rwv, vs, vw); // issue 37 hook: prescribed velocities
        if (const unsigned int k = plate_of[i]; k != no_plate)
          {
            const bool permeable = prm.rigid_plates[k].permeable;
            // the water's factor of V: 1 (impermeable), its row's drag share
            // (permeable, with soil at the node), 0 (no coupling)
            const double ew =
              !permeable ? (has_water ? 1.0 : 0.0) : (has_soil && has_water ? h * Q / (Mwi + h * Q) : 0.0);
            vs = plate_v[k];
            if (!permeable)
              vw = ew * plate_v[k];
            else if (has_soil && has_water)
              vw = (rwv + h * Q * plate_v[k]) / (Mwi + h * Q);
            for (unsigned int r = 0; r < force_plates.size(); ++r)
              if (force_plates[r] == k)
                {
                  plate_response[r].es.local_element(i) = 1.0;
                  plate_response[r].ew.local_element(i) = ew;
                }
          }
        vw_star.local_element(i) = vw;
        vs_star.local_element(i) = vs;
      }
    add_lap(phase.grid);

    // (5) pressure-increment Poisson equation (60)-(63): per point the
    // coefficient dt phi / rho and the source phi div v* (phi = 1 - n for the
    // soil, n for the water; point porosity, see docs/semi-implicit.md)
    {
      const double *vss = at(vs_star), *vws = at(vw_star);
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          double      *P            = it->get_properties().data();
          const double phi          = 1 - P[fs.porosity];
          const double rs           = prm.materials[static_cast<unsigned int>(P[L::material])]->density();
          P[fs.poisson_coefficient] = prm.rigid_skeleton ? 0.0 : h * phi / rs;
          double v[dim];
          s.vector_value(vss, v);
          for (unsigned int d = 0; d < dim; ++d)
            P[fs.poisson_flux + d] = prm.rigid_skeleton ? 0.0 : phi * v[d];
        });
      transfer::for_each_point_stencil<dim, K>(grid, water, stencils<K>(water),
                                               [&](unsigned int, It &it, const Stencil &s) {
                                                 double      *P            = it->get_properties().data();
                                                 const double phi          = P[fw.porosity];
                                                 P[fw.poisson_coefficient] = h * phi / rw;
                                                 double v[dim];
                                                 s.vector_value(vws, v);
                                                 for (unsigned int d = 0; d < dim; ++d)
                                                   P[fw.poisson_flux + d] = phi * v[d];
                                               });
    }
    add_lap(phase.poisson); // the points' Poisson coefficient and flux (also in a dry scene)
    // a dry scene (soil points only) is a single-phase solid: no pressure
    if (water.handler.n_global_particles() == 0)
      dp_node = 0;
    else
      {
        // the pressure DoF set: rebuilt (with the sparsity, the matrix and the AMG
        // hierarchy) only when a point set's cells changed on some rank, or a
        // point's B-spline window moved (a half-cell line) onto a pair the kept
        // pattern lacks (couplings_covered). The decision is global:
        // ActiveSet::reinit and the AMG set-up are collective.
        const bool cells_changed =
          soil.cell_set_changed() || water.cell_set_changed() || step_number == 0 || partition_changed || A.m() == 0;
        const bool         window_moved = !cells_changed && !active.template couplings_covered<K>({&soil, &water});
        const unsigned int why         = dealii::Utilities::MPI::max(cells_changed ? 2u : window_moved ? 1u : 0u, comm);
        const bool         new_pattern = why != 0;
        if (new_pattern)
          {
            active.template reinit<K>({&soil, &water}, ActiveSet<dim>::Couplings::record);
            ++n_pattern_changes;
            if (why == 1)
              ++n_pattern_window_changes;
          }
        partition_changed = false;
        // free water surface: per node, whether it is a vertex of a wet and of a
        // dry cell, and whether it is a vertex of a cell next to a wet one
        // (shares a vertex with it: the layer of nodes just outside the water)
        {
          double *wt = at(wet), *dr = at(dry);
          for (unsigned int c = 0; c < grid.cells.size(); ++c)
            if (grid.cells[c].locally_owned)
              {
                double cell_volume = 1;
                for (unsigned int d = 0; d < dim; ++d)
                  cell_volume *= grid.cells[c].h[d];
                const bool is_wet = cell_water_volume[c] >= prm.free_surface_fraction * cell_volume;
                for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
                  (is_wet ? wt : dr)[grid.cells[c].dofs[v * dim]] += 1;
              }
        }
        exchange({&wet, &dry});
        {
          const double *wt = at(wet);
          double       *nr = at(near_wet);
          for (unsigned int c = 0; c < grid.cells.size(); ++c)
            if (grid.cells[c].locally_owned)
              {
                bool touches_wet = false;
                for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
                  touches_wet = touches_wet || wt[grid.cells[c].dofs[v * dim]] > 0;
                if (touches_wet)
                  for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
                    nr[grid.cells[c].dofs[v * dim]] += 1;
              }
        }
        exchange({&near_wet});
        dealii::AffineConstraints<double> dirichlet, dirichlet_homogeneous; // the second: a plate's unit response
        dirichlet.reinit(pspace.locally_relevant_dofs());
        dirichlet_homogeneous.reinit(pspace.locally_relevant_dofs());
        for (unsigned int i = 0; i < nl; ++i)
          if (component[i] == 0)
            {
              const auto gdof = pspace.node_dof(i, 0);
              if (!pspace.locally_relevant_dofs().is_element(gdof) || dirichlet.is_constrained(gdof))
                continue;
              const bool has_water = Mw.local_element(i) > mw_cut;
              // issue 37 hook: the pressure row from the free-surface rule (A6),
              // the drainage conditions and the sealing of loaded faces
              // (BoundaryLoads::pressure_row): dp = -p^t at a drained node (p^{t+1}
              // = 0), dp = 0 at a node without water or one that keeps its mapped p^t
              const auto row =
                bloads.pressure_row(i, has_water, drained[i], plate_sealed[i], wet.local_element(i),
                                    dry.local_element(i), near_wet.local_element(i), p_node.local_element(i));
              if (row.first)
                {
                  dirichlet.add_line(gdof);
                  dirichlet_homogeneous.add_line(gdof);
                  dirichlet.set_inhomogeneity(gdof, row.second);
                }
            }
        dirichlet.close();
        dirichlet_homogeneous.close();
        bloads.check_pressure_reference(); // issue 37 hook: a sealed box is refused
        const auto constraints = active.constraints_with(dirichlet);
        if (new_pattern)
          {
            active.reinit_matrix(A); // a new Epetra matrix: the kept hierarchy referenced the old one
            pressure_solver.invalidate();
          }
        else
          A = 0; // same pattern: refill the values in place
        pspace.reinit_vector(rhs);
        pspace.reinit_vector(dp_solution);
        {
          // one local system per cell for the soil and the water points of the
          // cell, distributed once (the distribution was the step's largest single
          // cost when each set's cells were distributed on their own)
          const PoissonWithFlux                                terms[2] = {{fs.poisson_coefficient, fs.poisson_flux},
                                                                           {fw.poisson_coefficient, fw.poisson_flux}};
          transfer::AssembleSystem<dim, K, 1, PoissonWithFlux> assembly(active, constraints, terms[0], &A, &rhs);
          transfer::for_each_cell_of_sets<dim>(grid, {&soil, &water}, assembly,
                                               [&](const unsigned int k) { assembly.integrand = terms[k]; });
          transfer::finish_assembly(active, assembly.diag_sum, assembly.diag_count, &A, &rhs);
        }
        add_lap(phase.poisson);
        {
          const auto          t0 = Clock::now();
          LinearSolverOptions options;
          options.method             = LinearSolverOptions::Method::cg_amg;
          options.relative_tolerance = prm.pressure_tolerance;
          pressure_solver.set_rebuild_interval(prm.pressure_rebuild_interval);
          if (rhs.l2_norm() > 0)
            last_solve = pressure_solver.solve(A, dp_solution, rhs, options, step_number);
          else
            last_solve = {"cg_amg", 0, 0.0};
          constraints.distribute(dp_solution);
          dp_solution.update_ghost_values();
          seconds_solve += seconds_since(t0);
          solver_iterations += last_solve.iterations;
          ++n_solves;
          lap = Clock::now();
        }
        for (unsigned int i = 0; i < nl; ++i)
          if (component[i] == 0)
            dp_node.local_element(i) = dp_solution(pspace.node_dof(i, 0));

        // rigid plates under force control: the pressure increment of a unit
        // plate velocity, on the same matrix and hierarchy, with homogeneous
        // Dirichlet values (the equation is linear in V: dp = dp(V = 0) + V dp_1)
        if (!force_plates.empty())
          {
            // without any Dirichlet row the pressure is fixed only up to a
            // constant and a plate's unit inflow has no consistent answer
            const unsigned int n_dirichlet =
              dealii::Utilities::MPI::sum(static_cast<unsigned int>(dirichlet.n_constraints()), comm);
            require(n_dirichlet > 0, prm.rigid_plates[force_plates[0]].where,
                    "the pore water has no pressure reference: no free surface, drained boundary or permeable plate "
                    "(a closed, impermeable box); allowed: 'drainage = permeable', 'semi implicit/drained boundaries', "
                    "or water with a free surface");
            const auto constraints_h = active.constraints_with(dirichlet_homogeneous);
            for (auto &r : plate_response)
              {
                const double *es = at(r.es), *ew = at(r.ew);
                transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                                         [&](unsigned int, It &it, const Stencil &s) {
                                                           double *P = it->get_properties().data();
                                                           double  v[dim];
                                                           s.vector_value(es, v);
                                                           for (unsigned int d = 0; d < dim; ++d)
                                                             P[fs.plate_flux + d] = (1 - P[fs.porosity]) * v[d];
                                                         });
                transfer::for_each_point_stencil<dim, K>(grid, water, stencils<K>(water),
                                                         [&](unsigned int, It &it, const Stencil &s) {
                                                           double *P = it->get_properties().data();
                                                           double  v[dim];
                                                           s.vector_value(ew, v);
                                                           for (unsigned int d = 0; d < dim; ++d)
                                                             P[fw.plate_flux + d] = P[fw.porosity] * v[d];
                                                         });
                Vector rhs1, x1;
                pspace.reinit_vector(rhs1);
                pspace.reinit_vector(x1);
                const PoissonFluxSource                                terms[2] = {{fs.plate_flux}, {fw.plate_flux}};
                transfer::AssembleSystem<dim, K, 1, PoissonFluxSource> assembly(active, constraints_h, terms[0],
                                                                                nullptr, &rhs1);
                transfer::for_each_cell_of_sets<dim>(grid, {&soil, &water}, assembly,
                                                     [&](const unsigned int k) { assembly.integrand = terms[k]; });
                transfer::finish_assembly(active, assembly.diag_sum, assembly.diag_count, nullptr, &rhs1);
                const auto          t0 = Clock::now();
                LinearSolverOptions options;
                options.method             = LinearSolverOptions::Method::cg_amg;
                options.relative_tolerance = prm.pressure_tolerance;
                if (rhs1.l2_norm() > 0)
                  {
                    const auto info = pressure_solver.solve(A, x1, rhs1, options, step_number);
                    solver_iterations += info.iterations;
                    last_solve.iterations += info.iterations;
                    last_solve.relative_residual = std::max(last_solve.relative_residual, info.relative_residual);
                  }
                constraints_h.distribute(x1);
                x1.update_ghost_values();
                seconds_solve += seconds_since(t0);
                for (unsigned int i = 0; i < nl; ++i)
                  if (component[i] == 0)
                    r.dp.local_element(i) = x1(pspace.node_dof(i, 0));
              }
            lap = Clock::now();
          }
      }

    // (6) correction (64)-(68): sum V N grad(Delta p) over each phase's points
    {
      const double *dpn = at(dp_node);
      double       *gsv = at(gs), *gwv = at(gw);
      transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), dpn, L::volume, gsv);
      transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), dpn, L::volume, gwv);
    }
    for (auto &r : plate_response) // the unit responses' pressure forces
      {
        const double *dpn = at(r.dp);
        transfer::scatter_weak_gradient<dim, K>(grid, soil, stencils<K>(soil), dpn, L::volume, at(r.gs));
        transfer::scatter_weak_gradient<dim, K>(grid, water, stencils<K>(water), dpn, L::volume, at(r.gw));
        exchange({&r.gs, &r.gw});
      }
    exchange({&gs, &gw});
    add_lap(phase.p2n);
    // v^{t+1} from v* and the pressure increment's force; a plate's axis DoF
    // moves with its velocity Vp[k] (the water too at an impermeable plate)
    const auto correct = [&](const unsigned int i, const double vss, const double vws, const double gsi,
                             const double gwi, const double *Vp, double &vs, double &vw) {
      const unsigned int j   = node_of[i];
      const double       Mwi = Mw_node.local_element(j), Msi = Ms.local_element(j), n = n_node.local_element(j);
      vw = Mwi > 0 ? vws + h * n * gwi / Mwi : 0.0;
      vs = Msi > ms_cut && !prm.rigid_skeleton ? vss + h * (1 - n) * gsi / Msi : 0.0;
      if (constrained[i])
        vs = 0;
      if (water_constrained[i])
        vw = 0;
      bloads.correct(i, Mwi, vs, vw); // issue 37 hook: prescribed velocities
      if (const unsigned int k = plate_of[i]; k != no_plate)
        {
          vs = Vp[k];
          if (!prm.rigid_plates[k].permeable)
            vw = Mwi > 0 ? Vp[k] : 0.0;
        }
    };
    for (unsigned int i = 0; i < nl; ++i)
      correct(i, vs_star.local_element(i), vw_star.local_element(i), gs.local_element(i), gw.local_element(i),
              plate_v.data(), vs_new.local_element(i), vw_new.local_element(i));
    if (n_plates > 0)
      {
        // The plates' momentum balance at the end of the step. Per plate j the
        // force it exerts on the material along its axis is the mixture's
        // residual over its owned axis DoFs (the drag between the phases
        // cancels in the sum; at a permeable plate the water's own row is
        // satisfied, so what remains is the soil's with the drag):
        //   R_j = sum [M_s (v_s - v_s^t) + M_w (v_w - v_w^t)] / h
        //         - F_s - M_w b - (1 - n)(G_s p^t + g_s) - n (G_w p^t + g_w),
        // g_s, g_w the weak gradients of the pressure increment. Every term is
        // affine in the force plates' velocities: R = R0 + R1 V, R0 from the
        // step with V = 0, column r of R1 from force plate r's unit response.
        const unsigned int owned = grid.partitioner->locally_owned_size();
        const unsigned int nf    = force_plates.size();
        // R0 (the V = 0 step, displacement plates at their velocities) and R1
        std::vector<double> R(n_plates * (1 + nf), 0.0);
        const auto          add_residual = [&](const unsigned int column, const Vector &vsn, const Vector &vwn,
                                      const Vector &gsv, const Vector &gwv, const bool base) {
          for (unsigned int i = 0; i < owned; ++i)
            if (const unsigned int k = plate_of[i]; k != no_plate)
              {
                const unsigned int j = node_of[i];
                const double Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
                double       r = (Msi * vsn.local_element(i) + Mwi * vwn.local_element(i)) / h -
                           (1 - n) * gsv.local_element(i) - n * gwv.local_element(i);
                if (base)
                  r -= (Msi * vs_t.local_element(i) + Mwi * vw_t.local_element(i)) / h + Fs.local_element(i) +
                       Mwi * g[component[i]] + (1 - n) * Gps.local_element(i) + n * Gpw.local_element(i);
                R[column * n_plates + k] += r;
              }
        };
        add_residual(0, vs_new, vw_new, gs, gw, true);
        for (unsigned int r = 0; r < nf; ++r)
          {
            PlateResponse      &u = plate_response[r];
            std::vector<double> unit(n_plates, 0.0);
            unit[force_plates[r]] = 1.0;
            for (unsigned int i = 0; i < nl; ++i)
              correct(i, u.es.local_element(i), u.ew.local_element(i), u.gs.local_element(i), u.gw.local_element(i),
                      unit.data(), u.vs.local_element(i), u.vw.local_element(i));
            add_residual(1 + r, u.vs, u.vw, u.gs, u.gw, false);
          }
        // the same sums, so the same V, on every rank
        MPI_Allreduce(MPI_IN_PLACE, R.data(), static_cast<int>(R.size()), MPI_DOUBLE, MPI_SUM, comm);
        // force control: sum_r R1(f_q, r) V_r = F_q(t + h) - R0(f_q) (Gauss, nf <= 4)
        if (nf > 0)
          {
            std::vector<double> a(nf * nf), x(nf);
            for (unsigned int q = 0; q < nf; ++q)
              {
                const auto &pl = prm.rigid_plates[force_plates[q]];
                for (unsigned int r = 0; r < nf; ++r)
                  a[q * nf + r] = R[(1 + r) * n_plates + force_plates[q]];
                x[q] = pl.force_at(time + h) - R[force_plates[q]];
                if (!(a[q * nf + q] > 0))
                  throw InstabilityError(pl.where + ": the plate touches no material (its nodes carry no mass), so "
                                                    "its velocity under a force is undetermined");
              }
            for (unsigned int c = 0; c < nf; ++c) // no pivoting: R1 is dominated by its diagonal (mass / h)
              for (unsigned int q = c + 1; q < nf; ++q)
                {
                  const double f = a[q * nf + c] / a[c * nf + c];
                  for (unsigned int r = c; r < nf; ++r)
                    a[q * nf + r] -= f * a[c * nf + r];
                  x[q] -= f * x[c];
                }
            for (unsigned int c = nf; c-- > 0;)
              {
                for (unsigned int r = c + 1; r < nf; ++r)
                  x[c] -= a[c * nf + r] * x[r];
                x[c] /= a[c * nf + c];
              }
            for (unsigned int r = 0; r < nf; ++r)
              {
                const double   V         = x[r];
                PlateResponse &u         = plate_response[r];
                plate_v[force_plates[r]] = V;
                for (unsigned int i = 0; i < nl; ++i) // owned and ghost entries alike
                  {
                    vs_new.local_element(i) += V * u.vs.local_element(i);
                    vw_new.local_element(i) += V * u.vw.local_element(i);
                    dp_node.local_element(i) += V * u.dp.local_element(i);
                    gs.local_element(i) += V * u.gs.local_element(i);
                    gw.local_element(i) += V * u.gw.local_element(i);
                  }
              }
          }
        // the tangential reaction of a rough plate: the same residual over its
        // held tangential DoFs, per component
        std::vector<double> T(n_plates * dim, 0.0);
        for (unsigned int i = 0; i < owned; ++i)
          if (const unsigned int k = plate_tangential_of[i]; k != no_plate)
            {
              const unsigned int j   = node_of[i];
              const double       Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
              T[k * dim + component[i]] += (Msi * (vs_new.local_element(i) - vs_t.local_element(i)) +
                                            Mwi * (vw_new.local_element(i) - vw_t.local_element(i))) /
                                             h -
                                           Fs.local_element(i) - Mwi * g[component[i]] -
                                           (1 - n) * (Gps.local_element(i) + gs.local_element(i)) -
                                           n * (Gpw.local_element(i) + gw.local_element(i));
            }
        MPI_Allreduce(MPI_IN_PLACE, T.data(), static_cast<int>(T.size()), MPI_DOUBLE, MPI_SUM, comm);
        for (unsigned int k = 0; k < n_plates; ++k)
          {
            PlateState &st = plate_state[k];
            double      f  = R[k];
            for (unsigned int r = 0; r < nf; ++r)
              f += R[(1 + r) * n_plates + k] * plate_v[force_plates[r]];
            double t2 = 0;
            for (unsigned int d = 0; d < dim; ++d)
              t2 += T[k * dim + d] * T[k * dim + d];
            st.velocity = plate_v[k];
            st.displacement += plate_v[k] * h;
            st.force      = f;
            st.tangential = std::sqrt(t2);
          }
      }
    // issue 37 hook: the reactions of the velocity conditions, the mixture's
    // momentum residual over their DoFs (the plates' R and T)
    bloads.reactions([&](const unsigned int i) {
      const unsigned int j   = node_of[i];
      const double       Msi = Ms.local_element(j), Mwi = Mw_node.local_element(j), n = n_node.local_element(j);
      return (Msi * (vs_new.local_element(i) - vs_t.local_element(i)) +
              Mwi * (vw_new.local_element(i) - vw_t.local_element(i))) /
               h -
             Fs.local_element(i) - Mwi * g[component[i]] - (1 - n) * (Gps.local_element(i) + gs.local_element(i)) -
             n * (Gpw.local_element(i) + gw.local_element(i));
    });
    add_lap(phase.grid);

    // (7) FLIP velocities of both sets, pore pressure to the water points;
    // (8a) MUSL: the soil's new momentum to the nodes (Ps reused)
    Ps = 0;
    {
      const double *vsn = at(vs_new), *vst = at(vs_t), *vwn = at(vw_new), *vwt = at(vw_t), *dpn = at(dp_node),
                   *pn  = at(p_node);
      const double flip = prm.flip_fraction;
      double      *ps   = at(Ps);
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          double *P = it->get_properties().data();
          double  a[dim], b[dim];
          s.vector_value(vsn, a);
          s.vector_value(vst, b);
          for (unsigned int d = 0; d < dim; ++d)
            P[L::velocity + d] = flip * (P[L::velocity + d] + a[d] - b[d]) + (1 - flip) * a[d];
          s.scatter_vector(ps, P[L::mass], P + L::velocity);
        });
      transfer::for_each_point_stencil<dim, K>(
        grid, water, stencils<K>(water), [&](unsigned int, It &it, const Stencil &s) {
          double *P = it->get_properties().data();
          double  a[dim], b[dim];
          s.vector_value(vwn, a);
          s.vector_value(vwt, b);
          for (unsigned int d = 0; d < dim; ++d)
            P[L::velocity + d] = flip * (P[L::velocity + d] + a[d] - b[d]) + (1 - flip) * a[d];
          P[fw.pressure] += s.value(dpn); // (7c) as an increment: p_I^t + dp_I interpolated differs by the remap
          double gp[dim], gdp[dim];
          s.gradient(pn, gp);
          s.gradient(dpn, gdp);
          for (unsigned int d = 0; d < dim; ++d)
            P[fw.pressure_gradient + d] = gp[d] + gdp[d];
        });
    }
    exchange({&Ps});
    for (unsigned int i = 0; i < nl; ++i)
      {
        const double m        = Ms.local_element(node_of[i]);
        vs_t.local_element(i) = (m > ms_cut && !constrained[i]) ? Ps.local_element(i) / m : 0.0; // remapped
        if (plate_of[i] != no_plate) // the plate's velocity, as the walls' zero (A11)
          vs_t.local_element(i) = plate_v[plate_of[i]];
        bloads.remap(i, vs_t.local_element(i)); // issue 37 hook: prescribed velocities
      }
    if (!prm.rigid_plates.empty()) // what the nodes moved the soil with: node_spread
      {
        // [0, n): axis spread; [n, 2n): tangential slip of the nodes
        const unsigned int  np = prm.rigid_plates.size();
        std::vector<double> spread(2 * np, 0.0);
        for (unsigned int i = 0; i < grid.partitioner->locally_owned_size(); ++i)
          {
            const unsigned int k = plate_node_of[node_of[i]];
            if (k == no_plate)
              continue;
            if (plate_of[i] != no_plate)
              spread[k] = std::max({spread[k], std::abs(vs_new.local_element(i) - plate_v[k]),
                                    std::abs(vs_t.local_element(i) - plate_v[k])});
            else if (component[i] != prm.rigid_plates[k].axis &&
                     (!constrained[i] || plate_tangential_of[i] != no_plate))
              spread[np + k] =
                std::max({spread[np + k], std::abs(vs_new.local_element(i)), std::abs(vs_t.local_element(i))});
          }
        MPI_Allreduce(MPI_IN_PLACE, spread.data(), static_cast<int>(spread.size()), MPI_DOUBLE, MPI_MAX, comm);
        for (unsigned int k = 0; k < np; ++k)
          {
            plate_state[k].node_spread += 2 * h * spread[k];
            plate_state[k].node_slip += h * spread[np + k];
          }
      }
    add_lap(phase.n2p);

    if (prm.stabilisation != VolumetricStabilisation::none || smooth_jacobian)
      volume_averages<K>(h, ms_cut);

    // (7a) positions from the new nodal velocities; (8b-g) soil: ΔF from the
    // remapped increment at x^t, volume, J, porosity, conductivity, stress
    struct SoilUpdate
    {
      const Solver                                                  &s;
      const std::vector<std::shared_ptr<const materials::Material>> &models; // per material, this step's
      const double                                                  *v_grid; // v_s^{t+1}: the point moves with it
      const double                                                   h;
      struct PointState
      {
      };
      inline void
      increments(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du, const double *,
                 double (&gu)[dim][dim], double (&dx)[dim])
      {
        double unused[dim];
        K::value_and_gradient(cell, du, e, unused, gu);
        typename K::Field vg;
        K::gather(cell, v_grid, h, vg, false);
        K::interpolate(vg, e, dx);
      }
      inline void
      update(const unsigned int, const typename K::Cell &, double *P, const double (&gu)[dim][dim], PointState &)
      {
        // ΔF = I + grad Δu (Alg. 8(b), the usual index order)
        dealii::Tensor<2, 3> dF;
        for (unsigned int i = 0; i < 3; ++i)
          dF[i][i] = 1;
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int j = 0; j < dim; ++j)
            dF[i][j] += gu[i][j];
        const double dJ = dealii::determinant(dF);
        if (!(dJ > 0))
          throw InstabilityError("a soil point's volume increment det(ΔF) = " + std::to_string(dJ) +
                                 " is not positive");
        const unsigned int         mid     = static_cast<unsigned int>(P[L::material]);
        const materials::Material &m       = *models[mid];
        double *const              history = P + s.soil.layout.history;
        // the increment the model sees: ΔF, or ΔF-bar (79); the modified F-bar
        // also replaces the model's b_e by b_e-bar (82) before the push (81)
        dealii::Tensor<2, 3> dF_model = dF;
        if (s.prm.stabilisation != VolumetricStabilisation::none)
          {
            const double dJ_bar = P[s.fs.smoothed_volume_increment];
            if (!(dJ_bar > 0))
              throw InstabilityError("a soil point's smoothed volume increment (F-bar) " + std::to_string(dJ_bar) +
                                     " is not positive");
            if (s.prm.stabilisation == VolumetricStabilisation::modified_f_bar)
              scale_elastic_b(history, P[s.fs.patch_elastic_jacobian] / elastic_jacobian(m, history));
            dF_model = stabilised_increment<dim>(dF, dJ_bar);
          }
        P[L::volume] *= dJ;             // (8d)
        if (s.bloads.carries_offsets()) // the loaded face moves with the material: d <- dF d (0 stays 0)
          {
            double d[dim];
            for (unsigned int i = 0; i < dim; ++i)
              d[i] = P[s.fs.surface_offset + i];
            for (unsigned int i = 0; i < dim; ++i)
              {
                double di = 0;
                for (unsigned int j = 0; j < dim; ++j)
                  di += dF[i][j] * d[j];
                P[s.fs.surface_offset + i] = di;
              }
          }
        const double J   = P[L::volume] / P[s.fs.initial_volume]; // (8e)
        const double n0  = P[s.fs.initial_porosity];
        const double n   = std::clamp(1 - (1 - n0) / J, 1e-6, 1 - 1e-6); // (8f)
        P[s.fs.porosity] = n;
        if (s.prm.kozeny_carman) // (8g), C1 from k0 and n0
          {
            const double k0      = s.prm.soil_of_material[mid].conductivity;
            const double C1      = k0 * (1 - n0) * (1 - n0) / (n0 * n0 * n0);
            P[s.fs.conductivity] = C1 * n * n * n / ((1 - n) * (1 - n));
          }
        // Nor-Sand (96): v^{t+1} = v0 Jbar^{t+1}; the model multiplies its v by
        // det of the increment it is given, so it gets v0 Jbar / det(dF_model)
        if (s.smooth_jacobian)
          if (const auto *ns = dynamic_cast<const materials::NorSand *>(&m))
            history[materials::NorSand::specific_volume_slot] =
              ns->parameters().v0 * P[s.fs.smoothed_jacobian] / dealii::determinant(dF_model);
        auto                            sigma = L::get_stress(P);
        const dealii::ArrayView<double> hist(history, m.n_history());
        if (m.has_finite_strain_form())
          {
            // the finite-strain return with the increment itself (Hencky
            // Mohr-Coulomb, Nor-Sand, Neo-Hookean): b_e^tr = ΔF b_e ΔF^T, the
            // return in principal logarithmic strains, Kirchhoff tau; then
            // sigma' = tau / J with the point's own J = V / V0 (Alg. step
            // 10(d)), so that V sigma' = V0 tau: the model's J follows the
            // stabilised increments, which may wander from the point's volume
            // (a gas-like point of a landslide: 4e-6 against 1.0)
            sigma = m.finite_strain_step(dF_model, hist) / J;
          }
        else
          {
            // small-strain models: the rate form with the strain and spin
            // increments of ΔF (as the explicit family)
            materials::Strain d_eps;
            materials::Spin   d_omega;
            double            gu_model[dim][dim];
            for (unsigned int i = 0; i < dim; ++i)
              for (unsigned int j = 0; j < dim; ++j)
                gu_model[i][j] = dF_model[i][j] - (i == j ? 1.0 : 0.0);
            materials::strain_and_spin_increments<dim>(gu_model, d_eps, d_omega);
            if (dim == 2) // the out-of-plane stretch of the F-bar's isotropic factor
              d_eps[2][2] = dF_model[2][2] - 1;
            m.update_stress(d_eps, d_omega, h, sigma, hist);
          }
        L::set_stress(sigma, P);
      }
      inline void
      moved(const It &, double *, const dealii::Point<dim> &, PointState &)
      {
      }
    };
    struct WaterMove
    {
      struct PointState
      {
      };
      inline void
      increments(const typename K::Cell &cell, const typename K::Eval &e, const typename K::Field &du, const double *,
                 double (&gu)[dim][dim], double (&dx)[dim])
      {
        transfer::default_increments<dim, K>(cell, e, du, gu, dx);
      }
      inline void
      update(const unsigned int, const typename K::Cell &, double *, const double (&)[dim][dim], PointState &)
      {
      }
      inline void
      moved(const It &, double *, const dealii::Point<dim> &, PointState &)
      {
      }
    };
    {
      SoilUpdate su{*this, initial_stage ? initialisation_models : prm.materials, at(vs_new), h};
      transfer::UpdateAndMove<dim, K, SoilUpdate> move_soil(grid, soil, at(vs_t), h, su);
      transfer::for_each_active_cell(soil, move_soil);
      add_lap(phase.stress);
      soil.relocate();
      WaterMove wm;
      // single point: the water rides on the soil points (the same positions,
      // moved by the same velocity field and the same arithmetic)
      transfer::UpdateAndMove<dim, K, WaterMove> move_water(
        grid, water, at(prm.single_point || initial_stage ? vs_new : vw_new), h, wm);
      transfer::for_each_active_cell(water, move_water);
      water.relocate();
      add_lap(phase.relocation);
    }
    if (initial_stage && !initialising(time + h))
      end_initialisation();
  }

  template <int dim>
  void
  Solver<dim>::end_initialisation()
  {
    // the conductivity jumps to k0: the pressure matrix with it (at the same
    // step in a restarted run)
    pressure_solver.invalidate();
    unsigned long long n = 0;
    for (auto &pt : soil.handler)
      {
        auto P = pt.get_properties();
        if (const auto *ns =
              dynamic_cast<const materials::NorSand *>(prm.materials[static_cast<unsigned int>(P[L::material])].get()))
          {
            ns->reinitialize_reference(dealii::ArrayView<double>(P.data() + soil.layout.history, ns->n_history()));
            ++n;
          }
      }
    n = dealii::Utilities::MPI::sum(n, comm);
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      std::cout << "initialisation (seed 002 App. B.4) ends at t = " << prm.initialisation_time << " s: " << n
                << " nor sand points take their current pressure and elastic volumetric strain as the reference, "
                   "the image pressure from the OCR (Eq. 113); plasticity on, conductivity k0, water points free"
                << std::endl;
  }

  template <int dim>
  template <class K>
  double
  Solver<dim>::shape_walk_seconds()
  {
    // the cost of finding every point's cell and evaluating its stencil (values
    // and gradients), with one interpolation per point so that it is not
    // optimised away: each point pass of the step pays this once. The least
    // of 5 walks (one walk is short: a shared machine's hiccup would dominate)
    double        sum = 0, t = std::numeric_limits<double>::max();
    const double *nn = n_node.begin();
    for (unsigned int repeat = 0; repeat < 5; ++repeat)
      {
        const auto t0 = Clock::now();
        for (MaterialPointSet<dim> *set : {&soil, &water})
          transfer::for_each_point_stencil<dim, K>(
            grid, *set, [&](unsigned int, transfer::PointIterator<dim> &, const transfer::PointStencil<dim, K> &s) {
              sum += s.value(nn);
            });
        t = std::min(t, seconds_since(t0));
      }
    volatile double keep = sum;
    (void)keep;
    return t;
  }

  template <int dim>
  template <class K>
  void
  Solver<dim>::volume_averages(const double h, const double ms_cut)
  {
    const bool fbar     = prm.stabilisation != VolumetricStabilisation::none;
    using Stencil       = transfer::PointStencil<dim, K>;
    using It            = transfer::PointIterator<dim>;
    const bool modified = prm.stabilisation == VolumetricStabilisation::modified_f_bar;
    if (modified)
      {
        patch_mass.assign(patches.size(), 0.0);
        patch_mass_Je.assign(patches.size(), 0.0);
      }
    // dJ of the increment the update will use (h x the remapped velocity, at x^t)
    Mdj = 0;
    Mjt = 0;
    {
      const double *v  = vs_t.begin();
      double       *mj = Mdj.begin(), *mt = Mjt.begin();
      transfer::for_each_point_stencil<dim, K>(
        grid, soil, stencils<K>(soil), [&](unsigned int, It &it, const Stencil &s) {
          double *P = it->get_properties().data();
          double  gv[dim][dim];
          s.vector_gradient(v, gv);
          dealii::Tensor<2, 3> dF; // I + h grad v (plane strain: dF_33 = 1)
          for (unsigned int i = 0; i < 3; ++i)
            dF[i][i] = 1;
          for (unsigned int i = 0; i < dim; ++i)
            for (unsigned int j = 0; j < dim; ++j)
              dF[i][j] += h * gv[i][j];
          const double dJ = dealii::determinant(dF);
          if (fbar)
            s.scatter(mj, P[L::mass] * dJ);
          if (smooth_jacobian) // J^{t+1} = (V / V0) dJ
            s.scatter(mt, P[L::mass] * P[L::volume] / P[fs.initial_volume] * dJ);
          if (modified)
            {
              const auto        &m = *prm.materials[static_cast<unsigned int>(P[L::material])];
              const unsigned int k = patches.index(it->get_location());
              patch_mass[k] += P[L::mass];
              patch_mass_Je[k] += P[L::mass] * elastic_jacobian(m, P + soil.layout.history);
            }
        });
    }
    exchange({&Mdj, &Mjt});
    // every rank needs the sums of the patches its points are in; a patch may
    // span cells of several ranks: one sum over all ranks (2 x the number of
    // patches per step; a neighbour exchange would scale better, not needed yet)
    if (modified && dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
      {
        dealii::Utilities::MPI::sum(patch_mass, comm, patch_mass);
        dealii::Utilities::MPI::sum(patch_mass_Je, comm, patch_mass_Je);
      }
    for (unsigned int i = 0; i < n_local(); ++i)
      if (component[i] == 0)
        {
          const double m       = Ms.local_element(i);
          Mdj.local_element(i) = m > ms_cut ? Mdj.local_element(i) / m : 0.0; // now dJ_I
          Mjt.local_element(i) = m > ms_cut ? Mjt.local_element(i) / m : 0.0; // now J_I
        }
    const double *dj = Mdj.begin(), *jt = Mjt.begin();
    transfer::for_each_point_stencil<dim, K>(grid, soil, stencils<K>(soil),
                                             [&](unsigned int, It &it, const Stencil &s) {
                                               double *P = it->get_properties().data();
                                               // the stencil's nodes all carry soil mass (this point's), so the
                                               // partition of unity holds: a uniform dJ is returned exactly
                                               if (fbar)
                                                 P[fs.smoothed_volume_increment] = s.value(dj);
                                               if (smooth_jacobian)
                                                 P[fs.smoothed_jacobian] = s.value(jt);
                                               if (modified)
                                                 {
                                                   const unsigned int k         = patches.index(it->get_location());
                                                   P[fs.patch_elastic_jacobian] = patch_mass_Je[k] / patch_mass[k];
                                                 }
                                             });
  }

  // ---------------------------------------------------------------- diagnostics and files
  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    bool bad = false;
    for (const Vector *v : {&vs_new, &vw_new, &p_node})
      for (unsigned int i = 0; i < v->locally_owned_size(); ++i)
        bad = bad || !std::isfinite(v->local_element(i));
    if (dealii::Utilities::MPI::max(bad ? 1 : 0, comm))
      throw InstabilityError("a nodal velocity or pore pressure became non-finite");
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    std::vector<std::string> c = {"kinetic_energy_soil",
                                  "kinetic_energy_water",
                                  "max_speed_soil",
                                  "max_speed_water",
                                  "min_pore_pressure",
                                  "pressure_cg_iterations",
                                  "pressure_relative_residual",
                                  "soil_volume",
                                  "load_settlement",
                                  "pressure_amg_setups"};
    for (const auto &name : loads::rigid_plate_series_columns(prm.rigid_plates))
      c.push_back(name);
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k) // this family's check that the nodes move as one
      {
        c.push_back("plate_" + std::to_string(k) + "_node_spread");
        c.push_back("plate_" + std::to_string(k) + "_node_slip");
      }
    for (const auto &name : bloads.series_columns()) // issue 37 hook: velocity_k_reaction_x, ...
      c.push_back(name);
    balance.add_series_column(c);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool)
  {
    double ek[2] = {0, 0}, vmax[2] = {0, 0}, pmin = 0, soil_volume = 0, fu = 0, fsum = 0;
    for (const bool is_soil : {true, false})
      for (const auto &pt : (is_soil ? soil : water).handler)
        {
          const auto P  = pt.get_properties();
          double     v2 = 0;
          for (unsigned int d = 0; d < dim; ++d)
            v2 += P[L::velocity + d] * P[L::velocity + d];
          ek[is_soil ? 0 : 1] += 0.5 * P[L::mass] * v2;
          vmax[is_soil ? 0 : 1] = std::max(vmax[is_soil ? 0 : 1], std::sqrt(v2));
          if (!is_soil)
            pmin = std::min(pmin, P[fw.pressure]);
          else // the mixture volume of the skeleton: a 1D column's height x its width
            {
              soil_volume += P[L::volume];
              // the points carrying a traction: their force-weighted mean
              // displacement along the force (issue 37 hook: the settlement
              // conjugate to the load)
              double fdu, f;
              bloads.settlement_weights(P.data(), fdu, f);
              fu += fdu;
              fsum += f;
            }
        }
    fu                    = dealii::Utilities::MPI::sum(fu, comm);
    fsum                  = dealii::Utilities::MPI::sum(fsum, comm);
    std::vector<double> v = {dealii::Utilities::MPI::sum(ek[0], comm),
                             dealii::Utilities::MPI::sum(ek[1], comm),
                             dealii::Utilities::MPI::max(vmax[0], comm),
                             dealii::Utilities::MPI::max(vmax[1], comm),
                             dealii::Utilities::MPI::min(pmin, comm),
                             static_cast<double>(last_solve.iterations),
                             last_solve.relative_residual,
                             dealii::Utilities::MPI::sum(soil_volume, comm),
                             fsum > 0 ? fu / fsum : 0.0,
                             static_cast<double>(pressure_solver.n_setups())};
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        v.push_back(plate_state[k].displacement);
        v.push_back(plate_state[k].force);
        if (prm.rigid_plates[k].rough)
          v.push_back(plate_state[k].tangential);
      }
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        v.push_back(plate_state[k].node_spread);
        v.push_back(plate_state[k].node_slip);
      }
    bloads.series_values(v); // issue 37 hook
    balance.add_series_value(v);
    return v;
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    for (const bool is_soil : {true, false})
      {
        MaterialPointSet<dim>          &set = is_soil ? soil : water;
        dealii::Particles::DataOut<dim> out;
        out.build_patches(set.handler, set.layout.names(), set.layout.interpretations());
        const std::string name    = io::write_vtu_atomic(out, prm.output_directory, set.name(), counter, comm);
        auto             &records = pvd_records[is_soil ? 0 : 1];
        records.emplace_back(time, name);
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0) // soil.pvd, water.pvd for ParaView
          io::write_pvd(prm.output_directory + "/" + set.name() + ".pvd", records);
      }
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &)
  {
    if (!prm.final_particles_csv)
      return;
    // <set>_final.csv: x, (y, z,) then the properties; rank 0 gathers, writes
    // under a temporary name and renames
    for (const bool is_soil : {true, false})
      {
        const MaterialPointSet<dim> &set = is_soil ? soil : water;
        std::ostringstream           rows;
        rows << std::setprecision(12);
        for (const auto &pt : set.handler)
          {
            const auto x = pt.get_location();
            for (unsigned int d = 0; d < dim; ++d)
              rows << x[d] << ",";
            const auto P = pt.get_properties();
            for (unsigned int k = 0; k < P.size(); ++k)
              rows << P[k] << (k + 1 < P.size() ? "," : "\n");
          }
        const auto all = dealii::Utilities::MPI::gather(comm, rows.str(), 0);
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          {
            const std::string path = prm.output_directory + "/" + set.name() + "_final.csv";
            {
              std::ofstream f(path + ".tmp");
              const char   *xyz[] = {"x", "y", "z"};
              for (unsigned int d = 0; d < dim; ++d)
                f << "pos_" << xyz[d] << ",";
              // vector properties get their component as suffix (velocity_x,
              // pore_pressure_gradient_y, ...)
              const auto       names = set.layout.names();
              std::vector<int> component(names.size(), -1);
              for (unsigned int k = L::velocity; k < L::stress; ++k)
                component[k] = (k - L::velocity) % dim;
              for (const auto &e : set.layout.extras)
                if (e.vector)
                  for (unsigned int i = 0; i < e.size; ++i)
                    component[e.offset + i] = i % dim;
              for (unsigned int k = 0; k < names.size(); ++k)
                {
                  f << names[k];
                  if (component[k] >= 0)
                    f << "_" << xyz[component[k]];
                  f << (k + 1 < names.size() ? "," : "\n");
                }
              for (const auto &r : all)
                f << r;
            }
            std::filesystem::rename(path + ".tmp", path);
          }
      }
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &timings)
  {
    log() << "talus-semi-implicit: done: " << step_number << " steps, dt " << dt << " s, wall " << timings.total
          << " s (pressure solves " << seconds_solve << " s, mean "
          << (n_solves ? double(solver_iterations) / n_solves : 0.0) << " CG iterations; AMG set-ups "
          << pressure_solver.n_setups() << " (interval " << prm.pressure_rebuild_interval << ", fallbacks "
          << pressure_solver.n_fallbacks() << ", after slow solves " << pressure_solver.n_slow_solves()
          << "), pressure DoF set rebuilds " << n_pattern_changes << " (" << n_pattern_window_changes
          << " for a stencil outside the kept pattern)), lost points " << lost_points() << balance.summary()
          << ", output in " << prm.output_directory << "/" << std::endl;
    // per-phase wall clock (rank 0's; the step's point passes: 7 walks of each
    // set per step, 8-9 of the soil with F-bar)
    // the timing walk only when asked (make bench passes --time-shape-walk): it is work of its own
    const bool   time_walk = tool_option_given("--time-shape-walk");
    const double walk      = !time_walk      ? 0.0
                             : prm.bspline() ? shape_walk_seconds<shape::BSpline2Box<dim>>()
                                             : shape_walk_seconds<shape::Q1Box<dim>>();
    log() << std::setprecision(4) << "  breakdown [s]: P2N " << phase.p2n << ", grid " << phase.grid
          << ", Poisson assembly " << phase.poisson << ", pressure solve " << seconds_solve << " (AMG set-up "
          << pressure_solver.setup_seconds() << "), N2P " << phase.n2p << ", update+stress " << phase.stress
          << ", relocation " << phase.relocation << "; points soil " << soil.handler.n_global_particles() << " water "
          << water.handler.n_global_particles();
    if (time_walk)
      log() << "; shape functions: one stencil walk over both sets " << walk << " s";
    log() << std::endl;
  }

  // ================================================================ tool entry points
  void
  check_parameters(dealii::ParameterHandler &prm, const std::string &)
  {
    check_formulation(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  TALUS_INSTANTIATE_FORMULATION(class);
  template double soil_critical_time_step<2>(const Parameters<2> &, double);
  template double soil_critical_time_step<3>(const Parameters<3> &, double);
} // namespace talus::semi_implicit
