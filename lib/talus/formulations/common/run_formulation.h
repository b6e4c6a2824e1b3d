// talus — the one `run()` of every formulation family's tool: dispatch on
// 'dimension', parse the family's parameters, build its Solver, set it up, run
// the time loop (time_loop.h), then write fields.txt and draw the pictures
// 'output/png snapshots' asks for (io/png_snapshots.h; every family, every point
// set it writes). A family's tool entry is one line:
//
//   int run(dealii::ParameterHandler &prm, const std::string &)
//   { return run_formulation<Solver>(prm, &parse_parameters<2>, &parse_parameters<3>); }
//
// Solver<dim> must be constructible from (const Parameters<dim> &, MPI_Comm),
// keep that reference, have setup(), and be a Formulation.
#pragma once

#include <talus/base/startup.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/io/png_snapshots.h>

#include <deal.II/base/parameter_handler.h>

#include <mpi.h>

#include <iomanip>
#include <sstream>

namespace talus
{
  /// Build, set up and run one Solver of one dimension over `p` (collective).
  template <class Solver, class Parameters>
  void
  run_solver(const Parameters &p, MPI_Comm comm)
  {
    Solver s(p, comm);
    s.setup();
    std::ostringstream startup; // its own stream: log()'s precision stays as it is
    startup << std::fixed << std::setprecision(2) << "  start-up: " << seconds_since_process_start()
            << " s from the process start to the first step (main entered at " << startup_seconds_until_main()
            << " s, MPI started at " << startup_seconds_until_mpi() << " s)\n";
    log() << startup.str();
    TimeLoop(s, loop_settings(p), comm).run();
  }

  /// The dimension dispatch of a family's tool; returns the exit code.
  template <template <int> class Solver, class Parameters2, class Parameters3>
  int
  run_formulation(dealii::ParameterHandler &prm, Parameters2 (*parse_2d)(dealii::ParameterHandler &),
                  Parameters3 (*parse_3d)(dealii::ParameterHandler &))
  {
    if (prm.get_integer("dimension") == 2)
      run_solver<Solver<2>>(parse_2d(prm), MPI_COMM_WORLD);
    else
      run_solver<Solver<3>>(parse_3d(prm), MPI_COMM_WORLD);
    io::draw_png_snapshots(prm, MPI_COMM_WORLD); // after every output file is complete
    return exit_ok;
  }

  /// The --check of a family's tool: parsing validates every entry (InputError
  /// names it), then the run's files (output and checkpoint directories,
  /// restart) are checked.
  template <class Parameters2, class Parameters3>
  void
  check_formulation(dealii::ParameterHandler &prm, Parameters2 (*parse_2d)(dealii::ParameterHandler &),
                    Parameters3 (*parse_3d)(dealii::ParameterHandler &))
  {
    if (prm.get_integer("dimension") == 2)
      check_run_files(parse_2d(prm));
    else
      check_run_files(parse_3d(prm));
  }
} // namespace talus

/// Explicit instantiation of a family's Parameters and parse_parameters for
/// dim 2 and 3 (in the family's parameters .cc, inside its namespace; the
/// Solver<dim> members are instantiated where they are defined).
#define TALUS_INSTANTIATE_PARAMETERS()                                    \
  template struct Parameters<2>;                                          \
  template struct Parameters<3>;                                          \
  template Parameters<2> parse_parameters<2>(dealii::ParameterHandler &); \
  template Parameters<3> parse_parameters<3>(dealii::ParameterHandler &)
