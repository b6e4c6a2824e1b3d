// talus — mesh preparation (talus-mesh): the background grid (a structured box,
// or a gmsh quad/hex mesh with boundary and material ids from its physical
// groups) and the material points of the bodies (seeded in grid cells for .prm
// shapes and grid regions, or per element of a separate gmsh body mesh), with the
// checks of docs/mesh.md. Serial: talus-mesh runs it on rank 0.
#pragma once

#include <talus/io/grid_mesh.h>
#include <talus/io/particle_file.h>
#include <talus/mesh/gmsh_model.h>
#include <talus/particles/material_points.h>

#include <map>
#include <string>
#include <vector>

namespace talus::mesh
{
  template <int dim>
  struct BodySpec
  {
    enum class Source
    {
      box,
      ball,
      polygon,
      grid, ///< the grid cells of some physical groups of the grid mesh (all cells if none given)
      gmsh  ///< the elements of a gmsh body mesh
    };
    std::string              name;
    Source                   source = Source::box;
    BodyDescription<dim>     shape; ///< box / ball / polygon geometry (contains())
    std::vector<std::string> groups;
    std::string              file;         ///< gmsh body mesh (.geo or .msh)
    int                      material = 0; ///< -1: from the "material <id>" groups of the mesh
    unsigned int             n        = 2; ///< points per direction
    bool                     gauss    = false;
    // optional K0 initial stress (vertical axis = last coordinate)
    double k0            = 0; ///< 0: no initial stress
    double k0_density    = 0;
    double k0_gravity    = 9.81;
    double surface_level = std::numeric_limits<double>::quiet_NaN(); ///< NaN: top of the body
  };

  template <int dim>
  struct Settings
  {
    bool                                grid_from_gmsh = false;
    double                              lower[3] = {0, 0, 0}, upper[3] = {1, 1, 1};
    std::vector<unsigned int>           cells;
    std::string                         grid_file; ///< .geo / .msh
    GmshOptions                         grid_options;
    std::map<std::string, unsigned int> boundary_map, material_map; ///< normalised group name -> id
    bool                                allow_distorted = false;
    std::vector<BodySpec<dim>>          bodies;
  };

  struct Summary
  {
    std::map<unsigned int, std::size_t> faces_per_boundary, cells_per_material;
    std::vector<std::size_t>            points_per_body;
    std::vector<double>                 volume_per_body;
    std::vector<std::string>            notes; ///< ignored groups, flipped surfaces, ...
  };

  template <int dim>
  struct Result
  {
    io::GridMesh      grid;
    io::ParticleTable particles;
    Summary           summary;
  };

  /// Build the grid and the points and run every check; InputError (naming the
  /// cell, element, particle or group) on any failure.
  template <int dim>
  Result<dim> prepare(const Settings<dim> &settings);

  /// --check: the referenced files open and every physical group the settings
  /// name exists (geometry only, nothing is meshed).
  template <int dim>
  void check_groups(const Settings<dim> &settings);
} // namespace talus::mesh
