// talus — material points: the property layout stored in deal.II's
// ParticleHandler, seeding from geometric primitives, and relocation to new
// cells whose cost follows the particles that actually changed cell.
#pragma once

#include <talus/grid/background_grid.h>

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <functional>

#include <string>
#include <vector>

namespace talus
{
  /// Layout of the double-valued properties of one material point.
  ///
  ///  offset            size      quantity
  ///  mass              1         mass m_p [kg] (per unit thickness in 2D)
  ///  volume            1         current volume V_p [m^3] (area in 2D)
  ///  material          1         material id (integer stored as double)
  ///  body              1         body id
  ///  velocity          dim       v_p [m/s]
  ///  displacement      dim       u_p = x_p - X_p [m]
  ///  stress            n_stress  Cauchy stress, tension positive [Pa]:
  ///                              2D xx,yy,zz,xy; 3D xx,yy,zz,xy,yz,xz
  ///  history           n_history constitutive history variables (per model)
  ///  extras            optional named blocks added by features that need them
  ///                    (2-phase: porosity, pore pressure, liquid velocity, ...;
  ///                    liquids: free-surface flag), allocated only when used
  template <int dim>
  struct PropertyLayout
  {
    static constexpr unsigned int n_stress     = dim == 2 ? 4 : 6;
    static constexpr unsigned int mass         = 0;
    static constexpr unsigned int volume       = 1;
    static constexpr unsigned int material     = 2;
    static constexpr unsigned int body         = 3;
    static constexpr unsigned int velocity     = 4;
    static constexpr unsigned int displacement = velocity + dim;
    static constexpr unsigned int stress       = displacement + dim;
    static constexpr unsigned int history      = stress + n_stress;

    unsigned int n_history = 0;
    unsigned int
    n_properties() const
    {
      return history + n_history + n_extra;
    }

    /// Optional named block after the history; call after n_history is final
    /// and before the ParticleHandler is initialised. Returns its offset.
    /// `vector`: a dim-sized block shown as a vector in the VTU output.
    unsigned int
    add_extra(const std::string &name, const unsigned int size, const bool vector = false)
    {
      extras.push_back({name, history + n_history + n_extra, size, vector});
      n_extra += size;
      return extras.back().offset;
    }
    struct Extra
    {
      std::string  name;
      unsigned int offset, size;
      bool         vector;
    };
    std::vector<Extra> extras;
    unsigned int       n_extra = 0;

    /// Names for output (vectors get dim identical names for ParaView).
    std::vector<std::string>                                                      names() const;
    std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> interpretations() const;

    static dealii::SymmetricTensor<2, 3> get_stress(const double *p);
    static void                          set_stress(const dealii::SymmetricTensor<2, 3> &s, double *p);
  };

  // inline: the update pass reads and writes the stress of every point and step
  template <int dim>
  inline dealii::SymmetricTensor<2, 3>
  PropertyLayout<dim>::get_stress(const double *p)
  {
    dealii::SymmetricTensor<2, 3> s;
    s[0][0] = p[stress + 0];
    s[1][1] = p[stress + 1];
    s[2][2] = p[stress + 2];
    s[0][1] = p[stress + 3];
    if constexpr (dim == 3)
      {
        s[1][2] = p[stress + 4];
        s[0][2] = p[stress + 5];
      }
    return s;
  }

  template <int dim>
  inline void
  PropertyLayout<dim>::set_stress(const dealii::SymmetricTensor<2, 3> &s, double *p)
  {
    p[stress + 0] = s[0][0];
    p[stress + 1] = s[1][1];
    p[stress + 2] = s[2][2];
    p[stress + 3] = s[0][1];
    if constexpr (dim == 3)
      {
        p[stress + 4] = s[1][2];
        p[stress + 5] = s[0][2];
      }
  }

  /// t = -V sigma of the point with properties P (the in-plane part in 2D): the
  /// integrand of the internal force f_int,i = -sum_p t grad N_i(x_p).
  template <int dim>
  inline void
  minus_V_sigma(const double *P, const double V, double (&t)[dim][dim])
  {
    using L = PropertyLayout<dim>;
    t[0][0] = -V * P[L::stress + 0];
    t[1][1] = -V * P[L::stress + 1];
    t[0][1] = t[1][0] = -V * P[L::stress + 3];
    if constexpr (dim == 3)
      {
        t[2][2] = -V * P[L::stress + 2];
        t[1][2] = t[2][1] = -V * P[L::stress + 4];
        t[0][2] = t[2][0] = -V * P[L::stress + 5];
      }
  }

