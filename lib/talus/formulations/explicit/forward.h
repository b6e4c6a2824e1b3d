// talus — forward declarations of the explicit family's classes, for headers
// that only name them (one place instead of one copy per header).
#pragma once

namespace talus::loads
{
  template <int dim>
  class LoadControl;
}

namespace talus::explicit_mpm
{
  template <int dim>
  class Solver;
  struct Energies;
} // namespace talus::explicit_mpm
