// talus-implicit: implicit updated-Lagrangian MPM (seed 001, Iaconeta 2019), driven by a .prm file.
#include <talus/base/tool.h>
#include <talus/formulations/common/tool_options.h>
#include <talus/formulations/implicit/implicit_solver.h>

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-implicit";
  tool.summary = "Implicit updated-Lagrangian material point method (seed 001, Kratos MPM): every step\n"
                 "the grid is reset, Newton-Raphson solves the Newmark-discretised (or static) momentum\n"
                 "balance for the nodal displacement increment with the consistent tangent of the\n"
                 "finite-strain models, and the converged increment moves the points. Steps whose Newton\n"
                 "iteration fails are halved and retried. Writes particles.pvd (+ VTU/PVTU) and series.csv\n"
                 "(Newton iterations, residuals, observed order per step).";
  tool.declare = &talus::implicit_mpm::declare_parameters;
  tool.check   = &talus::implicit_mpm::check_scene;
  tool.run     = &talus::implicit_mpm::run;
  tool.options = talus::formulation_tool_options();
  return talus::run_tool(argc, argv, tool);
}
