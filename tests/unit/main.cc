// Shared GoogleTest main: MPI must be initialised for anything that touches
// deal.II's parallel classes.
#include <talus/base/mpi_session.h>

#include <deal.II/base/mpi.h>

#include <gtest/gtest.h>

int
main(int argc, char **argv)
{
  // private Open MPI session directory for singleton starts (base/mpi_session.h)
  const talus::PrivateMpiSessionBase       session_base;
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
