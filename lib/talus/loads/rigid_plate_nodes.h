// talus — the checks of the rigid plates on the grid that every family makes at
// setup, once (loads/rigid_plate.cc): each plate holds a grid node, no node
// belongs to two plates, and in every stage some node of each plate is free
// along its axis (a fixed/roller wall keeps the components it holds). The box
// grid's version that needs no grid (so --check finds the same errors) is
// check_rigid_plates_on_box in rigid_plate.h; both word their errors alike.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/loads/rigid_plate.h>

#include <mpi.h>

#include <string>
#include <vector>

namespace talus::loads
{
  /// What check_rigid_plate_nodes counted of one plate (over the ranks).
  struct RigidPlateNodes
  {
    unsigned long long              nodes = 0; ///< grid nodes it holds
    std::vector<unsigned long long> held;      ///< per stage: nodes whose axis component a wall holds
  };

  /// InputError naming 'boundary conditions/rigid plate k' when a plate holds
  /// no grid node, shares a node with another plate, or has its axis component
  /// held by the walls of stage j (`stage_walls[j]`; `stage_names[j]` in the
  /// message when there are several stages) at every one of its nodes. Returns
  /// the counts for the family's log line. Collective.
  template <int dim>
  std::vector<RigidPlateNodes> check_rigid_plate_nodes(const BackgroundGrid<dim>                         &grid,
                                                       const std::vector<RigidPlate<dim>>                &plates,
                                                       const std::vector<std::vector<BoundaryCondition>> &stage_walls,
                                                       const std::vector<std::string> &stage_names, MPI_Comm comm);

  /// One line per plate for the setup log: target, node count (and how many a
  /// wall holds along the axis in the first stage), direction, surface, control.
  template <int dim>
  std::string rigid_plate_log_line(const RigidPlate<dim> &plate, unsigned int k, const RigidPlateNodes &count);
} // namespace talus::loads
