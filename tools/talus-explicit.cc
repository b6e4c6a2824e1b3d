// talus-explicit: explicit dynamic MPM (Anura3D-style), driven by a .prm file.
#include <talus/base/tool.h>
#include <talus/formulations/common/tool_options.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/input_checks.h>

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name    = "talus-explicit";
  tool.summary = "Explicit dynamic material point method, 1-phase solid (seed 000 §4.3): lumped mass,\n"
                 "momentum-based nodal velocities, Jaumann-rate stress update, background grid of\n"
                 "axis-aligned quads/hexes, material points seeded in box/ball/polygon bodies.\n"
                 "Writes particles.pvd (+ VTU/PVTU), series.csv (energies, momentum, probes).";
  tool.declare = &talus::explicit_mpm::declare_parameters;
  tool.check   = &talus::explicit_mpm::check_scene;
  tool.run     = &talus::explicit_mpm::run;
  tool.options = talus::formulation_tool_options();
  return talus::run_tool(argc, argv, tool);
}
