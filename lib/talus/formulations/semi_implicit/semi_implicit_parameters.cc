// talus — the .prm of talus-semi-implicit: its entries (declare_parameters),
// their reading and validation (parse_parameters, InputError naming the entry),
// the scene checks that need no grid, the soil skeleton's critical step and the
// tool's --check.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/formulations/semi_implicit/boundary_loads.h>
#include <talus/formulations/semi_implicit/semi_implicit.h>
#include <talus/loads/damping.h>
#include <talus/loads/rigid_plate.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/materials/material.h>
#include <talus/materials/pore_liquid.h>
#include <talus/particles/material_points.h>
#include <talus/transfer/pressure_relaxation.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/utilities.h>

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

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
      prm.declare_entry("pressure smoothing fraction", "1", dealii::Patterns::Anything(),
                        "The share beta of the smoothed value in a water point's pore pressure at each step: "
                        "p <- (1 - beta) p + beta sum N p_I, then p += sum N dp. 1 (the paper's Eq. 77): the "
                        "point's value is replaced every step. The map-remap keeps linear fields and flattens "
                        "curvature a little at every application, so its effect grows with the number of "
                        "steps, not with time: where a consolidation needs millions of steps (low k) a "
                        "smaller share keeps the profile (docs/semi-implicit.md, 'The smoothing at low k'). "
                        "automatic: per material and step min(1, c_v dt / h_min^2), c_v = k E_c / (rho_w g) "
                        "the skeleton's consolidation coefficient (the share of a grid cell's own diffusion "
                        "time that the step is). A number in [0, 1] or automatic. Ignored with pressure "
                        "smoothing = none.");
      prm.declare_entry("flip fraction", "1", Double(0, 1),
                        "Point velocity update: this fraction of FLIP (v_p + sum N (v^{t+1} - v^t)), the rest "
                        "PIC (sum N v^{t+1}). 1 = pure FLIP as in the paper.");
      prm.declare_entry("point sets", "double", Selection("double|single|one set"),
                        "double: soil and water are two sets of material points, each moving with its own "
                        "velocity (the paper's double-point method). one set: the single-point variant, one "
                        "set of points each carrying the soil and its pore water (water velocity, mass and "
                        "pore pressure; the water's porosity is the point's), every point pass made once for "
                        "both phases (the paper's single-point code of Table 4). single: the single-point "
                        "variant as two sets, the water points seeded on the soil points and moved with the "
                        "soil's velocity, so they stay on them (the same passes as double). single and one set "
                        "need every body to be saturated or soil.");
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
    // the shared 'loads' (tractions, velocity conditions), the
    // drainage conditions and 'semi implicit/traction acts at' (boundary_loads.cc)
    declare_boundary_load_parameters(prm, prm_file, counts.dim);
    for (unsigned int k = 0; k < counts.n_materials; ++k)
      {
        // the shared 'pore liquid' (materials/pore_liquid.h): the soil's n0 and k0
        prm.enter_subsection("material " + std::to_string(k));
        materials::declare_pore_liquid(prm);
        prm.leave_subsection();
      }
    loads::declare_damping(prm); // the shared 'damping' (loads/damping.h): refused
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

  std::string
  number_text(const double x)
  {
    std::ostringstream os;
    os << std::setprecision(4) << x;
    return os.str();
  }

  namespace
  {
    /// The checks of a scene that need no grid: the shared ones (boundary ids,
    /// bodies inside the grid, the memory of the grid and both point sets:
    /// formulations/common/scene_checks.h), the B-spline window, the time step.
    template <int dim>
    void
    check_scene(const Parameters<dim> &p)
    {
      // a shared output entry this family does not write: refused, not ignored
      require(!p.write_grid, "output/write grid",
              "not written by talus-semi-implicit (its nodal fields are the step's two-phase vectors, not the grid "
              "vectors talus-explicit writes; the results file's grid/ group holds the soil's final fields on the "
              "nodes); remove the entry");
      SceneCheckOptions o;
      o.cell_memory_factor = 2;              // the pressure space, its matrix and the two-phase nodal vectors
      for (const Phase ph : p.phase_of_body) // a saturated body seeds soil and water points
        o.point_sets_of_body.push_back(ph == Phase::saturated ? 2 : 1);
      check_scene_consistency(p, o);
      double h_min = std::numeric_limits<double>::max();
      for (unsigned int d = 0; d < dim; ++d)
        h_min = std::min(h_min, (p.grid_upper[d] - p.grid_lower[d]) / p.grid_cells[d]);
      if (p.bspline())
        for (unsigned int d = 0; d < dim; ++d)
          require(p.grid_cells[d] >= 3, "grid/cells",
                  "quadratic B-splines need at least 3 cells in every direction (a point's 3-node window)");
      const double dt_cr = soil_critical_time_step(p, h_min);
      require(p.time_step <= dt_cr, "time/time step",
              "is " + number_text(p.time_step) + " s, above the soil skeleton's critical step " + number_text(dt_cr) +
                " s (h_min / sqrt(E_c / ((1 - n) rho_s))); the semi-implicit step is limited by it");
    }

    /// 'semi implicit': the family's numerics, drained boundaries, stabilisation
    template <int dim>
    void
    parse_semi_implicit(dealii::ParameterHandler &prm, Parameters<dim> &p)
    {
      prm.enter_subsection("semi implicit");
      p.water_density             = prm.get_double("water density");
      p.unit_weight_gravity       = prm.get_double("unit weight gravity");
      p.free_surface_fraction     = prm.get_double("free surface volume fraction");
      p.pressure_tolerance        = prm.get_double("pressure solver tolerance");
      p.pressure_rebuild_interval = prm.get_integer("pressure preconditioner rebuild interval");
      p.kozeny_carman             = prm.get_bool("kozeny carman");
      p.pressure_smoothing        = prm.get("pressure smoothing") != "none";
      p.linear_smoothing          = prm.get("pressure smoothing") == "linear";
      {
        const std::string text         = prm.get("pressure smoothing fraction");
        p.automatic_smoothing_fraction = text == "automatic";
        if (!p.automatic_smoothing_fraction)
          {
            char  *end = nullptr;
            double x   = std::strtod(text.c_str(), &end);
            require(!text.empty() && end != text.c_str() && *end == '\0' && x >= 0 && x <= 1,
                    "semi implicit/pressure smoothing fraction",
                    "is '" + text + "'; allowed: a number in [0, 1] or automatic");
            p.smoothing_fraction = x;
          }
      }
      p.flip_fraction  = prm.get_double("flip fraction");
      p.rigid_skeleton = prm.get_bool("rigid skeleton");
      // rigid plates (issue 37): a rigid skeleton holds every soil node, so no
      // plate can move it (a physical impossibility, not a missing feature)
      if (p.grid_mesh == nullptr) // (a grid file is refused below)
        loads::check_rigid_plates_on_box(p.rigid_plates, p.grid_lower, p.grid_upper, p.grid_cells,
                                         p.boundary_conditions);
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
                      "D box, 0 to " + std::to_string(2 * dim - 1) + " (x-, x+, y-, y+" +
                      (dim == 3 ? ", z-, z+)" : ")"));
            // issue 37: an alias of 'boundary conditions/drainage k' (drained boundary)
            p.drainage.push_back(loads::drained_boundary<dim>(static_cast<dealii::types::boundary_id>(id),
                                                              "semi implicit/drained boundaries"));
          }
      }
      {
        p.patch_size               = prm.get_double("patch size");
        p.single_point             = prm.get("point sets") != "double";
        p.one_set                  = prm.get("point sets") == "one set";
        p.smoothed_specific_volume = prm.get("nor sand specific volume") == "node-smoothed";
        require(p.patch_size >= 0.5 && p.patch_size <= 10, "semi implicit/patch size", "must lie in [0.5, 10] cells");
      }
      require(p.water_density > 0, "semi implicit/water density", "must be > 0 kg/m^3");
      require(p.unit_weight_gravity > 0, "semi implicit/unit weight gravity", "must be > 0 m/s^2");
      require(p.free_surface_fraction > 0 && p.free_surface_fraction < 1, "semi implicit/free surface volume fraction",
              "must lie in (0, 1)");
      require(p.pressure_tolerance > 0, "semi implicit/pressure solver tolerance", "must be > 0");
      prm.leave_subsection();
    }

    /// 'initial state': the App. B.4 initialisation (the geostatic start is
    /// 'body k/initial stress', formulations/common/initial_stress.h)
    template <int dim>
    void
    parse_initial_state(dealii::ParameterHandler &prm, Parameters<dim> &p)
    {
      prm.enter_subsection("initial state");
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
    }

    /// 'material k/pore liquid' of every material (materials/pore_liquid.h):
    /// the soil's porosity n0 and hydraulic conductivity k0; what this family
    /// cannot honour is refused
    template <int dim>
    void
    parse_pore_liquid(dealii::ParameterHandler &prm, Parameters<dim> &p)
    {
      const materials::PoreLiquid defaults;
      for (unsigned int k = 0; k < p.materials.size(); ++k)
        {
          const std::string where = "material " + std::to_string(k) + "/pore liquid";
          prm.enter_subsection("material " + std::to_string(k));
          const materials::PoreLiquid pl = materials::read_pore_liquid(prm);
          prm.leave_subsection();
          require(pl.drainage != materials::Drainage::undrained, where + "/drainage",
                  "is 'undrained': talus-semi-implicit seeds what each body's 'phase' says (saturated: soil and "
                  "water points) and has no undrained 1-phase analysis (that is talus-explicit's); allowed: "
                  "drained or coupled (read alike)");
          materials::check_porosity(pl, where);
          require(pl.density == p.water_density, where + "/liquid density",
                  "is " + number_text(pl.density) +
                    " kg/m^3: talus-semi-implicit has one water, of 'semi implicit/water density' = " +
                    number_text(p.water_density) +
                    " kg/m^3; allowed: the same value (or leave both at their default 1000)");
          require(pl.bulk_modulus == defaults.bulk_modulus, where + "/liquid bulk modulus",
                  "is " + number_text(pl.bulk_modulus) +
                    " Pa: talus-semi-implicit's water is incompressible (its pressure equation has no storage "
                    "term), so it cannot honour a bulk modulus; allowed: leave it at its default " +
                    number_text(defaults.bulk_modulus));
          materials::check_seepage(pl, where);
          SoilData s;
          s.porosity     = pl.porosity;
          s.conductivity = pl.hydraulic_conductivity();
          require(std::isfinite(s.conductivity) && s.conductivity > 0, where + "/hydraulic conductivity",
                  "the conductivity is " + number_text(s.conductivity) + "; must be > 0 m/s");
          p.soil_of_material.push_back(s);
        }
    }

    /// The shared 'damping' (loads/damping.h): every entry refused
    void
    refuse_damping(dealii::ParameterHandler &prm)
    {
      const loads::Damping d = loads::parse_damping(prm);
      const std::string    why =
        "talus-semi-implicit has no damping term (its momentum equations have the Darcy drag only); allowed: 0";
      loads::refuse_damping(d.local, "local damping", "talus-semi-implicit", why);
      loads::refuse_damping(d.viscous, "viscous damping", "talus-semi-implicit", why);
      loads::refuse_damping(d.stiffness, "stiffness damping", "talus-semi-implicit", why);
    }

    /// 'body k': phase, the material ids of its points; the
    /// checks of the phases against the point sets and the stabilisation
    template <int dim>
    void
    parse_bodies(dealii::ParameterHandler &prm, Parameters<dim> &p)
    {
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
                  std::string(p.one_set ? "one set" : "single") +
                    " needs every body to carry soil points (the water rides on them), but body " + std::to_string(b) +
                    " has phase = water; allowed: point sets = double, or phase = saturated");
      // a soil body has no pore water: its K0 state is the dry weight
      for (unsigned int b = 0; b < p.bodies.size(); ++b)
        require(p.phase_of_body[b] != Phase::soil || !p.initial_stress[b].enabled ||
                  !p.initial_stress[b].has_water_level(),
                "body " + std::to_string(b) + "/initial stress/water level",
                "body " + std::to_string(b) +
                  " has phase = soil (soil points only, no pore water: the K0 state takes the dry weight); "
                  "allowed: empty, or phase = saturated");
      // a dry scene (soil points only) is a single-phase solid: allowed
      (void)any_water;
      require(any_soil, phases,
              "the scene has no soil points (free water needs a skeleton for the drag and the mixture): give a "
              "body phase = saturated or soil");
      if (p.volumetric_stabilisation == VolumetricStabilisation::modified_f_bar)
        for (unsigned int b = 0; b < p.bodies.size(); ++b)
          if (p.phase_of_body[b] != Phase::water)
            for (const unsigned int mid : p.materials_of_body[b])
              {
                const auto &m = *p.materials[mid];
                require(
                  m.keeps_elastic_b(), "numerics/volumetric stabilisation",
                  "modified f-bar needs a model that keeps the elastic left Cauchy-Green tensor b_e, but material " +
                    std::to_string(mid) + " (of body " + std::to_string(b) + ") is '" + m.model_name() +
                    "'; allowed: hencky mohr coulomb, nor sand, neo hookean (or volumetric stabilisation = none | "
                    "f-bar)");
              }
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
    parse_semi_implicit(prm, p);
    parse_initial_state(prm, p);
    parse_pore_liquid(prm, p);
    refuse_damping(prm);
    parse_bodies(prm, p);
    require(p.grid_mesh == nullptr, "grid/source", "talus-semi-implicit needs a box grid (source = box)");
    parse_boundary_load_parameters(prm, p); // tractions, velocity and drainage conditions
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

  template <int dim>
  std::vector<double>
  smoothing_fractions_of_materials(const Parameters<dim> &p, const double dt, const double h_min,
                                   const bool initial_stage)
  {
    std::vector<double> beta(p.materials.size(), p.automatic_smoothing_fraction ? 1.0 : p.smoothing_fraction);
    if (!p.automatic_smoothing_fraction)
      return beta;
    for (unsigned int b = 0; b < p.bodies.size(); ++b)
      if (p.phase_of_body[b] != Phase::water)
        for (const unsigned int m : p.materials_of_body[b])
          {
            const double k   = initial_stage ? p.initialisation_conductivity : p.soil_of_material[m].conductivity;
            const double c_v = transfer::consolidation_coefficient(k, p.materials[m]->constrained_modulus(),
                                                                   p.water_density, p.unit_weight_gravity);
            beta[m]          = transfer::pressure_smoothing_fraction(c_v, dt, h_min);
          }
    return beta;
  }

  void
  check_parameters(dealii::ParameterHandler &prm, const std::string &)
  {
    check_formulation(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  // the Solver's instantiations: semi_implicit_setup.cc and the other parts'
  TALUS_INSTANTIATE_PARAMETERS();
  template double              soil_critical_time_step<2>(const Parameters<2> &, double);
  template double              soil_critical_time_step<3>(const Parameters<3> &, double);
  template std::vector<double> smoothing_fractions_of_materials<2>(const Parameters<2> &, double, double, bool);
  template std::vector<double> smoothing_fractions_of_materials<3>(const Parameters<3> &, double, double, bool);
} // namespace talus::semi_implicit
