// talus-critical-dt: the critical time step of an explicit scene, from the
// formula (seed 000 §4.6.1) and, with --probe, measured by short runs. For an
// implicit scene (a talus-implicit .prm) it says that the step is not CFL-limited
// and prints the explicit critical step of the same grid and materials beside it.
#include <talus/analysis/scheme_stability.h>
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/implicit/implicit_solver.h>
#include <talus/io/output.h>

#include <deal.II/base/mpi.h>
#include <deal.II/particles/particle_handler.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <regex>
#include <iomanip>
#include <sstream>

namespace
{
  using namespace talus;

  /// --crossing-velocity=V [m/s]: a finite number >= 0 (0 when absent)
  double
  crossing_velocity()
  {
    if (!tool_option_given("--crossing-velocity"))
      return 0;
    const std::string v    = tool_option_value("--crossing-velocity", "");
    std::size_t       used = 0;
    double            x    = -1;
    try
      {
        x = std::stod(v, &used);
      }
    catch (const std::exception &)
      {
        used = 0;
      }
    if (used != v.size() || v.empty() || !std::isfinite(x) || x < 0)
      throw InputError("option --crossing-velocity: '" + v + "' is not a finite velocity >= 0 [m/s]");
    return x;
  }

  /// A talus-implicit .prm: it has the top-level subsection 'implicit'.
  bool
  is_implicit_scene(const std::string &prm_file)
  {
    if (prm_file.empty())
      return false;
    std::ifstream    in(prm_file);
    std::string      line;
    const std::regex opening(R"(^\s*subsection\s+implicit\s*(#.*)?$)");
    while (std::getline(in, line))
      if (std::regex_match(line, opening))
        return true;
    return false;
  }

  /// Implicit scene: no CFL limit for an unconditionally stable Newmark pair (or
  /// a static analysis); the explicit critical step of the same grid and
  /// materials (Eq. 4.120 per material) and the ratio of the implicit step to it.
  template <int dim>
  int
  run_implicit(dealii::ParameterHandler &prm)
  {
    using P            = implicit_mpm::Parameters<dim>;
    const auto   p     = implicit_mpm::parse_parameters<dim>(prm);
    const double L_min = smallest_cell_edge(p);
    const auto   rows  = explicit_mpm::critical_time_steps(p.materials, {}, L_min);
    std::size_t  ctrl  = 0;
    for (std::size_t i = 1; i < rows.size(); ++i)
      if (rows[i].dt < rows[ctrl].dt)
        ctrl = i;
    const double dt_cr = rows[ctrl].dt;
    // the smallest step of the run (with stages: of any stage)
    const double h       = *std::min_element(p.stage_time_steps.begin(), p.stage_time_steps.end());
    const bool   dynamic = p.analysis == P::Analysis::dynamic;
    // Newmark on a linear undamped system: unconditionally stable for
    // 2 beta >= gamma >= 1/2; else stable for omega h <= 1 / sqrt(gamma / 2 - beta).
    // The largest frequency of the lumped Q1 grid is omega_max = 2 c / L_min, so
    // that bound is h <= Omega_crit / 2 x (L_min / c).
    const bool   unconditional = !dynamic || 2 * p.beta >= p.gamma;
    const double omega_crit    = unconditional ? 0.0 : 1.0 / std::sqrt(0.5 * p.gamma - p.beta);
    const double h_limit       = unconditional ? std::numeric_limits<double>::infinity() : 0.5 * omega_crit * dt_cr;

    log() << std::setprecision(6) << "talus-critical-dt: implicit MPM scene (talus-implicit), analysis = "
          << (dynamic ? "dynamic, Newmark gamma = " + std::to_string(p.gamma) + ", beta = " + std::to_string(p.beta)
                      : std::string("static"))
          << "\n  L_min = " << L_min << " m (smallest cell edge of the grid)\n";
    for (const auto &r : rows)
      log() << "  " << r.material << " (" << r.model << "): c = " << r.wave_speed << " m/s, explicit dt_cr = " << r.dt
            << " s (" << r.formula << ")\n";
    if (!dynamic)
      log() << "  static analysis: no inertia, time is a load parameter; the step is not limited by stability "
               "(load steps are chosen for Newton convergence)\n";
    else if (unconditional)
      log() << "  Newmark with 2 beta >= gamma >= 1/2 is unconditionally stable (linear analysis): the time step is "
               "not CFL-limited; it is chosen for accuracy (trapezoidal rule: period error (omega h)^2 / 12) and "
               "Newton convergence\n";
    else
      log() << "  Newmark with 2 beta < gamma is only conditionally stable: for finite elements with the lumped "
               "mass, omega h <= "
            << omega_crit << " with omega_max = 2 c / L_min, i.e. h <= " << h_limit << " s = " << h_limit / dt_cr
            << " x the explicit dt_cr. WARNING: this is not a safe bound for MPM: the projection of velocity and "
               "acceleration through the points every step lowers it (measured on the implicit bar, beta = 0.2: "
               "unstable from about 0.7 x this value; docs/implicit.md). Use 2 beta >= gamma.\n";
    log() << "  controlling material: " << rows[ctrl].material << "; explicit critical time step " << dt_cr << " s\n"
          << "  implicit time step in use: " << h << " s = " << h / dt_cr
          << " x the explicit critical step (explicit steps per implicit step)"
          << (unconditional ? ""
                            : (h <= h_limit ? "; within the finite-element Newmark bound"
                                            : "; ABOVE the finite-element Newmark bound"))
          << "\n";

    const std::string csv = tool_option_value("--csv", "");
    if (!csv.empty() && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        io::AtomicFile f(csv);
        f.stream() << std::setprecision(10)
                   << "material,model,formula,wave_speed,L_min,dt_critical_explicit,controlling,analysis,newmark_gamma,"
                      "newmark_beta,cfl_limited,dt_newmark_limit,dt_in_use,ratio_to_explicit\n";
        for (std::size_t i = 0; i < rows.size(); ++i)
          f.stream() << rows[i].material << "," << rows[i].model << ",\"" << rows[i].formula << "\","
                     << rows[i].wave_speed << "," << L_min << "," << rows[i].dt << "," << (i == ctrl ? 1 : 0) << ","
                     << (dynamic ? "dynamic" : "static") << "," << p.gamma << "," << p.beta << ","
                     << (unconditional ? 0 : 1) << "," << (unconditional ? 0.0 : h_limit) << "," << h << ","
                     << h / dt_cr << "\n";
        f.commit();
      }
    return exit_ok;
  }

