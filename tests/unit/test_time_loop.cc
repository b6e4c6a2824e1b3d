// The one time loop (formulations/common/time_loop.h) driving a stand-in
// formulation: exact exponential decay y(t) = exp(-lambda t), so that the state
// at any time is known whatever steps the loop took. Checks the cadence of
// series rows, output sets and checkpoints, stages (by end time and by a
// convergence criterion), step cut-backs, lost points and max steps.
#include <talus/base/errors.h>
#include <talus/formulations/common/time_loop.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace
{
  using namespace talus;

  struct Decay : Formulation
  {
    double lambda = 2.0, y = 1.0;
    // stages: end times; a stage with a threshold ends when y drops below it
    std::vector<double> stage_end       = {1.0};
    std::vector<double> stage_threshold = {0.0};
    double              largest_step    = 1e9; ///< steps above this are refused (cut back)
    unsigned long long  lost = 0, lose_at_step = 0;
    std::vector<double> vtu_times, checkpoint_times, steps_taken;
    bool                finished          = false;
    unsigned int        diagnostics_steps = 0;

    std::string
    tool_name() const override
    {
      return "talus-test";
    }
    void
    describe(std::ostream &out) const override
    {
      out << "decay\n";
    }
    unsigned int
    n_stages() const override
    {
      return stage_end.size();
    }
    double
    begin_stage(const unsigned int k, const bool, const bool) override
    {
      return stage_end[k];
    }
    bool
    stage_converged(std::string &message) override
    {
      if (stage_threshold[current_stage] > 0 && y < stage_threshold[current_stage])
        {
          message = "y below threshold";
          return true;
        }
      return false;
    }
    void
    before_step(const double, const bool diagnostics_due) override
    {
      diagnostics_steps += diagnostics_due;
    }
    StepOutcome
    advance_by(const double h) override
    {
      if (h > largest_step * (1 + 1e-12))
        return StepOutcome::cut_back;
      y *= std::exp(-lambda * h);
      steps_taken.push_back(h);
      if (lose_at_step && step_number + 1 == lose_at_step)
        lost += 3;
      return StepOutcome::done;
    }
    void
    check_stability() const override
    {
      if (!std::isfinite(y))
        throw InstabilityError("y is not finite");
    }
    unsigned long long
    lost_points() const override
    {
      return lost;
    }
    std::vector<std::string>
    series_columns() const override
    {
      return {"y"};
    }
    std::vector<double>
    series_values(const bool) override
    {
      return {y};
    }
    void
    write_vtu(const unsigned int counter) override
    {
      EXPECT_EQ(counter, vtu_times.size());
      vtu_times.push_back(time);
    }
    std::string
    write_checkpoint() override
    {
      checkpoint_times.push_back(time);
      return "checkpoint-" + std::to_string(step_number);
    }
    void
    finish(const std::string &series_csv) override
    {
      finished = std::filesystem::exists(series_csv);
    }
    void
    summary(const LoopTimings &t) override
    {
      EXPECT_GE(t.total, t.output);
    }
  };

  std::string
  scratch(const std::string &name)
  {
    const std::string dir =
      "time_loop_test_" + name + "_" + std::to_string(dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD));
    std::filesystem::remove_all(dir);
    return dir;
  }

  /// (time, step, stage, y) rows of series.csv
  std::vector<std::array<double, 4>>
  read_series(const std::string &dir)
  {
    std::ifstream                      in(dir + "/series.csv");
    std::string                        line;
    std::vector<std::array<double, 4>> rows;
    std::getline(in, line);
    EXPECT_EQ(line, "time,step,stage,y");
    while (std::getline(in, line))
      {
        std::array<double, 4> r;
        std::stringstream     ss(line);
        std::string           cell;
        for (unsigned int k = 0; k < 4 && std::getline(ss, cell, ','); ++k)
          r[k] = std::stod(cell);
        rows.push_back(r);
      }
    return rows;
  }
} // namespace

TEST(TimeLoop, CadenceOfRowsOutputAndCheckpoints)
{
  Decay f;
  f.dt = 0.03; // 1/0.03 is not an integer: the last step is shortened
  LoopSettings s;
  s.end_time            = 1.0;
  s.output_directory    = scratch("cadence");
  s.series_interval     = 0.1;
  s.vtu_interval        = 0.25;
  s.checkpoint_interval = 0.4;
  s.progress            = false;
  TimeLoop(f, s, MPI_COMM_SELF).run();

  EXPECT_NEAR(f.time, 1.0, 1e-14);
  EXPECT_EQ(f.step_number, 34u);
  EXPECT_NEAR(f.steps_taken.back(), 1.0 - 33 * 0.03, 1e-14);
  EXPECT_NEAR(f.y, std::exp(-2.0), 1e-14);
  EXPECT_TRUE(f.finished);
  // rows: t = 0, then the first step at or after each 0.1 mark, and the last
  const auto rows = read_series(s.output_directory);
  ASSERT_EQ(rows.size(), 11u);
  EXPECT_EQ(rows[0][0], 0.0);
  for (unsigned int k = 1; k < rows.size(); ++k)
    {
      EXPECT_GE(rows[k][0], 0.1 * k - 1e-12);
      EXPECT_LT(rows[k][0], 0.1 * k + 0.03);
      EXPECT_NEAR(rows[k][3], std::exp(-2.0 * rows[k][0]), 1e-10 * rows[k][3]); // 12 digits written
    }
  EXPECT_NEAR(rows.back()[0], 1.0, 1e-12);
  // output sets: t = 0, the first step at or after 0.25, 0.5, 0.75, and the end
  ASSERT_EQ(f.vtu_times.size(), 5u);
  EXPECT_NEAR(f.vtu_times[1], 0.27, 1e-12);
  EXPECT_NEAR(f.vtu_times[2], 0.51, 1e-12);
  EXPECT_NEAR(f.vtu_times[3], 0.75, 1e-12);
  // checkpoints at the first steps at or after 0.4 and 0.8, none at the end
  ASSERT_EQ(f.checkpoint_times.size(), 2u);
  EXPECT_NEAR(f.checkpoint_times[0], 0.42, 1e-12);
  EXPECT_NEAR(f.checkpoint_times[1], 0.81, 1e-12);
  // diagnostics are asked for exactly before the steps that write a row
  EXPECT_EQ(f.diagnostics_steps, rows.size() - 1);
  std::filesystem::remove_all(s.output_directory);
}

