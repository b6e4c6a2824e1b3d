#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/kinematics.h>
#include <talus/loads/rigid_plate.h>

#include <deal.II/base/utilities.h>

#include <cmath>

namespace talus::loads
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {
    constexpr unsigned int max_rigid_plates = 4;
  }

  template <int dim>
  PrescribedVelocity<dim>
  RigidPlate<dim>::node_condition() const
  {
    PrescribedVelocity<dim> v;
    v.target   = target == Target::boundary ? PrescribedVelocity<dim>::Target::boundary
                                            : PrescribedVelocity<dim>::Target::region;
    v.boundary = boundary;
    v.lower    = lower;
    v.upper    = upper;
    for (unsigned int d = 0; d < dim; ++d)
      v.component[d] = rough || d == axis;
    v.where = where;
    return v;
  }

  unsigned int
  peek_rigid_plates(const std::string &prm_file)
  {
    if (prm_file.empty())
      return 0;
    return dealii::Utilities::string_to_int(peek_entry(prm_file, "boundary conditions", "number of rigid plates", "0",
                                                       Integer(0, max_rigid_plates)));
  }

  void
  declare_rigid_plate_parameters(dealii::ParameterHandler &prm, const unsigned int dim, const unsigned int n)
  {
    prm.declare_entry("number of rigid plates", "0", Integer(0, max_rigid_plates),
                      "Number of 'rigid plate k' subsections: sets of grid nodes that move as one rigid body "
                      "along one axis, driven by a total force or by a displacement history (docs/boundary-conditions.md).");
    for (unsigned int k = 0; k < n; ++k)
      {
        prm.enter_subsection("rigid plate " + std::to_string(k));
        prm.declare_entry("apply to", "boundary", Selection("boundary|region"),
                          "'boundary': every grid node of the faces with 'boundary id'; 'region': the grid nodes "
                          "inside the region box (e.g. a footing on the material's surface).");
        prm.declare_entry("boundary id", "0", Integer(0), "Boundary id (apply to = boundary).");
        prm.declare_entry("region lower corner", zeros_text(dim), Anything(), "Region: lower corner [m].");
        prm.declare_entry("region upper corner", zeros_text(dim), Anything(), "Region: upper corner [m].");
        prm.declare_entry("direction", dim == 2 ? "y" : "z", Selection(dim == 2 ? "x|y" : "x|y|z"),
                          "The grid axis along which the plate moves.");
        prm.declare_entry("surface", "frictionless", Selection("frictionless|rough"),
                          "frictionless: the other velocity components of the plate's nodes are free; rough: they "
                          "are held at zero (no slip).");
        prm.declare_entry("total force", "", Anything(),
                          "Force control: the force the plate exerts on the material along +direction [N; per unit "
                          "thickness in 2D] (negative pushes towards -direction), times the time function; the "
                          "plate's displacement is an unknown. Give this or 'displacement'.");
        prm.declare_entry("displacement", "", Anything(),
                          "Displacement control: the plate's displacement along +direction [m], times the time "
                          "function; its reaction is reported. Give this or 'total force'.");
        prm.declare_entry("time function", "constant", Anything(),
                          "Factor f(t) of the force or displacement (absolute time): constant | step T | ramp T1 | "
                          "ramp T0 T1 | table t0:f0, t1:f1, ... | table file NAME.csv.");
        prm.declare_entry("drainage", "impermeable", Selection("impermeable|permeable"),
                          "Two-phase families: 'permeable': the pore pressure is zero at the plate's nodes (the "
                          "water drains through it); 'impermeable': no water crosses the plate. One-phase runs ignore it.");
        prm.leave_subsection();
      }
  }

  template <int dim>
  std::vector<RigidPlate<dim>>
  parse_rigid_plate_parameters(dealii::ParameterHandler &prm, const bool box_grid)
  {
    std::vector<RigidPlate<dim>> plates;
    const unsigned int           n = prm.get_integer("number of rigid plates");
    for (unsigned int k = 0; k < n; ++k)
      {
        RigidPlate<dim> p;
        p.where = "boundary conditions/rigid plate " + std::to_string(k);
        prm.enter_subsection("rigid plate " + std::to_string(k));
        if (prm.get("apply to") == "boundary")
          {
            p.target             = RigidPlate<dim>::Target::boundary;
            const unsigned int b = prm.get_integer("boundary id");
            require(!box_grid || b < 2 * dim, p.where + "/boundary id",
                    "boundary id " + std::to_string(b) + " does not exist in the grid (a " + std::to_string(dim) +
                      "D box grid has ids 0.." + std::to_string(2 * dim - 1) + ")");
            require(b < 256, p.where + "/boundary id", "boundary ids are 0..255");
            p.boundary = static_cast<dealii::types::boundary_id>(b);
          }
        else
          {
            p.target = RigidPlate<dim>::Target::region;
            p.lower  = parse_point<dim>(prm.get("region lower corner"), p.where + "/region lower corner");
            p.upper  = parse_point<dim>(prm.get("region upper corner"), p.where + "/region upper corner");
            for (unsigned int d = 0; d < dim; ++d)
              require(p.upper[d] >= p.lower[d], p.where + "/region upper corner",
                      "must not be below 'region lower corner'");
          }
        p.axis                  = static_cast<unsigned int>(prm.get("direction")[0] - 'x');
        p.rough                 = prm.get("surface") == "rough";
        const std::string force = prm.get("total force"), disp = prm.get("displacement");
        require(force.empty() != disp.empty(), p.where,
                force.empty() ? "give 'total force' (force control) or 'displacement' (displacement control)"
                              : "give either 'total force' or 'displacement', not both");
        if (!force.empty())
          {
            const auto v = parse_doubles(force, p.where + "/total force");
            require(v.size() == 1, p.where + "/total force", "one number [N] (the component along 'direction')");
            p.control = RigidPlate<dim>::Control::force;
            p.force   = v[0];
          }
        else
          {
            const auto v = parse_doubles(disp, p.where + "/displacement");
            require(v.size() == 1, p.where + "/displacement", "one number [m] (the component along 'direction')");
            p.control      = RigidPlate<dim>::Control::displacement;
            p.displacement = v[0];
          }
        p.function  = TimeFunction::parse(prm.get("time function"), p.where + "/time function");
        p.permeable = prm.get("drainage") == "permeable";
        prm.leave_subsection();
        plates.push_back(p);
      }
    return plates;
  }

  template <int dim>
  std::vector<PrescribedNodeDof>
  rigid_plate_node_dofs(const BackgroundGrid<dim> &grid, const std::vector<RigidPlate<dim>> &plates, const bool owned_only)
  {
    std::vector<PrescribedVelocity<dim>> conditions;
    for (const auto &p : plates)
      conditions.push_back(p.node_condition());
    return prescribed_node_dofs(grid, conditions, owned_only);
  }

  template <int dim>
  std::vector<std::string>
  rigid_plate_series_columns(const std::vector<RigidPlate<dim>> &plates)
  {
    std::vector<std::string> c;
    for (unsigned int k = 0; k < plates.size(); ++k)
      {
        const std::string p = "plate_" + std::to_string(k) + "_";
        c.push_back(p + "displacement");
        c.push_back(p + "force");
        if (plates[k].rough)
          c.push_back(p + "tangential_force");
      }
    return c;
  }

  template <int dim>
  void
  refuse_rigid_plates(const std::vector<RigidPlate<dim>> &plates, const std::string &tool, const std::string &reason)
  {
    require(plates.empty(), plates.empty() ? std::string() : plates.front().where,
            tool + " cannot honour a rigid plate: " + reason);
  }

  template struct RigidPlate<2>;
  template struct RigidPlate<3>;
  template std::vector<RigidPlate<2>> parse_rigid_plate_parameters<2>(dealii::ParameterHandler &, bool);
  template std::vector<RigidPlate<3>> parse_rigid_plate_parameters<3>(dealii::ParameterHandler &, bool);
  template std::vector<PrescribedNodeDof> rigid_plate_node_dofs(const BackgroundGrid<2> &,
                                                                const std::vector<RigidPlate<2>> &, bool);
  template std::vector<PrescribedNodeDof> rigid_plate_node_dofs(const BackgroundGrid<3> &,
                                                                const std::vector<RigidPlate<3>> &, bool);
  template std::vector<std::string> rigid_plate_series_columns(const std::vector<RigidPlate<2>> &);
  template std::vector<std::string> rigid_plate_series_columns(const std::vector<RigidPlate<3>> &);
  template void refuse_rigid_plates(const std::vector<RigidPlate<2>> &, const std::string &, const std::string &);
  template void refuse_rigid_plates(const std::vector<RigidPlate<3>> &, const std::string &, const std::string &);
} // namespace talus::loads
