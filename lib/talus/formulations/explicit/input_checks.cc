#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/explicit/explicit_two_phase.h>
#include <talus/formulations/common/run_formulation.h>
#include <talus/formulations/common/scene_checks.h>
#include <talus/formulations/explicit/input_checks.h>
#include <talus/io/particle_file.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace talus::explicit_mpm
{

  template <int dim>
  double
  critical_time_step_of(const Parameters<dim> &p)
  {
    const double h  = smallest_cell_edge(p);
    double       dt = std::numeric_limits<double>::infinity();
    for (const auto &c : critical_time_steps(p.materials, p.liquid.pore_liquid, h))
      dt = std::min(dt, c.dt);
    // mass scaling (seed 000 Eq. 6.31): the step must suit the stage with the
    // smallest factor beta
    double beta = std::numeric_limits<double>::infinity();
    for (const auto &st : p.loads.stages)
      beta = std::min(beta, st.mass_scaling);
    if (std::isfinite(beta))
      dt *= std::sqrt(beta);
    return dt;
  }

  template <int dim>
  void
  check_consistency(const Parameters<dim> &p)
  {
    check_scene_consistency(p); // grid, boundary ids, memory, bodies (formulations/common/scene_checks.h)
    for (unsigned int k = 0; k < p.bodies.size() && k < p.liquid.tractions.size(); ++k)
      {
        const auto &b = p.bodies[k];
        if (p.liquid.tractions[k].face < 0)
          continue;
        if (b.shape == BodyDescription<dim>::Shape::file)
          throw InputError("body " + std::to_string(k) +
                           "/traction face: tractions are supported on box bodies only (this body is "
                           "read from a file; allowed here: none)");
        require(b.shape == BodyDescription<dim>::Shape::box, "body " + std::to_string(k) + "/traction face",
                "tractions are supported on box bodies only (this body is a " +
                  std::string(b.shape == BodyDescription<dim>::Shape::ball ? "ball" : "polygon") +
                  "; allowed here: none)");
      }
    // The 2-phase step calls the hooks of lib/talus/loads (stages, K0, tractions,
    // prescribed velocities, friction, damping, mass scaling, convergence; their
    // 2-phase meaning in docs/explicit-liquid-two-phase.md). One restriction is
    // left: mass scaling below 1 with coupled materials. Scaling the inertia of
    // both phases by beta changes the relaxation time of the relative (seepage)
    // velocity, beta (1 - n) rho_S k / (n rho g), by beta, not by sqrt(beta):
    // the step sqrt(beta) dt_cr of Eq. 6.31 is safe for beta >= 1 (the coupled
    // limit Eq. 4.129 grows at least as fast) and unstable for a drag-controlled
    // column with beta < 1.
    if (p.liquid.any_coupled())
      for (unsigned int k = 0; k < p.loads.stages.size(); ++k)
        require(p.loads.stages[k].mass_scaling >= 1.0,
                p.loads.staged ? "stage " + std::to_string(k) + "/mass scaling/factor"
                               : std::string("mass scaling/factor"),
                "must be >= 1 with coupled 2-phase materials: a factor beta < 1 shortens the drag relaxation time of "
                "the seepage by beta, and the time step sqrt(beta) x critical (Eq. 6.31) would be unstable "
                "(allowed: >= 1)");
    if (p.time_step > 0 && !p.force_time_step)
      {
        const double dt_cr = critical_time_step_of(p);
        if (p.time_step > dt_cr * (1 + 1e-12))
          {
            std::ostringstream os;
            os << "time/time step: " << p.time_step << " s exceeds the critical time step " << dt_cr;
            throw InputError(os.str() +
                             " s (seed 000 §4.6, smallest cell edge over the fastest wave speed); lower it, or set "
                             "'force time step = true' to run anyway");
          }
      }
  }


  void
  check_scene(dealii::ParameterHandler &prm, const std::string &)
  {
    check_formulation(prm, &parse_parameters<2>, &parse_parameters<3>);
  }


  template void   check_consistency<2>(const Parameters<2> &);
  template void   check_consistency<3>(const Parameters<3> &);
  template double critical_time_step_of<2>(const Parameters<2> &);
  template double critical_time_step_of<3>(const Parameters<3> &);
} // namespace talus::explicit_mpm
