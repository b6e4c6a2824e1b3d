#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/damping.h>
#include <talus/loads/node_target.h>
#include <talus/loads/settings.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <vector>

namespace talus::loads
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {


    std::vector<dealii::types::boundary_id>
    ids(const std::string &text, const std::string &where, const unsigned int dim)
    {
      std::vector<dealii::types::boundary_id> r;
      if (text == "none")
        return r;
      for (const auto &x : parse_doubles(text, where))
        {
          require(x >= 0 && x == std::floor(x) && x < 2 * dim, where,
                  "boundary id " + std::to_string(x) + " does not exist (box grid ids 0.." +
                    std::to_string(2 * dim - 1) + ")");
          r.push_back(static_cast<dealii::types::boundary_id>(x));
        }
      return r;
    }

    const char *face_names = "x-|x+|y-|y+|z-|z+";

    const NodeTargetEntries traction_target{
      "body face|region|boundary",
      "body face",
      "'body face': the outermost layer of material points of a box body on 'face'; 'region': the points whose "
      "initial position lies in the region box, loaded on the face normal to the axis of 'face'; 'boundary': the grid "
      "nodes of the faces with 'boundary id' (nodal forces on the material touching that grid face; "
      "talus-semi-implicit only, docs/boundary-conditions.md).",
      "body face",
      /*flat_region=*/false,
      /*grid_file_ids=*/false};
    const NodeTargetEntries velocity_target{
      "boundary|region|body",
      "boundary",
      "'boundary': every grid node of 'boundary id'; 'region': the grid nodes inside the region box; 'body': the "
      "material points of 'body'.",
      "body",
      /*flat_region=*/true,
      /*grid_file_ids=*/false};

    /// 'loads' of the top level (`path` "loads") or of a stage; point loads are
    /// global loads only (`with_point_loads`: the top level)
    void
    declare_loads(dealii::ParameterHandler &prm, const std::string &prm_file, const std::string &path,
                  const unsigned int dim, const bool with_velocities = true, const bool with_point_loads = false)
    {
      const auto count = [&](const char *entry, const bool on) {
        return on ? dealii::Utilities::string_to_int(peek_entry(prm_file, path, entry, "0", Integer(0, 16))) : 0;
      };
      const unsigned int n_tr = count("number of tractions", true);
      const unsigned int n_v  = count("number of velocity conditions", with_velocities);
      const unsigned int n_p  = count("number of point loads", with_point_loads);
      prm.enter_subsection("loads");
      prm.declare_entry("number of tractions", "0", Integer(0, 16),
                        "Number of 'traction k' subsections: surface tractions carried by boundary material "
                        "points (seed 000 §4.3.2, §5.2).");
      if (with_velocities)
        prm.declare_entry(
          "number of velocity conditions", "0", Integer(0, 16),
          "Number of 'velocity k' subsections: prescribed velocities on grid nodes or material points.");
      if (with_point_loads)
        prm.declare_entry("number of point loads", "0", Integer(0, 16),
                          "Number of 'point load k' subsections: a force carried by the one material point nearest "
                          "a position (global loads, absolute time; docs/boundary-conditions.md).");
      for (unsigned int k = 0; k < n_tr; ++k)
        {
          prm.enter_subsection("traction " + std::to_string(k));
          declare_node_target(prm, dim, traction_target);
          prm.declare_entry("face", dim == 2 ? "y+" : "z+", Selection(face_names),
                            "Loaded face: its outward normal axis and side.");
          prm.declare_entry("traction", zeros_text(dim), Anything(),
                            "Traction vector [Pa], force per unit initial area of the face (e.g. 0, -1e4 pushes down); "
                            "direction and size do not follow the deformation (seed 000 §5.2).");
          prm.declare_entry("total force", "", Anything(),
                            "Instead of 'traction': the resultant force [N; per unit thickness in 2D] spread over "
                            "the selected points in proportion to their area shares (traction = total force / loaded "
                            "area: exact totals where the seeded points do not fill the face exactly); empty = off.");
          prm.declare_entry("pressure centre", "", Anything(),
                            "Instead of 'traction' (2D, apply to = region): the centre of a circle that carries a "
                            "pressure, e.g. the bore of a thick cylinder; empty = off. The points within one point "
                            "spacing of the circle (and in the region box) carry 'pressure' times their share of the "
                            "arc inside the region box, along the unit vector from the centre to their initial "
                            "position; the direction does not follow the deformation.");
          prm.declare_entry("pressure radius", "0", Double(0),
                            "With 'pressure centre': the circle's radius [m] (> 0).");
          prm.declare_entry("pressure", "0", Double(),
                            "With 'pressure centre': the pressure [Pa]; positive pushes the material away from the "
                            "centre (an internal pressure on a bore; an external pressure on an outer surface is "
                            "negative).");
          declare_time_function(prm, "the traction", "the stage's time for a stage load, else the absolute time");
          prm.leave_subsection();
        }
      for (unsigned int k = 0; k < n_v; ++k)
        {
          prm.enter_subsection("velocity " + std::to_string(k));
          declare_node_target(prm, dim, velocity_target);
          prm.declare_entry("components", "all", Anything(), "Prescribed components: 'all' or a list of x, y, z.");
          prm.declare_entry("velocity", zeros_text(dim), Anything(),
                            "Velocity vector [m/s] (unprescribed components ignored).");
          declare_time_function(prm, "the velocity", "the stage's time for a stage load, else the absolute time");
          prm.leave_subsection();
        }
      for (unsigned int k = 0; k < n_p; ++k)
        {
          prm.enter_subsection("point load " + std::to_string(k));
          prm.declare_entry("position", "", Anything(),
                            "The point [m] (dim numbers, inside the grid): the material point nearest to it at setup "
                            "(by initial position; ties: the smaller initial position, then particle id) carries the "
                            "whole force and moves with the material.");
          prm.declare_entry("force", "", Anything(),
                            "Force vector [N; per unit thickness in 2D] (dim numbers); it keeps its direction.");
          declare_time_function(prm, "the force", "the absolute time");
          prm.declare_entry("body", "any", Anything(),
                            "The body whose points are candidates: a body id, or 'any' (also -1): every body's.");
          prm.leave_subsection();
        }
      prm.leave_subsection();
    }

    /// the 'point load k' subsections (in 'loads') as point tractions
    template <int dim>
    void
    parse_point_loads(dealii::ParameterHandler &prm, const std::vector<BodyDescription<dim>> &bodies,
                      const dealii::Point<dim> &grid_lower, const dealii::Point<dim> &grid_upper,
                      std::vector<Traction<dim>> &tractions)
    {
      const unsigned int n = prm.get_integer("number of point loads");
      for (unsigned int k = 0; k < n; ++k)
        {
          Traction<dim> t;
          t.where  = "loads/point load " + std::to_string(k);
          t.target = Traction<dim>::Target::point;
          t.total  = true;
          prm.enter_subsection("point load " + std::to_string(k));
          t.position = parse_point<dim>(prm.get("position"), t.where + "/position");
          std::string extent;
          bool        inside = true;
          for (unsigned int d = 0; d < dim; ++d)
            {
              inside = inside && t.position[d] >= grid_lower[d] && t.position[d] <= grid_upper[d];
              extent += std::string(d ? ", " : "") + char('x' + d) + " " + std::to_string(grid_lower[d]) + " .. " +
                        std::to_string(grid_upper[d]);
            }
          require(inside, t.where + "/position",
                  "'" + prm.get("position") + "' lies outside the grid (grid extent " + extent +
                    "); allowed: a point inside the grid");
          t.traction          = parse_point<dim>(prm.get("force"), t.where + "/force");
          t.function          = parse_time_function(prm, t.where);
          const std::string b = dealii::Utilities::trim(prm.get("body"));
          if (b == "any" || b == "-1")
            t.body = Traction<dim>::any_body;
          else
            {
              const auto v = parse_doubles(b, t.where + "/body");
              require(v.size() == 1 && v[0] >= 0 && v[0] == std::floor(v[0]) && v[0] < bodies.size(), t.where + "/body",
                      "'" + b + "' is not a body; allowed: any (or -1) or a body id 0.." +
                        std::to_string(bodies.size() - 1));
              t.body = static_cast<unsigned int>(v[0]);
            }
          prm.leave_subsection();
          tractions.push_back(t);
        }
    }

    template <int dim>
    void
    parse_loads(dealii::ParameterHandler &prm, const std::string &path, const std::vector<BodyDescription<dim>> &bodies,
                std::vector<Traction<dim>> &tractions, std::vector<PrescribedVelocity<dim>> *velocities,
                const dealii::Point<dim> *grid_lower = nullptr, const dealii::Point<dim> *grid_upper = nullptr)
    {
      prm.enter_subsection("loads");
      const std::string  base = path.empty() ? "loads" : path + "/loads";
      const unsigned int n_tr = prm.get_integer("number of tractions");
      const unsigned int n_v  = velocities ? prm.get_integer("number of velocity conditions") : 0;
      for (unsigned int k = 0; k < n_tr; ++k)
        {
          const std::string where = base + "/traction " + std::to_string(k);
          prm.enter_subsection("traction " + std::to_string(k));
          Traction<dim> t;
          t.where             = where;
          const std::string f = prm.get("face");
          t.axis              = static_cast<unsigned int>(f[0] - 'x');
          t.side              = f[1] == '+' ? +1 : -1;
          require(t.axis < dim, where + "/face", "'" + f + "' does not exist in " + std::to_string(dim) + "D");
          using Kind        = typename NodeTarget<dim>::Kind;
          const auto target = parse_node_target<dim>(prm, where, traction_target, true, bodies.size());
          copy_node_target(target, t);
          t.target = target.kind == Kind::region     ? Traction<dim>::Target::region
                     : target.kind == Kind::boundary ? Traction<dim>::Target::boundary
                                                     : Traction<dim>::Target::body_face;
          if (t.target == Traction<dim>::Target::boundary)
            {
              // the face's normal is the boundary's; 'face' is not used
              t.axis = t.boundary / 2;
              t.side = t.boundary % 2 ? +1 : -1;
            }
          else if (t.target == Traction<dim>::Target::body_face)
            {
              t.body = target.body;
              require(bodies[t.body].shape == BodyDescription<dim>::Shape::box, where + "/apply to",
                      "'body face' needs a box body (body " + std::to_string(t.body) + " is not a box); use 'region'");
            }
          t.traction            = parse_point<dim>(prm.get("traction"), where + "/traction");
          const std::string tot = prm.get("total force");
          if (!tot.empty())
            {
              require(t.traction.norm() == 0, where + "/total force",
                      "give either 'traction' or 'total force', not both");
              t.traction = parse_point<dim>(tot, where + "/total force");
              t.total    = true;
            }
          const std::string centre = prm.get("pressure centre");
          if (!centre.empty())
            {
              require(dim == 2, where + "/pressure centre", "a pressure on a circle is available in 2D only");
              require(t.target == Traction<dim>::Target::region, where + "/apply to",
                      "'pressure centre' needs apply to = region (the region box bounds the loaded arc)");
              require(t.traction.norm() == 0 && !t.total, where + "/pressure centre",
                      "give either 'pressure centre' with 'pressure' or 'traction'/'total force', not both");
              t.radial = true;
              t.centre = parse_point<dim>(centre, where + "/pressure centre");
              t.radius = prm.get_double("pressure radius");
              require(t.radius > 0, where + "/pressure radius", "must be > 0 with 'pressure centre'");
              t.pressure = prm.get_double("pressure");
              // the arc inside the region box: midpoint samples of 2^16 angles; one
              // connected arc (or the whole circle) is required
              const unsigned int n = 1u << 16;
              std::vector<bool>  in(n);
              unsigned int       n_in = 0, n_starts = 0, start = 0;
              for (unsigned int k = 0; k < n; ++k)
                {
                  const double phi = -M_PI + 2.0 * M_PI * (k + 0.5) / n;
                  const double x = t.centre[0] + t.radius * std::cos(phi), y = t.centre[1] + t.radius * std::sin(phi);
                  in[k] = x >= t.lower[0] && x <= t.upper[0] && y >= t.lower[1] && y <= t.upper[1];
                  n_in += in[k] ? 1 : 0;
                }
              for (unsigned int k = 0; k < n; ++k)
                if (in[k] && !in[(k + n - 1) % n])
                  ++n_starts, start = k;
              require(n_in > 0, where + "/pressure radius",
                      "the circle does not pass through the region box (region lower/upper corner)");
              require(n_starts <= 1, where + "/region lower corner",
                      "the circle crosses the region box in " + std::to_string(n_starts) +
                        " separate arcs; allowed: one arc (or the whole circle) per traction");
              t.arc_span  = 2.0 * M_PI * n_in / n;
              t.arc_start = n_in == n ? -M_PI : -M_PI + 2.0 * M_PI * start / n;
            }
          else
            require(prm.get_double("pressure radius") == 0 && prm.get_double("pressure") == 0,
                    where + (prm.get_double("pressure") != 0 ? "/pressure" : "/pressure radius"),
                    "is given without 'pressure centre' (set the centre, or remove the entry)");
          t.function = parse_time_function(prm, where);
          prm.leave_subsection();
          tractions.push_back(t);
        }
      for (unsigned int k = 0; k < n_v; ++k)
        {
          const std::string where = base + "/velocity " + std::to_string(k);
          prm.enter_subsection("velocity " + std::to_string(k));
          PrescribedVelocity<dim> v;
          v.where           = where;
          using Kind        = typename NodeTarget<dim>::Kind;
          const auto target = parse_node_target<dim>(prm, where, velocity_target, true, bodies.size());
          copy_node_target(target, v);
          v.body                  = target.body;
          v.target                = target.kind == Kind::boundary ? PrescribedVelocity<dim>::Target::boundary
                                    : target.kind == Kind::region ? PrescribedVelocity<dim>::Target::region
                                                                  : PrescribedVelocity<dim>::Target::body;
          const std::string comps = prm.get("components");
          for (unsigned int d = 0; d < dim; ++d)
            v.component[d] = comps == "all";
          if (comps != "all")
            for (const auto &c : dealii::Utilities::split_string_list(comps, ','))
              {
                require(c.size() == 1 && c[0] >= 'x' && c[0] < 'x' + dim, where + "/components",
                        "'" + c + "' is not a component (allowed: all, or a list of " +
                          std::string(dim == 2 ? "x, y" : "x, y, z") + ")");
                v.component[c[0] - 'x'] = true;
              }
          v.velocity = parse_point<dim>(prm.get("velocity"), where + "/velocity");
          v.function = parse_time_function(prm, where);
          prm.leave_subsection();
          velocities->push_back(v);
        }
      if (grid_lower) // the top level: its point loads after the tractions
        parse_point_loads<dim>(prm, bodies, *grid_lower, *grid_upper, tractions);
      prm.leave_subsection();
    }

    /// the per-stage switches; `stage` true: defaults mean "inherit"
    void
    declare_switches(dealii::ParameterHandler &prm, const bool stage)
    {
      declare_damping(prm, stage); // the shared section (loads/damping.h)
      prm.enter_subsection("mass scaling");
      prm.declare_entry("factor", stage ? "-1" : "1", Double(stage ? -1 : 0),
                        "Mass scaling factor beta of seed 000 §6.5: inertia beta m (gravity keeps m); the critical "
                        "time step grows by sqrt(beta) (Eq. 6.31). 1 = off." +
                          std::string(stage ? " -1: as the top-level 'mass scaling'." : ""));
      prm.leave_subsection();
      prm.enter_subsection("convergence");
      prm.declare_entry("enabled", stage ? "inherit" : "false",
                        stage ? Selection("inherit|true|false") : Selection("true|false"),
                        "Evaluate the quasi-static convergence ratios of seed 000 §6.4: force ratio "
                        "|f_ext - f_int| / |f_ext| over the free DoFs (Eq. 6.29) and energy ratio KE / W_ext "
                        "(Eq. 6.30, W_ext = work of gravity and loads since the stage start).");
      prm.declare_entry("force ratio tolerance", stage ? "-1" : "1e-3", Double(-1), "Tolerance of the force ratio.");
      prm.declare_entry("energy ratio tolerance", stage ? "-1" : "1e-5", Double(-1), "Tolerance of the energy ratio.");
      prm.declare_entry("check interval", stage ? "0" : "10", Integer(0),
                        "Steps between evaluations (an MPI reduction each)." +
                          std::string(stage ? " 0: inherit." : ""));
      prm.declare_entry("end stage", stage ? "inherit" : "true",
                        stage ? Selection("inherit|true|false") : Selection("true|false"),
                        "End the stage (the run, if it is the last) once both ratios are below their tolerances "
                        "and every load of the stage has reached its final value.");
      prm.leave_subsection();
    }

    template <int dim>
    void
    parse_switches(dealii::ParameterHandler &prm, const std::string &path, Stage<dim> &s, const Stage<dim> *base)
    {
      const std::string pre = path.empty() ? "" : path + "/";
      Damping           inherited; // a stage's -1 entries: the top level's values
      if (base)
        {
          inherited.local   = base->damping;
          inherited.viscous = base->viscous_damping;
        }
      const Damping d   = parse_damping(prm, path, base ? &inherited : nullptr);
      s.damping         = d.local;
      s.viscous_damping = d.viscous;
      prm.enter_subsection("mass scaling");
      const double b = prm.get_double("factor");
      s.mass_scaling = (b < 0 && base) ? base->mass_scaling : b;
      require(s.mass_scaling > 0, pre + "mass scaling/factor", "must be > 0 (1 = no mass scaling)");
      prm.leave_subsection();
      prm.enter_subsection("convergence");
      const auto pick = [&](const std::string &e, const bool inherited) {
        const std::string v = prm.get(e);
        return v == "inherit" ? inherited : v == "true";
      };
      const Convergence c0    = base ? base->convergence : Convergence();
      s.convergence.enabled   = pick("enabled", c0.enabled);
      s.convergence.end_stage = pick("end stage", c0.end_stage);
      const double ft = prm.get_double("force ratio tolerance"), et = prm.get_double("energy ratio tolerance");
      s.convergence.force_tolerance  = (ft < 0 && base) ? c0.force_tolerance : ft;
      s.convergence.energy_tolerance = (et < 0 && base) ? c0.energy_tolerance : et;
      const unsigned int n           = prm.get_integer("check interval");
      s.convergence.interval         = (n == 0 && base) ? c0.interval : n;
      require(s.convergence.force_tolerance > 0, pre + "convergence/force ratio tolerance", "must be > 0");
      require(s.convergence.energy_tolerance > 0, pre + "convergence/energy ratio tolerance", "must be > 0");
      require(s.convergence.interval > 0, pre + "convergence/check interval", "must be > 0");
      prm.leave_subsection();
    }
    /// The body entries 'traction face' / 'traction' (declared with the 2-phase
    /// entries, explicit_two_phase.cc) are aliases: a constant global traction
    /// on that face of a box body, exactly 'loads/traction k' with apply to =
    /// body face. Other body shapes are refused later (input_checks.cc).
    template <int dim>
    void
    parse_two_phase_aliases(dealii::ParameterHandler &prm, const std::vector<BodyDescription<dim>> &bodies,
                            std::vector<Traction<dim>> &tractions)
    {
      for (unsigned int k = 0; k < bodies.size(); ++k)
        {
          const std::string where = "body " + std::to_string(k);
          prm.enter_subsection(where);
          const std::string f = prm.get("traction face"), v = prm.get("traction");
          prm.leave_subsection();
          if (f == "none" || bodies[k].shape != BodyDescription<dim>::Shape::box)
            continue;
          Traction<dim> t;
          t.where    = where + "/traction face";
          t.target   = Traction<dim>::Target::body_face;
          t.body     = k;
          t.axis     = static_cast<unsigned int>(f[0] - 'x');
          t.side     = f[1] == '+' ? +1 : -1;
          t.traction = parse_point<dim>(v, where + "/traction");
          t.function = TimeFunction::parse("constant", t.where);
          tractions.push_back(t);
        }
    }
  } // namespace

  template <int dim>
  bool
  Settings<dim>::active() const
  {
    if (staged)
      return true;
    for (const auto &s : stages)
      if (!s.friction_ids.empty() || !s.tractions.empty() || !s.velocities.empty() || s.damping > 0 ||
          s.viscous_damping > 0 || s.mass_scaling != 1.0 || s.convergence.enabled)
        return true;
    return false;
  }

  void
  declare_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, const unsigned int dim)
  {
    prm.enter_subsection("boundary conditions");
    prm.declare_entry("friction", "", Anything(),
                      "Boundary ids with frictional contact (seed 000 §6.2 against a rigid fixed boundary): "
                      "no penetration, free separation, Coulomb friction on the tangential velocity.");
    prm.declare_entry("friction coefficient", "0", Double(0),
                      "Coulomb friction coefficient mu of the 'friction' boundaries.");
    prm.declare_entry("adhesion", "0", Double(0),
                      "Adhesion a [Pa] of the 'friction' boundaries (Eq. 6.19: f_adh = a A_k).");
    prm.leave_subsection();
    declare_loads(prm, prm_file, "loads", dim, true, true);
    declare_switches(prm, false);

    declare_stage_parameters(prm, prm_file, dim, true);
  }

  void
  declare_stage_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, const unsigned int dim,
                           const bool                                             explicit_entries,
                           const std::function<void(dealii::ParameterHandler &)> &family_entries)
  {
    const unsigned int n_stages =
      dealii::Utilities::string_to_int(peek_entry(prm_file, "", "number of stages", "0", Integer(0, 32)));
    prm.declare_entry("number of stages", "0", Integer(0, 32),
                      "Staged calculation: number of 'stage k' subsections run one after the other (0 = one stage "
                      "from the top-level entries and time/end time).");
    for (unsigned int k = 0; k < n_stages; ++k)
      {
        const std::string name = "stage " + std::to_string(k);
        prm.enter_subsection(name);
        prm.declare_entry("name", name, Anything(), "Name used in messages.");
        prm.declare_entry("duration", "1", Double(0),
                          "Simulated duration of the stage [s] (it may end earlier by convergence).");
        prm.enter_subsection("gravity");
        prm.declare_entry("acceleration", "", Anything(), "Gravity of the stage; empty = the top-level gravity.");
        prm.leave_subsection();
        prm.enter_subsection("boundary conditions");
        for (const char *e : {"fixed", "roller", "friction"})
          if (explicit_entries || std::string(e) != "friction")
            prm.declare_entry(e, "inherit", Anything(),
                              std::string("Boundary ids of the stage, 'none', or 'inherit' (top-level ") + e + ").");
        if (explicit_entries)
          {
            prm.declare_entry("friction coefficient", "-1", Double(-1), "-1: the top-level value.");
            prm.declare_entry("adhesion", "-1", Double(-1), "-1: the top-level value.");
          }
        prm.leave_subsection();
        declare_loads(prm, prm_file, name + "/loads", dim);
        if (explicit_entries)
          declare_switches(prm, true);
        if (family_entries)
          family_entries(prm);
        prm.leave_subsection();
      }
  }

  template <int dim>
  std::vector<Stage<dim>>
  parse_stages(dealii::ParameterHandler &prm, const Stage<dim> &top, const std::vector<BodyDescription<dim>> &bodies,
               const bool explicit_entries)
  {
    std::vector<Stage<dim>> stages;
    const unsigned int      n_stages = prm.get_integer("number of stages");
    for (unsigned int k = 0; k < n_stages; ++k)
      {
        const std::string where = "stage " + std::to_string(k);
        prm.enter_subsection(where);
        Stage<dim> st;
        st.name     = prm.get("name");
        st.duration = prm.get_double("duration");
        require(st.duration > 0, where + "/duration", "must be > 0");
        prm.enter_subsection("gravity");
        const std::string g = prm.get("acceleration");
        st.gravity =
          g.empty() ? top.gravity : dealii::Tensor<1, dim>(parse_point<dim>(g, where + "/gravity/acceleration"));
        prm.leave_subsection();
        prm.enter_subsection("boundary conditions");
        const auto list = [&](const char *e, const std::vector<dealii::types::boundary_id> &inherited) {
          const std::string v = prm.get(e);
          return v == "inherit" ? inherited : ids(v, where + "/boundary conditions/" + e, dim);
        };
        std::vector<dealii::types::boundary_id> top_fixed, top_roller;
        for (const auto &bc : top.boundary_conditions)
          (bc.kind == BoundaryCondition::Kind::fixed ? top_fixed : top_roller).push_back(bc.id);
        for (const auto id : list("fixed", top_fixed))
          st.boundary_conditions.push_back({id, BoundaryCondition::Kind::fixed});
        for (const auto id : list("roller", top_roller))
          st.boundary_conditions.push_back({id, BoundaryCondition::Kind::roller});
        if (explicit_entries)
          {
            st.friction_ids         = list("friction", top.friction_ids);
            const double mu         = prm.get_double("friction coefficient");
            const double ad         = prm.get_double("adhesion");
            st.friction_coefficient = mu < 0 ? top.friction_coefficient : mu;
            st.adhesion             = ad < 0 ? top.adhesion : ad;
            for (const auto id : st.friction_ids)
              for (const auto &bc : st.boundary_conditions)
                require(bc.id != id, where + "/boundary conditions/friction",
                        "boundary " + std::to_string(id) + " is also fixed/roller in this stage");
          }
        prm.leave_subsection();
        st.tractions           = top.tractions;
        st.velocities          = top.velocities;
        st.n_global_tractions  = top.tractions.size();
        st.n_global_velocities = top.velocities.size();
        parse_loads<dim>(prm, where, bodies, st.tractions, &st.velocities);
        if (explicit_entries)
          parse_switches<dim>(prm, where, st, &top);
        prm.leave_subsection();
        stages.push_back(st);
      }
    return stages;
  }

  template <int dim>
  Settings<dim>
  parse_parameters(dealii::ParameterHandler &prm, const double end_time, const dealii::Tensor<1, dim> &gravity,
                   const std::vector<BoundaryCondition>    &boundary_conditions,
                   const std::vector<BodyDescription<dim>> &bodies, const dealii::Point<dim> &grid_lower,
                   const dealii::Point<dim> &grid_upper)
  {
    Settings<dim> s;
    Stage<dim>    top;
    top.name                = "main";
    top.duration            = end_time;
    top.gravity             = gravity;
    top.boundary_conditions = boundary_conditions;
    prm.enter_subsection("boundary conditions");
    top.friction_ids         = ids(prm.get("friction"), "boundary conditions/friction", dim);
    top.friction_coefficient = prm.get_double("friction coefficient");
    top.adhesion             = prm.get_double("adhesion");
    for (const auto id : top.friction_ids)
      for (const auto &bc : boundary_conditions)
        require(bc.id != id, "boundary conditions/friction",
                "boundary " + std::to_string(id) + " is also fixed/roller; give each boundary one condition");
    prm.leave_subsection();
    parse_loads<dim>(prm, "", bodies, top.tractions, &top.velocities, &grid_lower, &grid_upper);
    parse_two_phase_aliases<dim>(prm, bodies, top.tractions);
    top.n_global_tractions  = top.tractions.size();
    top.n_global_velocities = top.velocities.size();
    parse_switches<dim>(prm, "", top, nullptr);
    {
      // 'two phase/local damping' is an alias of the top-level 'damping/local
      // damping' (the same alpha, the 2-phase form of §6.3.2 in the 2-phase step)
      prm.enter_subsection("two phase");
      const double a2 = prm.get_double("local damping");
      prm.leave_subsection();
      if (a2 > 0)
        {
          require(top.damping == 0 || top.damping == a2, "two phase/local damping",
                  "is an alias of 'damping/local damping', which is set to another value; give only one of them");
          top.damping = a2;
        }
    }

    s.stages = parse_stages<dim>(prm, top, bodies, true);
    s.staged = !s.stages.empty();
    if (!s.staged)
      s.stages.push_back(top);
    for (const auto &st : s.stages)
      s.max_tractions = std::max<unsigned int>(s.max_tractions, st.tractions.size());
    return s;
  }

  void
  declare_traction_parameters(dealii::ParameterHandler &prm, const std::string &prm_file, const unsigned int dim,
                              const bool with_velocities)
  {
    declare_loads(prm, prm_file, "loads", dim, with_velocities, true);
  }

  template <int dim>
  std::vector<Traction<dim>>
  parse_traction_parameters(dealii::ParameterHandler &prm, const std::vector<BodyDescription<dim>> &bodies,
                            const dealii::Point<dim> &grid_lower, const dealii::Point<dim> &grid_upper,
                            std::vector<PrescribedVelocity<dim>> *velocities)
  {
    std::vector<Traction<dim>> t;
    parse_loads<dim>(prm, "", bodies, t, velocities, &grid_lower, &grid_upper);
    return t;
  }

  template <int dim>
  void
  refuse_boundary_tractions(const std::vector<Traction<dim>> &tractions, const std::string &tool,
                            const std::string &reason)
  {
    for (const auto &t : tractions)
      require(t.target != Traction<dim>::Target::boundary, t.where + "/apply to",
              "is 'boundary': " + tool + " cannot honour a traction on a grid boundary id: " + reason);
  }

  template void refuse_boundary_tractions(const std::vector<Traction<2>> &, const std::string &, const std::string &);
  template void refuse_boundary_tractions(const std::vector<Traction<3>> &, const std::string &, const std::string &);
  template std::vector<Traction<2>> parse_traction_parameters<2>(dealii::ParameterHandler &,
                                                                 const std::vector<BodyDescription<2>> &,
                                                                 const dealii::Point<2> &, const dealii::Point<2> &,
                                                                 std::vector<PrescribedVelocity<2>> *);
  template std::vector<Traction<3>> parse_traction_parameters<3>(dealii::ParameterHandler &,
                                                                 const std::vector<BodyDescription<3>> &,
                                                                 const dealii::Point<3> &, const dealii::Point<3> &,
                                                                 std::vector<PrescribedVelocity<3>> *);
  template std::vector<Stage<2>>    parse_stages<2>(dealii::ParameterHandler &, const Stage<2> &,
                                                 const std::vector<BodyDescription<2>> &, const bool);
  template std::vector<Stage<3>>    parse_stages<3>(dealii::ParameterHandler &, const Stage<3> &,
                                                 const std::vector<BodyDescription<3>> &, const bool);
  template struct Settings<2>;
  template struct Settings<3>;
  template Settings<2> parse_parameters<2>(dealii::ParameterHandler &, const double, const dealii::Tensor<1, 2> &,
                                           const std::vector<BoundaryCondition> &,
                                           const std::vector<BodyDescription<2>> &, const dealii::Point<2> &,
                                           const dealii::Point<2> &);
  template Settings<3> parse_parameters<3>(dealii::ParameterHandler &, const double, const dealii::Tensor<1, 3> &,
                                           const std::vector<BoundaryCondition> &,
                                           const std::vector<BodyDescription<3>> &, const dealii::Point<3> &,
                                           const dealii::Point<3> &);
} // namespace talus::loads
