// talus — the explicit solver's kernel dispatch (Solver::with_kernel), for the
// .cc files whose walks are templates on the shape kernel (the solver's step,
// the loads' point-force scatters): one place that maps numerics/shape function
// to a kernel type.
#pragma once

#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/shape/with_kernel.h>

namespace talus::explicit_mpm
{
  template <int dim>
  template <class F>
  void
  Solver<dim>::with_kernel(F &&f)
  {
    shape::with_kernel<dim>(prm.bspline(), std::forward<F>(f));
  }
} // namespace talus::explicit_mpm
