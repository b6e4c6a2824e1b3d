// talus-critical-dt: the critical time step of an explicit scene, from the
// formula (seed 000 §4.6.1) and, with --probe, measured by short runs.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/io/output.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace
{
  using namespace talus;

  template <int dim>
  int
  run(dealii::ParameterHandler &prm)
  {
    auto p = explicit_mpm::parse_parameters<dim>(prm);
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

    log() << std::setprecision(6)
          << "talus-critical-dt: explicit MPM (seed 000 §4.6: 1-phase solid Eq. 4.120, dt_cr = L_min / c, "
             "c = sqrt(E_c / rho); 1-phase liquid Eq. 4.121 and the viscous limit rho L^2 / (2 mu); "
             "2-phase coupled Eqs. 4.122 and 4.129)\n"
          << "  L_min = " << L_min << " m (smallest cell edge of the grid)\n";
    for (const auto &r : rows)
      {
        log() << "  " << r.material << " (" << r.model << ", " << r.phase << "): c = " << r.wave_speed
              << " m/s, dt_cr = " << r.dt << " s (" << r.formula << ")";
        if (r.phase == "coupled")
          log() << "; Eq. 4.123 L/c_1 = " << r.dt_wave << " s, Eq. 4.124 = " << r.dt_other
                << " s, Eq. 4.122 min = " << r.dt_4_122 << " s";
        else if (r.phase == "liquid" && r.dt_other > 0)
          log() << "; L/c = " << r.dt_wave << " s, viscous = " << r.dt_other << " s";
        log() << "\n";
      }
    log() << "  controlling material: " << rows[ctrl].material << "; critical time step " << dt_cr << " s\n"
          << "  time step in use: " << dt << " s = " << dt / dt_cr << " x critical\n";

    double measured = 0, probe_lo = 0, probe_hi = 0;
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
              const double mid = 0.5 * (lo + hi);
              (stable(mid) ? lo : hi) = mid;
            }
        probe_lo = lo;
        probe_hi = hi;
        measured = lo * dt_cr;
        log() << "  probe (" << n_steps << " steps per run, bisection): stable at " << lo << " x, unstable at " << hi
              << " x critical; measured critical time step " << measured << " s = " << lo
              << " x the formula\n";
      }

    const std::string csv = tool_option_value("--csv", "");
    if (!csv.empty() && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        io::AtomicFile f(csv);
        f.stream() << std::setprecision(10)
                   << "material,model,phase,formula,wave_speed,L_min,dt_critical_formula,dt_wave,dt_other,dt_eq_4_122,"
                      "controlling,dt_in_use,courant_in_use,dt_measured,probe_stable_factor,probe_unstable_factor\n";
        for (std::size_t i = 0; i < rows.size(); ++i)
          f.stream() << rows[i].material << "," << rows[i].model << "," << rows[i].phase << ",\"" << rows[i].formula
                     << "\"," << rows[i].wave_speed << "," << L_min << "," << rows[i].dt << "," << rows[i].dt_wave << ","
                     << rows[i].dt_other << "," << rows[i].dt_4_122 << "," << (i == ctrl ? 1 : 0) << "," << dt << "," << dt / dt_cr << ","
                     << (probe && i == ctrl ? measured : 0.0) << "," << (probe && i == ctrl ? probe_lo : 0.0) << ","
                     << (probe && i == ctrl ? probe_hi : 0.0) << "\n";
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
                 "time step in use.\n"
                 "With --probe, the real limit is measured by bisection on short forced runs whose\n"
                 "instability check (energy growth, non-finite state) decides stable / unstable.";
  tool.declare = &talus::explicit_mpm::declare_parameters;
  tool.options = {{"--probe", "measure the limit by bisection on f x dt_cr, f in [0.5, 4]"},
                  {"--probe-steps=", "steps per probe run (default 400)"},
                  {"--csv=", "also write the results to this CSV file"}};
  tool.check   = [](dealii::ParameterHandler &prm, const std::string &) {
    if (prm.get_integer("dimension") == 2)
      talus::explicit_mpm::parse_parameters<2>(prm);
    else
      talus::explicit_mpm::parse_parameters<3>(prm);
    talus::tool_option_uint("--probe-steps", 400, 1, 1000000);
    if (talus::tool_option_given("--csv"))
      talus::require_output_file(talus::tool_option_value("--csv", ""), "option --csv");
  };
  tool.run     = [](dealii::ParameterHandler &prm, const std::string &) {
    return prm.get_integer("dimension") == 2 ? run<2>(prm) : run<3>(prm);
  };
  return talus::run_tool(argc, argv, tool);
}
