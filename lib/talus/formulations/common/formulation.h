// talus — what every formulation family (explicit, implicit, semi-implicit)
// offers the one time loop (time_loop.h): a step, stages, a stability check,
// series.csv columns, VTU output, checkpoints and an end-of-run summary. The
// loop owns the cadence (when to step, write, check, save, report); the
// formulation owns the physics and its files' content.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace talus
{
  /// The run settings the time loop reads (sections time, output, checkpoint,
  /// stability of every tool's .prm).
  struct LoopSettings
  {
    double       end_time                 = 1.0;
    unsigned int max_steps                = 0; ///< 0: no limit
    std::string  output_directory         = "output";
    double       series_interval          = 0;     ///< simulated time between series rows, 0: every step
    double       vtu_interval             = 0;     ///< simulated time between VTU files, 0: first and last only
    double       checkpoint_interval      = 0;     ///< simulated time, 0: off
    double       checkpoint_wall_interval = 0;     ///< seconds of wall time, 0: off
    bool         progress                 = true;  ///< progress/ETA lines every 2 s of wall time
    bool         stop_on_lost_points      = false; ///< else: removed points are counted and reported
    /// Step cut-backs: a formulation that cannot complete a step (Newton did
    /// not converge) asks for it; the loop retries with half the step, at most
    /// this many times in a row, then stops the run.
    unsigned int max_cut_backs = 6;
  };

  /// The state of a run that the loop advances and a checkpoint saves.
  struct RunState
  {
    double       time = 0, dt = 0;
    unsigned int step_number = 0;
    /// Stage of a staged calculation, and the simulated time it started.
    unsigned int current_stage    = 0;
    double       stage_start_time = 0;
    /// Output cadence a restart resumes.
    struct RunCounters
    {
      unsigned int       vtu_counter = 0;
      double             next_series = 0, next_vtu = 0, next_checkpoint = 0;
      unsigned long long lost_reported = 0;
    };
    RunCounters counters;
    /// Set when the state came from a checkpoint (its path).
    std::string restored_from;
    /// Steps redone with a smaller step since the start (not saved).
    unsigned int cut_backs = 0;
  };

  /// Wall-clock figures of the loop, handed to the formulation's summary.
  struct LoopTimings
  {
    double output = 0; ///< series rows, VTU, checkpoints
    double total  = 0; ///< the whole loop
    /// the VTU snapshots (write_vtu) of the run, the one before the loop included
    double       snapshots   = 0;
    unsigned int n_snapshots = 0;
  };

  enum class StepOutcome
  {
    done,    ///< the state is at t + h
    cut_back ///< the state is unchanged at t; retry with a smaller step
  };

  class Formulation : public RunState
  {
  public:
    virtual ~Formulation() = default;

    /// "talus-explicit", ... (log prefix)
    virtual std::string tool_name() const = 0;
    /// The lines printed once before the first step (grid, points, time step).
    virtual void describe(std::ostream &out) const = 0;

    // ---- stages (a run without stages has one)
    virtual unsigned int
    n_stages() const
    {
      return 1;
    }
    /// Enter stage k; returns the simulated time at which it ends. `first` is
    /// true for the first stage this process runs, `resumed` when the state
    /// comes from a checkpoint taken inside stage k.
    virtual double begin_stage(const unsigned int k, const bool first, const bool resumed) = 0;
    /// A stage that ends on a criterion (quasi-static convergence): true when
    /// met, with a line for the log.
    virtual bool
    stage_converged(std::string &)
    {
      return false;
    }

    // ---- one step
    /// Called before each step: the step of size h is the last of the run, or
    /// a series row follows it (diagnostics such as energies are needed).
    virtual void
    before_step(const double /*h*/, const bool /*diagnostics_due*/)
    {
    }
    /// Advance the state from `time` by h (the loop then moves time and
    /// step_number). Throws InstabilityError when the state became invalid.
    virtual StepOutcome advance_by(const double h) = 0;
    /// After each step: throws InstabilityError when the run went unstable.
    virtual void check_stability() const = 0;
    /// After each completed and checked step (e.g. rebalance the partition).
    virtual void
    after_step()
    {
    }
    /// Material points removed so far because they left the grid.
    virtual unsigned long long
    lost_points() const
    {
      return 0;
    }

    // ---- output
    /// Once before the first row: fill what the first row reports.
    virtual void
    prepare_output()
    {
    }
    /// series.csv columns after time, step, stage.
    virtual std::vector<std::string> series_columns() const = 0;
    /// Values of those columns (collective; only rank 0's are written).
    /// `after_step` is false for the row of the initial state.
    virtual std::vector<double> series_values(const bool after_step) = 0;
    /// Write output file set number `counter` (collective).
    virtual void write_vtu(const unsigned int counter) = 0;
    /// After a restart: rewrite the PVD records up to the checkpoint.
    virtual void
    rewrite_records()
    {
    }
    /// Write a checkpoint of the full state (collective); returns its name.
    virtual std::string write_checkpoint() = 0;
    /// After the loop, when series.csv is complete: final files (results, CSV).
    virtual void
    finish(const std::string & /*series_csv*/)
    {
    }
    /// The closing lines of the log.
    virtual void summary(const LoopTimings &timings) = 0;
  };
} // namespace talus
