// talus — where a condition acts, as the shared .prm vocabulary words it
// (issue 37): 'apply to' = boundary | region [| a body choice], with
// 'boundary id', 'region lower corner', 'region upper corner' [and 'body'].
// Declared and parsed once for 'loads/traction k', 'loads/velocity k',
// 'boundary conditions/rigid plate k' and 'boundary conditions/drainage k';
// each condition keeps its own target enum and fields (they are copied from
// the NodeTarget the parse returns).
#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/types.h>

#include <string>

namespace talus::loads
{
  /// What one kind of section offers in 'apply to' and how its entries are checked.
  struct NodeTargetEntries
  {
    std::string choices;        ///< the Selection of 'apply to', e.g. "boundary|region"
    std::string default_choice; ///< its default
    std::string help;           ///< the documentation of 'apply to'
    std::string body_choice;    ///< the choice that names a body ('body', 'body face'); empty: no 'body' entry
    /// a region may be flat (upper corner == lower corner along an axis: a
    /// plane of grid nodes); otherwise it must exceed the lower corner in every
    /// direction
    bool flat_region = false;
    /// boundary ids may come from a grid file: checked against the box grid's
    /// ids only when the parse is told the grid is a box, and against 0..255;
    /// otherwise always against the box grid's ids
    bool grid_file_ids = false;
  };

  template <int dim>
  struct NodeTarget
  {
    enum class Kind
    {
      boundary, ///< the grid nodes of the faces with `boundary`
      region,   ///< the box [lower, upper]
      body      ///< body `body` (the choice NodeTargetEntries::body_choice)
    };
    Kind                       kind     = Kind::boundary;
    dealii::types::boundary_id boundary = 0;
    dealii::Point<dim>         lower, upper;
    unsigned int               body = 0;
  };

  /// Declare 'apply to', 'boundary id', 'region lower corner', 'region upper
  /// corner' and, with a body choice, 'body' in the current subsection.
  void declare_node_target(dealii::ParameterHandler &prm, unsigned int dim, const NodeTargetEntries &entries);

  /// Parse them in the current subsection; `where` is the subsection's path
  /// (errors name `where`/entry). InputError: a boundary id the grid lacks (a
  /// box grid: 0..2 dim - 1; `box_grid` says whether the grid is a box where
  /// the entries allow grid-file ids), a region upside down (or flat where not
  /// allowed), a body beyond `n_bodies`.
  template <int dim>
  NodeTarget<dim> parse_node_target(dealii::ParameterHandler &prm, const std::string &where,
                                    const NodeTargetEntries &entries, bool box_grid = true, unsigned int n_bodies = 0);

  /// Copy the boundary id and the region of `t` into a condition (its own
  /// `boundary`, `lower`, `upper`).
  template <class Condition, int dim>
  void
  copy_node_target(const NodeTarget<dim> &t, Condition &c)
  {
    c.boundary = t.boundary;
    c.lower    = t.lower;
    c.upper    = t.upper;
  }
} // namespace talus::loads
