// talus — the one time loop of every formulation family: stages, steps with
// cut-back, stability and lost-point checks, series.csv, VTU cadence,
// checkpoints (time and wall-clock), progress/ETA, the end-of-run files.
#pragma once

#include <talus/formulations/common/formulation.h>

#include <mpi.h>

namespace talus
{
  class TimeLoop
  {
  public:
    TimeLoop(Formulation &formulation, const LoopSettings &settings, MPI_Comm comm);

    /// Run from the formulation's state (t = 0 or a restored checkpoint) to
    /// the end time or max steps, with all output. Throws InstabilityError or
    /// RunStopped after closing series.csv (output up to the last good step
    /// stays).
    void run();

    /// n steps of the formulation's time step with the stability check after
    /// each and no output (probes, tests, the critical-time-step tool).
    void advance_steps(const unsigned int n_steps);

  private:
    /// One step of size h with cut-backs; returns the step actually taken.
    double step(const double h);
    void   report_lost_points();

    Formulation        &f;
    const LoopSettings &settings;
    MPI_Comm            comm;
  };
} // namespace talus
