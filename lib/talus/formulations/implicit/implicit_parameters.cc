// talus — the .prm of talus-implicit: its own entries (analysis, Newmark,
// Newton, linear solver, contact, mixed u-p, axisymmetry, stages) declared after
// the shared scene and run sections, parsed into Parameters<dim> and checked
// (InputError naming the entry); the --check entry point.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/loads/damping.h>
#include <talus/loads/kinematics.h>
#include <talus/materials/pore_liquid.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace talus::implicit_mpm
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  // ================================================================ parameters
  void
  declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file)
  {
    const SceneCounts counts =
      declare_common_parameters(prm, prm_file,
                                "Time step [s] (static analysis: the load step, in the same units as 'end time'); "
                                "> 0, required. Not limited by the explicit critical step; a step whose Newton "
                                "iteration fails is halved and retried (at most 6 times in a row).",
                                /*png fields not written:*/ {"pore pressure", "free surface"});
    loads::declare_traction_parameters(prm, prm_file, counts.dim, true);
    prm.enter_subsection("boundary conditions");
    {
      prm.declare_entry("contact", "", Anything(),
                        "Boundary ids (comma-separated) of unilateral contact walls: a grid node of such a wall is "
                        "held (its increment normal to the wall is zero, with 'contact friction = no slip' the "
                        "tangential ones too) while the wall pushes on it, released when the wall would pull on it "
                        "(the nodal reaction, internal + inertia - external force, turns tensile) and held again "
                        "when it would move into the wall; the active set is iterated within each step "
                        "(docs/implicit.md, 'Contact floor'). Applies in every stage.");
      prm.declare_entry("contact friction", "no slip", Anything(),
                        "Tangential behaviour of the 'contact' walls: 'no slip' (a node / point in contact sticks), "
                        "'frictionless' (only the normal component is held / pushed) or a Coulomb coefficient mu >= "
                        "0: on the points, stick while the tangential penalty force is at most mu times the normal "
                        "one, else slip at that force; on the nodes, a node in contact sticks (tangential increment "
                        "held) while its tangential reaction is at most mu times its normal reaction, else slips "
                        "under the tangential force mu |normal reaction| opposing its slip (docs/implicit.md, "
                        "'Contact floor').");
      prm.declare_entry("contact gap", "0.1", Double(0),
                        "A contact node can be held only while the material next to it is at the wall: the gap, "
                        "the smallest (distance to the wall - half the point size V_p^(1/dim)/2) over the points of "
                        "the node's cells at the start of the step, at most this fraction of the cell size normal "
                        "to the wall; a held node whose gap grew beyond it is released.");
      prm.declare_entry("contact passes", "10", Integer(1, 1000),
                        "Active-set passes (Newton solves) per step at most; a node that changed its state twice "
                        "in a step stays in contact for the rest of that step.");
      prm.declare_entry("contact method", "nodes", Anything(),
                        "How the 'contact' walls act: 'nodes' (the grid nodes of the wall are held or free, an active "
                        "set per step; 'contact gap' and 'contact passes' apply) or 'points' (a rigid plane pushes on "
                        "the material points that penetrate it, point extent r_p = V_p^(1/dim)/2, by a penalty inside "
                        "Newton with its consistent tangent; tangentially a penalty on the slip since the point "
                        "touched the wall (no slip) or Coulomb friction; docs/implicit.md, 'Contact walls on the "
                        "points').");
      prm.declare_entry("contact penalty", "1", Anything(),
                        "contact method = points: the penalty factor kappa > 0 of the normal and tangential "
                        "stiffness per point, k = kappa M V_p / h^2 (M the constrained modulus of the point's "
                        "material, V_p its volume, h the cell size normal to the wall).");
    }
    prm.leave_subsection();
    loads::declare_damping(prm); // the shared 'damping' (loads/damping.h)
    for (unsigned int k = 0; k < counts.n_materials; ++k)
      {
        // the shared 'pore liquid' (materials/pore_liquid.h): drained only
        prm.enter_subsection("material " + std::to_string(k));
        materials::declare_pore_liquid(prm);
        prm.leave_subsection();
      }
    loads::declare_stage_parameters(prm, prm_file, counts.dim, false, [](dealii::ParameterHandler &p) {
      p.declare_entry("time step", "0", Double(0),
                      "Time step of the stage [s] (static: its load step); 0 = the top-level time/time step.");
    });
    prm.enter_subsection("implicit");
    {
      prm.declare_entry("analysis", "dynamic", Selection("static|dynamic"),
                        "dynamic: Newmark time integration with inertia (seed 001 §2.4.1); static: "
                        "equilibrium without inertia, time is a load parameter.");
      prm.declare_entry("newmark gamma", "0.5", Double(0.5, 1), "Newmark gamma in [1/2, 1] (thesis: 1/2).");
      prm.declare_entry("newmark beta", "0.25", Double(0, 0.5),
                        "Newmark beta in (0, 1/2] (thesis: 1/4, the trapezoidal rule).");
      prm.declare_entry("mass matrix", "lumped", Selection("lumped|consistent"),
                        "dynamic: the mass matrix of the inertia M a and of the damping alpha_v M v ('damping/viscous "
                        "damping'). lumped: "
                        "M_ii = sum_p m_p N_i(x_p) (the default: Kratos MPM's choice, positive for every node "
                        "a point touches); consistent: M_ij = sum_p m_p N_i(x_p) N_j(x_p) per component (thesis "
                        "Eq. 4.36; singular where a lone point is the only support of several nodes). The "
                        "projection of v_p and a_p to the nodes is lumped in both (docs/implicit.md). No effect "
                        "in a static analysis.");
      prm.declare_entry("ramp loads", "true", Bool(),
                        "static: body forces grow linearly from 0 at t = 0 to their full value at the end "
                        "time (load stepping); false: full loads from the first step (a cut-back step applies "
                        "that share of the load still to apply; docs/implicit.md).");
      prm.declare_entry("formulation", "irreducible", Selection("irreducible|mixed up"),
                        "irreducible: the nodal displacement only; mixed up: displacement and the nodal pressure "
                        "p (mean Cauchy stress, tension positive) on the same Q1 nodes, stabilised by polynomial "
                        "pressure projection (seed 001 ch. 5; static analysis, neo hookean with 'volumetric energy "
                        "= split' or j2 plasticity, linear solver 'direct' or 'gmres block amg').");
      prm.declare_entry("stabilisation factor", "1", Double(0),
                        "mixed up: alpha of the PPP term int (alpha/G)(q - q~)(p - p~) dv (Eq. 5.15), q~, p~ the "
                        "means over the points of a grid cell; 0 = no stabilisation (the pressure oscillates).");
      prm.declare_entry("velocity regions follow", "false", Bool(),
                        "true: the region of each 'loads/velocity k' with 'apply to = region' moves with the "
                        "displacement that condition has prescribed so far, so the prescribed nodes are chosen "
                        "anew each step at the current position of a rigid plate pressed into the material (they "
                        "jump a grid row when the shifted region does); false: the nodes are fixed in space.");
      prm.declare_entry(
        "carry start imbalance", "false", Bool(),
        "Static analyses (no effect in dynamic ones, where the out-of-balance force is inertia): "
        "true: each step solves r(du) = r(0) at the previous load level, so that "
        "the out-of-balance force of the converged state re-assembled on the reset grid (the "
        "change of the grid's test functions, largest at cells the material has just entered) "
        "is carried instead of being relaxed anew every step (from the run's second step on); "
        "false: every step rebalances it (the default until the carried force is understood in "
        "displacement-controlled plastic runs). Its size goes to series.csv either way "
        "('start_imbalance_norm' [N], 'start_imbalance' = that over |f_ext|). docs/implicit.md 'Load steps'.");
      prm.declare_entry("ghost penalty", "0", Double(0),
                        "gamma of the ghost penalty (linear shape functions): on every grid face between two "
                        "cells whose nodes are all active, one of them at the edge of the material, the term "
                        "gamma E h int_F [[grad du . n]] . [[grad w . n]] dF ties the step's increment in a partly "
                        "filled cell to its neighbours (E the largest constrained modulus of the materials, h "
                        "the cell size; docs/implicit.md 'Ghost penalty'). Regularises the nodes that one point "
                        "or a few control after a cell crossing; 0 = off.");
      prm.declare_entry("negligible nodal mass", "0", Double(0, 1),
                        "The DoFs (displacement and, in mixed u-p, pressure) of an active node whose lumped mass is "
                        "below this fraction of the largest nodal mass of the step are held at zero increment (nodes "
                        "touched by the corner "
                        "of a point's support only, e.g. at a heaving free surface); 0 = off. The number of held "
                        "DoFs and the force they carry go to series.csv and the log ('negligible mass load limit').");
      prm.declare_entry("negligible mass load limit", "0.01", Double(0, 1),
                        "With 'negligible nodal mass' > 0: the largest share the held DoFs may carry, at a "
                        "converged step, of all the forces on the nodes (summed magnitudes: the loads |f_ext| "
                        "and the reactions of walls, prescribed DoFs, contact and the hold); above it the run "
                        "stops with exit 3 and the figures (the answer would not be that of the posed problem). "
                        "In [0, 1].");
      prm.declare_entry("geometry", "plane strain", Selection("plane strain|axisymmetric"),
                        "2D only. plane strain: dF_zz = 1. axisymmetric: the scene is the r-z half-plane of a "
                        "body of revolution about the y axis (x = radius, grid lower x >= 0; seed 001 App. C): a "
                        "point's volume and mass are those of its ring (2 pi r x its area), the hoop stretch "
                        "dF_zz = r_{n+1} / r_n enters the models, stress_zz is the hoop stress; tractions are per "
                        "unit ring area; the radial displacement of nodes on the axis (x = 0) is fixed "
                        "automatically. Irreducible formulation only; 3D: leave 'plane strain'.");
    }
    prm.leave_subsection();
    prm.enter_subsection("rigid footing");
    {
      prm.declare_entry("enabled", "false", Bool(),
                        "true: a rigid footing is pressed into the material at a prescribed rate: its base, a plane "
                        "of finite span, pushes on the material points by a penalty inside Newton (as 'contact "
                        "method = points'), so the loaded points move with the material and no grid row is "
                        "prescribed; its reaction is the series column footing_force (docs/implicit.md, 'Rigid "
                        "footing on the points').");
      prm.declare_entry("normal axis", "y", Selection("x|y|z"), "The axis normal to the footing's base.");
      prm.declare_entry("side", "above", Selection("above|below"),
                        "above: the footing lies on the upper side of its base (the material below it, pushed "
                        "towards -axis when it moves down); below: the reverse.");
      prm.declare_entry("level", "0", Double(), "The base's coordinate along the normal axis at t = 0 [m].");
      prm.declare_entry("lower corner", "", Anything(),
                        "The base's span along the other axes (in increasing axis order; 1 value in 2D, 2 in 3D): "
                        "lower ends [m]. A point acts on the base while its contact spot is within the span at "
                        "the start of the step.");
      prm.declare_entry("upper corner", "", Anything(), "Upper ends of the base's span [m].");
      prm.declare_entry("velocity", "0", Double(),
                        "Rate of the base along the normal axis [m per unit time; static analysis: per unit of "
                        "load time, e.g. -0.002 with time step 1 = 2 mm per step].");
      prm.declare_entry("interface", "rough", Selection("rough|smooth"),
                        "rough: a point in contact sticks to the base (no slip); smooth: frictionless.");
      prm.declare_entry("penalty", "1", Double(0),
                        "kappa > 0 of the normal and tangential penalty k = kappa M V_p / h^2 (as 'contact "
                        "penalty').");
    }
    prm.leave_subsection();
    prm.enter_subsection("newton");
    {
      prm.declare_entry("max iterations", "20", Integer(1), "Linear solves per step before the step is cut back.");
      prm.declare_entry("residual relative", "1e-4", Double(0),
                        "Converged when |r| <= max(residual relative x |r_0|, residual absolute); r_0: the "
                        "residual at the predictor (or the external force scale when larger).");
      prm.declare_entry("residual absolute", "1e-9", Double(0), "Absolute residual tolerance [N].");
      prm.declare_entry("increment relative", "1e-4", Double(0),
                        "Increment test: |du| <= max(increment relative x |Du|, increment absolute).");
      prm.declare_entry("increment absolute", "1e-9", Double(0), "Absolute increment tolerance [m].");
      prm.declare_entry("criterion", "residual",
                        Selection("residual|increment|residual and increment|residual or increment"),
                        "Which tests must pass.");
      prm.declare_entry("line search", "none", Selection("none|residual|energy"),
                        "none; residual: backtracking on the residual norm (Armijo); energy: regula falsi on the "
                        "energy's derivative du . r along the increment, only when the full step overshoots "
                        "(docs/implicit.md, 'Newton driver').");
    }
    prm.leave_subsection();
    prm.enter_subsection("linear solver");
    {
      prm.declare_entry("method", "direct", Selection("direct|cg amg|gmres amg|gmres block amg"),
                        "direct: Amesos KLU; gmres amg: GMRES (restart 100) with ML algebraic multigrid (any tangent "
                        "of the irreducible form: plastic models, F-bar, Coulomb friction); cg amg: conjugate "
                        "gradients with ML algebraic multigrid "
                        "(symmetric tangents only: elastic models); gmres block amg: mixed u-p only, GMRES with a "
                        "block-triangular preconditioner (ML AMG on the displacement block and on a Schur "
                        "complement approximation of the pressure block).");
      prm.declare_entry("direct package", "klu", Selection("klu|mumps"),
                        "direct: the Amesos package, KLU or MUMPS (MUMPS is much faster on the indefinite mixed "
                        "u-p tangent, whose pivoting fills KLU's factors).");
      prm.declare_entry("relative tolerance", "1e-10", Double(0, 1), "cg amg, gmres amg: |b - A x| <= tol |b|.");
      prm.declare_entry("max iterations", "1000", Integer(1), "cg amg, gmres amg: iteration limit.");
    }
    prm.leave_subsection();
  }

  template <int dim>
  Parameters<dim>
  parse_parameters(dealii::ParameterHandler &prm)
  {
    Parameters<dim> p;
    parse_run_parameters<dim>(prm, p);
    parse_scene_parameters<dim>(prm, p);
    prm.enter_subsection("time");
    p.time_step = prm.get_double("time step");
    prm.leave_subsection();
    prm.enter_subsection("implicit");
    p.analysis =
      prm.get("analysis") == "static" ? Parameters<dim>::Analysis::quasi_static : Parameters<dim>::Analysis::dynamic;
    p.gamma                   = prm.get_double("newmark gamma");
    p.beta                    = prm.get_double("newmark beta");
    p.consistent_mass         = prm.get("mass matrix") == "consistent";
    p.ramp_loads              = prm.get_bool("ramp loads");
    p.mixed_up                = prm.get("formulation") == "mixed up";
    p.stabilisation           = prm.get_double("stabilisation factor");
    p.axisymmetric            = prm.get("geometry") == "axisymmetric";
    p.moving_velocity_regions = prm.get_bool("velocity regions follow");
    p.negligible_mass         = prm.get_double("negligible nodal mass");
    p.ghost_penalty           = prm.get_double("ghost penalty");
    p.carry_imbalance         = prm.get_bool("carry start imbalance");
    p.negligible_load_limit   = prm.get_double("negligible mass load limit");
    prm.leave_subsection();
    require(p.beta > 0, "implicit/newmark beta", "must be > 0 (beta = 0 is the explicit central difference)");
    Newmark(p.gamma, p.beta); // validates the pair
    // 'numerics/volumetric stabilisation' is the shared scene's (scene_parameters.cc): here f-bar
    // is the cell mean of det dF with its exact tangent (docs/implicit.md, "F-bar")
    require(p.volumetric_stabilisation != transfer::VolumetricStabilisation::modified_f_bar,
            "numerics/volumetric stabilisation",
            "modified f-bar (the b_e scaling over patches of seed 002) is not implemented in talus-implicit; "
            "allowed: none, f-bar");
    p.fbar = p.volumetric_stabilisation == transfer::VolumetricStabilisation::f_bar;
    require(!p.fbar || !p.mixed_up, "numerics/volumetric stabilisation",
            "'f-bar' is for 'formulation = irreducible' (the mixed u-p form treats the volume through its pressure "
            "field); allowed with 'mixed up': none");
    require(!p.fbar || !p.bspline(), "numerics/volumetric stabilisation",
            "'f-bar' (a mean over the points of a cell) is for 'shape function = linear': a B-spline point "
            "reaches beyond its cell; allowed with 'quadratic bspline': none");
    require(p.ghost_penalty == 0 || !p.bspline(), "implicit/ghost penalty",
            "the penalty on jumps of the normal derivative is for 'shape function = linear' (a quadratic "
            "B-spline's derivative has no jump across a face); allowed with 'quadratic bspline': 0");
    require(p.ghost_penalty == 0 || !p.axisymmetric, "implicit/ghost penalty",
            "the face integral has no ring measure (2 pi r) yet; allowed with 'geometry = axisymmetric': 0");
    require(!p.bspline() || !p.axisymmetric, "numerics/shape function",
            "'quadratic bspline' is not available with 'geometry = axisymmetric' (the axis is no wall of the "
            "B-spline basis); allowed there: linear");
    require(!p.fbar || !p.axisymmetric, "numerics/volumetric stabilisation",
            "'f-bar' is not available with 'geometry = axisymmetric' (the hoop stretch is not in the cell mean); "
            "allowed there: none");
    prm.enter_subsection("rigid footing");
    {
      auto &f   = p.footing;
      f.enabled = prm.get_bool("enabled");
      if (f.enabled)
        {
          const std::string axis = prm.get("normal axis");
          f.axis                 = axis == "x" ? 0 : axis == "y" ? 1 : 2;
          require(f.axis < dim, "rigid footing/normal axis", "'z' needs a 3D scene; allowed: x | y");
          f.sign     = prm.get("side") == "above" ? 1 : -1;
          f.level    = prm.get_double("level");
          f.velocity = prm.get_double("velocity");
          f.friction = prm.get("interface") == "rough" ? std::numeric_limits<double>::infinity() : 0.0;
          f.penalty  = prm.get_double("penalty");
          require(f.penalty > 0, "rigid footing/penalty", "must be > 0");
          for (const std::string entry : {"lower corner", "upper corner"})
            {
              const auto v = parse_doubles(prm.get(entry), "rigid footing/" + entry);
              require(v.size() == dim - 1, "rigid footing/" + entry,
                      "needs " + std::to_string(dim - 1) + " value(s): the span along the axes other than the normal");
              for (unsigned int k = 0; k + 1 < dim; ++k)
                (entry == "lower corner" ? f.lower : f.upper)[k] = v[k];
            }
          for (unsigned int k = 0; k + 1 < dim; ++k)
            require(f.lower[k] < f.upper[k], "rigid footing/upper corner", "must exceed 'lower corner'");
        }
    }
    prm.leave_subsection();
    prm.enter_subsection("newton");
    p.newton.max_iterations     = prm.get_integer("max iterations");
    p.newton.residual_relative  = prm.get_double("residual relative");
    p.newton.residual_absolute  = prm.get_double("residual absolute");
    p.newton.increment_relative = prm.get_double("increment relative");
    p.newton.increment_absolute = prm.get_double("increment absolute");
    p.newton.criterion          = parse_newton_criterion(prm.get("criterion"));
    {
      const std::string ls = prm.get("line search");
      p.newton.line_search = ls == "residual" ? LineSearch::residual
                             : ls == "energy" ? LineSearch::energy
                                              : LineSearch::none;
    }
    prm.leave_subsection();
    p.newton.validate();
    prm.enter_subsection("boundary conditions");
    for (const auto id : parse_ids(prm.get("contact"), "boundary conditions/contact"))
      {
        require(id < 2 * dim, "boundary conditions/contact",
                "boundary id " + std::to_string(id) + " is not a face of the box grid (0 .. " +
                  std::to_string(2 * dim - 1) + ")");
        for (const auto &bc : p.boundary_conditions)
          require(bc.id != id, "boundary conditions/contact",
                  "boundary " + std::to_string(id) + " is also " +
                    (bc.kind == BoundaryCondition::Kind::fixed ? "fixed" : "roller") + "; give it one condition");
        p.contact_ids.push_back(static_cast<dealii::types::boundary_id>(id));
      }
    {
      const std::string method = prm.get("contact method");
      require(method == "nodes" || method == "points", "boundary conditions/contact method",
              "'" + method + "' is not a contact method; allowed: nodes | points");
      p.contact_on_points = method == "points";
      // walls on the points keep their state (stick anchors, flags) in the
      // point properties, which travel with the points through a repartition;
      // walls on the nodes keep an active set per grid node between steps,
      // which a repartition does not carry
      require(p.contact_ids.empty() || p.contact_on_points || !p.balance.enabled(), "load balancing/interval",
              "load balancing is not available with contact walls on the nodes (boundary conditions/contact "
              "method = nodes: their active set per node is not carried through a repartition); allowed: "
              "interval = 0, or contact method = points");
      const std::string f  = prm.get("contact friction");
      double            mu = -1;
      if (f != "no slip" && f != "frictionless")
        {
          std::size_t used = 0;
          try
            {
              mu = std::stod(f, &used);
            }
          catch (...)
            {
              used = 0;
            }
          require(used == f.size() && used > 0 && std::isfinite(mu) && mu >= 0, "boundary conditions/contact friction",
                  "'" + f +
                    "' is not a contact friction; allowed: no slip | frictionless | a Coulomb coefficient mu >= 0");
        }
      p.contact_no_slip   = f == "no slip";
      p.contact_mu        = f == "no slip" ? std::numeric_limits<double>::infinity() : f == "frictionless" ? 0.0 : mu;
      const std::string k = prm.get("contact penalty");
      double            kappa = -1;
      std::size_t       used  = 0;
      try
        {
          kappa = std::stod(k, &used);
        }
      catch (...)
        {
          used = 0;
        }
      require(used == k.size() && used > 0 && std::isfinite(kappa) && kappa > 0, "boundary conditions/contact penalty",
              "'" + k + "' is not a penalty factor; allowed: a number > 0 (k = penalty x M V_p / h^2)");
      p.contact_penalty = kappa;
    }
    p.contact_passes = prm.get_integer("contact passes");
    p.contact_gap    = prm.get_double("contact gap");
    if (p.contact_on_points)
      {
        // the node active set's entries mean nothing on the points: refused, not ignored
        require(p.contact_passes == 10, "boundary conditions/contact passes",
                "applies to 'contact method = nodes' only; remove it (contact method = points)");
        require(p.contact_gap == 0.1, "boundary conditions/contact gap",
                "applies to 'contact method = nodes' only; remove it (contact method = points)");
        require(!p.contact_ids.empty(), "boundary conditions/contact method",
                "'points' needs contact walls: give their boundary ids in 'boundary conditions/contact'");
      }
    else
      require(p.contact_penalty == 1, "boundary conditions/contact penalty",
              "applies to 'contact method = points' only; remove it or set 'contact method = points'");
    prm.leave_subsection();
    p.tractions = loads::parse_traction_parameters<dim>(prm, p.bodies, p.grid_lower, p.grid_upper, &p.velocities);
    p.traction_stage.assign(p.tractions.size(), -1);
    {
      // the stages; without 'number of stages' one from the top-level entries
      loads::Stage<dim> top;
      top.name                = "main";
      top.duration            = p.end_time;
      top.gravity             = p.gravity;
      top.boundary_conditions = p.boundary_conditions;
      top.tractions           = p.tractions;
      top.velocities          = p.velocities;
      top.n_global_tractions  = p.tractions.size();
      top.n_global_velocities = p.velocities.size();
      p.stages                = loads::parse_stages<dim>(prm, top, p.bodies, false);
      p.staged                = !p.stages.empty();
      if (!p.staged)
        p.stages.push_back(top);
    }
    // a traction on a grid boundary id (nodal forces): talus-semi-implicit only
    for (const auto &st : p.stages)
      loads::refuse_boundary_tractions(st.tractions, "talus-implicit",
                                       "its tractions are carried by material points; allowed: 'body face' or "
                                       "'region' (docs/boundary-conditions.md)");
    refuse_water_level(p.initial_stress, "talus-implicit",
                       "its points are one-phase, without pore water (allowed: empty)");
    if (!p.staged)
      {
        require(p.time_step > 0, "time/time step", "must be > 0 (the implicit step is chosen by the user)");
        require(p.time_step <= p.end_time * (1 + 1e-12), "time/time step",
                "must not exceed time/end time (" + std::to_string(p.end_time) +
                  " s): a larger step is a typo, the run would be one step to the end time (allowed: 0 < time step "
                  "<= end time)");
      }
    for (unsigned int k = 0; k < p.stages.size(); ++k)
      {
        const auto       &st    = p.stages[k];
        const std::string where = p.staged ? "stage " + std::to_string(k) : std::string("time");
        double            h     = p.time_step;
        if (p.staged)
          {
            prm.enter_subsection(where);
            const double own = prm.get_double("time step");
            prm.leave_subsection();
            h = own > 0 ? own : p.time_step;
            require(h > 0, where + "/time step", "must be > 0: give it here or in time/time step");
            require(h <= st.duration * (1 + 1e-12), where + "/time step",
                    "must not exceed the stage's duration (" + std::to_string(st.duration) + " s)");
          }
        p.stage_time_steps.push_back(h);
        for (const auto &bc : st.boundary_conditions)
          for (const auto id : p.contact_ids)
            require(bc.id != id,
                    where == "time" ? std::string("boundary conditions/contact") : where + "/boundary conditions",
                    "boundary " + std::to_string(id) + " is a contact wall and also fixed/roller here");
        // the stage's own tractions get slots after the global ones
        for (unsigned int j = st.n_global_tractions; j < st.tractions.size(); ++j)
          {
            p.tractions.push_back(st.tractions[j]);
            p.traction_stage.push_back(int(k));
          }
        for (const auto &v : st.velocities)
          require(v.target != loads::PrescribedVelocity<dim>::Target::body, v.where + "/apply to",
                  "'body' (a velocity of material points) is not available in talus-implicit: the points move with "
                  "the grid's solution; allowed: boundary | region (prescribed grid nodes)");
      }
    prm.enter_subsection("linear solver");
    p.linear.method             = prm.get("method") == "direct"      ? LinearSolverOptions::Method::direct
                                  : prm.get("method") == "cg amg"    ? LinearSolverOptions::Method::cg_amg
                                  : prm.get("method") == "gmres amg" ? LinearSolverOptions::Method::gmres_amg
                                                                     : LinearSolverOptions::Method::gmres_block_amg;
    p.linear.direct_package     = prm.get("direct package") == "mumps" ? "Amesos_Mumps" : "Amesos_Klu";
    p.linear.relative_tolerance = prm.get_double("relative tolerance");
    p.linear.max_iterations     = prm.get_integer("max iterations");
    prm.leave_subsection();
    require(!p.footing.enabled || p.contact_ids.empty() || p.contact_on_points, "rigid footing/enabled",
            "a rigid footing acts on the material points; with contact walls set 'boundary conditions/contact "
            "method = points'");
    require(!p.contact_on_points || p.contact_mu == 0 || std::isinf(p.contact_mu) ||
              p.linear.method != LinearSolverOptions::Method::cg_amg,
            "linear solver/method",
            "Coulomb friction on the contact walls gives a non-symmetric tangent: use 'direct' or 'gmres amg' (or "
            "contact friction = no slip | frictionless with cg amg)");

    for (unsigned int k = 0; k < p.materials.size(); ++k)
      {
        const auto &m = *p.materials[k];
        require(m.has_finite_strain_form(), "material " + std::to_string(k) + "/model",
                "'" + m.model_name() +
                  "' has no finite-strain form; talus-implicit needs one of: neo hookean, j2 plasticity, "
                  "hencky mohr coulomb, nor sand");
        require(m.n_history() <= 64, "material " + std::to_string(k), "more than 64 history variables");
      }
    require(p.mixed_up || p.linear.method != LinearSolverOptions::Method::gmres_block_amg, "linear solver/method",
            "'gmres block amg' is the solver of the mixed u-p system ('implicit/formulation = mixed up'); allowed "
            "with the displacement formulation: direct | cg amg | gmres amg");
    if (p.mixed_up)
      {
        require(p.linear.method == LinearSolverOptions::Method::direct ||
                  p.linear.method == LinearSolverOptions::Method::gmres_block_amg,
                "linear solver/method",
                "'mixed up' needs 'direct' or 'gmres block amg' (the u-p system is indefinite: CG does not apply, "
                "and AMG on the whole system does not see the pressure block's structure)");
        for (unsigned int k = 0; k < p.materials.size(); ++k)
          {
            // the split (materials/material.h): the nodal pressure replaces p(J); a
            // yield that depends on the pressure would need it inside the return
            const auto &m = *p.materials[k];
            require(m.has_volumetric_split(), "material " + std::to_string(k) + "/model",
                    "'mixed up' needs a volumetric/deviatoric split with a pressure-independent deviatoric response; "
                    "allowed: 'neo hookean' with 'volumetric energy = split', 'j2 plasticity' (got '" +
                      m.model_name() +
                      (m.model_name() == "neo hookean" ? "' with 'volumetric energy = coupled')"
                                                       : "': its yield depends on the pressure or it has no split)"));
          }
      }
    // what the implicit family does not offer yet: refused, not ignored
    const auto not_yet = [](const bool used, const std::string &entry) {
      require(!used, entry, "not available in talus-implicit yet (issue 13); remove the entry");
    };
    require(!p.write_grid, "output/write grid",
            "not written by talus-implicit (its nodal fields live on the step's NodalSpace, not on the grid "
            "vectors talus-explicit writes; the results file's grid/ group holds the final fields on the nodes); "
            "remove the entry");
    not_yet(bool(p.grid_mesh), "grid/source");
    require(!p.moving_velocity_regions || p.restart == Parameters<dim>::Restart::no, "implicit/velocity regions follow",
            "restarting with moving velocity regions is not available yet (the region shifts are not in the "
            "checkpoint); set it to false or start from t = 0");
    check_scene_consistency(p); // grid, boundary ids, memory, bodies
    if (p.axisymmetric)
      {
        // what the axisymmetric form covers (docs/implicit.md, "Axisymmetry"); the rest is refused
        const std::string where = "implicit/geometry";
        require(dim == 2, where, "'axisymmetric' is a 2D geometry (x = radius, y = axis); in 3D use 'plane strain'");
        require(!p.mixed_up, where,
                "'axisymmetric' is available with 'formulation = irreducible' only (the mixed u-p "
                "form has no hoop terms yet)");
        require(p.grid_lower[0] >= 0, where,
                "'axisymmetric' needs grid/lower corner x >= 0 (x is the radius; got " +
                  std::to_string(p.grid_lower[0]) + ")");
        for (unsigned int k = 0; k < p.stages.size(); ++k)
          require(p.stages[k].gravity[0] == 0,
                  p.staged ? "stage " + std::to_string(k) + "/gravity/acceleration"
                           : std::string("gravity/acceleration"),
                  "with 'axisymmetric' the body force must act along the axis (y): its x (radial) component must be 0");
        for (const auto &t : p.tractions)
          require(t.target != loads::Traction<dim>::Target::point, t.where,
                  "a point load is not available with 'axisymmetric' (a material point off the axis stands for a "
                  "ring, so its force would be a ring load); allowed: plane strain, or a traction in Pa");
        for (const auto &t : p.tractions)
          require(!t.radial, t.where + "/pressure centre",
                  "a pressure on a circle is not available with 'axisymmetric' (the circle would be a torus); "
                  "allowed: plane strain, or a traction on a body face");
        for (const auto &t : p.tractions)
          require(!t.total, t.where,
                  "'total force' is not available with 'axisymmetric' (give the traction in Pa; it is applied per "
                  "unit ring area)");
        require(p.tractions.empty() || p.restart == Parameters<dim>::Restart::no, "checkpoint/restart",
                "restarting an 'axisymmetric' run with tractions is not available yet (the ring weights of the "
                "traction point forces are set on the seeded state)");
      }
    {
      // the shared 'damping' (loads/damping.h): viscous = Rayleigh alpha, stiffness = Rayleigh beta
      const loads::Damping d = loads::parse_damping(prm);
      p.rayleigh_alpha       = d.viscous;
      p.rayleigh_beta        = d.stiffness;
      loads::refuse_damping(d.local, "local damping", "talus-implicit",
                            "local damping acts on the unbalanced nodal force of an explicit step (seed 000 §6.3); "
                            "allowed: 0 (damp with 'viscous damping' or 'stiffness damping', analysis = dynamic)");
      const bool        dyn = p.analysis == Parameters<dim>::Analysis::dynamic;
      const std::string static_reason =
        "damping needs 'implicit/analysis = dynamic' (a static analysis has no velocity); allowed: 0";
      if (!dyn)
        {
          loads::refuse_damping(d.viscous, "viscous damping", "talus-implicit", static_reason);
          loads::refuse_damping(d.stiffness, "stiffness damping", "talus-implicit", static_reason);
        }
      if (p.mixed_up)
        loads::refuse_damping(d.stiffness, "stiffness damping", "talus-implicit",
                              "stiffness-proportional damping is for 'implicit/formulation = irreducible' (the u-p "
                              "tangent's pressure blocks are not a stiffness); allowed with 'mixed up': 0 (use "
                              "'viscous damping')");
    }
    for (unsigned int k = 0; k < p.materials.size(); ++k)
      {
        const std::string where = "material " + std::to_string(k);
        prm.enter_subsection(where);
        const materials::PoreLiquid pl = materials::read_pore_liquid(prm);
        prm.leave_subsection();
        require(pl.drainage == materials::Drainage::drained, where + "/pore liquid/drainage",
                "is '" + materials::drainage_name(pl.drainage) +
                  "': talus-implicit is a 1-phase solid family (no pore pressure, no liquid phase; undrained and "
                  "coupled analyses are talus-explicit's, saturated soil talus-semi-implicit's); allowed: drained");
      }
    for (unsigned int k = 0; k < p.stages.size(); ++k)
      require(p.analysis == Parameters<dim>::Analysis::dynamic || !p.stages[k].boundary_conditions.empty(),
              p.staged ? "stage " + std::to_string(k) + "/boundary conditions" : std::string("boundary conditions"),
              "a static analysis needs at least one fixed or roller wall (without, the "
              "bodies can move as rigid bodies and the stiffness is singular)");
    if (p.axisymmetric && p.grid_lower[0] == 0)
      {
        // the axis: u_r = 0 on the nodes at r = 0 (a roller on the x-min wall)
        // unless the wall is already fixed or a roller
        bool on_axis = false;
        for (const auto &bc : p.boundary_conditions)
          on_axis = on_axis || bc.id == 0;
        if (!on_axis)
          p.boundary_conditions.push_back({0, BoundaryCondition::Kind::roller});
      }
    return p;
  }

  void
  check_scene(dealii::ParameterHandler &prm, const std::string &)
  {
    check_formulation(prm, &parse_parameters<2>, &parse_parameters<3>);
  }


  TALUS_INSTANTIATE_PARAMETERS();
} // namespace talus::implicit_mpm
