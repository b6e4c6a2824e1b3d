#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/time_loop.h>
#include <talus/io/output.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

namespace talus
{
  namespace
  {
    /// The step number of a series.csv row (its second column), or -1.
    long long
    row_step(const std::string &line)
    {
      const auto c1 = line.find(','), c2 = line.find(',', c1 + 1);
      if (c1 == std::string::npos || c2 == std::string::npos)
        return -1;
      return std::stoll(line.substr(c1 + 1, c2 - c1 - 1));
    }
  } // namespace

  TimeLoop::TimeLoop(Formulation &formulation, const LoopSettings &s, MPI_Comm c)
      : f(formulation)
      , settings(s)
      , comm(c)
  {
  }

  double
  TimeLoop::step(const double h_wanted)
  {
    double h = h_wanted;
    for (unsigned int cuts = 0;; ++cuts)
      {
        if (f.advance_by(h) == StepOutcome::done)
          return h;
        if (cuts == settings.max_cut_backs)
          {
            std::ostringstream os;
            os << "step " << f.step_number + 1 << " (t = " << f.time << " s): the step could not be completed even "
               << "after " << cuts << " cut-backs to dt = " << h << " s";
            throw InstabilityError(os.str());
          }
        ++f.cut_backs;
        h /= 2;
        log() << "  step " << f.step_number + 1 << " (t = " << f.time << " s): cut back to dt = " << h << " s"
              << std::endl;
        f.before_step(h, true);
      }
  }

  void
  TimeLoop::report_lost_points()
  {
    const unsigned long long lost = f.lost_points();
    if (lost <= f.counters.lost_reported)
      return;
    std::ostringstream os;
    os << "step " << f.step_number << " (t = " << f.time << " s): " << lost - f.counters.lost_reported
       << " material point(s) left the grid (" << lost << " in total)";
    f.counters.lost_reported = lost;
    if (settings.stop_on_lost_points)
      throw RunStopped(os.str() + "; 'stability/lost particles = stop'. Enlarge the grid or add boundary conditions.");
    log() << "  warning: " << os.str() << "; removed" << std::endl;
  }

  void
  TimeLoop::advance_steps(const unsigned int n_steps)
  {
    for (unsigned int i = 0; i < n_steps; ++i)
      {
        f.before_step(f.dt, false);
        f.time += step(f.dt);
        ++f.step_number;
        f.check_stability();
      }
  }

