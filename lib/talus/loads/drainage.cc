#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/drainage.h>
#include <talus/loads/node_target.h>

#include <deal.II/base/utilities.h>

#include <cmath>

namespace talus::loads
{
  using dealii::Patterns::Anything;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  namespace
  {
    constexpr unsigned int max_drainage = 16;

    const NodeTargetEntries drainage_target{
      "boundary|region",
      "boundary",
      "'boundary': every grid node of the faces with 'boundary id' that carries water; 'region': the grid nodes on "
      "the material's free surface (a vertex of a wet and of a dry cell) inside the region box, e.g. a loaded face "
      "beside dry cells.",
      "",
      /*flat_region=*/false,
      /*grid_file_ids=*/true};
  } // namespace

  template <int dim>
  bool
  Drainage<dim>::holds(const dealii::Point<dim> &x, const dealii::Point<dim> &grid_lower,
                       const dealii::Point<dim> &grid_upper) const
  {
    if (target == Target::boundary)
      {
        const unsigned int d    = boundary / 2;
        const double       face = boundary % 2 ? grid_upper[d] : grid_lower[d];
        return std::abs(x[d] - face) <= 1e-9 * (grid_upper[d] - grid_lower[d]);
      }
    for (unsigned int d = 0; d < dim; ++d)
      {
        const double tol = 1e-9 * (grid_upper[d] - grid_lower[d]);
        if (x[d] < lower[d] - tol || x[d] > upper[d] + tol)
          return false;
      }
    return true;
  }

  unsigned int
  peek_drainage(const std::string &prm_file)
  {
    if (prm_file.empty())
      return 0;
    return dealii::Utilities::string_to_int(
      peek_entry(prm_file, "boundary conditions", "number of drainage conditions", "0", Integer(0, max_drainage)));
  }

  void
  declare_drainage_parameters(dealii::ParameterHandler &prm, const unsigned int dim, const unsigned int n)
  {
    prm.declare_entry("number of drainage conditions", "0", Integer(0, max_drainage),
                      "Number of 'drainage k' subsections: what the pore water does at a grid boundary id or at "
                      "the material's surface inside a region (two-phase families that solve for the pore "
                      "pressure; docs/boundary-conditions.md).");
    for (unsigned int k = 0; k < n; ++k)
      {
        prm.enter_subsection("drainage " + std::to_string(k));
        declare_node_target(prm, dim, drainage_target);
        prm.declare_entry("condition", "drained", Selection("drained|impermeable|pressure"),
                          "drained: the pore pressure is 0 there and the water leaves or enters freely (at a "
                          "boundary its velocity normal to the face is not held by the wall); impermeable: no "
                          "water crosses (a wall's default; on a region's surface: the surface is sealed, its "
                          "pressure is solved); pressure: the pore pressure is 'pressure' x the time function "
                          "(the water crosses as at a drained face).");
        prm.declare_entry("pressure", "", Anything(),
                          "condition = pressure: the pore pressure [Pa] in the family's sign convention "
                          "(talus-semi-implicit: tension positive, so a water pressure of 10 kPa is -1e4).");
        declare_time_function(prm, "the pressure", "the absolute time");
        prm.leave_subsection();
      }
  }

  template <int dim>
  std::vector<Drainage<dim>>
  parse_drainage_parameters(dealii::ParameterHandler &prm, const bool box_grid)
  {
    std::vector<Drainage<dim>> out;
    const unsigned int         n = prm.get_integer("number of drainage conditions");
    for (unsigned int k = 0; k < n; ++k)
      {
        Drainage<dim> c;
        c.where = "boundary conditions/drainage " + std::to_string(k);
        prm.enter_subsection("drainage " + std::to_string(k));
        const auto t = parse_node_target<dim>(prm, c.where, drainage_target, box_grid);
        copy_node_target(t, c);
        c.target =
          t.kind == NodeTarget<dim>::Kind::boundary ? Drainage<dim>::Target::boundary : Drainage<dim>::Target::region;
        const std::string kind = prm.get("condition"), value = prm.get("pressure");
        c.kind = kind == "drained"       ? Drainage<dim>::Kind::drained
                 : kind == "impermeable" ? Drainage<dim>::Kind::impermeable
                                         : Drainage<dim>::Kind::pressure;
        if (c.kind == Drainage<dim>::Kind::pressure)
          {
            const auto v = parse_doubles(value, c.where + "/pressure");
            require(v.size() == 1 && std::isfinite(v[0]), c.where + "/pressure",
                    "condition = pressure needs one number [Pa] (got '" + value + "')");
            c.pressure = v[0];
          }
        else
          require(dealii::Utilities::trim(value).empty(), c.where + "/pressure",
                  "is given but the condition is '" + kind + "'; allowed: a pressure with condition = pressure only");
        c.function = parse_time_function(prm, c.where);
        prm.leave_subsection();
        out.push_back(c);
      }
    return out;
  }

  template <int dim>
  Drainage<dim>
  drained_boundary(const dealii::types::boundary_id id, const std::string &where)
  {
    Drainage<dim> c;
    c.target   = Drainage<dim>::Target::boundary;
    c.boundary = id;
    c.kind     = Drainage<dim>::Kind::drained;
    c.where    = where;
    return c;
  }

  template struct Drainage<2>;
  template struct Drainage<3>;
  template std::vector<Drainage<2>> parse_drainage_parameters<2>(dealii::ParameterHandler &, bool);
  template std::vector<Drainage<3>> parse_drainage_parameters<3>(dealii::ParameterHandler &, bool);
  template Drainage<2>              drained_boundary<2>(dealii::types::boundary_id, const std::string &);
  template Drainage<3>              drained_boundary<3>(dealii::types::boundary_id, const std::string &);
} // namespace talus::loads
