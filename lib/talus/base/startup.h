// talus — the start-up time of a tool's process (docs/scaling.md, "Start-up").
#pragma once

#include <mpi.h>

namespace talus
{
  /// True between MPI_Init and MPI_Finalize. False in a singleton's --help,
  /// --print-parameters and --check (run_tool() starts no MPI for them): code on
  /// their path that talks to MPI asks first. deal.II 9.4's
  /// Utilities::MPI::n_mpi_processes / this_mpi_process do not ask: they call
  /// MPI_Comm_size / MPI_Comm_rank, which abort before MPI_Init.
  inline bool
  mpi_started()
  {
    int initialized = 0, finalized = 0;
    MPI_Initialized(&initialized);
    MPI_Finalized(&finalized);
    return initialized && !finalized;
  }

  /// Seconds from this process's start (the kernel's start time of the process,
  /// resolution 1/CLK_TCK = 10 ms) to now: dynamic loading and static
  /// initialisation included. Negative if /proc is not readable.
  double seconds_since_process_start();
  /// seconds_since_process_start() when run_tool() was entered (dynamic loading and
  /// static initialisation done); negative outside run_tool().
  double startup_seconds_until_main();
  /// seconds_since_process_start() when run_tool() had MPI started (or had
  /// decided to run without it); negative outside run_tool().
  double startup_seconds_until_mpi();
} // namespace talus