  template <int dim>
  int
  run(dealii::ParameterHandler &prm)
  {
    auto p     = explicit_mpm::parse_parameters<dim>(prm);
    p.progress = false;
    explicit_mpm::Solver<dim> s(p, MPI_COMM_WORLD);
    s.setup();
    const double L_min = s.grid.min_cell_size();

    // per material: phase, formula, wave speed and step (seed 000 §4.6)
    const auto  rows = s.critical_time_steps();
    std::size_t ctrl = 0;
    for (std::size_t i = 1; i < rows.size(); ++i)
      if (rows[i].dt < rows[ctrl].dt)
        ctrl = i;
    const double dt_cr = rows[ctrl].dt;
    const double dt    = s.time_step();

    // Per material: the cell with the smallest edge among the cells holding its
    // points (the controlling cell) and the points per direction (largest over the
    // bodies of that material: the scheme limit decreases with n).
    const unsigned int n_mat = rows.size();
    struct CellInfo
    {
      double      h = std::numeric_limits<double>::max();
      std::string id, center;
    };
    std::vector<CellInfo> cell_of(n_mat);
    {
      std::vector<double>      h_loc(n_mat, std::numeric_limits<double>::max());
      std::vector<std::string> id_loc(n_mat), center_loc(n_mat);
      for (const auto &pt : s.points.handler)
        {
          const unsigned int m = static_cast<unsigned int>(pt.get_properties()[2] + 0.5);
          if (m >= n_mat)
            continue;
          const auto   cell = pt.get_surrounding_cell();
          const double h    = cell->minimum_vertex_distance();
          if (h < h_loc[m])
            {
              h_loc[m]  = h;
              id_loc[m] = cell->id().to_string();
              std::ostringstream c;
              c << std::setprecision(6) << "(" << cell->center() << ")";
              center_loc[m] = c.str();
            }
        }
      for (unsigned int m = 0; m < n_mat; ++m)
        {
          const auto all_h  = dealii::Utilities::MPI::all_gather(MPI_COMM_WORLD, h_loc[m]);
          const auto all_id = dealii::Utilities::MPI::all_gather(MPI_COMM_WORLD, id_loc[m]);
          const auto all_c  = dealii::Utilities::MPI::all_gather(MPI_COMM_WORLD, center_loc[m]);
          for (std::size_t r = 0; r < all_h.size(); ++r)
            if (all_h[r] < cell_of[m].h)
              cell_of[m] = {all_h[r], all_id[r], all_c[r]};
        }
    }
    std::vector<unsigned int> n_points(n_mat, 0);
    for (const auto &b : p.bodies)
      if (b.material_id < n_mat)
        n_points[b.material_id] = std::max(n_points[b.material_id], b.particles_per_direction);
    // Stability limit of the scheme actually implemented (lumped mass, USL update with
    // the momentum re-projection), from the eigenvalues of one step on a uniform 1D
    // grid (docs/stability-analysis.md): dt_scheme = f(n) L / c for the wave part of
    // solid, undrained and liquid materials; not analysed for the coupled 2-phase step.
    std::vector<double> f_scheme(n_mat, 0.0), dt_scheme(n_mat, 0.0), dt_moved(n_mat, 0.0);
    for (unsigned int m = 0; m < n_mat; ++m)
      if (rows[m].phase != "coupled" && n_points[m] > 0)
        {
          f_scheme[m]  = analysis::scheme_critical_factor_closed_form(n_points[m]);
          dt_scheme[m] = f_scheme[m] * rows[m].dt_wave;
          dt_moved[m]  = analysis::scheme_critical_factor_moved(n_points[m]) * rows[m].dt_wave;
          // the viscous limit of a liquid is not covered by the analysis
          if (rows[m].phase == "liquid" && rows[m].dt_other > 0 && rows[m].dt_other < dt_scheme[m])
            f_scheme[m] = dt_scheme[m] = dt_moved[m] = 0;
        }

    log() << std::setprecision(6)
          << "talus-critical-dt: explicit MPM (seed 000 §4.6: 1-phase solid Eq. 4.120, dt_cr = L_min / c, "
             "c = sqrt(E_c / rho); 1-phase liquid Eq. 4.121 and the viscous limit rho L^2 / (2 mu); "
             "2-phase coupled Eqs. 4.122 and 4.129)\n"
          << "  L_min = " << L_min << " m (smallest cell edge of the grid)\n";
    if (s.mass_scaling != 1.0)
      log() << "  mass scaling factor " << s.mass_scaling << " (first stage): wave speeds and critical time steps "
            << "below are scaled (Eq. 6.31, dt_cr x sqrt(beta))\n";
    for (std::size_t i = 0; i < rows.size(); ++i)
      {
        const auto &r = rows[i];
        log() << "  " << r.material << " (" << r.model << ", " << r.phase << "): c = " << r.wave_speed
              << " m/s, dt_cr = " << r.dt << " s (" << r.formula << ")";
        if (r.phase == "coupled")
          log() << "; Eq. 4.123 L/c_1 = " << r.dt_wave << " s, Eq. 4.124 = " << r.dt_other
                << " s, Eq. 4.122 min = " << r.dt_4_122 << " s";
        else if (r.phase == "liquid" && r.dt_other > 0)
          log() << "; L/c = " << r.dt_wave << " s, viscous = " << r.dt_other << " s";
        log() << "\n    controlling cell " << cell_of[i].id << " centre " << cell_of[i].center << ", smallest edge "
              << cell_of[i].h << " m; " << n_points[i] << " points per direction";
        if (dt_scheme[i] > 0)
          log() << "; scheme limit (1D analysis of the implemented step, docs/stability-analysis.md): points at "
                << "their regular positions " << dt_scheme[i] << " s = " << dt_scheme[i] / r.dt << " x " << r.formula
                << ", moved points (worst uniform shift) " << dt_moved[i] << " s = " << dt_moved[i] / r.dt << " x";
        else
          log() << "; scheme limit not analysed for this phase / limit";
        log() << "\n";
      }
    // points crossing cells at a velocity V (Floquet analysis of the translating state)
    const double        V_cross = crossing_velocity();
    std::vector<double> growth(n_mat, 0.0), v_used(n_mat, 0.0), courant_m(n_mat, 0.0);
    if (V_cross > 0)
      for (unsigned int m = 0; m < n_mat; ++m)
        if (f_scheme[m] > 0)
          {
            courant_m[m]     = dt / rows[m].dt_wave; // dt c / h of this material
            const double voc = V_cross / rows[m].wave_speed;
            if (voc * courant_m[m] < 1e-3)
              throw InputError("option --crossing-velocity: V dt / h = " + std::to_string(voc * courant_m[m]) +
                               " < 1e-3 for " + rows[m].material +
                               " (the analysis needs K = h / (V dt) <= 1000 steps)");
            growth[m]         = analysis::crossing_growth_per_step(n_points[m], courant_m[m], voc, 8, &v_used[m]);
            const double rate = std::log(growth[m]) / dt;
            log() << "  cell crossing at V = " << V_cross << " m/s, " << rows[m].material << " (V/c = " << voc
                  << ", analysed at " << v_used[m] << ", dt c / h = " << courant_m[m] << "): growth per step "
                  << std::setprecision(8) << growth[m] << std::setprecision(6) << ", rate " << rate
                  << " 1/s (e-folding time " << (rate > 0 ? 1.0 / rate : 0.0) << " s)"
                  << (growth[m] > 1 + 1e-9 ? ": unstable while the points cross cells" : "") << "\n";
          }
    log() << "  controlling material: " << rows[ctrl].material << "; critical time step " << dt_cr << " s ("
          << rows[ctrl].formula << ", the default), controlling cell " << cell_of[ctrl].id << "\n"
          << "  time step in use: " << dt << " s = " << dt / dt_cr << " x critical"
          << (p.time_step > 0 ? " (fixed time step)" : " (Courant number " + std::to_string(p.courant) + ")") << "\n";

    double     measured = 0, probe_lo = 0, probe_hi = 0;
    const bool probe = tool_option_given("--probe");
    if (probe)
      {
        const unsigned int n_steps = tool_option_uint("--probe-steps", 400, 1, 1000000);
        // stable(f): n_steps at f x dt_cr without the instability check firing
        const auto stable = [&](const double f) {
          auto q            = p;
          q.time_step       = f * dt_cr;
          q.force_time_step = true;
          explicit_mpm::Solver<dim> t(q, MPI_COMM_WORLD);
          t.setup();
          try
            {
              t.advance(n_steps);
              return true;
            }
          catch (const InstabilityError &)
            {
              return false;
            }
        };
        double lo = 0.5, hi = 4.0;
        if (!stable(lo))
          throw InstabilityError("the scene is unstable already at 0.5 x the critical time step over " +
                                 std::to_string(n_steps) + " steps: check the material data");
        if (stable(hi))
          {
            log() << "  probe: stable up to 4 x critical over " << n_steps << " steps (no limit found)\n";
            lo = hi;
          }
        else
          for (int it = 0; it < 8; ++it)
            {
              const double mid        = 0.5 * (lo + hi);
              (stable(mid) ? lo : hi) = mid;
            }
        probe_lo = lo;
        probe_hi = hi;
        measured = lo * dt_cr;
        log() << "  probe (" << n_steps << " steps per run, bisection): stable at " << lo << " x, unstable at " << hi
              << " x critical; measured critical time step " << measured << " s = " << lo << " x the formula";
        if (dt_scheme[ctrl] > 0)
          log() << ", " << measured / dt_scheme[ctrl] << " x the scheme limit " << dt_scheme[ctrl]
                << " s (regular points), " << measured / dt_moved[ctrl] << " x " << dt_moved[ctrl]
                << " s (moved points)";
        log() << "\n";
      }

    const std::string csv = tool_option_value("--csv", "");
    if (!csv.empty() && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        io::AtomicFile f(csv);
        f.stream() << std::setprecision(10)
                   << "material,model,phase,formula,wave_speed,L_min,dt_critical_formula,dt_wave,dt_other,dt_eq_4_122,"
                      "controlling,dt_in_use,courant_in_use,dt_measured,probe_stable_factor,probe_unstable_factor,"
                      "controlling_cell,cell_edge,points_per_direction,scheme_factor,dt_scheme,crossing_velocity,"
                      "crossing_v_over_c_analysed,crossing_growth_per_step,crossing_growth_rate,dt_scheme_moved\n";
        for (std::size_t i = 0; i < rows.size(); ++i)
          f.stream() << rows[i].material << "," << rows[i].model << "," << rows[i].phase << ",\"" << rows[i].formula
                     << "\"," << rows[i].wave_speed << "," << L_min << "," << rows[i].dt << "," << rows[i].dt_wave
                     << "," << rows[i].dt_other << "," << rows[i].dt_4_122 << "," << (i == ctrl ? 1 : 0) << "," << dt
                     << "," << dt / dt_cr << "," << (probe && i == ctrl ? measured : 0.0) << ","
                     << (probe && i == ctrl ? probe_lo : 0.0) << "," << (probe && i == ctrl ? probe_hi : 0.0) << ","
                     << cell_of[i].id << "," << cell_of[i].h << "," << n_points[i] << "," << f_scheme[i] << ","
                     << dt_scheme[i] << "," << V_cross << "," << v_used[i] << "," << growth[i] << ","
                     << (growth[i] > 0 ? std::log(growth[i]) / dt : 0.0) << "," << dt_moved[i] << "\n";
        f.commit();
      }
    return exit_ok;
  }
} // namespace

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-critical-dt";
  tool.summary = "Critical time step of an explicit scene (the talus-explicit .prm): per material the phase\n"
                 "(solid, liquid, undrained, coupled), the wave speed and the formula of seed 000 §4.6\n"
                 "(Eq. 4.120, 4.121 + viscous limit, 4.122 and 4.129), the controlling material and the\n"
                 "time step in use, the controlling cell of each material and the stability limit of\n"
                 "the scheme actually implemented (eigenvalues of one step on a uniform 1D grid with the\n"
                 "points per direction of the scene; docs/stability-analysis.md).\n"
                 "With --probe, the real limit is measured by bisection on short forced runs whose\n"
                 "instability check (energy growth, non-finite state) decides stable / unstable.\n"
                 "An implicit scene (a talus-implicit .prm, recognised by its 'implicit' subsection): the\n"
                 "tool states whether the step is CFL-limited (static, or Newmark with 2 beta >= gamma:\n"
                 "no; else the Newmark limit) and prints the explicit critical step of the same grid and\n"
                 "materials and the ratio of the implicit step to it (the speed-up in steps).";
  tool.declare = [](dealii::ParameterHandler &prm, const std::string &prm_file) {
    if (is_implicit_scene(prm_file))
      talus::implicit_mpm::declare_parameters(prm, prm_file);
    else
      talus::explicit_mpm::declare_parameters(prm, prm_file);
  };
  tool.options = {{"--probe", "measure the limit by bisection on f x dt_cr, f in [0.5, 4] (explicit scenes)"},
                  {"--probe-steps=", "steps per probe run (default 400)"},
                  {"--csv=", "also write the results to this CSV file"},
                  {"--crossing-velocity=", "points cross cells at VALUE m/s: growth per step (Floquet, 1D)"}};
  tool.check   = [](dealii::ParameterHandler &prm, const std::string &prm_file) {
    const bool implicit = is_implicit_scene(prm_file);
    const bool two      = prm.get_integer("dimension") == 2;
    if (implicit)
      {
        if (two)
          talus::implicit_mpm::parse_parameters<2>(prm);
        else
          talus::implicit_mpm::parse_parameters<3>(prm);
        for (const char *o : {"--probe", "--probe-steps", "--crossing-velocity"})
          if (talus::tool_option_given(o))
            throw talus::InputError(std::string("option ") + o +
                                      ": the probe runs and the crossing analysis are those of the explicit scheme; "
                                        "not available for an implicit scene (allowed: --csv=FILE)");
      }
    else if (two)
      talus::explicit_mpm::parse_parameters<2>(prm);
    else
      talus::explicit_mpm::parse_parameters<3>(prm);
    talus::tool_option_uint("--probe-steps", 400, 1, 1000000);
    crossing_velocity();
    if (talus::tool_option_given("--csv"))
      talus::require_output_file(talus::tool_option_value("--csv", ""), "option --csv");
  };
  tool.run = [](dealii::ParameterHandler &prm, const std::string &prm_file) {
    const bool two = prm.get_integer("dimension") == 2;
    if (is_implicit_scene(prm_file))
      return two ? run_implicit<2>(prm) : run_implicit<3>(prm);
    return two ? run<2>(prm) : run<3>(prm);
  };
  return talus::run_tool(argc, argv, tool);
}
