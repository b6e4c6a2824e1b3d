// talus — the run-time choice of the shape kernel: calls f(K()) with K the
// linear Q1 kernel or the quadratic B-spline one, so that a solver's walks,
// written as templates on the kernel, are instantiated once per kernel and
// chosen by its .prm entry (docs/shape-functions.md).
#pragma once

#include <talus/shape/bspline2_box.h>
#include <talus/shape/q1_box.h>

namespace talus::shape
{
  template <int dim, class F>
  inline void
  with_kernel(const bool bspline, F &&f)
  {
    if (bspline)
      f(BSpline2Box<dim>());
    else
      f(Q1Box<dim>());
  }
} // namespace talus::shape
