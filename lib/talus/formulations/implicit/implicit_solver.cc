#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/seeding.h>
#include <talus/formulations/common/point_checkpoint.h>
#include <talus/formulations/common/point_output.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/formulations/implicit/updated_lagrangian_ops.h>
#include <talus/io/output.h>
#include <talus/loads/rigid_plate_nodes.h>
#include <talus/loads/kinematics.h>
#include <talus/shape/with_kernel.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>

#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

namespace talus::implicit_mpm
{
  namespace
  {
    /// The consistent inertia of one point on the displacement components
    /// (`with_matrix`, `with_vector` as the walk's integrand flags):
    /// b_ic += m_p N_i sum_j N_j w_jc (w: the nodal a + alpha_R v, the walk's
    /// field) and A_ic,jc += coef m_p N_i N_j. Summed over the points this is
    /// M w and coef M with M_ij = sum_p m_p N_i N_j (its row sums are the lumped
    /// masses); a pressure component (mixed u-p) carries no mass.
    template <int dim, bool with_matrix, bool with_vector>
    struct ConsistentInertia
    {
      double                coef   = 0;
      static constexpr bool matrix = with_matrix, vector = with_vector;
      template <int d_, unsigned int nc, class PN>
      inline void
      add(const double *P, const PN &p, transfer::LocalSystem &ls) const
      {
        static_assert(nc >= dim && d_ == dim, "ConsistentInertia: the displacement components come first");
        const double m = P[PropertyLayout<dim>::mass];
        if constexpr (with_vector)
          {
            double w[dim] = {};
            for (unsigned int j = 0; j < p.n; ++j)
              for (unsigned int c = 0; c < dim; ++c)
                w[c] += p.N[j] * ls.u[p.local[j] * nc + c];
            for (unsigned int i = 0; i < p.n; ++i)
              for (unsigned int c = 0; c < dim; ++c)
                ls.b[p.local[i] * nc + c] += m * p.N[i] * w[c];
          }
        if constexpr (with_matrix)
          for (unsigned int i = 0; i < p.n; ++i)
            for (unsigned int j = 0; j < p.n; ++j)
              {
                const double v = coef * m * p.N[i] * p.N[j];
                for (unsigned int c = 0; c < dim; ++c)
                  ls.a(p.local[i] * nc + c, p.local[j] * nc + c) += v;
              }
      }
    };
  } // namespace

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
                        "'frictionless' (only the normal component is held / pushed) or, with 'contact method = "
                        "points' only, a Coulomb coefficient mu >= 0 (stick while the tangential penalty force is at "
                        "most mu times the normal one, else slip at that force).");
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
      prm.declare_entry("rayleigh alpha", "0", Double(0),
                        "Mass-proportional Rayleigh damping C = alpha M [1/s] (dynamic only; the column "
                        "collapse of thesis §6.1 uses 1.5).");
      prm.declare_entry("rayleigh beta", "0", Double(0),
                        "Stiffness-proportional Rayleigh damping C += beta K [s] (dynamic, irreducible form): K the "
                        "material + geometric tangent at the start of each step, held for the step so that Newton's "
                        "tangent stays exact; a mode of frequency omega gets the damping ratio beta omega / 2. "
                        "Rows and columns of constrained DoFs carry no damping force.");
      prm.declare_entry("mass matrix", "lumped", Selection("lumped|consistent"),
                        "dynamic: the mass matrix of the inertia M a and of the damping alpha M v. lumped: "
                        "M_ii = sum_p m_p N_i(x_p) (the default: Kratos MPM's choice, positive for every node "
                        "a point touches); consistent: M_ij = sum_p m_p N_i(x_p) N_j(x_p) per component (thesis "
                        "Eq. 4.36; singular where a lone point is the only support of several nodes). The "
                        "projection of v_p and a_p to the nodes is lumped in both (docs/implicit.md). No effect "
                        "in a static analysis.");
      prm.declare_entry("ramp loads", "true", Bool(),
                        "static: body forces grow linearly from 0 at t = 0 to their full value at the end "
                        "time (load stepping); false: full loads from the first step.");
      prm.declare_entry("formulation", "irreducible", Selection("irreducible|mixed up"),
                        "irreducible: the nodal displacement only; mixed up: displacement and the nodal pressure "
                        "p (mean Cauchy stress, tension positive) on the same Q1 nodes, stabilised by polynomial "
                        "pressure projection (seed 001 ch. 5; static analysis, neo hookean with 'volumetric energy "
                        "= split' or j2 plasticity, direct linear solver).");
      prm.declare_entry("volumetric stabilisation", "none", Selection("none|f-bar"),
                        "irreducible formulation: none, or f-bar: each point's constitutive update sees "
                        "dFbar = (jbar / j)^(1/dim) dF (in-plane in 2D), jbar the volume-weighted mean of "
                        "det dF over the points of its grid cell, and its volume follows jbar (de Souza Neto "
                        "et al. 1996, with the cell as the patch; the exact tangent couples the points of a "
                        "cell). Removes the volumetric locking of Q1 cells with several points (near "
                        "incompressible elasticity, isochoric plastic flow). Not with 'mixed up' or "
                        "'axisymmetric'.");
      prm.declare_entry("stabilisation factor", "1", Double(0),
                        "mixed up: alpha of the PPP term int (alpha/G)(q - q~)(p - p~) dv (Eq. 5.15), q~, p~ the "
                        "means over the points of a grid cell; 0 = no stabilisation (the pressure oscillates).");
      prm.declare_entry("velocity regions follow", "false", Bool(),
                        "true: the region of each 'loads/velocity k' with 'apply to = region' moves with the "
                        "displacement that condition has prescribed so far, so the prescribed nodes are chosen "
                        "anew each step at the current position of a rigid plate pressed into the material (they "
                        "jump a grid row when the shifted region does); false: the nodes are fixed in space.");
      prm.declare_entry("negligible nodal mass", "0", Double(0, 1),
                        "The DoFs (displacement and, in mixed u-p, pressure) of an active node whose lumped mass is "
                        "below this fraction of the largest nodal mass of the step are held at zero increment (nodes "
                        "touched by the corner "
                        "of a point's support only, e.g. at a heaving free surface); 0 = off.");
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
      prm.declare_entry("line search", "false", Bool(), "Backtracking line search on the residual norm.");
    }
    prm.leave_subsection();
    prm.enter_subsection("linear solver");
    {
      prm.declare_entry("method", "direct", Selection("direct|cg amg|gmres amg"),
                        "direct: Amesos KLU; gmres amg: GMRES (restart 100) with ML algebraic multigrid (any tangent "
                        "of the irreducible form: plastic models, F-bar, Coulomb friction); cg amg: conjugate "
                        "gradients with ML algebraic multigrid "
                        "(symmetric tangents only: elastic models).");
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
    p.rayleigh_alpha          = prm.get_double("rayleigh alpha");
    p.rayleigh_beta           = prm.get_double("rayleigh beta");
    p.consistent_mass         = prm.get("mass matrix") == "consistent";
    p.ramp_loads              = prm.get_bool("ramp loads");
    p.mixed_up                = prm.get("formulation") == "mixed up";
    p.stabilisation           = prm.get_double("stabilisation factor");
    p.fbar                    = prm.get("volumetric stabilisation") == "f-bar";
    p.axisymmetric            = prm.get("geometry") == "axisymmetric";
    p.moving_velocity_regions = prm.get_bool("velocity regions follow");
    p.negligible_mass         = prm.get_double("negligible nodal mass");
    prm.leave_subsection();
    require(p.beta > 0, "implicit/newmark beta", "must be > 0 (beta = 0 is the explicit central difference)");
    Newmark(p.gamma, p.beta); // validates the pair
    require(!p.fbar || !p.mixed_up, "implicit/volumetric stabilisation",
            "'f-bar' is for 'formulation = irreducible' (the mixed u-p form treats the volume through its pressure "
            "field); allowed with 'mixed up': none");
    require(!p.fbar || !p.bspline(), "implicit/volumetric stabilisation",
            "'f-bar' (a mean over the points of a cell) is for 'shape function = linear': a B-spline point "
            "reaches beyond its cell; allowed with 'quadratic bspline': none");
    require(!p.bspline() || !p.axisymmetric, "numerics/shape function",
            "'quadratic bspline' is not available with 'geometry = axisymmetric' (the axis is no wall of the "
            "B-spline basis); allowed there: linear");
    require(!p.fbar || !p.axisymmetric, "implicit/volumetric stabilisation",
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
    p.newton.line_search        = prm.get_bool("line search");
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
      if (p.contact_on_points && f != "no slip" && f != "frictionless")
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
                    "' is not a contact friction; allowed: no slip | frictionless | a Coulomb coefficient "
                    "mu >= 0 (contact method = points)");
        }
      else
        require(f == "no slip" || f == "frictionless", "boundary conditions/contact friction",
                "'" + f +
                  "' is not a contact friction; allowed: no slip | frictionless (a Coulomb coefficient "
                  "needs 'contact method = points')");
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
    p.tractions = loads::parse_traction_parameters<dim>(prm, p.bodies, &p.velocities);
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
    p.linear.method             = prm.get("method") == "direct"   ? LinearSolverOptions::Method::direct
                                  : prm.get("method") == "cg amg" ? LinearSolverOptions::Method::cg_amg
                                                                  : LinearSolverOptions::Method::gmres_amg;
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
    if (p.mixed_up)
      {
        require(p.linear.method == LinearSolverOptions::Method::direct, "linear solver/method",
                "'mixed up' needs 'direct' (the u-p system is indefinite; no block preconditioner yet)");
        for (unsigned int k = 0; k < p.materials.size(); ++k)
          {
            // the split (materials/material.h): the nodal pressure replaces p(J); a
            // yield that depends on the pressure would need it inside the return
            const auto &m = *p.materials[k];
            require(m.has_volumetric_split(), "material " + std::to_string(k) + "/model",
                    "'mixed up' needs a volumetric/deviatoric split with a pressure-independent deviatoric response; "
                    "allowed: 'neo hookean' with 'volumetric energy = split', 'j2 plasticity' (got '" +
                      m.model_name() +
                      (dynamic_cast<const materials::NeoHookean *>(&m)
                         ? "' with 'volumetric energy = coupled')"
                         : "': its yield depends on the pressure or it has no split)"));
          }
      }
    // what the implicit family does not offer yet: refused, not ignored
    const auto not_yet = [](const bool used, const std::string &entry) {
      require(!used, entry, "not available in talus-implicit yet (issue 13); remove the entry");
    };
    not_yet(!p.results_file.empty(), "output/results file");
    not_yet(!p.probes.empty(), "output/probes");
    not_yet(p.write_grid, "output/write grid");
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
          require(!t.total, t.where,
                  "'total force' is not available with 'axisymmetric' (give the traction in Pa; it is applied per "
                  "unit ring area)");
        require(p.tractions.empty() || p.restart == Parameters<dim>::Restart::no, "checkpoint/restart",
                "restarting an 'axisymmetric' run with tractions is not available yet (the ring weights of the "
                "traction point forces are set on the seeded state)");
      }
    require(p.analysis == Parameters<dim>::Analysis::dynamic || p.rayleigh_alpha == 0, "implicit/rayleigh alpha",
            "damping needs 'analysis = dynamic'");
    require(p.analysis == Parameters<dim>::Analysis::dynamic || p.rayleigh_beta == 0, "implicit/rayleigh beta",
            "damping needs 'analysis = dynamic'");
    require(!p.mixed_up || p.rayleigh_beta == 0, "implicit/rayleigh beta",
            "stiffness-proportional damping is for 'formulation = irreducible' (the u-p tangent's pressure blocks are "
            "not a stiffness); allowed with 'mixed up': 0 (use 'rayleigh alpha')");
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

  // ================================================================ solver
  template <int dim>
  template <class F>
  void
  Solver<dim>::with_kernel(F &&f) const
  {
    shape::with_kernel<dim>(prm.bspline(), std::forward<F>(f));
  }

  template <int dim>
  Solver<dim>::Solver(const Parameters<dim> &p, MPI_Comm c)
      : prm(p)
      , comm(c)
      , grid(c, p.balance.enabled())
      , points(grid, "points")
      , balance(grid, p.balance, {&points}, [this] { grid_changed(); })
      , space(grid, p.mixed_up ? dim + 1 : dim)
      , active(space)
      , newmark(p.gamma, p.beta)
  {
  }

  template <int dim>
  Solver<dim>::~Solver() = default;

  template <int dim>
  void
  Solver<dim>::setup()
  {
    grid.make_box(prm.grid_lower, prm.grid_upper, prm.grid_cells);
    grid.setup();
    if (prm.bspline())
      grid.setup_bspline_patches(); // the 4^dim node patch of every owned cell
    space.setup();

    unsigned int n_history = 0;
    for (const auto &m : prm.materials)
      n_history = std::max(n_history, m->n_history());
    points.layout.n_history = n_history;
    acceleration_offset     = points.layout.add_extra("acceleration", dim, true);
    point_forces.extend_layout(points.layout, prm.tractions.size());
    if (prm.axisymmetric)
      radius_offset = points.layout.add_extra("radius", 1);
    if (prm.contact_on_points || prm.footing.enabled)
      {
        // the contact walls as planes (box faces: id = 2 axis + (0 lower | 1 upper))
        std::vector<ContactPlane> planes;
        const auto                cell_size = [&](const unsigned int axis) {
          return (prm.grid_upper[axis] - prm.grid_lower[axis]) / prm.grid_cells[axis];
        };
        for (const auto id : prm.contact_on_points ? prm.contact_ids : std::vector<dealii::types::boundary_id>())
          {
            ContactPlane c;
            c.axis     = id / 2;
            c.sign     = id % 2 ? 1 : -1;
            c.wall     = c.sign < 0 ? prm.grid_lower[c.axis] : prm.grid_upper[c.axis];
            c.cell     = cell_size(c.axis);
            c.penalty  = prm.contact_penalty;
            c.friction = prm.contact_mu;
            planes.push_back(c);
          }
        if (prm.footing.enabled)
          {
            const auto  &f = prm.footing;
            ContactPlane c;
            c.axis   = f.axis;
            c.sign   = f.sign;
            c.wall_0 = f.level;
            c.wall = c.wall_n = f.level; // set_time moves it every step
            c.velocity        = f.velocity;
            c.cell            = cell_size(c.axis);
            c.penalty         = f.penalty;
            c.friction        = f.friction;
            c.footing         = true;
            for (unsigned int k = 0; k + 1 < dim; ++k)
              {
                c.lower[k] = f.lower[k];
                c.upper[k] = f.upper[k];
              }
            planes.push_back(c);
          }
        point_contact = std::make_unique<PointContact<dim>>(planes, prm.materials, prm.axisymmetric, prm.bspline());
        point_contact->extend_layout(points.layout);
      }
    if (prm.mixed_up)
      {
        pressure_offset = points.layout.add_extra("pressure", 1);
        for (const auto &m : prm.materials)
          split_models.push_back(m.get());
      }
    points.initialize();

    const unsigned int n_plates = prm.rigid_plates.size();
    plate_displacement.assign(n_plates, 0.0);
    plate_step.assign(n_plates, 0.0);
    plate_c.assign(n_plates, 0.0);
    plate_target.assign(n_plates, 0.0);
    plate_sum.assign(n_plates, 0.0);
    plate_reaction.assign(n_plates, dealii::Tensor<1, dim>());
    plate_owned.assign(n_plates, {});
    idle_plates.assign(n_plates, 0);
    const bool restored = restore_if_asked(prm, [this] { return restore_checkpoint(); });
    if (!restored)
      {
        seed_scene_bodies(grid, prm.bodies, material_densities(prm), points, "material point", &prm);
        using L = PropertyLayout<dim>;
        initialize_point_histories(prm.materials, points, L::history);
        for (auto &pt : points.handler)
          {
            auto P = pt.get_properties();
            for (unsigned int d = 0; d < dim; ++d)
              P[acceleration_offset + d] = 0.0;
            if (prm.mixed_up) // the mean of the initial stress
              P[pressure_offset] = dealii::trace(L::get_stress(P.data())) / 3.0;
          }
        if (point_contact)
          point_contact->initialize_points(points);
        dt = prm.stage_time_steps[0];
      }
    require(current_stage < prm.stages.size(), "checkpoint/restart",
            "the checkpoint is in stage " + std::to_string(current_stage) + " but the .prm has " +
              std::to_string(prm.stages.size()) + " stage(s)");
    enter_stage(current_stage);
    check_plates();
    points.collect_active_cells();
    if (!prm.tractions.empty())
      point_forces.assign(prm.tractions, points, grid, prm.bodies, comm);
    if (prm.axisymmetric && !restored)
      {
        // The ring measure (docs/implicit.md, "Axisymmetry"): the seeded V_p is
        // the point's area in the r-z plane; its volume and mass become those
        // of the ring it stands for, 2 pi r_p V_p and 2 pi r_p m_p, so that every
        // integral of the step (internal force, m_p g, the lumped mass, V_{n+1} =
        // det(dF) V_n with the hoop stretch in dF) is the plane one with the
        // ring's measure. The traction forces were assigned on the areas (per
        // unit length of the face in the r-z plane); they get the ring weight of
        // the loaded surface: 2 pi x the face's radius for a body face normal to
        // x (r = the body's lower/upper x), 2 pi r_p otherwise.
        using L                = PropertyLayout<dim>;
        const double two_pi    = 2 * dealii::numbers::PI;
        double       totals[2] = {0, 0};
        // a point on or across the axis (only a particle file can put one there:
        // seeded points sit at sub-cell centres of a grid with x >= 0)
        double r_min = std::numeric_limits<double>::max();
        for (const auto &pt : points.handler)
          r_min = std::min(r_min, pt.get_location()[0]);
        r_min = dealii::Utilities::MPI::min(r_min, comm);
        require(r_min > 0, "implicit/geometry",
                "'axisymmetric': a material point lies at x = " + std::to_string(r_min) +
                  " <= 0, on or across the axis (x is the radius; points must have x > 0)");
        for (auto &pt : points.handler)
          {
            auto         P = pt.get_properties();
            const double r = pt.get_location()[0];
            for (unsigned int j = 0; j < prm.tractions.size(); ++j)
              {
                const auto &t      = prm.tractions[j];
                double      r_face = r;
                if (t.target == loads::Traction<dim>::Target::body_face && t.axis == 0)
                  r_face = t.side < 0 ? prm.bodies[t.body].lower[0] : prm.bodies[t.body].upper[0];
                for (unsigned int d = 0; d < dim; ++d)
                  P[point_forces.offset() + j * dim + d] *= two_pi * r_face;
              }
            P[L::volume] *= two_pi * r;
            P[L::mass] *= two_pi * r;
            totals[0] += P[L::volume];
            totals[1] += P[L::mass];
          }
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(totals, 2), comm,
                                    dealii::ArrayView<double>(totals, 2));
        log() << "  axisymmetric: points carry their rings (2 pi r x area): volume " << totals[0] << " m^3, mass "
              << totals[1] << " kg" << std::endl;
        if (prm.grid_lower[0] == 0)
          for (const auto &bc : prm.boundary_conditions)
            if (bc.id == 0)
              log() << "  axisymmetric: the x-min wall is the axis, u_r = 0 there ("
                    << (bc.kind == BoundaryCondition::Kind::roller ? "roller" : "fixed") << ")" << std::endl;
      }
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap})
      space.reinit_vector(*v);
    // every contact node starts in contact (released in the first step where
    // the wall would pull on it); a restart starts so too
    contact_state = 1.0;
    contact_state.update_ghost_values();
    // load balancing: partition by points from the start (a restart on as many
    // ranks has recreated its saved partition instead)
    balance.initial();
  }

  template <int dim>
  void
  Solver<dim>::grid_changed()
  {
    space.setup();
    if (current_stage < prm.stages.size())
      stage_nodes(current_stage);
    for (Vector *v : {&du, &delta, &residual, &mass, &v_n, &a_n, &a_new, &inertia_field, &contact_state, &contact_gap})
      space.reinit_vector(*v);
    contact_state = 1.0; // (load balancing is refused with contact walls on the nodes)
    contact_state.update_ghost_values();
    points.collect_active_cells();
  }

  template <int dim>
  void
  Solver<dim>::after_step()
  {
    balance.after_step(step_number, prm.progress);
  }

  template <int dim>
  double
  Solver<dim>::load_factor(const double t) const
  {
    if (dynamic() || !prm.ramp_loads)
      return 1.0;
    if (!prm.staged)
      return std::min(1.0, t / prm.end_time);
    return std::min(1.0, (t - stage_start_time) / prm.stages[current_stage].duration);
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::apply_loads_at(const double t)
  {
    const double r = load_factor(t);
    if (!prm.staged) // the ramp scales gravity and every traction alike
      {
        point_forces.update_factors(prm.tractions, prm.tractions.size(), t, 0.0);
        point_force_scale = r;
        return r * prm.gravity;
      }
    // global tractions (absolute time) ramp in with stage 0 and stay on; a
    // stage's own (stage time) ramp in over it and are off in other stages
    const unsigned int  k = current_stage;
    std::vector<double> f(prm.tractions.size(), 0.0);
    for (unsigned int j = 0; j < prm.tractions.size(); ++j)
      if (prm.traction_stage[j] < 0)
        f[j] = prm.tractions[j].function.value(t) * (k == 0 ? r : 1.0);
      else if (static_cast<unsigned int>(prm.traction_stage[j]) == k)
        f[j] = prm.tractions[j].function.value(t - stage_start_time) * r;
    point_forces.set_factors(std::move(f));
    point_force_scale               = 1;
    const dealii::Tensor<1, dim> &g = prm.stages[k].gravity;
    if (r == 1.0)
      return g;
    const dealii::Tensor<1, dim> g_before = k > 0 ? prm.stages[k - 1].gravity : dealii::Tensor<1, dim>();
    return g_before + r * (g - g_before);
  }

  template <int dim>
  void
  Solver<dim>::enter_stage(const unsigned int k)
  {
    stage_nodes(k);
    idle_conditions.assign(prm.stages[k].velocities.size() + prm.rigid_plates.size(), 0);
    region_shift.assign(prm.stages[k].velocities.size(), dealii::Tensor<1, dim>());
  }

  template <int dim>
  void
  Solver<dim>::stage_nodes(const unsigned int k)
  {
    const auto &st = prm.stages[k];
    boundary_flags = loads::wall_dof_flags(grid, st.boundary_conditions);
    contact_nodes  = prm.contact_on_points ? std::vector<loads::ContactNode>()
                                           : loads::contact_wall_nodes(grid, prm.contact_ids, boundary_flags);
    node_contact.assign(boundary_flags.size(), -1);
    for (std::size_t k = 0; k < contact_nodes.size(); ++k)
      node_contact[contact_nodes[k].node] = int(k);
    // the grid nodes of the stage's 'velocity k' (owned and ghost: constraints
    // of a distributed assembly must be known where a rank assembles)
    prescribed_dofs = loads::prescribed_node_dofs(grid, st.velocities, false);
    // the plates' nodes (their walls are those of the stage)
    plate_nodes = loads::rigid_plate_node_dofs(grid, prm.rigid_plates, false);
    append_plate_dofs();
  }

  template <int dim>
  void
  Solver<dim>::append_plate_dofs()
  {
    // a component a fixed/roller wall holds stays the wall's (wall_constraints
    // would let a prescribed line win); the axis component of a force plate is
    // no prescribed DoF but the plate's unknown
    const unsigned int n_vel = n_velocities();
    for (const auto &p : plate_nodes)
      {
        const auto &plate = prm.rigid_plates[p.condition];
        if (boundary_flags[p.dof] || (force_plate(p.condition) && p.component == plate.axis))
          continue;
        prescribed_dofs.push_back({p.dof, p.node, n_vel + p.condition, p.component});
      }
  }

  template <int dim>
  void
  Solver<dim>::check_plates()
  {
    // the shared node checks (exit 2 naming the plate) of every stage's walls
    std::vector<std::vector<BoundaryCondition>> walls;
    std::vector<std::string>                    names;
    for (const auto &st : prm.stages)
      walls.push_back(st.boundary_conditions), names.push_back(st.name);
    const auto counts = loads::check_rigid_plate_nodes(grid, prm.rigid_plates, walls, names, comm);
    for (unsigned int k = 0; k < counts.size(); ++k)
      log() << loads::rigid_plate_log_line(prm.rigid_plates[k], k, counts[k]) << std::endl;
  }

  template <int dim>
  void
  Solver<dim>::find_plate_dofs()
  {
    // the axis DoFs of each force plate that the step leaves free (not held by
    // a wall, a prescribed line, contact, the inactive pins or the negligible
    // mass rule, which includes the prescribed lines of displacement plates;
    // plates share no node: check_plates)
    const auto                                  &owned = space.locally_owned_dofs();
    std::vector<dealii::types::global_dof_index> mine;
    for (auto &v : plate_owned)
      v.clear();
    for (const auto &p : plate_nodes)
      {
        const auto &plate = prm.rigid_plates[p.condition];
        if (!force_plate(p.condition) || p.component != plate.axis)
          continue;
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || constraints.is_constrained(i))
          continue;
        plate_owned[p.condition].push_back(i);
        mine.push_back(i);
      }
    plate_all.clear();
    for (const auto &v : dealii::Utilities::MPI::all_gather(comm, mine))
      plate_all.insert(plate_all.end(), v.begin(), v.end());
    std::sort(plate_all.begin(), plate_all.end());
  }

  template <int dim>
  void
  Solver<dim>::prepare_step()
  {
    if (prm.axisymmetric) // r_n of every point, read by the residual and the convective phase
      for (auto &pt : points.handler)
        pt.get_properties()[radius_offset] = pt.get_location()[0];
    if (prm.moving_velocity_regions)
      {
        // the regions shifted by what their conditions have prescribed so far
        auto velocities = prm.stages[current_stage].velocities;
        for (unsigned int k = 0; k < velocities.size(); ++k)
          if (velocities[k].target == loads::PrescribedVelocity<dim>::Target::region)
            {
              velocities[k].lower += region_shift[k];
              velocities[k].upper += region_shift[k];
            }
        prescribed_dofs = loads::prescribed_node_dofs(grid, velocities, false);
        append_plate_dofs();
      }
    // the cell terms (PPP cell means, F-bar's cell mean) couple all the nodes a cell's points touch
    const auto reach = prm.mixed_up || prm.fbar ? ActiveSet<dim>::Reach::cell : ActiveSet<dim>::Reach::point;
    with_kernel(
      [&](auto k) { active.template reinit<decltype(k)>({&points}, ActiveSet<dim>::Couplings::skip, reach); });
    active.reinit_matrix(tangent);
    project_to_grid();
    find_negligible_nodes();
    // the walls' fixed and roller DoFs as homogeneous constraints on the
    // increment, merged with the pins of the inactive DoFs
    contact_changes.assign(contact_nodes.size(), 0);
    if (!prm.contact_ids.empty() && !point_contact)
      measure_contact_gaps();
    if (point_contact) // x_n of the points, read by the contact terms of the step
      point_contact->start_step(points);
    constraints = step_constraints();
    if (any_force_plate())
      find_plate_dofs();
  }

  template <int dim>
  void
  Solver<dim>::measure_contact_gaps()
  {
    using L          = PropertyLayout<dim>;
    const double far = std::numeric_limits<double>::max();
    contact_gap      = far;
    contact_gap.update_ghost_values();
    contact_gap.set_ghost_state(false); // ghost entries written below and sent to the owners (compress)
    for (const auto &pt : points.handler)
      {
        const auto &cc = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
        const auto &x  = pt.get_location();
        const auto  P  = pt.get_properties();
        double      V  = P[L::volume];
        if (prm.axisymmetric)
          V /= 2 * M_PI * std::max(x[0], 1e-300);
        const double half = 0.5 * std::pow(V, 1.0 / dim);
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            const int k = node_contact[cc.dofs[v * dim]];
            if (k < 0)
              continue;
            const auto  &c   = contact_nodes[k];
            const auto   in  = space.node_dof(c.node, c.axis);
            const double gap = c.sign * (c.wall - x[c.axis]) - half;
            contact_gap(in)  = std::min(contact_gap(in), gap);
          }
      }
    contact_gap.compress(dealii::VectorOperation::min);
    contact_gap.update_ghost_values();
    // the material has left the wall at a node in contact: released
    const auto  &owned = space.locally_owned_dofs();
    unsigned int left  = 0;
    for (const auto &c : contact_nodes)
      {
        const auto in = space.node_dof(c.node, c.axis);
        if (owned.is_element(in) && contact_state(in) != 0.0 && contact_gap(in) > contact_gap_tolerance(c))
          {
            contact_state(in) = 0.0;
            ++left;
          }
      }
    contact_state.update_ghost_values();
    gap_releases += dealii::Utilities::MPI::sum(left, comm);
  }

  template <int dim>
  dealii::AffineConstraints<double>
  Solver<dim>::step_constraints(const std::vector<double> *values, const bool with_contact, const bool with_prescribed,
                                const bool hold_plates) const
  {
    // the contact nodes now in contact: their normal DoF, with no slip all
    std::vector<dealii::types::global_dof_index> held;
    if (with_contact)
      for (const auto &c : contact_nodes)
        {
          const auto in = space.node_dof(c.node, c.axis);
          if (contact_state(in) == 0.0)
            continue;
          for (unsigned int d = 0; d < dim; ++d)
            if (d == c.axis || prm.contact_no_slip)
              held.push_back(space.node_dof(c.node, d));
        }
    held.insert(held.end(), negligible_dofs.begin(), negligible_dofs.end());
    if (hold_plates) // the force plates' axis DoFs at zero increment (the predictor)
      for (const auto &p : plate_nodes)
        if (force_plate(p.condition) && p.component == prm.rigid_plates[p.condition].axis)
          held.push_back(space.node_dof(p.node, p.component));
    return active.constraints_with(loads::wall_constraints(
      grid, space, boundary_flags, with_prescribed ? &prescribed_dofs : nullptr, values, &held));
  }

  template <int dim>
  void
  Solver<dim>::find_negligible_nodes()
  {
    // A node touched only by the far corner of a point's support (a point
    // heaving into an empty cell row) has a tiny mass and a stiffness from
    // that one point only; with a perfectly plastic model it has none in the
    // flow direction and Newton breaks down. Such nodes' DoFs are held at zero
    // increment for the step (the reading notes' choice, §7: the thesis is
    // silent); a prescribed or wall DoF keeps its own line.
    negligible_dofs.clear();
    if (!(prm.negligible_mass > 0))
      return;
    double m_max = 0;
    for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
      if (space.component(k) < dim)
        m_max = std::max(m_max, mass.local_element(k));
    m_max              = dealii::Utilities::MPI::max(m_max, comm);
    const double limit = prm.negligible_mass * m_max;
    // every component of such a node is held, in u-p its pressure too: the
    // pressure row scales with the node's tiny point volume (V N / K and the
    // stabilisation) and left free it kept the system near-singular (h = 0.1 m
    // footing: increments of 1e5 .. 1e7 in converged steps, breakdown at
    // s = 0.084 m; held: docs/implicit.md, "Rigid strip footing")
    const unsigned int n_held = space.n_components();
    mass.update_ghost_values();
    std::vector<unsigned char> seen(mass.locally_owned_size() + mass.get_partitioner()->n_ghost_indices(), 0);
    for (const auto &cell : grid.tria.active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int v = 0; v < CellCache<dim>::n_vertices; ++v)
          {
            const unsigned int node = grid.cells[cell->active_cell_index()].dofs[v * dim];
            const auto         i0   = space.node_dof(node, 0);
            const auto         j    = mass.get_partitioner()->global_to_local(i0);
            if (seen[j] || !active.is_active(i0))
              continue;
            seen[j] = 1;
            if (mass(i0) < limit)
              for (unsigned int k = 0; k < n_held; ++k)
                negligible_dofs.push_back(space.node_dof(node, k));
          }
    mass.zero_out_ghost_values();
  }

  template <int dim>
  std::pair<unsigned int, unsigned int>
  Solver<dim>::update_contact(const dealii::Tensor<1, dim> &g, const double force_scale)
  {
    // the residual assembled without the contact constraints: at a contact
    // DoF it is the force the wall must exert on the node, r = f_int + m a -
    // f_ext (the residual of the other DoFs is kept)
    Vector kept(residual);
    auto   free_contact = step_constraints(nullptr, false);
    std::swap(constraints, free_contact);
    try
      {
        assemble(false, g);
      }
    catch (...)
      {
        std::swap(constraints, free_contact);
        residual = kept;
        throw;
      }
    std::swap(constraints, free_contact);
    const auto  &owned  = space.locally_owned_dofs();
    const auto  &pins   = active.constraints();
    const double du_max = du.linfty_norm();
    // a pull below 1e-8 of the load scale and a penetration below 1e-8 of the
    // largest increment are round-off of the Newton solve, not a change
    const double tol_pull = 1e-8 * force_scale, tol_in = 1e-8 * du_max;
    unsigned int released = 0, added = 0;
    for (std::size_t k = 0; k < contact_nodes.size(); ++k)
      {
        const auto &c  = contact_nodes[k];
        const auto  in = space.node_dof(c.node, c.axis);
        if (!owned.is_element(in) || pins.is_constrained(in) || free_contact.is_constrained(in) || mass(in) == 0)
          continue;
        if (contact_changes[k] >= 2) // changed twice in this step: held
          continue;
        if (contact_state(in) != 0.0)
          {
            // compressive: the wall pushes the node into the domain, r . n_out < 0
            if (residual(in) * c.sign > tol_pull)
              {
                contact_state(in) = 0.0;
                ++contact_changes[k];
                ++released;
              }
          }
        else if (du(in) * c.sign > tol_in && contact_gap(in) <= contact_gap_tolerance(c))
          {
            contact_state(in) = 1.0;
            ++contact_changes[k];
            ++added;
          }
      }
    residual = kept;
    contact_state.update_ghost_values();
    return {dealii::Utilities::MPI::sum(released, comm), dealii::Utilities::MPI::sum(added, comm)};
  }

  template <int dim>
  dealii::Tensor<1, dim>
  Solver<dim>::condition_increment(const unsigned int k, const double h) const
  {
    // v f integrated over [t, t + h] by the trapezoidal rule (exact for constant
    // and piecewise-linear time functions whose kinks fall on step ends)
    const auto  &st = prm.stages[current_stage];
    const auto  &pv = st.velocities[k];
    const double t0 = k < st.n_global_velocities ? 0.0 : stage_start_time; // stage loads: stage time
    return pv.velocity * (0.5 * (pv.function.value(time - t0) + pv.function.value(time + h - t0)) * h);
  }

  template <int dim>
  double
  Solver<dim>::prescribed_increment(const loads::PrescribedNodeDof &p, const double h) const
  {
    const unsigned int n_vel = n_velocities();
    if (p.condition < n_vel)
      return condition_increment(p.condition, h)[p.component];
    // a plate: its displacement history along its axis (absolute time; the
    // static ramp does not scale it), zero tangential increments (rough)
    const auto &plate = prm.rigid_plates[p.condition - n_vel];
    if (plate.control != loads::RigidPlate<dim>::Control::displacement || p.component != plate.axis)
      return 0.0;
    return plate.displacement_at(time + h) - plate.displacement_at(time);
  }

  template <int dim>
  void
  Solver<dim>::prescribed_reaction(const dealii::Tensor<1, dim> &g)
  {
    // the residual r = f_int - f_ext assembled without the prescribed lines: at
    // a prescribed DoF it is the force the node exerts on the material (the
    // same device as the contact reactions); the other DoFs keep theirs
    Vector kept(residual);
    auto   free_prescribed = step_constraints(nullptr, true, false);
    std::swap(constraints, free_prescribed);
    try
      {
        assemble(false, g);
      }
    catch (...)
      {
        std::swap(constraints, free_prescribed);
        residual = kept;
        throw;
      }
    std::swap(constraints, free_prescribed);
    const auto &owned = space.locally_owned_dofs();
    const auto &pins  = active.constraints();
    // the velocity conditions' sum per component, then each plate's per component
    const unsigned int                           n_vel = n_velocities();
    std::vector<double>                          f(dim * (1 + prm.rigid_plates.size()), 0.0);
    std::vector<dealii::types::global_dof_index> seen; // a node of two conditions counts once
    for (const auto &p : prescribed_dofs)
      {
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || pins.is_constrained(i) || free_prescribed.is_constrained(i) ||
            std::find(seen.begin(), seen.end(), i) != seen.end())
          continue;
        seen.push_back(i);
        const unsigned int slot = p.condition < n_vel ? 0 : 1 + p.condition - n_vel;
        f[slot * dim + p.component] += residual(i);
      }
    dealii::Utilities::MPI::sum(f, comm, f);
    for (unsigned int d = 0; d < dim; ++d)
      last.prescribed_force[d] = f[d];
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        plate_reaction[k][d] = f[(1 + k) * dim + d];
    residual = kept;
  }

  namespace
  {
    /// A singular tangent (a body free to move as a rigid body in a static
    /// analysis, a point set cut loose) gives a direct solve without error but
    /// a solution that does not solve the system: a failed step.
    void
    require_solved(const LinearSolveInfo &info)
    {
      if (!(info.relative_residual <= 1e-6))
        {
          std::ostringstream os;
          os << "the linear system is singular or nearly so (|b - A x| / |b| = " << info.relative_residual
             << " after the " << info.method
             << " solve): are rigid-body motions of every body prevented by boundary conditions?";
          throw NewtonFailure(os.str());
        }
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta()
  {
    return solve_for_delta(residual);
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_for_delta(const Vector &r)
  {
    const auto start = Clock::now();
    Vector     rhs(r);
    rhs *= -1.0;
    delta = 0;
    LinearSolveInfo info;
    try
      {
        info = solve_linear(tangent, delta, rhs, prm.linear, space.constant_modes());
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    ++n_solves;
    require_solved(info);
    return info;
  }

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_several(std::vector<Vector> &r)
  {
    // iterative methods: one solve_for_delta per right-hand side
    if (prm.linear.method != LinearSolverOptions::Method::direct)
      {
        LinearSolveInfo info;
        for (auto &x : r)
          {
            // a zero right-hand side (the first iteration of a step whose only
            // load is a plate's force: the free rows are in balance) has the
            // solution 0; a Krylov solver would stop with a breakdown on it
            if (x.linfty_norm() == 0)
              continue;
            const auto one = solve_for_delta(x);
            info.method    = one.method;
            info.iterations += one.iterations;
            info.relative_residual = std::max(info.relative_residual, one.relative_residual);
            x                      = delta;
          }
        return info;
      }
    // direct: one factorisation for all of them (solvers/linear_solver.h)
    const auto      start = Clock::now();
    LinearSolveInfo info;
    try
      {
        std::vector<Vector> b(r.size()), x;
        for (unsigned int k = 0; k < r.size(); ++k)
          {
            b[k].reinit(r[k], true);
            b[k] = r[k];
            b[k] *= -1.0;
          }
        info = solve_direct(tangent, x, b, prm.linear.direct_package);
        for (unsigned int k = 0; k < r.size(); ++k)
          r[k].copy_locally_owned_data_from(x[k]);
        info.method = "direct (" + prm.linear.direct_package + ", one factorisation for " + std::to_string(r.size()) +
                      " right-hand sides)";
      }
    catch (const std::exception &e)
      {
        throw NewtonFailure(std::string("linear solve failed: ") + e.what());
      }
    seconds_solve += seconds_since(start);
    n_solves += r.size();
    require_solved(info);
    return info;
  }

  template <int dim>
  void
  Solver<dim>::predict_prescribed(const double h, const dealii::Tensor<1, dim> &g)
  {
    // The first iterate of a step with prescribed DoFs: one linear solve at
    // Du = 0 with the prescribed increments as inhomogeneous constraints (the
    // lifting: rhs_F = -r_F - K_FP Du_P), so the free nodes follow the
    // prescribed ones at once instead of a cell next to them being crushed by
    // a predictor that moves only the prescribed nodes. The assembly moves
    // -A_ij g_j to the vector it builds, which here is the residual, whose
    // negative is the right-hand side: hence g = -Du_P.
    std::vector<double> minus_increment(prescribed_dofs.size());
    for (std::size_t k = 0; k < prescribed_dofs.size(); ++k)
      minus_increment[k] = -prescribed_increment(prescribed_dofs[k], h);
    // a force plate's DoFs are held here (Newton moves them as one from this iterate on)
    auto lifted = step_constraints(&minus_increment, true, true, true);
    std::swap(constraints, lifted);
    plates_held = true;
    try
      {
        // the out-of-balance force the prescribed increment creates: the scale
        // Newton's residual test measures against (after this solve the
        // residual is small, so its own first value is no scale)
        lifted_residual = assemble(true, g);
        solve_for_delta();
      }
    catch (...)
      {
        std::swap(constraints, lifted);
        plates_held = false;
        throw;
      }
    std::swap(constraints, lifted);
    plates_held = false;
    for (const auto &dofs : plate_owned)
      for (const auto i : dofs)
        delta[i] = 0.0;

    // Du: the solve's free values, the prescribed increments at the prescribed
    // DoFs of active nodes, 0 at the other constrained DoFs
    constraints.set_zero(delta);
    const auto         &pins       = active.constraints(); // inactive nodes: no mass, pinned to 0
    const auto         &owned      = space.locally_owned_dofs();
    const auto         &velocities = prm.stages[current_stage].velocities;
    std::vector<double> n_active(velocities.size() + prm.rigid_plates.size(), 0.0);
    for (const auto &p : prescribed_dofs)
      {
        const auto i = space.node_dof(p.node, p.component);
        if (!owned.is_element(i) || pins.is_constrained(i))
          continue;
        delta[i] = prescribed_increment(p, h);
        n_active[p.condition] += 1;
      }
    delta.compress(dealii::VectorOperation::insert);
    du = delta;
    du.update_ghost_values();
    // the nodes of a condition are fixed in space: once the material has left
    // their cells they carry no mass and the condition acts on nothing; say so
    // (once per condition) instead of letting a displacement control go slack
    dealii::Utilities::MPI::sum(n_active, comm, n_active);
    for (unsigned int k = 0; k < n_active.size(); ++k)
      if (n_active[k] == 0 && !idle_conditions[k] && (k < velocities.size() || !force_plate(k - velocities.size())))
        {
          idle_conditions[k] = 1;
          log() << "  WARNING: "
                << (k < velocities.size() ? velocities[k].where : prm.rigid_plates[k - velocities.size()].where)
                << " reaches no grid node next to material at t = " << time
                << " s (the prescribed nodes are fixed in space and the material has left their cells): "
                << "the condition has no effect from here on" << std::endl;
        }
  }

  template <int dim>
  void
  Solver<dim>::project_to_grid()
  {
    using L                                   = PropertyLayout<dim>;
    std::vector<MaterialPointSet<dim> *> sets = {&points};
    const auto                          &pins = active.constraints(); // inactive DoFs only: walls keep their mass
    mass                                      = 0;
    with_kernel([&](auto k) {
      with_components([&](auto nc) {
        transfer::assemble<dim, decltype(k), decltype(nc)::value>(sets, active, pins, transfer::NodalProjection<dim>{},
                                                                  nullptr, &mass);
      });
    });
    if (!dynamic())
      return;
    v_n = 0;
    a_n = 0;
    // mixed u-p: onto the displacement components of the u-p space (the
    // pressure components get no mass, hence no inertia)
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{L::velocity}, nullptr, &v_n);
        transfer::assemble<dim, K, n>(sets, active, pins, transfer::NodalProjection<dim>{acceleration_offset}, nullptr,
                                      &a_n);
      });
    });
    for (unsigned int i = 0; i < mass.locally_owned_size(); ++i)
      {
        const double m       = mass.local_element(i);
        v_n.local_element(i) = m > 0 ? v_n.local_element(i) / m : 0.0;
        a_n.local_element(i) = m > 0 ? a_n.local_element(i) / m : 0.0;
      }
  }

  template <int dim>
  void
  Solver<dim>::compute_cell_jbar()
  {
    cell_jbar.assign(grid.tria.n_active_cells(), 1.0);
    transfer::CellMeanJacobian<dim, shape::Q1Box<dim>> mean{grid, space, du, cell_jbar};
    transfer::for_each_active_cell(points, mean);
  }

  template <int dim>
  double
  Solver<dim>::assemble(const bool with_tangent, const dealii::Tensor<1, dim> &g)
  {
    const auto                            start = Clock::now();
    transfer::PointFailure                failure;
    transfer::UpdatedLagrangianForce<dim> force;
    force.materials      = &prm.materials;
    force.history_offset = PropertyLayout<dim>::history;
    force.gravity        = g;
    force.point_forces   = &point_forces;
    force.load_scale     = point_force_scale; // set with g by apply_loads_at
    force.tangent        = with_tangent;
    force.failure        = &failure;
    force.radius_offset  = radius_offset;
    if (prm.fbar)
      {
        compute_cell_jbar();
        force.jbar = &cell_jbar;
      }
    residual = 0;
    if (with_tangent)
      tangent = 0;
    if (prm.mixed_up)
      {
        transfer::MixedUpForce<dim> up;
        up.models         = &split_models;
        up.history_offset = force.history_offset;
        up.gravity        = g;
        up.point_forces   = &point_forces;
        up.load_scale     = force.load_scale;
        up.alpha          = prm.stabilisation;
        up.tangent        = with_tangent;
        up.failure        = &failure;
        with_kernel([&](auto k) {
          transfer::assemble<dim, decltype(k), dim + 1>({&points}, active, constraints, up,
                                                        with_tangent ? &tangent : nullptr, &residual, &du);
        });
      }
    else
      with_kernel([&](auto k) {
        transfer::assemble<dim, decltype(k), dim>({&points}, active, constraints, force,
                                                  with_tangent ? &tangent : nullptr, &residual, &du);
      });
    const bool any_failed = dealii::Utilities::MPI::max(failure.failed ? 1 : 0, comm) > 0;
    if (any_failed)
      throw NewtonFailure(failure.failed ? failure.what : "a material point on another rank failed");
    if (assembling_damping)
      return 0.0;
    if (dynamic() && prm.rayleigh_beta > 0)
      {
        // stiffness-proportional damping: r += beta_R K_n v^{n+1}(du) on the free DoFs and
        // tangent += beta_R gamma/(beta h) K_n (K_n held for the step: the tangent is exact)
        Vector v, Kv;
        space.reinit_vector(v);
        space.reinit_vector(Kv);
        const auto &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          v.local_element(k) = constraints.is_constrained(owned.nth_index_in_set(k))
                                 ? 0.0
                                 : newmark.velocity(du.local_element(k), v_n.local_element(k), a_n.local_element(k));
        damping_stiffness.vmult(Kv, v);
        for (unsigned int k = 0; k < v.locally_owned_size(); ++k)
          if (!constraints.is_constrained(owned.nth_index_in_set(k)))
            residual.local_element(k) += prm.rayleigh_beta * Kv.local_element(k);
        if (with_tangent)
          tangent.add(prm.rayleigh_beta * newmark.damping_coefficient(), damping_stiffness);
      }
    if (point_contact) // the penalty walls on the points (point_contact.h)
      point_contact->assemble(points, active, constraints, du, with_tangent ? &tangent : nullptr, residual);
    if (dynamic() && prm.consistent_mass)
      add_consistent_inertia(with_tangent);
    else if (dynamic())
      {
        // lumped inertia and mass-proportional damping at the nodes:
        // r_i += m_i (a_i + alpha v_i), tangent_ii += m_i (1/(beta h^2) + alpha gamma/(beta h))
        const double coef  = newmark.tangent_factors(prm.rayleigh_alpha, 0).mass;
        const auto  &owned = space.locally_owned_dofs();
        for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
          {
            const auto   i = owned.nth_index_in_set(k);
            const double m = mass.local_element(k);
            if (m == 0 || constraints.is_constrained(i))
              continue;
            const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
            residual.local_element(k) +=
              m * (newmark.acceleration(u, v, a) + prm.rayleigh_alpha * newmark.velocity(u, v, a));
            if (with_tangent)
              tangent.add(i, i, m * coef);
          }
        if (with_tangent)
          tangent.compress(dealii::VectorOperation::add);
      }
    seconds_assembly += seconds_since(start);
    ++n_assemblies;
    if (!any_force_plate() || plates_held)
      return residual.l2_norm();
    // force plates: their DoFs' equations are the plates' balances, one per
    // plate: sum_{i in P_k} r_i = F_k (the force the plate exerts on the
    // material). The sums are kept and the rows zeroed (the solve's right-hand
    // side there is 0); the norm Newton tests is that of the free rows and the
    // plates' out-of-balance forces.
    const unsigned int  n = prm.rigid_plates.size();
    std::vector<double> sums(n, 0.0);
    for (unsigned int k = 0; k < n; ++k)
      for (const auto i : plate_owned[k])
        {
          sums[k] += residual(i);
          residual(i) = 0.0;
        }
    dealii::Utilities::MPI::sum(sums, comm, sums);
    double norm2 = residual.norm_sqr();
    for (unsigned int k = 0; k < n; ++k)
      if (force_plate(k))
        {
          plate_sum[k] = sums[k];
          norm2 += (sums[k] - plate_target[k]) * (sums[k] - plate_target[k]);
        }
    return std::sqrt(norm2);
  }

  namespace
  {
    /// Zero the rows and columns of the global DoFs `dofs` (sorted, the same
    /// list on every rank) of a filled Trilinos matrix, keeping each row's
    /// diagonal: the matrix of the system with those DoFs prescribed
    /// (symmetric if A is). In place on Epetra's values (the pattern is kept).
    void
    zero_rows_and_columns(dealii::TrilinosWrappers::SparseMatrix             &A,
                          const std::vector<dealii::types::global_dof_index> &dofs)
    {
      auto                      &E    = const_cast<Epetra_CrsMatrix &>(A.trilinos_matrix());
      const Epetra_Map          &rows = E.RowMap(), &cols = E.ColMap();
      std::vector<unsigned char> col_hit(E.NumMyCols(), 0);
      for (const auto g : dofs)
        {
          const int l = cols.LID(static_cast<int>(g));
          if (l >= 0)
            col_hit[l] = 1;
        }
      for (int r = 0; r < E.NumMyRows(); ++r)
        {
          int     n       = 0;
          double *values  = nullptr;
          int    *indices = nullptr;
          E.ExtractMyRowView(r, n, values, indices);
          const int  gid = rows.GID(r);
          const bool hit = std::binary_search(dofs.begin(), dofs.end(), dealii::types::global_dof_index(gid));
          for (int j = 0; j < n; ++j)
            if ((hit && cols.GID(indices[j]) != gid) || (!hit && col_hit[indices[j]]))
              values[j] = 0.0;
        }
      // values changed behind Epetra's back: drop its cached norms
      E.SumIntoMyValues(0, 0, nullptr, nullptr);
    }

    /// Solve the small dense system M c = b (n x n, row-major) by Gaussian
    /// elimination with partial pivoting; the same arithmetic on every rank.
    std::vector<double>
    solve_dense(std::vector<double> M, std::vector<double> b)
    {
      const unsigned int n = b.size();
      for (unsigned int k = 0; k < n; ++k)
        {
          unsigned int p = k;
          for (unsigned int i = k + 1; i < n; ++i)
            if (std::abs(M[i * n + k]) > std::abs(M[p * n + k]))
              p = i;
          for (unsigned int j = 0; j < n; ++j)
            std::swap(M[k * n + j], M[p * n + j]);
          std::swap(b[k], b[p]);
          for (unsigned int i = k + 1; i < n; ++i)
            {
              const double f = M[i * n + k] / M[k * n + k];
              for (unsigned int j = k; j < n; ++j)
                M[i * n + j] -= f * M[k * n + j];
              b[i] -= f * b[k];
            }
        }
      std::vector<double> c(n, 0.0);
      for (unsigned int k = n; k-- > 0;)
        {
          double s = b[k];
          for (unsigned int j = k + 1; j < n; ++j)
            s -= M[k * n + j] * c[j];
          c[k] = s / M[k * n + k];
        }
      return c;
    }
  } // namespace

  template <int dim>
  LinearSolveInfo
  Solver<dim>::solve_with_plates()
  {
    // The plates' DoFs condensed by superposition (docs/implicit.md, "Rigid
    // plate"): exact, the same solution as a master-slave line u_i = u_m per
    // plate node, without couplings of the master in the sparsity or the
    // master as a ghost on every rank.
    const auto                start = Clock::now();
    const unsigned int        n_all = prm.rigid_plates.size();
    std::vector<unsigned int> ks; // the force plates
    for (unsigned int k = 0; k < n_all; ++k)
      if (force_plate(k))
        ks.push_back(k);
    const unsigned int  n = ks.size();
    std::vector<Vector> e(n), v(n), w(n), z(n);
    std::vector<double> size(n, 0.0);
    for (unsigned int a = 0; a < n; ++a)
      {
        for (Vector *x : {&e[a], &v[a], &w[a], &z[a]})
          space.reinit_vector(*x);
        for (const auto i : plate_owned[ks[a]])
          e[a][i] = 1.0;
        size[a] = plate_owned[ks[a]].size();
        tangent.vmult(v[a], e[a]);  // K e: the plate's column sum (K_FP 1 in the free rows)
        tangent.Tvmult(w[a], e[a]); // K^T e: its row sum, sum_{i in P} K_ij
      }
    dealii::Utilities::MPI::sum(size, comm, size);
    zero_rows_and_columns(tangent, plate_all);
    const auto zero_plate_entries = [&](Vector &x) {
      for (const auto &dofs : plate_owned)
        for (const auto i : dofs)
          x[i] = 0.0;
    };
    // z_0 (the plates held) and z_a (the response to a unit displacement of
    // plate a), from one factorisation with the direct solver
    std::vector<Vector> x(1 + n);
    x[0] = residual; // its plate rows are 0 (assemble)
    for (unsigned int a = 0; a < n; ++a)
      {
        x[1 + a] = v[a];
        zero_plate_entries(x[1 + a]);
      }
    seconds_plates += seconds_since(start);
    const auto      start_solve = Clock::now();
    LinearSolveInfo info        = solve_several(x);
    const double    t_solve     = seconds_since(start_solve);
    const auto      start2      = Clock::now();
    Vector          z0(x[0]);
    zero_plate_entries(z0);
    for (unsigned int a = 0; a < n; ++a)
      {
        z[a] = x[1 + a];
        zero_plate_entries(z[a]);
      }
    seconds_plates_solve += t_solve;
    // the linearised balance of plate a: sum_{i in P_a} (r + K delta)_i = F_a,
    // delta = z_0 + sum_b c_b (z_b + e_b): sum_b (w_a . z_b + e_a . v_b) c_b = F_a - R_a - w_a . z_0
    std::vector<double> M(n * n), b(n);
    for (unsigned int a = 0; a < n; ++a)
      {
        const auto k = ks[a];
        if (size[a] == 0)
          {
            // the plate acts on no free node next to material: its force has
            // nothing to act on (said once), its increment is 0
            for (unsigned int c = 0; c < n; ++c)
              M[a * n + c] = c == a ? 1.0 : 0.0;
            b[a] = 0;
            if (!idle_plates[k])
              {
                idle_plates[k] = 1;
                log() << "  WARNING: " << prm.rigid_plates[k].where
                      << " reaches no free grid node next to material at t = " << time
                      << " s: its force acts on nothing from here on" << std::endl;
              }
            continue;
          }
        for (unsigned int c = 0; c < n; ++c)
          M[a * n + c] = (w[a] * z[c]) + (e[a] * v[c]);
        b[a] = plate_target[k] - plate_sum[k] - (w[a] * z0);
      }
    const std::vector<double> c = solve_dense(M, b);
    delta                       = z0;
    for (unsigned int a = 0; a < n; ++a)
      {
        delta.add(c[a], z[a]);
        plate_c[ks[a]] = c[a];
        for (const auto i : plate_owned[ks[a]])
          delta[i] = c[a]; // exactly c: the plate's nodes move as one
      }
    seconds_plates += seconds_since(start2);
    return info;
  }

  template <int dim>
  void
  Solver<dim>::add_consistent_inertia(const bool with_tangent)
  {
    // The inertia and damping with the consistent mass: r += M (a + alpha_R v),
    // tangent += (1/(beta h^2) + alpha_R gamma/(beta h)) M. As with the lumped
    // mass, only the free DoFs carry inertia: w = 0 at every DoF constrained in
    // this assembly (walls, held contact nodes, prescribed and inactive nodes),
    // so a constrained node neither feels nor exerts an inertial force.
    const auto  &owned = space.locally_owned_dofs();
    const double alpha = prm.rayleigh_alpha;
    for (unsigned int k = 0; k < inertia_field.locally_owned_size(); ++k)
      {
        const auto i = owned.nth_index_in_set(k);
        if (mass.local_element(k) == 0 || constraints.is_constrained(i))
          {
            inertia_field.local_element(k) = 0.0;
            continue;
          }
        const double u = du.local_element(k), v = v_n.local_element(k), a = a_n.local_element(k);
        inertia_field.local_element(k) = newmark.acceleration(u, v, a) + alpha * newmark.velocity(u, v, a);
      }
    inertia_field.update_ghost_values();
    const double coef = newmark.tangent_factors(alpha, 0).mass;
    // The matrix and the vector go through the constraints in one call unless
    // the constraints are inhomogeneous (the lifted predictor of prescribed
    // nodes): there the combined call would move -coef M_ij g_j to the residual,
    // an inertia of the prescribed nodes that the residual (w = 0 there) does not have.
    with_kernel([&](auto k) {
      using K = decltype(k);
      with_components([&](auto nc) {
        constexpr unsigned int n = decltype(nc)::value;
        if (with_tangent && !constraints.has_inhomogeneities())
          transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, true>{coef},
                                        &tangent, &residual, &inertia_field);
        else
          {
            if (with_tangent)
              transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, true, false>{coef},
                                            &tangent, nullptr);
            transfer::assemble<dim, K, n>({&points}, active, constraints, ConsistentInertia<dim, false, true>{coef},
                                          nullptr, &residual, &inertia_field);
          }
      });
    });
  }

  template <int dim>
  void
  Solver<dim>::predict_pressure()
  {
    // Eq. 5.20: p_i = sum_p N_i m_p p_p / sum_p N_i m_p (residual and delta as scratch)
    const auto &pins = active.constraints();
    residual         = 0;
    delta            = 0;
    with_kernel([&](auto k) {
      using K = decltype(k);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, true}, nullptr, &residual);
      transfer::assemble<dim, K, dim + 1>({&points}, active, pins,
                                          transfer::PressureProjection<dim>{pressure_offset, false}, nullptr, &delta);
    });
    for (unsigned int k = 0; k < du.locally_owned_size(); ++k)
      if (space.component(k) == dim && delta.local_element(k) > 0)
        du.local_element(k) = residual.local_element(k) / delta.local_element(k);
    du.update_ghost_values();
    delta = 0;
  }

  template <int dim>
  void
  Solver<dim>::nodal_acceleration(Vector &a) const
  {
    for (unsigned int k = 0; k < a.locally_owned_size(); ++k)
      a.local_element(k) = mass.local_element(k) > 0
                             ? newmark.acceleration(du.local_element(k), v_n.local_element(k), a_n.local_element(k))
                             : 0.0;
    a.update_ghost_values();
  }

  template <int dim>
  void
  Solver<dim>::assemble_damping_stiffness(const dealii::Tensor<1, dim> &g)
  {
    const Vector saved(du);
    du = 0;
    du.update_ghost_values();
    assembling_damping = true;
    try
      {
        assemble(true, g);
      }
    catch (...)
      {
        assembling_damping = false;
        throw;
      }
    assembling_damping = false;
    damping_stiffness.copy_from(tangent);
    du = saved;
    du.update_ghost_values();
  }

  template <int dim>
  StepOutcome
  Solver<dim>::advance_by(const double h)
  {
    newmark.set_time_step(h);
    if (point_contact) // a footing's base to where it is at the step's start and end
      point_contact->set_time(time, time + h);
    prepare_step();
    const dealii::Tensor<1, dim> g = apply_loads_at(time + h);
    if (dynamic() && prm.rayleigh_beta > 0)
      assemble_damping_stiffness(g);
    // the external force scale |f_ext| (lumped nodal masses times g)
    double f2 = 0;
    for (unsigned int k = 0; k < mass.locally_owned_size(); ++k)
      {
        const unsigned int c = space.component(k);
        if (c < dim)
          f2 += std::pow(mass.local_element(k) * g[c], 2);
      }
    double f_ext = std::sqrt(dealii::Utilities::MPI::sum(f2, comm));
    if (point_forces.any())
      {
        // the scale of gravity plus tractions: |sum_p N_i (m_p g + lambda f_p)|
        transfer::ExternalForce<dim> load{g, &point_forces, point_force_scale};
        residual = 0;
        with_kernel([&](auto k) {
          with_components([&](auto nc) {
            transfer::assemble<dim, decltype(k), decltype(nc)::value>({&points}, active, active.constraints(), load,
                                                                      nullptr, &residual);
          });
        });
        f_ext = residual.l2_norm();
      }
    // the plates' forces at t + h (their own time functions) join the scale
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        plate_target[k] = force_plate(k) ? prm.rigid_plates[k].force_at(time + h) : 0.0;
        plate_step[k]   = 0.0;
        plate_c[k]      = 0.0;
        f_ext           = std::sqrt(f_ext * f_ext + plate_target[k] * plate_target[k]);
      }

    du = 0;
    du.update_ghost_values();
    lifted_residual = 0;
    // collective: the predictor assembles and solves on every rank, also on a
    // rank none of whose nodes is prescribed (else the ranks part ways and the
    // run hangs in the next collective)
    if (dealii::Utilities::MPI::logical_or(!prescribed_dofs.empty(), comm))
      {
        try
          {
            predict_prescribed(h, g);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the prescribed-displacement predictor failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
      }
    if (prm.mixed_up)
      predict_pressure();
    unsigned int  linear_iterations     = 0;
    double        worst_linear_residual = 0;
    NewtonProblem problem;
    problem.assemble = [&](const bool with_tangent) { return assemble(with_tangent, g); };
    problem.solve    = [&]() {
      const LinearSolveInfo info = any_force_plate() ? solve_with_plates() : solve_for_delta();
      linear_iterations += info.iterations;
      worst_linear_residual = std::max(worst_linear_residual, info.relative_residual);
      constraints.set_zero(delta);
      delta.update_ghost_values();
      return delta.l2_norm();
    };
    problem.apply = [&](const double alpha) {
      du.add(alpha, delta);
      du.update_ghost_values();
      for (unsigned int k = 0; k < plate_step.size(); ++k)
        plate_step[k] += alpha * plate_c[k];
    };
    problem.step_increment_norm = [&]() { return du.l2_norm(); };
    problem.residual_reference  = [&]() { return std::max(f_ext, lifted_residual); };
    // Newton, then (contact walls) the active set from the converged state's
    // reactions and penetrations; a change re-solves from there
    NewtonResult       result;
    unsigned int       iterations = 0, passes = 0, released = 0, added = 0;
    std::ostringstream pass_log;
    const bool         any_contact = dealii::Utilities::MPI::sum(contact_nodes.size(), comm) > 0;
    for (;;)
      {
        result = NewtonSolver(prm.newton).solve(problem);
        iterations += result.iterations;
        ++passes;
        if (!result.converged || !any_contact)
          break;
        std::pair<unsigned int, unsigned int> changed;
        try
          {
            changed = update_contact(g, f_ext);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the contact reactions failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
        released += changed.first;
        added += changed.second;
        if (changed.first + changed.second == 0)
          break;
        pass_log << " [pass " << passes << ": " << changed.first << " released, " << changed.second << " in contact]";
        if (passes >= prm.contact_passes)
          {
            // the last solution keeps the previous set; the new one starts the next step
            log() << "  WARNING: step " << step_number + 1 << " (t = " << time + h
                  << "): the contact active set still changed after " << passes
                  << " passes (contact passes); the step keeps the last solve" << std::endl;
            break;
          }
        constraints = step_constraints();
        if (any_force_plate())
          find_plate_dofs();
        constraints.set_zero(du);
        du.update_ghost_values();
      }
    result.iterations = iterations;

    last                   = StepReport();
    last.iterations        = result.iterations;
    last.contact_passes    = passes;
    last.contact_released  = released;
    last.contact_added     = added;
    last.linear_iterations = linear_iterations;
    last.observed_order    = result.observed_order;
    {
      // the order seen in the increments |du_k| (the error of iterate k-1): the
      // residual norm of a stiff structure mixes stiff and soft modes and hits
      // its round-off floor first (docs/implicit.md); increments at round-off
      // level (below 1e-13 |Du|) are left out
      std::vector<double> inc;
      for (unsigned int k = 1; k < result.history.size(); ++k)
        if (result.history[k].increment > 1e-13 * du.l2_norm())
          inc.push_back(result.history[k].increment);
      last.increment_order = observed_order(inc);
    }
    if (!result.history.empty())
      {
        last.residual_first = result.history.front().residual;
        last.residual_last  = result.history.back().residual;
      }
    std::ostringstream hist;
    hist << std::setprecision(3);
    for (unsigned int k = 0; k < result.history.size(); ++k)
      hist << (k ? " " : "") << result.history[k].residual;
    hist << "; |du|";
    for (unsigned int k = 1; k < result.history.size(); ++k)
      hist << " " << result.history[k].increment;
    last.history = hist.str();
    total_iterations += result.iterations;
    total_linear_iterations += linear_iterations;
    total_contact_passes += passes;
    total_contact_released += released;
    total_contact_added += added;
    if (any_contact)
      {
        unsigned int n = 0;
        for (const auto &c : contact_nodes)
          {
            const auto in = space.node_dof(c.node, c.axis);
            if (space.locally_owned_dofs().is_element(in) && contact_state(in) != 0.0 && mass(in) > 0 &&
                !active.constraints().is_constrained(in))
              ++n;
          }
        last.contact_nodes = dealii::Utilities::MPI::sum(n, comm);
      }
    if (!result.converged)
      {
        log() << "  step " << step_number + 1 << " (t = " << time + h << "): Newton " << to_string(result.status)
              << " after " << result.iterations << " iterations (|r|: " << last.history << "); " << result.message
              << std::endl;
        return StepOutcome::cut_back;
      }

    if (any_velocity_condition() || any_plate_reaction()) // collective: the same on every rank
      {
        try
          {
            prescribed_reaction(g);
          }
        catch (const NewtonFailure &e)
          {
            log() << "  step " << step_number + 1 << " (t = " << time + h
                  << "): the reactions of the prescribed nodes failed: " << e.what() << std::endl;
            return StepOutcome::cut_back;
          }
      }
    for (unsigned int k = 0; k < region_shift.size(); ++k)
      region_shift[k] += condition_increment(k, h);
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &plate = prm.rigid_plates[k];
        plate_displacement[k] +=
          force_plate(k) ? plate_step[k] : plate.displacement_at(time + h) - plate.displacement_at(time);
      }

    if (point_contact)
      {
        // the stick anchors and contact flags of the converged increment
        last.point_contact = point_contact->commit(points, space, du);
        total_point_contacts += last.point_contact.new_contacts;
        total_point_releases += last.point_contact.released;
        total_point_slip_steps += last.point_contact.slipping;
        worst_penetration_ratio = std::max(worst_penetration_ratio, last.point_contact.max_penetration_ratio);
      }
    // convective phase
    const auto start = Clock::now();
    if (dynamic())
      nodal_acceleration(a_new);
    transfer::PointFailure failure;
    if (prm.fbar)
      compute_cell_jbar(); // of the converged du
    with_kernel([&](auto k) {
      transfer::CommitUpdatedLagrangian<dim, decltype(k)> commit(points, space, du, dynamic() ? &a_new : nullptr,
                                                                 prm.materials, acceleration_offset, h, newmark.gamma(),
                                                                 failure, pressure_offset, radius_offset);
      if (prm.fbar)
        commit.jbar = &cell_jbar;
      transfer::for_each_active_cell(points, commit);
    });
    if (dealii::Utilities::MPI::max(failure.failed ? 1 : 0, comm) > 0)
      throw InstabilityError("the constitutive update of the converged step failed: " +
                             (failure.failed ? failure.what : std::string("on another rank")));
    points.relocate();
    seconds_commit += seconds_since(start);
    log() << "  step " << step_number + 1 << " t = " << std::setprecision(6) << time + h << ": " << result.iterations
          << " Newton iterations, |r| " << last.history << ", order (|r|) " << std::setprecision(3)
          << result.observed_order << ", (|du|) " << last.increment_order << ", " << linear_iterations
          << " linear iterations (largest |b - A x|/|b| " << worst_linear_residual << ")";
    if (point_contact)
      log() << "; contact (points): " << last.point_contact.in_contact << " in contact (" << last.point_contact.slipping
            << " slipping, " << last.point_contact.new_contacts << " new, " << last.point_contact.released
            << " released), normal force " << last.point_contact.normal_force << ", largest penetration / r_p "
            << last.point_contact.max_penetration_ratio;
    if (prm.footing.enabled)
      log() << "; footing force " << last.point_contact.footing_force;
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      log() << "; plate " << k << " displacement " << std::setprecision(8) << plate_displacement[k] << ", force "
            << (force_plate(k) ? plate_sum[k] : plate_reaction[k][prm.rigid_plates[k].axis]) << std::setprecision(6);
    if (any_contact)
      log() << "; contact: " << passes << " pass(es), " << released << " released, " << added << " in contact again, "
            << last.contact_nodes << " nodes in contact" << pass_log.str();
    log() << std::endl;
    return StepOutcome::done;
  }

  template <int dim>
  double
  Solver<dim>::tangent_error(const double h, const double scale, const double eps, const double pressure_scale)
  {
    newmark.set_time_step(h);
    prepare_step();
    const dealii::Tensor<1, dim> g = apply_loads_at(time + h);
    if (dynamic() && prm.rayleigh_beta > 0)
      assemble_damping_stiffness(g);
    const auto &owned = space.locally_owned_dofs();
    Vector      v;
    space.reinit_vector(v);
    for (unsigned int k = 0; k < du.locally_owned_size(); ++k)
      {
        const auto i = owned.nth_index_in_set(k);
        // deterministic, rank-independent values from the global index
        du.local_element(k) =
          (space.component(k) == dim ? pressure_scale : 1.0) * scale * std::sin(1.3 * double(i) + 0.7);
        v.local_element(k) = std::cos(2.1 * double(i) + 0.3);
      }
    constraints.set_zero(du);
    constraints.set_zero(v);
    const Vector u0(du);
    du.update_ghost_values();
    assemble(true, g);
    Vector Kv;
    space.reinit_vector(Kv);
    tangent.vmult(Kv, v);
    Vector r_plus, fd;
    space.reinit_vector(r_plus);
    space.reinit_vector(fd);
    du = u0;
    du.add(eps, v);
    du.update_ghost_values();
    assemble(false, g);
    r_plus = residual;
    du     = u0;
    du.add(-eps, v);
    du.update_ghost_values();
    assemble(false, g);
    fd = r_plus;
    fd.add(-1.0, residual);
    fd *= 1.0 / (2 * eps);
    fd.add(-1.0, Kv);
    constraints.set_zero(fd); // constrained rows hold the matrix's diagonal, not the residual's derivative
    Vector Kv_free(Kv);
    constraints.set_zero(Kv_free);
    du = 0;
    // per block (displacement rows, pressure rows): the pressure rows of u-p
    // are divided by K and are orders of magnitude smaller than the force rows,
    // so one norm over both would hide an error in them
    double sums[4] = {0, 0, 0, 0}; // |error|^2, |Kv|^2 of u rows; of p rows
    for (unsigned int k = 0; k < fd.locally_owned_size(); ++k)
      {
        const unsigned int b = space.component(k) < dim ? 0 : 2;
        sums[b] += fd.local_element(k) * fd.local_element(k);
        sums[b + 1] += Kv_free.local_element(k) * Kv_free.local_element(k);
      }
    dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(sums, 4), comm, dealii::ArrayView<double>(sums, 4));
    double error = std::sqrt(sums[0] / sums[1]);
    if (prm.mixed_up)
      error = std::max(error, std::sqrt(sums[2] / sums[3]));
    return error;
  }

  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    bool bad = false;
    using L  = PropertyLayout<dim>;
    for (const auto &pt : points.handler)
      {
        const auto P = pt.get_properties();
        for (unsigned int k = 0; k < L::history; ++k)
          bad = bad || !std::isfinite(P[k]);
      }
    if (dealii::Utilities::MPI::max(bad ? 1 : 0, comm) > 0)
      throw InstabilityError("a material point holds a non-finite value after step " + std::to_string(step_number));
  }

  template <int dim>
  double
  Solver<dim>::kinetic_energy() const
  {
    using L  = PropertyLayout<dim>;
    double e = 0;
    for (const auto &pt : points.handler)
      {
        const auto P = pt.get_properties();
        for (unsigned int d = 0; d < dim; ++d)
          e += 0.5 * P[L::mass] * P[L::velocity + d] * P[L::velocity + d];
      }
    return dealii::Utilities::MPI::sum(e, comm);
  }

  template <int dim>
  void
  Solver<dim>::describe(std::ostream &out) const
  {
    out << "  grid: " << grid.tria.n_global_active_cells() << " cells; " << n_points() << " material points"
        << std::endl;
    out << "  analysis: " << (dynamic() ? "dynamic (Newmark gamma = " : "static (")
        << (dynamic() ? std::to_string(prm.gamma) + ", beta = " + std::to_string(prm.beta) +
                          (prm.consistent_mass ? ", consistent mass" : ", lumped mass") +
                          (prm.rayleigh_alpha > 0 ? ", Rayleigh alpha = " + std::to_string(prm.rayleigh_alpha) : "") +
                          (prm.rayleigh_beta > 0 ? ", Rayleigh beta = " + std::to_string(prm.rayleigh_beta) : "")
                      : std::string(prm.ramp_loads ? "loads ramped over the end time" : "full loads"))
        << "), time step " << dt << std::endl;
    out << "  formulation: "
        << (prm.mixed_up ? std::string(prm.bspline() ? "mixed u-p (equal-order B-splines" : "mixed u-p (Q1-Q1") +
                             ", PPP stabilisation alpha = " + std::to_string(prm.stabilisation) + ")"
                         : std::string("irreducible (displacement)"))
        << (prm.bspline() ? ", quadratic B-splines" : ", linear shape functions")
        << (prm.tractions.empty() ? "" : ", " + std::to_string(prm.tractions.size()) + " traction(s) (dead loads)")
        << (prm.velocities.empty()
              ? ""
              : ", " + std::to_string(prm.velocities.size()) + " prescribed nodal velocity condition(s)")
        << (dim == 3           ? std::string()
            : prm.axisymmetric ? ", axisymmetric (x = radius)"
                               : ", plane strain")
        << std::endl;
    if (!prm.contact_ids.empty())
      {
        out << "  contact walls (unilateral, "
            << (prm.contact_no_slip   ? std::string("no slip")
                : prm.contact_mu == 0 ? std::string("frictionless")
                                      : "Coulomb mu = " + std::to_string(prm.contact_mu))
            << "): boundary";
        for (const auto id : prm.contact_ids)
          out << " " << id;
        if (point_contact)
          out << "; on the material points: penalty k = " << prm.contact_penalty
              << " x M V_p / h^2, point extent V_p^(1/dim)/2" << std::endl;
        else
          out << "; at most " << prm.contact_passes << " active-set passes per step" << std::endl;
      }
    if (prm.footing.enabled)
      {
        const auto &f    = prm.footing;
        const char *ax[] = {"x", "y", "z"};
        out << "  rigid footing on the points: base " << ax[f.axis] << " = " << f.level << " + " << f.velocity
            << " t, span";
        for (unsigned int k = 0; k + 1 < dim; ++k)
          out << " [" << f.lower[k] << ", " << f.upper[k] << "]";
        out << ", " << (std::isinf(f.friction) ? "rough (no slip)" : "smooth") << ", penalty k = " << f.penalty
            << " x M V_p / h^2" << std::endl;
      }
    out << "  Newton: " << to_string(prm.newton.criterion) << " test, residual relative "
        << prm.newton.residual_relative << ", absolute " << prm.newton.residual_absolute << ", at most "
        << prm.newton.max_iterations << " iterations; linear solver "
        << (prm.linear.method == LinearSolverOptions::Method::direct   ? "direct (" + prm.linear.direct_package + ")"
            : prm.linear.method == LinearSolverOptions::Method::cg_amg ? std::string("CG + ML AMG")
                                                                       : std::string("GMRES + ML AMG"))
        << std::endl;
  }

  template <int dim>
  double
  Solver<dim>::begin_stage(const unsigned int k, const bool, const bool resumed)
  {
    current_stage = k;
    if (!resumed) // a restart continues with the checkpointed stage start and step
      {
        stage_start_time = time;
        dt               = prm.stage_time_steps[k];
      }
    enter_stage(k);
    if (!prm.staged)
      return prm.end_time;
    const auto        &st = prm.stages[k];
    std::ostringstream os;
    os << "  stage " << k << " '" << st.name << "': t = " << stage_start_time << " s, duration " << st.duration
       << " s, dt = " << dt << " s, gravity " << st.gravity << ", " << st.boundary_conditions.size()
       << " fixed/roller wall(s)";
    const unsigned int own = st.tractions.size() - st.n_global_tractions;
    if (!st.tractions.empty())
      os << ", " << st.tractions.size() << " traction(s) (" << own << " of this stage)";
    if (!st.velocities.empty())
      os << ", " << st.velocities.size() << " velocity condition(s)";
    log() << os.str() << std::endl;
    return stage_start_time + st.duration;
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    std::vector<std::string> c    = {"newton_iterations", "residual_first",    "residual_last", "newton_order",
                                     "increment_order",   "linear_iterations", "load_factor",   "kinetic_energy"};
    const char              *ax[] = {"x", "y", "z"};
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("centre_of_mass_") + ax[d]);
    if (point_contact)
      for (const char *n : {"contact_points", "contact_slipping", "contact_normal_force", "contact_tangential_force"})
        c.push_back(n);
    if (prm.footing.enabled)
      for (const char *n : {"footing_level", "footing_force", "footing_points_behind"})
        c.push_back(n);
    if (any_velocity_condition())
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(std::string("prescribed_force_") + ax[d]);
    for (const auto &n : loads::rigid_plate_series_columns(prm.rigid_plates))
      c.push_back(n);
    balance.add_series_column(c);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool after_step)
  {
    const double        ke = kinetic_energy();
    std::vector<double> v  = {0, 0, 0, 0, 0, 0, load_factor(time), ke};
    if (after_step)
      v = {double(last.iterations), last.residual_first,
           last.residual_last,      last.observed_order,
           last.increment_order,    double(last.linear_iterations),
           load_factor(time),       ke};
    // centre of mass (mass-weighted mean position)
    std::vector<double> sums(dim + 1, 0.0);
    for (const auto &pt : points.handler)
      {
        const double m = pt.get_properties()[PropertyLayout<dim>::mass];
        for (unsigned int d = 0; d < dim; ++d)
          sums[d] += m * pt.get_location()[d];
        sums[dim] += m;
      }
    dealii::Utilities::MPI::sum(sums, comm, sums);
    for (unsigned int d = 0; d < dim; ++d)
      v.push_back(sums[d] / sums[dim]);
    if (point_contact)
      {
        const auto &s = last.point_contact; // zeros before the first step
        const bool  a = after_step;
        for (const double x : {double(s.in_contact), double(s.slipping), s.normal_force, s.tangential_force})
          v.push_back(a ? x : 0.0);
      }
    if (prm.footing.enabled)
      {
        v.push_back(prm.footing.level + prm.footing.velocity * time);
        v.push_back(after_step ? last.point_contact.footing_force : 0.0);
        v.push_back(after_step ? double(last.point_contact.behind_footing) : 0.0);
      }
    if (any_velocity_condition())
      for (unsigned int d = 0; d < dim; ++d)
        v.push_back(after_step ? last.prescribed_force[d] : 0.0);
    // the plates (rigid_plate_series_columns): displacement, the force on the
    // material along the axis (force control: F(t); displacement control: the
    // reaction), the tangential reaction's magnitude (rough)
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        const auto &plate = prm.rigid_plates[k];
        v.push_back(plate_displacement[k]);
        v.push_back((force_plate(k) ? plate.force_at(time)
                     : after_step   ? plate_reaction[k][plate.axis]
                                    : 0.0) +
                    0.0); // no -0
        if (plate.rough)
          {
            double t2 = 0;
            for (unsigned int d = 0; d < dim; ++d)
              if (d != plate.axis)
                t2 += plate_reaction[k][d] * plate_reaction[k][d];
            v.push_back(after_step ? std::sqrt(t2) : 0.0);
          }
      }
    balance.add_series_value(v);
    return v;
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    write_point_vtu(points, prm.output_directory, "particles", counter, time, pvd_records, comm);
  }

  // ---------------------------------------------------------------- checkpoints
  // The state between two steps is the points (with their accelerations, Eq.
  // 2.16), the loop's state and the Newton totals of the summary: the grid is
  // rebuilt from the points every step. Same rank count: bitwise continuation.
  namespace
  {
    const char *const checkpoint_format  = "talus-implicit-checkpoint";
    const int         checkpoint_version = 1;
  } // namespace

  template <int dim>
  std::string
  Solver<dim>::write_checkpoint()
  {
    return write_checkpoint_file(
      prm, *this, checkpoint_format, checkpoint_version, scene_signature(prm, points.layout.n_properties()), comm,
      [&](io::H5File &f) {
        f.set_attribute("newton iterations", std::int64_t(total_iterations));
        f.set_attribute("linear iterations", std::int64_t(total_linear_iterations));
        f.set_attribute("cut-backs", std::int64_t(cut_backs));
        for (unsigned int k = 0; k < plate_displacement.size(); ++k)
          {
            // the plate's state, and its last reaction for the series
            f.set_attribute("plate " + std::to_string(k) + " displacement", plate_displacement[k]);
            for (unsigned int d = 0; d < dim; ++d)
              f.set_attribute("plate " + std::to_string(k) + " reaction " + std::to_string(d), plate_reaction[k][d]);
          }
        write_points(f, points);
        write_pvd_times(f, "output/pvd", pvd_records);
        balance.write(f); // the partition of the last rebalance
      });
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      io::write_pvd(prm.output_directory + "/particles.pvd", pvd_records);
  }

  template <int dim>
  bool
  Solver<dim>::restore_checkpoint()
  {
    const auto fp = open_checkpoint_to_restore(prm, *this, checkpoint_format, checkpoint_version,
                                               scene_signature(prm, points.layout.n_properties()), comm);
    if (!fp)
      return false;
    total_iterations        = fp->get_int("newton iterations");
    total_linear_iterations = fp->get_int("linear iterations");
    cut_backs               = fp->get_int("cut-backs");
    for (unsigned int k = 0; k < plate_displacement.size(); ++k)
      {
        plate_displacement[k] = fp->get_double("plate " + std::to_string(k) + " displacement");
        for (unsigned int d = 0; d < dim; ++d)
          plate_reaction[k][d] = fp->get_double("plate " + std::to_string(k) + " reaction " + std::to_string(d));
      }
    balance.restore(*fp); // same ranks: the saved partition, before the points go in
    read_points(*fp, points, grid, "checkpoint " + fp->path());
    pvd_records = read_pvd_records(*fp, "output/pvd", "particles");
    return true;
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &)
  {
    if (prm.final_particles_csv)
      write_final_points_csv(points, prm.output_directory, comm);
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &t)
  {
    log() << "done: " << step_number << " steps, " << n_points() << " particles, wall " << std::setprecision(4)
          << t.total << " s; Newton iterations " << total_iterations << " (cut-backs " << cut_backs
          << "), linear iterations " << total_linear_iterations << balance.summary() << std::endl;
    if (point_contact)
      log() << "  contact on the points (walls, footing): " << total_point_contacts << " points came into contact, "
            << total_point_releases << " left it, " << total_point_slip_steps
            << " point-steps slipping; largest penetration / r_p " << worst_penetration_ratio << std::endl;
    else if (!prm.contact_ids.empty())
      log() << "  contact walls: " << total_contact_passes << " Newton solves (active-set passes), "
            << total_contact_released << " node releases, " << total_contact_added << " nodes put in contact, "
            << gap_releases << " nodes released because the material left the wall" << std::endl;
    log() << "  breakdown [s]: assembly " << seconds_assembly << " (" << n_assemblies << "), linear solve "
          << seconds_solve << " (" << n_solves << "), convective phase " << seconds_commit << ", output " << t.output
          << std::endl;
    if (any_force_plate())
      log() << "  rigid plates: the Newton solves " << seconds_plates_solve
            << " s (1 + number of force plates right-hand sides each, within the linear solve above), the products "
               "K e, K^T e, the row and column zeroing and the combination "
            << seconds_plates << " s" << std::endl;
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>);
  }

  TALUS_INSTANTIATE_FORMULATION(class);
} // namespace talus::implicit_mpm