  /// A body made of material points: a primitive region filled with regular
  /// points in every grid cell it covers (seed 000 §4.3.2: equal shares of the
  /// cell volume).
  template <int dim>
  struct BodyDescription
  {
    enum class Shape
    {
      box,
      ball, ///< disk in 2D, sphere in 3D
      polygon,
      file ///< the points of a talus particle file (io/particle_file.h)
    };
    Shape                         shape = Shape::box;
    dealii::Point<dim>            lower, upper;                // box
    dealii::Point<dim>            center;                      // ball
    double                        radius = 0;                  // ball
    std::vector<dealii::Point<2>> polygon;                     // polygon (2D)
    std::string                   particle_file;               // file
    unsigned int                  file_body_id            = 0; // file: rows with this body id
    unsigned int                  material_id             = 0;
    unsigned int                  particles_per_direction = 2;
    dealii::Tensor<1, dim>        initial_velocity;
    /// optional velocity field v(x) overriding initial_velocity (empty: none)
    std::function<dealii::Tensor<1, dim>(const dealii::Point<dim> &)> velocity_field;
    std::string                                                       name;
    /// 'clip to grid': drop the points outside the grid (logged) instead of
    /// refusing a body that is not wholly inside it
    bool clip_to_grid = false;

    bool contains(const dealii::Point<dim> &x) const;
    /// Bounding box of a box, ball or polygon (in 3D polygons do not exist).
    void bounding_box(dealii::Point<dim> &lo, dealii::Point<dim> &hi) const;
    /// Geometric volume (area in 2D) of a box, ball or polygon; 0 for file bodies.
    double volume() const;
  };

  /// Empty if the box/ball/polygon body `b` lies wholly inside [lo, hi] (to
  /// 1e-12 of the extent); else the reason, naming the body's first coordinate
  /// outside and the grid extent in that direction, e.g. "upper corner: y = 5.2
  /// lies outside the grid (y from 0 to 2.3)". An axis-aligned box contains a
  /// box, ball or polygon iff it contains its bounding box.
  template <int dim>
  std::string outside_extent(const BodyDescription<dim> &b, const dealii::Point<dim> &lo, const dealii::Point<dim> &hi);

  /// What clipping a body to a box grid [lo, hi] with `cells` per direction
  /// drops: the seeding positions of the grid's sub-cell lattice (continued
  /// beyond the grid) inside the body but outside the grid, and the volume they
  /// would carry (count x sub-cell volume). Box bodies are counted per
  /// direction; balls and polygons position by position (counted = false when
  /// more than 5e7 positions would have to be visited).
  struct ClipCount
  {
    double points = 0, volume = 0;
    bool   counted = true;
  };
  template <int dim>
  ClipCount clipped_by_box_grid(const BodyDescription<dim> &b, const dealii::Point<dim> &lo,
                                const dealii::Point<dim> &hi, const std::vector<unsigned int> &cells);

  struct SeedingResult
  {
    unsigned long long  n_particles = 0;
    std::vector<double> volume_per_body;
    /// file bodies with clip_to_grid: points outside the grid left out, and their volume
    std::vector<double> dropped_points, dropped_volume;
  };

