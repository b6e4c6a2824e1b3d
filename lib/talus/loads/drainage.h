// talus — drainage conditions of the pore water (issue 37), the vocabulary of
// the two-phase families that solve for the pore pressure: per grid boundary id
// or per region box, 'drained' (p = 0), 'impermeable' (no flux: the default of
// a wall) or 'pressure' (a prescribed pore pressure times a time function).
// Declared in 'boundary conditions' as 'number of drainage conditions' and
// 'drainage k'. What a condition means on the grid (which nodes, which
// velocity components of the water are freed) is worded here; how a family
// enforces it stays with the family (talus-semi-implicit:
// formulations/semi_implicit/boundary_loads.h). Families that have no pressure
// unknown do not declare these entries.
#pragma once

#include <talus/loads/time_function.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/types.h>

#include <string>
#include <vector>

namespace talus::loads
{
  template <int dim>
  struct Drainage
  {
    enum class Target
    {
      boundary, ///< every grid node of the faces with `boundary` that carries water
      region    ///< the grid nodes on the material's free surface inside the box [lower, upper]
    };
    enum class Kind
    {
      drained,     ///< p = 0
      impermeable, ///< no water crosses (a boundary: the wall's default; a region: its surface is sealed)
      pressure     ///< p = pressure x f(t)
    };
    Target                     target   = Target::boundary;
    dealii::types::boundary_id boundary = 0;
    dealii::Point<dim>         lower, upper;
    Kind                       kind     = Kind::drained;
    double                     pressure = 0; ///< [Pa], the family's sign convention (tension positive)
    TimeFunction               function;
    std::string                where; ///< 'boundary conditions/drainage k' (or the alias that made it)

    double
    pressure_at(const double t) const
    {
      return kind == Kind::pressure ? pressure * function.value(t) : 0.0;
    }
    /// Whether a grid node at `x` is one of this condition's (a boundary: on
    /// the face; a region: inside the box), with the tolerance of
    /// prescribed_node_dofs (1e-9 of the grid's extent per axis).
    bool holds(const dealii::Point<dim> &x, const dealii::Point<dim> &grid_lower,
               const dealii::Point<dim> &grid_upper) const;
  };

  /// 'boundary conditions/number of drainage conditions' read from the file
  /// before the declaration.
  unsigned int peek_drainage(const std::string &prm_file);
  /// Declare 'number of drainage conditions' and 'drainage k' (k < n) in the
  /// current subsection ('boundary conditions').
  void declare_drainage_parameters(dealii::ParameterHandler &prm, unsigned int dim, unsigned int n);
  /// Parse them in the current subsection. InputError naming the entry: a
  /// boundary id a box grid does not have (`box_grid`), an empty or upside-down
  /// region, 'pressure' without a value or a value with another condition.
  template <int dim>
  std::vector<Drainage<dim>> parse_drainage_parameters(dealii::ParameterHandler &prm, bool box_grid);
  /// A drained boundary id (the alias 'semi implicit/drained boundaries').
  template <int dim>
  Drainage<dim> drained_boundary(dealii::types::boundary_id id, const std::string &where);
} // namespace talus::loads
