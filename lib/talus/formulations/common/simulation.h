// talus — what every formulation family's solver is built on: the grid, the
// material-point sets, the load balancer over them, and the output of the sets
// (VTU/PVD records, the final tables). A family's Solver derives from
// Simulation<dim> and adds its step, its nodal data and its own series columns;
// the time loop (time_loop.h) sees it as a Formulation.
//
// Why a base class and not an accessor object (ASPECT's SimulatorAccess): the
// three families share state, not a protocol — every step reads the grid and
// the point sets directly in its hot loops, and the load balancer must call back
// into the family after a repartition (grid_changed). Lethe's solvers over a
// shared core are the closer model: one owner of the mesh and the particles,
// the formulation as a derived class. Scene checks, seeding, diagnostics and
// checkpoints are free functions in this folder (scene_checks.h, seeding.h,
// diagnostics.h, point_checkpoint.h) that take the pieces held here.
#pragma once

#include <talus/formulations/common/formulation.h>
#include <talus/formulations/common/load_balance.h>
#include <talus/formulations/common/scene_parameters.h>
#include <talus/grid/background_grid.h>
#include <talus/particles/material_point_set.h>

#include <mpi.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace talus
{
  /// The Simulation members a Solver<dim> uses by name, declared in its class
  /// body: a class template does not look names up in a base that depends on
  /// its template parameter, so each needs a using-declaration.
#define TALUS_SIMULATION_MEMBERS                    \
  using Simulation<dim>::comm;                      \
  using Simulation<dim>::grid;                      \
  using Simulation<dim>::balance;                   \
  using Simulation<dim>::point_sets;                \
  using Simulation<dim>::point_set_records;         \
  using Simulation<dim>::make_grid;                 \
  using Simulation<dim>::write_point_sets;          \
  using Simulation<dim>::rewrite_point_set_records; \
  using Simulation<dim>::lost_points;               \
  using Simulation<dim>::time;                      \
  using Simulation<dim>::dt;                        \
  using Simulation<dim>::step_number;               \
  using Simulation<dim>::current_stage;             \
  using Simulation<dim>::stage_start_time;          \
  using Simulation<dim>::counters;                  \
  using Simulation<dim>::restored_from;             \
  using Simulation<dim>::cut_backs

  template <int dim>
  class Simulation : public Formulation
  {
  public:
    /// The grid (built with mesh reconstruction when load balancing is on), one
    /// empty point set per name ("points" for the one-set families; the
    /// semi-implicit family's "soil" and "water") and the balancer over all of
    /// them, whose repartitions call grid_changed().
    Simulation(const SceneParameters<dim> &scene, const RunParameters<dim> &run, MPI_Comm comm,
               const std::vector<std::string> &set_names);
    ~Simulation() override;

    /// The scene's grid: the box or the grid file's mesh, DoFs, and the
    /// B-spline node patches with `numerics/shape function = quadratic bspline`.
    /// Collective.
    void make_grid();

    /// Check the load balance after a completed step and rebalance if due.
    void after_step() override;
    /// Points removed so far because they left the grid, over all sets.
    unsigned long long lost_points() const override;
    /// Write VTU file set `counter` of every point set (<set name>-<counter>,
    /// <set name>.pvd; "particles" for a one-set family). Collective.
    void write_point_sets(const unsigned int counter);
    /// After a restart: rewrite every set's PVD from its records (rank 0).
    void rewrite_point_set_records() const;
    /// The output name of set k: "particles" for a one-set family, else the set's name.
    std::string point_set_output_name(const unsigned int k) const;

    MPI_Comm            comm;
    BackgroundGrid<dim> grid;
    /// the material-point sets, in the order of the names given
    std::vector<std::unique_ptr<MaterialPointSet<dim>>> point_sets;
    /// Load balancing by material points over every set (load_balance.h).
    LoadBalance<dim> balance;
    /// (time, file) of every VTU written, per point set (the PVD records)
    std::vector<std::vector<std::pair<double, std::string>>> point_set_records;

  protected:
    /// After the partition changed (a rebalance): rebuild what depends on it
    /// (DoF numbering, nodal vectors, flags, matrices). The family's.
    virtual void grid_changed() = 0;

  private:
    const SceneParameters<dim> &scene;
    const RunParameters<dim>   &run;
    static std::vector<MaterialPointSet<dim> *>
    set_pointers(const std::vector<std::unique_ptr<MaterialPointSet<dim>>> &sets);
  };
} // namespace talus
