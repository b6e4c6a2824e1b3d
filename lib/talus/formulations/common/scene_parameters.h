// talus — the .prm sections every formulation family shares: the scene (grid,
// boundary conditions, gravity, materials, bodies) and the run (end time,
// maximum steps, lost points, output, checkpoint). A family declares these,
// then adds its own entries (in their own subsections, or by entering a shared
// subsection again: e.g. the explicit 'time/courant number'), parses them into
// these structs and its own.
#pragma once

#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/initial_stress.h>
#include <talus/grid/background_grid.h>
#include <talus/io/grid_mesh.h>
#include <talus/loads/rigid_plate.h>
#include <talus/materials/material.h>
#include <talus/particles/material_points.h>
#include <talus/shape/shape_function.h>
#include <talus/transfer/fbar.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <memory>
#include <string>
#include <vector>

namespace talus
{
  /// Grid, boundary conditions, gravity, materials, bodies and the shape functions.
  template <int dim>
  struct SceneParameters
  {
    // grid: a box from grid_lower/upper/cells, or (grid/source = file) the mesh
    // of a grid file, read and checked while parsing (grid_lower/upper are then
    // its bounding box, grid_cells = {number of cells, 1, ...})
    dealii::Point<dim>                  grid_lower, grid_upper;
    std::vector<unsigned int>           grid_cells;
    std::string                         grid_file;
    std::shared_ptr<const io::GridMesh> grid_mesh;
    std::vector<BoundaryCondition>      boundary_conditions;
    /// 'boundary conditions/rigid plate k' (loads/rigid_plate.h)
    std::vector<loads::RigidPlate<dim>>                     rigid_plates;
    dealii::Tensor<1, dim>                                  gravity;
    std::vector<std::shared_ptr<const materials::Material>> materials;
    std::vector<BodyDescription<dim>>                       bodies;
    /// 'body k/initial stress' of every body (initial_stress.h)
    std::vector<InitialStress> initial_stress;
    ShapeFunction              shape_function = ShapeFunction::linear;
    /// 'numerics/volumetric stabilisation' (transfer/fbar.h; each family refuses what it lacks)
    transfer::VolumetricStabilisation volumetric_stabilisation = transfer::VolumetricStabilisation::none;
    bool
    bspline() const
    {
      return shape_function == ShapeFunction::quadratic_bspline;
    }
  };

  /// End time, step limit, lost points, output and checkpoint settings.
  template <int dim>
  struct RunParameters
  {
    double       end_time               = 1.0;
    unsigned int max_steps              = 0;     ///< 0: no limit
    bool         stop_on_lost_particles = false; ///< else: remove them, count, go on
    // output
    std::string                     output_directory    = "output";
    double                          vtu_interval        = 0.0; ///< simulated time, 0: first and last
    double                          series_interval     = 0.0; ///< 0: every step
    bool                            write_grid          = false;
    bool                            final_particles_csv = false;
    bool                            progress            = true;
    std::vector<dealii::Point<dim>> probes;
    std::string                     results_file; ///< HDF5 results at the end ("": none)
    // checkpoint / restart
    double       checkpoint_interval      = 0; ///< simulated time, 0: off
    double       checkpoint_wall_interval = 0; ///< seconds of wall time, 0: off
    unsigned int checkpoint_keep          = 2;
    std::string  checkpoint_directory; ///< default <output>/checkpoints
    enum class Restart
    {
      no,
      yes,         ///< resume from the newest valid checkpoint, error if none
      if_available ///< resume if there is one, else start from t = 0
    };
    Restart restart = Restart::no;
    // load balancing by material points (subsection 'load balancing')
    struct Balance
    {
      unsigned int interval     = 0;   ///< steps between imbalance checks, 0: off
      double       threshold    = 1.1; ///< rebalance when max/mean points per rank exceeds it
      unsigned int point_weight = 100; ///< partition weight of a material point
      unsigned int cell_weight  = 1;   ///< partition weight of a cell (with or without points)
      bool
      enabled() const
      {
        return interval > 0;
      }
    };
    Balance balance;
  };

  /// The counts a .prm declares before its numbered subsections.
  struct SceneCounts
  {
    unsigned int dim = 2, n_materials = 1, n_bodies = 1, n_rigid_plates = 0;
  };
  /// 'dimension', 'number of materials', 'number of bodies', 'boundary
  /// conditions/number of rigid plates' read from the
  /// file before the declaration (the declaration depends on them).
  SceneCounts peek_scene_counts(const std::string &prm_file);

  /// Declare dimension, grid, boundary conditions, gravity, materials (the
  /// constitutive model entries of 'material k') and bodies ('body k': region,
  /// points per direction, clipping, initial velocity).
  void declare_scene_parameters(dealii::ParameterHandler &prm, const SceneCounts &counts);
  /// Declare time (end time, maximum steps), stability (lost particles), output
  /// (with io/png_snapshots' entries: 'png field' offers the fields of a run of
  /// dimension `dim` but those the family never writes), checkpoint and load
  /// balancing.
  void declare_run_parameters(dealii::ParameterHandler &prm, unsigned int dim = 3,
                              const std::vector<std::string> &png_fields_not_written = {});
  /// The head of every family's declaration: the counts peeked from `prm_file`,
  /// the scene and run entries, and 'time/time step' (default 0) with the
  /// family's own meaning in `time_step_doc`; `png_fields_not_written`: the
  /// talus-plot fields the family's VTU files never hold (e.g. {"pore pressure"}),
  /// refused in 'output/png field'. Returns the counts.
  SceneCounts declare_common_parameters(dealii::ParameterHandler &prm, const std::string &prm_file,
                                        const std::string              &time_step_doc,
                                        const std::vector<std::string> &png_fields_not_written = {});

  template <int dim>
  void parse_scene_parameters(dealii::ParameterHandler &prm, SceneParameters<dim> &p);
  template <int dim>
  void parse_run_parameters(dealii::ParameterHandler &prm, RunParameters<dim> &p);

  /// The time loop's settings from the run parameters.
  template <int dim>
  LoopSettings loop_settings(const RunParameters<dim> &p);

  /// The body entry 'clip to grid' (false: a body not wholly inside the grid is refused).
  void declare_clip_to_grid(dealii::ParameterHandler &prm);
  /// 'grid/cells': dim positive integers (cells per direction); InputError
  /// naming `where` and the offending item otherwise.
  std::vector<unsigned int> parse_cell_counts(const std::string &text, const std::string &where);
  /// Comma-separated non-negative integer ids (boundary ids, body ids).
  std::vector<unsigned int> parse_ids(const std::string &text, const std::string &where);
} // namespace talus
