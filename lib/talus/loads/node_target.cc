#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/loads/node_target.h>

namespace talus::loads
{
  void
  declare_node_target(dealii::ParameterHandler &prm, const unsigned int dim, const NodeTargetEntries &entries)
  {
    using dealii::Patterns::Anything;
    using dealii::Patterns::Integer;
    prm.declare_entry("apply to", entries.default_choice, dealii::Patterns::Selection(entries.choices), entries.help);
    prm.declare_entry("boundary id", "0", Integer(0), "Grid boundary id (apply to = boundary).");
    prm.declare_entry("region lower corner", zeros_text(dim), Anything(), "Region: lower corner [m].");
    prm.declare_entry("region upper corner", zeros_text(dim), Anything(), "Region: upper corner [m].");
    if (!entries.body_choice.empty())
      prm.declare_entry("body", "0", Integer(0), "Body id (apply to = " + entries.body_choice + ").");
  }

  template <int dim>
  NodeTarget<dim>
  parse_node_target(dealii::ParameterHandler &prm, const std::string &where, const NodeTargetEntries &entries,
                    const bool box_grid, const unsigned int n_bodies)
  {
    using Kind = typename NodeTarget<dim>::Kind;
    NodeTarget<dim>   t;
    const std::string a = prm.get("apply to");
    t.kind              = a == "boundary" ? Kind::boundary : a == "region" ? Kind::region : Kind::body;
    if (t.kind == Kind::boundary)
      {
        const unsigned int b    = prm.get_integer("boundary id");
        const std::string  last = std::to_string(2 * dim - 1);
        if (entries.grid_file_ids)
          {
            require(!box_grid || b < 2 * dim, where + "/boundary id",
                    "boundary id " + std::to_string(b) + " does not exist in the grid (a " + std::to_string(dim) +
                      "D box grid has ids 0.." + last + ")");
            require(b < 256, where + "/boundary id", "boundary ids are 0..255");
          }
        else
          require(b < 2 * dim, where + "/boundary id",
                  "boundary id " + std::to_string(b) + " does not exist (box grid ids 0.." + last + ")");
        t.boundary = static_cast<dealii::types::boundary_id>(b);
      }
    else if (t.kind == Kind::region)
      {
        t.lower = parse_point<dim>(prm.get("region lower corner"), where + "/region lower corner");
        t.upper = parse_point<dim>(prm.get("region upper corner"), where + "/region upper corner");
        for (unsigned int d = 0; d < dim; ++d)
          if (entries.flat_region)
            require(t.upper[d] >= t.lower[d], where + "/region upper corner",
                    "must not be below 'region lower corner'");
          else
            require(t.upper[d] > t.lower[d], where + "/region upper corner",
                    "must exceed 'region lower corner' in every direction");
      }
    else
      {
        t.body = prm.get_integer("body");
        require(t.body < n_bodies, where + "/body",
                "body " + std::to_string(t.body) + " is not defined (number of bodies = " + std::to_string(n_bodies) +
                  ")");
      }
    return t;
  }

  template NodeTarget<2> parse_node_target<2>(dealii::ParameterHandler &, const std::string &,
                                              const NodeTargetEntries &, bool, unsigned int);
  template NodeTarget<3> parse_node_target<3>(dealii::ParameterHandler &, const std::string &,
                                              const NodeTargetEntries &, bool, unsigned int);
} // namespace talus::loads
