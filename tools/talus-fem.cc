// talus-fem: the explicit solver of talus-explicit with the integration points at
// the Gauss points of the grid cells (numerics/integration defaults to 'fem';
// 'ul-fem' for the updated Lagrangian variant). Same .prm, same time loop,
// same outputs as talus-explicit; see docs/fem.md.
#include <talus/base/tool.h>
#include <talus/formulations/common/tool_options.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/input_checks.h>

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-fem";
  tool.summary = "Explicit dynamic finite elements on the background grid, from the same code as\n"
                 "talus-explicit (Anura3D FEM / UL-FEM modes): the integration points are the 2^dim\n"
                 "Gauss points of every cell covered by a body (volume = JxW, mass = density x JxW) and\n"
                 "stay there. numerics/integration = fem (default here): small strain on the fixed mesh;\n"
                 "ul-fem: the mesh follows the material. mpm | mpm-mixed are accepted too (then this is\n"
                 "talus-explicit). Same .prm and outputs as talus-explicit (series.csv, VTU, results file).";
  tool.declare = [](dealii::ParameterHandler &prm, const std::string &file) {
    talus::explicit_mpm::declare_parameters_with_integration(prm, file, "fem");
  };
  tool.check   = &talus::explicit_mpm::check_scene;
  tool.run     = &talus::explicit_mpm::run;
  tool.options = talus::formulation_tool_options();
  return talus::run_tool(argc, argv, tool);
}
