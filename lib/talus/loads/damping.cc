#include <talus/base/errors.h>
#include <talus/loads/damping.h>

#include <cmath>
#include <sstream>

namespace talus::loads
{
  void
  declare_damping(dealii::ParameterHandler &prm, const bool stage)
  {
    using dealii::Patterns::Double;
    const std::string inherit = stage ? " -1: as the top-level 'damping'." : "";
    prm.enter_subsection("damping");
    prm.declare_entry("local damping", stage ? "-1" : "0", Double(stage ? -1 : 0, 1),
                      "Local damping factor alpha of seed 000 §6.3 (Eq. 6.23): nodal f_damp = -alpha |f| sign(v); "
                      "0 = off; 0.7-0.8 for quasi-static runs. talus-explicit only (the others refuse a value "
                      "other than 0)." +
                        inherit);
    prm.declare_entry("viscous damping", stage ? "-1" : "0", Double(stage ? -1 : 0),
                      "Mass-proportional (Rayleigh alpha) damping alpha_v [1/s], C = alpha_v M: nodal f_damp = "
                      "-alpha_v m_i v_i (the damping of the granular column collapse of seed 001 §6.1, alpha = "
                      "1.5 1/s); 0 = off. talus-explicit; talus-implicit with 'analysis = dynamic' (with the "
                      "mass matrix of 'implicit/mass matrix'); refused by talus-semi-implicit." +
                        inherit);
    if (!stage)
      prm.declare_entry("stiffness damping", "0", Double(0),
                        "Stiffness-proportional (Rayleigh beta) damping beta [s], C += beta K: K the material + "
                        "geometric tangent at the start of each step, held for the step so that Newton's tangent "
                        "stays exact; a mode of frequency omega gets the damping ratio beta omega / 2. Rows and "
                        "columns of constrained DoFs carry no damping force. 0 = off. talus-implicit with "
                        "'analysis = dynamic' and 'formulation = irreducible' only (the others refuse a value "
                        "other than 0).");
    prm.leave_subsection();
  }

  Damping
  parse_damping(dealii::ParameterHandler &prm, const std::string &path, const Damping *base)
  {
    const std::string pre = (path.empty() ? "" : path + "/") + "damping/";
    Damping           d;
    prm.enter_subsection("damping");
    const double a  = prm.get_double("local damping");
    const double av = prm.get_double("viscous damping");
    d.local         = (a < 0 && base) ? base->local : a;
    d.viscous       = (av < 0 && base) ? base->viscous : av;
    d.stiffness     = base ? base->stiffness : prm.get_double("stiffness damping");
    prm.leave_subsection();
    require(d.local >= 0 && d.local < 1, pre + "local damping", "must be in [0, 1)");
    require(d.viscous >= 0 && std::isfinite(d.viscous), pre + "viscous damping", "must be >= 0 [1/s]");
    require(d.stiffness >= 0 && std::isfinite(d.stiffness), pre + "stiffness damping", "must be >= 0 [s]");
    return d;
  }

  void
  refuse_damping(const double value, const std::string &entry, const std::string &tool, const std::string &reason)
  {
    std::ostringstream v;
    v << value;
    require(value == 0, "damping/" + entry, "is " + v.str() + ": " + tool + " cannot honour it: " + reason);
  }
} // namespace talus::loads
