// talus-semi-implicit: the semi-implicit two-phase double-point MPM (seed 002),
// driven by a .prm file.
#include <talus/base/tool.h>
#include <talus/formulations/common/tool_options.h>
#include <talus/formulations/semi_implicit/semi_implicit.h>

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-semi-implicit";
  tool.summary = "Semi-implicit two-phase double-point material point method (seed 002, Xie, Navas &\n"
                 "López-Querol 2025): soil and water as two sets of material points on one grid, an\n"
                 "incremental fractional step with implicit Darcy drag and one pressure-increment Poisson\n"
                 "solve per step (CG + ML AMG), quadratic B-splines (or linear). The time step is limited\n"
                 "by the soil skeleton only. Writes soil.pvd / water.pvd (+ PVTU/VTU), series.csv and, with\n"
                 "'output/final particles csv', soil_final.csv and water_final.csv.";
  tool.declare = &talus::semi_implicit::declare_parameters;
  tool.check   = &talus::semi_implicit::check_parameters;
  tool.run     = &talus::semi_implicit::run;
  tool.options = talus::formulation_tool_options();
  return talus::run_tool(argc, argv, tool);
}
