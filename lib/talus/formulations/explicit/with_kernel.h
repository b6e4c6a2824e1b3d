// talus — the explicit solver's kernel dispatch (Solver::with_kernel), for the
// .cc files whose walks are templates on the shape kernel (the solver's step,
// the loads' point-force scatters): one place that maps numerics/shape function
// to a kernel type.
#pragma once

#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>

namespace talus::explicit_mpm
{
  template <int dim>
  template <class F>
  void
  Solver<dim>::with_kernel(F &&f)
  {
    if (prm.numerics.bspline())
      f(shape::BSpline2Box<dim>());
    else
      f(shape::Q1Box<dim>());
  }
} // namespace talus::explicit_mpm
