// talus — pictures a run draws of itself (`output/png snapshots`): after a
// complete run, rank 0 runs tools/talus-plot (found next to the solver
// executable) on the output directory. Kept out of the solver so that the
// time loop only carries a declaration, a check and one call.
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <mpi.h>

#include <string>
#include <vector>

namespace talus::io
{
  /// Declare `png snapshots` and `png field` in the current subsection (output).
  /// `png field` allows the fields of talus-plot that a run of dimension `dim`
  /// can have (no z component in 2D) except `not_written`: the fields the
  /// family never writes (talus-implicit: pore pressure, free surface), so that
  /// asking for one is refused with exit 2 before the run. Fields that depend on
  /// the scene (pore pressure of an explicit run without pore liquid) are left to
  /// talus-plot after the run (a warning, docs/plot.md).
  void declare_png_snapshot_parameters(dealii::ParameterHandler &prm, unsigned int dim = 3,
                                       const std::vector<std::string> &not_written = {});

  /// Check them in the current subsection (output), before any run: with
  /// snapshots on, talus-plot must sit next to the solver executable and
  /// gnuplot must be on PATH (InputError naming the entry otherwise).
  void check_png_snapshot_parameters(dealii::ParameterHandler &prm);

  /// After a complete run of any family (every output file renamed into place),
  /// with prm at the top level: rank 0 writes <output directory>/fields.txt
  /// (dimension, integration ('mpm' for families without 'numerics/
  /// integration'), the history names of each material, for talus-plot) and,
  /// unless `png snapshots = none`, runs talus-plot. A failure to draw is
  /// reported as a warning on stderr and does not change the exit code of the
  /// run (its results are complete); never throws.
  void draw_png_snapshots(dealii::ParameterHandler &prm, MPI_Comm comm);
} // namespace talus::io