TEST(TimeLoop, StagesEndByTimeOrByConvergence)
{
  Decay f;
  f.dt              = 0.01;
  f.stage_end       = {0.5, 10.0, 11.0};
  f.stage_threshold = {0.0, 0.1, 0.0}; // stage 1 ends when y < 0.1 (t = ln 10 / 2 = 1.151)
  LoopSettings s;
  s.end_time         = 11.0;
  s.output_directory = scratch("stages");
  s.series_interval  = 1.0;
  s.progress         = false;
  TimeLoop(f, s, MPI_COMM_SELF).run();
  const auto rows = read_series(s.output_directory);
  // stage 0 ends at 0.5 exactly; stage 1 at the first step with y < 0.1
  bool seen_end0 = false, seen_conv = false;
  for (const auto &r : rows)
    {
      if (r[2] == 0 && std::abs(r[0] - 0.5) < 1e-12)
        seen_end0 = true;
      if (r[2] == 1 && r[3] < 0.1)
        {
          EXPECT_NEAR(r[0], 1.16, 1e-9);
          seen_conv = true;
        }
    }
  EXPECT_TRUE(seen_end0);
  EXPECT_TRUE(seen_conv);
  // stage 2 ran from 1.16 to 11
  EXPECT_EQ(f.current_stage, 2u);
  EXPECT_NEAR(f.time, 11.0, 1e-12);
  EXPECT_NEAR(f.y, std::exp(-22.0), 1e-12 * std::exp(-22.0));
  std::filesystem::remove_all(s.output_directory);
}

TEST(TimeLoop, CutBackHalvesTheStepAndKeepsTheState)
{
  Decay f;
  f.dt           = 0.1;
  f.largest_step = 0.06; // every full step is cut once: 0.1 -> 0.05
  f.stage_end    = {0.5};
  LoopSettings s;
  s.end_time         = 0.5;
  s.output_directory = scratch("cutback");
  s.progress         = false;
  s.max_cut_backs    = 3;
  TimeLoop(f, s, MPI_COMM_SELF).run();
  for (const double h : f.steps_taken)
    EXPECT_NEAR(h, 0.05, 1e-15);
  EXPECT_EQ(f.steps_taken.size(), 10u);
  EXPECT_EQ(f.cut_backs, 9u); // the last step (0.05 left) needs none
  EXPECT_NEAR(f.time, 0.5, 1e-12);
  EXPECT_NEAR(f.y, std::exp(-1.0), 1e-13);
  // the last set of output files is written at the end, not at a cut-back step
  EXPECT_NEAR(f.vtu_times.back(), 0.5, 1e-12);

  // too many cut-backs: the run stops, series.csv up to the last step stays
  Decay g;
  g.dt               = 0.1;
  g.largest_step     = 0.001;
  s.output_directory = scratch("cutback_fail");
  s.max_cut_backs    = 3;
  EXPECT_THROW(TimeLoop(g, s, MPI_COMM_SELF).run(), InstabilityError);
  EXPECT_TRUE(std::filesystem::exists(s.output_directory + "/series.csv"));
  EXPECT_FALSE(g.finished);
  EXPECT_EQ(g.step_number, 0u);
  std::filesystem::remove_all(s.output_directory);
  std::filesystem::remove_all(scratch("cutback"));
}

TEST(TimeLoop, LostPointsAndMaxSteps)
{
  Decay f;
  f.dt           = 0.01;
  f.lose_at_step = 5;
  LoopSettings s;
  s.end_time         = 1.0;
  s.max_steps        = 20;
  s.output_directory = scratch("lost");
  s.progress         = false;
  TimeLoop(f, s, MPI_COMM_SELF).run(); // reported as a warning, run goes on
  EXPECT_EQ(f.step_number, 20u);
  EXPECT_EQ(f.counters.lost_reported, 3u);
  EXPECT_NEAR(f.vtu_times.back(), 0.2, 1e-12); // max steps: the last step writes output

  Decay g;
  g.dt                  = 0.01;
  g.lose_at_step        = 5;
  s.stop_on_lost_points = true;
  s.output_directory    = scratch("lost_stop");
  EXPECT_THROW(TimeLoop(g, s, MPI_COMM_SELF).run(), RunStopped);
  EXPECT_EQ(g.step_number, 5u);
  const auto rows = read_series(s.output_directory);
  EXPECT_EQ(rows.back()[1], 4.0); // rows up to the step before the stop
  std::filesystem::remove_all(s.output_directory);
  std::filesystem::remove_all(scratch("lost"));
}

TEST(TimeLoop, AdvanceStepsChecksStability)
{
  Decay f;
  f.dt     = 0.1;
  f.lambda = -1e308; // y overflows in the first step
  LoopSettings s;
  EXPECT_THROW(TimeLoop(f, s, MPI_COMM_SELF).advance_steps(3), InstabilityError);
  EXPECT_EQ(f.step_number, 1u);
}
