// talus — the explicit solver's results file (output/results file): the shared
// writer (formulations/common/results_file.h) on its one point set; FEM
// points stay at their Gauss points (position = location + u).
#include <talus/formulations/common/results_file.h>
#include <talus/formulations/explicit/explicit_solver.h>

namespace talus::explicit_mpm
{
  template <int dim>
  void
  Solver<dim>::write_results(const std::string &series_csv) const
  {
    ResultsFileInfo info;
    info.path               = prm.results_file;
    info.integration        = prm.numerics.integration_name();
    info.time               = time;
    info.steps              = step_number;
    info.position_is_origin = fem && !fem->updated_lagrangian();
    write_results_file(info, grid, points, probes.ids, series_csv, comm);
  }

  template void Solver<2>::write_results(const std::string &) const;
  template void Solver<3>::write_results(const std::string &) const;
} // namespace talus::explicit_mpm
