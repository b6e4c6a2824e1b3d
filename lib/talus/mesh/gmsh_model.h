// talus — what talus-mesh needs from a gmsh model, read through the gmsh C++ API
// (a .geo is meshed here, a .msh is read as it is): nodes, the first-order
// elements of dimension dim and dim-1 with the geometric entity they belong to,
// and the physical groups with their names. Serial (call on one rank).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace talus::mesh
{
  struct GmshElement
  {
    int                       type;   ///< gmsh element type (3 = quad, 5 = hex, 2 = triangle, 4 = tet, 1 = line)
    std::uint64_t             tag;    ///< gmsh element tag
    int                       entity; ///< tag of the geometric entity of dimension `dim` it belongs to
    std::vector<unsigned int> nodes;  ///< indices into GmshModel::nodes, gmsh order
  };

  struct GmshGroup
  {
    int              dim, tag;
    std::string      name; ///< empty for an unnamed group
    std::vector<int> entities;
    std::string      describe() const; ///< "'name' (dimension 2, tag 5)" / "unnamed (dimension 2, tag 5)"
  };

  struct GmshModel
  {
    unsigned int                       dim = 2;
    std::string                        file;
    bool                               meshed = false;
    std::vector<std::array<double, 3>> nodes;
    std::vector<GmshElement>           cells;  ///< elements of dimension dim
    std::vector<GmshElement>           facets; ///< elements of dimension dim - 1
    std::vector<GmshGroup>             groups; ///< physical groups of every dimension
    /// Elements that repeated an earlier one (same nodes) and were dropped: a MSH
    /// 2.2 file lists an element once per physical group it belongs to.
    std::size_t duplicates = 0;
    /// Group of dimension d referenced by name (case-insensitive, blanks
    /// collapsed) or, if `ref` is an integer, by tag; nullptr if none.
    const GmshGroup *find(int d, const std::string &ref) const;
    std::string      list_groups(int d) const; ///< for messages
  };

  struct GmshOptions
  {
    bool recombine = true;  ///< .geo: Mesh.RecombineAll (2D quads; 3D with transfinite/extruded volumes)
    bool subdivide = false; ///< .geo: Mesh.SubdivisionAlgorithm = all quads (2D) / all hexes (3D)
    bool generate  = true;  ///< false: only the geometry and its groups (for --check)
    /// Round the node coordinates to 10 decimal digits below the extent of the
    /// mesh (gmsh places transfinite nodes with errors of ~1e-12 of the extent;
    /// rounding restores 0.0625 from 0.062500000000260125).
    bool round_coordinates = true;
  };

  /// Open `file` (.geo: mesh it with gmsh; .msh: read it). InputError naming the
  /// file (and `where`) for: a gmsh error, no elements of dimension dim,
  /// second-order (or higher) elements anywhere in the mesh.
  GmshModel load_gmsh(const std::string &file, unsigned int dim, const GmshOptions &options, const std::string &where);

  /// Normalised group name: lower case, blanks collapsed and trimmed.
  std::string normalise_name(const std::string &name);
  /// Parse "<kind> <id> [label]" (kind "boundary" or "material"); -1 if the name does not follow it.
  long convention_id(const std::string &name, const std::string &kind);
} // namespace talus::mesh
