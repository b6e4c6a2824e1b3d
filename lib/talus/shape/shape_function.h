// talus — which shape functions a run's particle-grid transfers use
// ('numerics/shape function', the same entry in every family). The kernels
// themselves are the policies of q1_box.h and bspline2_box.h.
#pragma once

namespace talus
{
  enum class ShapeFunction
  {
    linear,           ///< Q1 on the box cells (shape/q1_box.h)
    quadratic_bspline ///< quadratic B-splines, 3^dim nodes per point (shape/bspline2_box.h)
  };
} // namespace talus
