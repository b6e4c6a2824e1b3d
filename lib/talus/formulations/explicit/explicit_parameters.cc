// talus — the .prm of talus-explicit (and talus-fem): its entries in the shared
// subsections (time, stability, output, 'material k' pore liquid, 'body k'
// tractions), the numerics, loads and stages, parsed into Parameters<dim> and
// checked (input_checks.h).
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/input_checks.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/io/png_snapshots.h>
#include <talus/loads/damping.h>
#include <talus/loads/kinematics.h>
#include <talus/shape/bspline2.h>

#include <cmath>
#include <sstream>

namespace talus::explicit_mpm
{
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;

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
    const SceneCounts counts =
      declare_common_parameters(prm, prm_file,
                                "Fixed time step [s]; 0 = courant number x critical time step. A value above the "
                                "critical time step is refused unless 'force time step' is true.");
    // the explicit family's entries in the shared subsections
    prm.enter_subsection("time");
    {
      prm.declare_entry("courant number", "0.5", Double(0, 1),
                        "Time step as a fraction of the critical time step L_min/c (seed 000 Eq. 4.120), "
                        "used when 'time step' is 0. Range (0, 1].");
      prm.declare_entry("force time step", "false", Bool(),
                        "Accept a 'time step' above the critical one (stability studies).");
    }
    prm.leave_subsection();
    prm.enter_subsection("stability");
    prm.declare_entry("energy growth limit", "10", Double(1),
                      "The run is stopped as unstable when kinetic + strain energy exceed this factor times "
                      "the energy available (initial kinetic + strain energy + released potential energy + "
                      "external work), or when any state becomes non-finite.");
    prm.leave_subsection();
    for (unsigned int k = 0; k < counts.n_materials; ++k)
      {
        prm.enter_subsection("material " + std::to_string(k));
        materials::declare_pore_liquid(prm); // the shared section
        prm.leave_subsection();
      }
    for (unsigned int k = 0; k < counts.n_bodies; ++k)
      {
        prm.enter_subsection("body " + std::to_string(k));
        declare_body_traction(prm, counts.dim);
        prm.leave_subsection();
      }
    // the explicit family's own subsections
    declare_numerics_parameters(prm, default_integration);
    declare_liquid_output(prm);
    loads::declare_parameters(prm, prm_file, counts.dim);
  }

  template <int dim>
  Parameters<dim>
  parse_parameters(dealii::ParameterHandler &prm)
  {
    Parameters<dim> p;
    parse_run_parameters<dim>(prm, p);
    prm.enter_subsection("time");
    p.courant         = prm.get_double("courant number");
    p.time_step       = prm.get_double("time step");
    p.force_time_step = prm.get_bool("force time step");
    require(p.courant > 0, "time/courant number", "must be > 0");
    prm.leave_subsection();
    prm.enter_subsection("stability");
    p.energy_growth_limit = prm.get_double("energy growth limit");
    prm.leave_subsection();

    parse_scene_parameters<dim>(prm, p);
    parse_liquid_output(prm, p.liquid);
    for (unsigned int k = 0; k < p.materials.size(); ++k)
      {
        const std::string where = "material " + std::to_string(k);
        prm.enter_subsection(where);
        p.liquid.pore_liquid.push_back(parse_pore_liquid(prm, where, p.materials[k]));
        prm.leave_subsection();
      }
    for (unsigned int k = 0; k < p.bodies.size(); ++k)
      {
        const std::string where = "body " + std::to_string(k);
        prm.enter_subsection(where);
        p.liquid.tractions.push_back(parse_body_traction<dim>(prm, where));
        prm.leave_subsection();
      }
    // a water level of the K0 procedure: the pore water of coupled 2-phase points only
    for (unsigned int k = 0; k < p.bodies.size(); ++k)
      {
        const auto &z = p.initial_stress[k];
        require(!z.enabled || !z.has_water_level() ||
                  p.liquid.pore_liquid[p.bodies[k].material_id].drainage == Drainage::coupled,
                "body " + std::to_string(k) + "/initial stress/water level",
                "talus-explicit cannot honour it for material " + std::to_string(p.bodies[k].material_id) +
                  ", whose points carry no pore water (allowed: empty, or 'pore liquid/drainage = coupled')");
      }
    const unsigned int n_bodies = p.bodies.size();
    p.loads = loads::parse_parameters<dim>(prm, p.end_time, p.gravity, p.boundary_conditions, p.bodies, p.grid_lower,
                                           p.grid_upper);
    // a traction on a grid boundary id (nodal forces): talus-semi-implicit only
    for (const auto &st : p.loads.stages)
      loads::refuse_boundary_tractions(st.tractions, "talus-explicit",
                                       "its tractions are carried by material points; allowed: 'body face' or "
                                       "'region' (docs/boundary-conditions.md)");
    // the shared 'damping' section (loads/damping.h): local and viscous damping
    // are read into the stages by loads::parse_parameters
    loads::refuse_damping(loads::parse_damping(prm).stiffness, "stiffness damping", "talus-explicit",
                          "the explicit step has no stiffness matrix to damp with; allowed: 0 (damp with 'viscous "
                          "damping' or 'local damping')");
    if (p.loads.staged)
      {
        p.end_time = 0; // the sum of the stage durations
        for (const auto &st : p.loads.stages)
          p.end_time += st.duration;
      }
    p.numerics = parse_numerics_parameters(prm, n_bodies);
    // 'numerics/volumetric stabilisation' is the shared scene's (scene_parameters.cc)
    require(p.volumetric_stabilisation != transfer::VolumetricStabilisation::modified_f_bar,
            "numerics/volumetric stabilisation",
            "modified f-bar scales the elastic left Cauchy-Green tensor b_e that finite-strain models keep "
            "(seed 002 Eqs. 81-83); talus-explicit updates its models in rate form, without b_e; allowed: "
            "none, f-bar");
    p.numerics.fbar = p.volumetric_stabilisation == transfer::VolumetricStabilisation::f_bar;
    if (p.numerics.fbar)
      {
        // the F-bar replaces the update pass's volume change (ExplicitPointUpdate): the
        // passes with their own update or their own volumetric treatment are refused
        const std::string why = " is not available with numerics/volumetric stabilisation = f-bar (";
        require(p.numerics.integration == NumericsOptions::Integration::mpm, "numerics/integration",
                std::string(p.numerics.integration_name()) + why +
                  "FEM and MPM-MIXED have their own update or stress averaging); allowed: mpm, or "
                  "volumetric stabilisation = none");
        require(p.numerics.smoothing == NumericsOptions::Smoothing::none, "numerics/strain smoothing",
                "strain smoothing" + why +
                  "both replace the volumetric strain increment: choose one); allowed: none, or volumetric "
                  "stabilisation = none");
        require(!p.liquid.any_coupled() && !p.liquid.any_traction(), "numerics/volumetric stabilisation",
                "f-bar is not available with coupled 2-phase materials (and body tractions, which run the 2-phase "
                "step): the storage equation turns any change of the skeleton's volume increment into pore "
                "pressure at K_L / n, and the node average of the skeleton's dJ alone put Terzaghi 500 % off "
                "(docs/explicit.md, \"F-bar and the 2-phase step\"); allowed: none, or 1-phase materials");
      }
    if (p.numerics.apic())
      {
        // APIC replaces the 1-phase step's G2P/P2G of the velocity (Solver::step,
        // affine_offset). The loads act on the nodal force or velocity that the
        // APIC G2P reads (tractions, point loads, friction walls, prescribed
        // nodes, rigid plates); body velocities set v_p and C_p (rows 0, the
        // gradient of a uniform field) before an affine P2G; C_p is a point
        // property, carried by load balancing and checkpoints. What stays refused
        // and why: docs/shape-functions.md, "APIC".
        // linear shape functions: the transfers are implemented and unit-tested
        // (C_p = grad v), but the collapse a = 3 blows up at Courant 0.5 and 0.2
        // (a = f / m at nodes a point barely touches goes straight into v^L)
        require(p.bspline(), "numerics/velocity transfer",
                "apic needs numerics/shape function = quadratic bspline: with linear shape functions the APIC "
                "step was measured unstable (granular column collapse, Courant 0.5 and 0.2; "
                "docs/shape-functions.md, \"APIC\"); allowed: velocity transfer = flip, or quadratic bspline");
        // the cell-integrated passes: they integrate on the cells with linear
        // shape functions by definition, and APIC needs quadratic B-splines
        // (strain smoothing takes the B-spline field's cell averages: allowed)
        const std::string cells = " is not available with numerics/velocity transfer = apic: APIC needs quadratic "
                                  "B-splines, and this pass integrates on the cells with linear shape functions "
                                  "(docs/shape-functions.md, \"APIC\"); allowed: ";
        require(p.numerics.integration == NumericsOptions::Integration::mpm, "numerics/integration",
                std::string(p.numerics.integration_name()) + cells + "mpm, or velocity transfer = flip");
        // the coupled 2-phase step keeps its own (FLIP) velocity transfer
        const std::string why = " is not available with numerics/velocity transfer = apic (its passes keep the "
                                "FLIP velocity update: the liquid's momentum); allowed: ";
        require(!p.liquid.any_coupled() && !p.liquid.any_traction(), "numerics/velocity transfer",
                "coupled 2-phase materials and body tractions" + why +
                  "1-phase materials, or velocity transfer = flip");
        // contact: each body's v^L_b (Contact::correct_accelerations); a body
        // velocity condition re-projects v_p, C_p of all points from the combined v^L
        if (p.numerics.contact())
          for (unsigned int k = 0; k < p.loads.stages.size(); ++k)
            for (const auto &v : p.loads.stages[k].velocities)
              require(v.target != loads::PrescribedVelocity<dim>::Target::body,
                      (p.loads.staged ? "stage " + std::to_string(k) + "/loads" : std::string("loads")) +
                        "/velocity k/apply to",
                      "a prescribed velocity of a body ('apply to = body') is not available with contact and "
                      "numerics/velocity transfer = apic: its APIC projection of v_p, C_p uses the combined "
                      "velocity field, not each body's (docs/explicit.md, \"APIC with contact\"); allowed: "
                      "'apply to = boundary | region', no contact pairs, or velocity transfer = flip");
      }
    // contact moves every body with its own nodal fields; the loads' rules
    // reach them through LoadControl::damp_and_scale / body_accelerations /
    // body_velocities, a rigid plate's balance does not (it sums the combined
    // field's nodes): a plate on a body in contact would act on nothing
    require(!p.numerics.contact() || p.rigid_plates.empty(), "boundary conditions/rigid plate 0",
            "a rigid plate is not available with contact pairs: every body moves with its own nodal fields and "
            "the plate's balance acts on the combined field only (docs/explicit.md, \"Contact and nodal "
            "loads\"); allowed: no rigid plate, or no contact pairs");
    if (p.bspline())
      {
        // MPM-MIXED and FEM/UL-FEM integrate on the cells of the Q1 element by
        // definition (cell stresses, its Gauss points); strain smoothing takes
        // the cell averages of the B-spline field (StrainSmoothing)
        require(p.numerics.integration == NumericsOptions::Integration::mpm, "numerics/integration",
                std::string(p.numerics.integration_name()) +
                  " is not available with numerics/shape function = quadratic bspline: it integrates on the cells "
                  "with the linear element by definition (cell stresses, Gauss points of the Q1 cell; "
                  "docs/shape-functions.md); allowed: mpm");
        // contact (contact/pairs) is a kernel template (contact.cc; normals from
        // the B-spline mass gradient, docs/explicit.md "Contact between bodies").
        // The loads are kernel templates: the nodal momentum p^t (ScatterMomentum),
        // the traction point forces and the momentum of prescribed point
        // velocities (ScatterPointVectors); wall friction acts on the wall nodes'
        // sums, whichever kernel made them. The 2-phase step is a kernel template
        // too; with B-splines it relaxes the point pore pressures towards their
        // node map-remap ('two phase/pressure relaxation', docs/shape-functions.md,
        // "2-phase on B-splines").
        require(!p.grid_mesh, "grid/source",
                "a grid file with quadratic B-splines: they need a uniform box grid; allowed: box");
        for (unsigned int d = 0; d < dim; ++d)
          require(p.grid_cells[d] >= shape::BSpline2<dim>::min_cells, "grid/cells",
                  "quadratic B-splines need at least 3 cells per direction (the wall treatment)");
      }
    if (p.balance.enabled())
      {
        // UL-FEM keeps the displacement of its moving mesh on the grid between
        // steps, which a repartition does not carry (docs/scaling.md); FEM's
        // state is on its Gauss points (the mesh is fixed), which travel with
        // their cells
        const std::string why = " is not available with load balancing (allowed with it: the 1-phase and "
                                "2-phase MPM steps with loads, damping, stages, free-surface output, contact, "
                                "strain smoothing, MPM-MIXED, and integration = fem); set load balancing/interval "
                                "= 0, or ";
        require(p.numerics.integration != NumericsOptions::Integration::ul_fem, "load balancing/interval",
                "numerics/integration = ul-fem" + why + "integration = mpm | fem");
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
                "'" + mode +
                  "' runs the 1-phase step only: coupled 2-phase materials and body tractions are "
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


  TALUS_INSTANTIATE_PARAMETERS();
} // namespace talus::explicit_mpm
