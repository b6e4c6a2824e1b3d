// Wall kinematics shared by every family (loads/kinematics.h): on a 4 x 3 box,
// bottom (y-, id 2) fixed and left (x-, id 0) roller flag exactly the DoFs they
// name (bottom: both components of its 5 nodes; left: the x component of its 4
// nodes, the corner counted once); the constraints on a vector NodalSpace hold
// the same DoFs, homogeneous; an id the grid lacks is refused naming the entry.
#include <talus/base/errors.h>
#include <talus/grid/background_grid.h>
#include <talus/grid/nodal_space.h>
#include <talus/loads/kinematics.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

#include <string>

using namespace talus;

TEST(Kinematics, FixedAndRollerFlagsAndConstraints)
{
  constexpr int       dim = 2;
  BackgroundGrid<dim> grid(MPI_COMM_WORLD);
  grid.make_box(dealii::Point<dim>(0, 0), dealii::Point<dim>(4, 3), {4, 3});
  grid.setup();
  const std::vector<BoundaryCondition> bcs   = {{2, BoundaryCondition::Kind::fixed},
                                                {0, BoundaryCondition::Kind::roller}};
  const auto                           flags = loads::wall_dof_flags(grid, bcs);

  // the position and component of every flagged local DoF, from the cells' vertices
  unsigned int               n_flagged = 0, n_expected = 0;
  std::vector<unsigned char> seen(flags.size(), 0);
  for (const auto &cell : grid.dof_handler.active_cell_iterators())
    if (!cell->is_artificial())
      for (unsigned int v = 0; v < 4; ++v)
        for (unsigned int k = 0; k < dim; ++k)
          {
            const unsigned int i = grid.cells[cell->active_cell_index()].dofs[v * dim + k];
            if (seen[i])
              continue;
            seen[i]          = 1;
            const auto x     = cell->vertex(v);
            const bool fixed = x[1] == 0.0, roller = x[0] == 0.0 && k == 0;
            n_expected += (fixed || roller);
            n_flagged += flags[i];
            EXPECT_EQ(flags[i] != 0, fixed || roller) << "node (" << x[0] << ", " << x[1] << "), component " << k;
          }
  EXPECT_EQ(n_expected, 10u + 3u);
  EXPECT_EQ(n_flagged, 13u);

  NodalSpace<dim> space(grid, dim);
  space.setup();
  const auto   walls   = loads::wall_constraints(grid, space, flags);
  unsigned int n_lines = 0;
  for (const auto &line : walls.get_lines())
    {
      ++n_lines;
      EXPECT_TRUE(line.entries.empty());
      EXPECT_EQ(line.inhomogeneity, 0.0);
    }
  EXPECT_EQ(n_lines, 13u);
  for (const auto &cell : grid.dof_handler.active_cell_iterators())
    if (!cell->is_artificial())
      for (unsigned int v = 0; v < 4; ++v)
        for (unsigned int k = 0; k < dim; ++k)
          {
            const auto &cc = grid.cells[cell->active_cell_index()];
            EXPECT_EQ(walls.is_constrained(space.node_dof(cc.dofs[v * dim], k)), flags[cc.dofs[v * dim + k]] != 0);
          }

  try
    {
      loads::wall_dof_flags(grid, {{7, BoundaryCondition::Kind::fixed}});
      FAIL() << "a boundary id the grid lacks must be refused";
    }
  catch (const InputError &e)
    {
      EXPECT_NE(std::string(e.what()).find("boundary conditions"), std::string::npos) << e.what();
    }
}