  void
  TimeLoop::run()
  {
    const bool         root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
    const std::string &dir  = settings.output_directory;
    if (root)
      {
        std::filesystem::create_directories(dir);
        // temporaries of a killed run (a complete file was never replaced)
        for (const auto &e : std::filesystem::directory_iterator(dir))
          if (e.path().extension() == ".part")
            std::filesystem::remove(e.path());
      }
    MPI_Barrier(comm);
    const bool restored = !f.restored_from.empty();
    if (restored)
      log() << f.tool_name() << ": restarting from " << f.restored_from << " (step " << f.step_number
            << ", t = " << f.time << " s)" << std::endl;
    f.describe(log());

    // series.csv: written as .part while running, renamed when the run ends
    std::unique_ptr<io::AtomicFile> series;
    if (root)
      {
        series  = std::make_unique<io::AtomicFile>(dir + "/series.csv");
        auto &s = series->stream();
        s << "time,step,stage";
        for (const auto &c : f.series_columns())
          s << "," << c;
        s << "\n" << std::setprecision(12);
        if (restored)
          {
            // the rows up to the checkpoint, from the series.csv committed with it
            std::ifstream old(dir + "/series.csv");
            std::string   line;
            unsigned int  kept = 0;
            for (std::getline(old, line); std::getline(old, line);)
              {
                const long long k = row_step(line);
                if (k < 0 || k > static_cast<long long>(f.step_number))
                  break;
                s << line << "\n";
                ++kept;
              }
            if (kept == 0)
              log() << "  warning: no series.csv rows before the checkpoint were found; series.csv restarts "
                       "at the checkpoint"
                    << std::endl;
          }
      }
    const auto write_series_row = [&](const bool after_step) {
      const std::vector<double> values = f.series_values(after_step);
      if (!root)
        return;
      auto &s = series->stream();
      s << f.time << "," << f.step_number << "," << f.current_stage;
      for (const double v : values)
        s << "," << v;
      s << "\n";
    };

    f.prepare_output();
    auto       &counters = f.counters;
    LoopTimings timings;
    const auto  snapshot = [&]() {
      const auto t0 = Clock::now();
      f.write_vtu(counters.vtu_counter++);
      timings.snapshots += seconds_since(t0);
      ++timings.n_snapshots;
    };
    if (!restored)
      {
        write_series_row(false);
        snapshot();
        counters.next_series     = settings.series_interval;
        counters.next_vtu        = settings.vtu_interval;
        counters.next_checkpoint = settings.checkpoint_interval;
      }
    else
      f.rewrite_records(); // the series up to the checkpoint (a VTU written after it is rewritten)

    auto       t_checkpoint   = Clock::now();
    const auto checkpoint_due = [&](const bool last) {
      if (last)
        return false;
      bool due = settings.checkpoint_interval > 0 && f.time >= counters.next_checkpoint - 1e-9 * f.dt;
      if (settings.checkpoint_wall_interval > 0)
        {
          // rank 0's clock decides, so that every rank takes part
          int w = seconds_since(t_checkpoint) >= settings.checkpoint_wall_interval ? 1 : 0;
          MPI_Bcast(&w, 1, MPI_INT, 0, comm);
          due = due || w;
        }
      return due;
    };

    const auto  t_start  = Clock::now();
    auto        t_report = t_start;
    bool        failed   = false; // unstable or stopped: the run ends after series.csv is closed
    bool        unstable = false;
    std::string failure;
    // stages (one without a staged .prm); a restarted run resumes in current_stage
    const unsigned int n_stages    = f.n_stages();
    bool               run_stopped = false; // max steps reached
    bool               first_stage = true;
    for (; f.current_stage < n_stages && !failed && !run_stopped; ++f.current_stage)
      {
        const double end_time   = f.begin_stage(f.current_stage, first_stage, restored && first_stage);
        first_stage             = false;
        const double eps_t      = 1e-9 * f.dt;
        bool         stage_done = false;
        while (!stage_done && f.time < end_time - eps_t &&
               (settings.max_steps == 0 || f.step_number < settings.max_steps))
          {
            // A remainder below 1e-3 dt after this step is taken with it: the sum of a
            // million steps drifts from the stage's end by up to ~1e-4 dt, and a sliver
            // step of its own is not harmless (talus-semi-implicit's pressure increment
            // scales with 1/h: docs/semi-implicit.md, 'The smoothing at low k')
            double h = std::min(f.dt, end_time - f.time);
            if (end_time - f.time - h < 1e-3 * f.dt)
              h = end_time - f.time;
            bool last_step =
              !(f.time + h < end_time - eps_t) || (settings.max_steps && f.step_number + 1 >= settings.max_steps);
            bool series_due = settings.series_interval == 0 || f.time + h >= counters.next_series - eps_t || last_step;
            f.before_step(h, series_due);
            try
              {
                const double taken = step(h);
                if (taken < h)
                  last_step = false; // a cut-back step leaves the rest of the stage to do
                f.time += taken;
                ++f.step_number;
                f.check_stability();
                report_lost_points();
                f.after_step();
              }
            catch (const InstabilityError &e)
              {
                failed = unstable = true;
                failure           = e.what();
                break;
              }
            catch (const RunStopped &e)
              {
                failed  = true;
                failure = e.what();
                break;
              }
            std::string converged;
            if (f.stage_converged(converged))
              {
                stage_done = last_step = series_due = true;
                log() << std::setprecision(6) << "  stage " << f.current_stage << " converged at step " << f.step_number
                      << " (t = " << f.time << " s): " << converged << std::endl;
              }
            auto t0 = Clock::now();
            if (series_due)
              {
                write_series_row(true);
                while (counters.next_series <= f.time + eps_t)
                  counters.next_series += settings.series_interval > 0 ? settings.series_interval : f.dt;
              }
            if ((settings.vtu_interval > 0 && f.time >= counters.next_vtu - eps_t) || last_step)
              {
                snapshot();
                while (settings.vtu_interval > 0 && counters.next_vtu <= f.time + eps_t)
                  counters.next_vtu += settings.vtu_interval;
              }
            if (checkpoint_due(last_step))
              {
                while (settings.checkpoint_interval > 0 && counters.next_checkpoint <= f.time + eps_t)
                  counters.next_checkpoint += settings.checkpoint_interval;
                if (root)
                  {
                    // series.csv up to now, committed with the checkpoint
                    series->stream().flush();
                    const std::string out = dir + "/series.csv";
                    std::filesystem::copy_file(out + ".part", out + ".copy.part",
                                               std::filesystem::copy_options::overwrite_existing);
                    std::filesystem::rename(out + ".copy.part", out);
                  }
                const std::string name = f.write_checkpoint();
                t_checkpoint           = Clock::now();
                if (settings.progress)
                  log() << "  checkpoint " << name << " (step " << f.step_number << ", t = " << f.time << " s)"
                        << std::endl;
              }
            timings.output += seconds_since(t0);
            if (settings.progress && seconds_since(t_report) > 2.0)
              {
                t_report          = Clock::now();
                const double el   = seconds_since(t_start);
                const double frac = std::max(f.time / settings.end_time,
                                             settings.max_steps ? double(f.step_number) / settings.max_steps : 0.0);
                log() << "  step " << f.step_number << "  t = " << std::setprecision(4) << f.time << " s  ("
                      << std::setprecision(3) << 100 * frac << " %)  elapsed " << el << " s  ETA "
                      << el * (1 - frac) / std::max(frac, 1e-12) << " s" << std::endl;
              }
          }
        if (settings.max_steps && f.step_number >= settings.max_steps)
          run_stopped = true;
      }
    if (f.current_stage >= n_stages)
      f.current_stage = n_stages - 1; // the last stage stays the current one after the run
    timings.total = seconds_since(t_start);
    if (root)
      series->commit();
    if (unstable)
      throw InstabilityError(failure + " Output up to the last stable step is in " + dir + ".");
    if (failed)
      throw RunStopped(failure + " Output up to the previous step is in " + dir + ".");
    f.finish(dir + "/series.csv");
    f.summary(timings);
  }
} // namespace talus