  /// Fill every locally owned cell with n^dim regular points (cell-centred
  /// sub-cells) of each body that contains them (first body wins). Volumes are
  /// equal shares of the cell volume, masses = density * volume. Particle ids
  /// are global and contiguous. Collective.
  template <int dim>
  SeedingResult seed_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                            const std::vector<double> &density_of_material, const PropertyLayout<dim> &layout,
                            dealii::Particles::ParticleHandler<dim> &particles);

  /// Insert the material points of the bodies with shape = file: the rows of
  /// their particle files whose body id is the body's file_body_id, in body and
  /// row order, with ids from `first_id` on. Material id and volume (and the
  /// initial stress, if the file has one) come from the file; body = the body's
  /// index; mass = density of the material x volume; velocity as for the shapes.
  /// Every rank reads the files; each point goes to the rank owning the cell that
  /// contains it (a point on a cell face: the lowest rank). A point in no cell of
  /// the grid is an InputError naming it. Collective.
  template <int dim>
  SeedingResult insert_file_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                                   const std::vector<double> &density_of_material, const PropertyLayout<dim> &layout,
                                   dealii::Particles::ParticleHandler<dim> &particles, unsigned long long first_id);

  struct RelocationStats
  {
    unsigned long long moved_locally = 0; ///< changed cell, found among neighbours
    unsigned long long sent_to_ranks = 0; ///< of those: entered a neighbour owned by another rank (sent there)
    unsigned long long global_sorts  = 0; ///< full deal.II sorts needed
    unsigned long long lost          = 0; ///< left the grid (removed)
    unsigned long long storage_sorts = 0; ///< memory-order rebuilds (Relocator::restore_memory_order)
    double             seconds_moves = 0; ///< wall time of local moves
    double             seconds_sorts = 0; ///< wall time of deal.II sorts and memory-order rebuilds
  };

  /// Relocator: after positions were updated, each particle still inside its
  /// cell only gets new reference coordinates (done by the caller in its loop);
  /// particles that left their cell are handed here. Those that landed in a
  /// locally owned vertex neighbour are moved directly; if any rank has a
  /// particle it cannot place (other rank, jumped past the neighbours, left
  /// the grid), everyone falls back to deal.II's collective sort.
  template <int dim>
  class Relocator
  {
  public:
    Relocator(const BackgroundGrid<dim> &grid, dealii::Particles::ParticleHandler<dim> &particles);

    /// Called from the particle loop for a particle whose new position left
    /// cell c (its location is already updated): `entered` is the vertex
    /// neighbour of c it is in (BackgroundGrid::find_cell_near, with xi its
    /// reference location there), or invalid_unsigned_int if none is (then a
    /// full sort places it). `added`: the caller has already added the point to
    /// what finish()'s `moved` callback would add it to.
    void
    leaving(const typename dealii::Particles::ParticleHandler<dim>::particle_iterator &it, const unsigned int c,
            const unsigned int entered, const dealii::Point<dim> &xi, const bool added)
    {
      pending.push_back({it, xi, c, entered, added});
    }

    /// Apply all moves. Collective. Each point that stays on this rank is
    /// removed and at once inserted again: deal.II's pool hands the slot just
    /// freed to the next insertion, so the point keeps its storage slot and the
    /// insertion writes the cache lines the removal has just read. Moved points
    /// are still walked with their new cell while their slot sits with the old
    /// one; once the particles moved since the last memory-order rebuild
    /// exceed `resort_fraction` of all particles, restore_memory_order()
    /// puts the storage back in cell-by-cell memory order. 2.0 measured best
    /// on the 3D bench with the rebuild (docs/scaling.md): 1.0 spent 3 ns per
    /// point-step more on rebuilds, 4.0 was no faster than 2.0, and the update
    /// pass did not get slower with the rarer rebuilds (the loops prefetch).
    /// `moved(c, xi, properties)` is called for every particle moved to a
    /// neighbour cell c (not for those handled by a full sort, nor for those
    /// handed to leaving() with `added`).
    void finish(RelocationStats                                                                     &stats,
                const std::function<void(unsigned int, const dealii::Point<dim> &, const double *)> &moved = {});

    double resort_fraction = 2.0;

    /// What the last finish() did to the handler's storage, for callers that
    /// keep per-cell bookkeeping: every removal (from its source cell) and every
    /// insertion (into its target cell) in the order they were applied, and
    /// whether a full deal.II sort ran (then everything may have changed:
    /// points sent to other ranks or lost, reference locations recomputed, so
    /// nodal sums and per-point sums of the step are stale), or whether only the
    /// storage was rebuilt in memory order (`reordered_last`: the same points in
    /// the same cells with the same data, so those sums stay valid; only the
    /// order of the cell groups changed).
    struct CellChange
    {
      unsigned int cell;
      bool         inserted; ///< false: a point was removed from `cell`
    };
    std::vector<CellChange> cell_changes;
    bool                    sorted_last    = false;
    bool                    reordered_last = false;

    /// Particles moved (locally) since the last full sort or memory-order
    /// rebuild: part of the state a checkpoint saves, since it decides when the
    /// next rebuild runs.
    unsigned long long &
    moves_since_sort()
    {
      return moved_since_sort;
    }
    unsigned long long
    moves_since_sort() const
    {
      return moved_since_sort;
    }

    /// Rebuild the handler's storage in memory order: afterwards the walk
    /// (cell groups in active-cell order) reads the pool's occupied slots in
    /// increasing order. Each point keeps its cell, its place among its cell's
    /// points, its location, reference location, id and properties bit for bit:
    /// unlike deal.II's sort_particles_into_subdomains_and_cells() there is no
    /// point location, no mapping and no communication except one collective
    /// update of the handler's counts. In place: the points are moved slot by
    /// slot through deal.II's free list (a few points copied at a time, no copy
    /// of all points beside the pool); a pool with free slots keeps them as gaps.
    /// Collective.
    void restore_memory_order();

  private:
    struct Pending
    {
      typename dealii::Particles::ParticleHandler<dim>::particle_iterator it;
      dealii::Point<dim>                                                  xi; ///< in `entered`
      unsigned int                                                        cell, entered;
      bool                                                                added;
    };
    const BackgroundGrid<dim>               &grid;
    dealii::Particles::ParticleHandler<dim> &particles;
    std::vector<Pending>                     pending;
    unsigned long long                       lost_counter     = 0;
    unsigned long long                       moved_since_sort = 0;
    // scratch kept between calls (no per-step allocation)
    struct Move
    {
      dealii::Point<dim>            x, xi;
      dealii::types::particle_index id;
      unsigned int                  cell;
      unsigned int                  prop_offset;
    };
    std::vector<Move>   moves;
    std::vector<double> props;
  };
} // namespace talus
