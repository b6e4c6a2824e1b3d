// talus — 'body k/initial stress', the geostatic initial state of every family:
// the entries (declared with the scene's bodies), their parsing, and the depths
// of a point below its body's surface and below the water level. Each family
// turns the depths into stresses with its own densities (one-phase bulk
// density; two-phase buoyant weight below the water level and the pore
// pressure of its water) and stores them in its own sign convention; the
// vertical/horizontal split and the rotation to the gravity axis are here.
#pragma once

#include <talus/grid/background_grid.h>
#include <talus/materials/material.h>
#include <talus/particles/material_point_set.h>
#include <talus/particles/material_points.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <mpi.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace talus
{
  /// 'body k/initial stress' of one body (seed 000 §6.4, the K0 procedure).
  struct InitialStress
  {
    bool   enabled       = false;
    double K0            = 0.5;
    double surface_level = std::numeric_limits<double>::quiet_NaN(); ///< along -g [m]; NaN: top of the body
    double water_level   = std::numeric_limits<double>::quiet_NaN(); ///< NaN: the surface level
    double surcharge     = 0; ///< vertical pressure on the surface [Pa], compression positive

    /// 'water level' was set (families without pore water refuse it)
    bool
    has_water_level() const
    {
      return !std::isnan(water_level);
    }
  };

  /// Declare 'initial stress' in the current 'body k' subsection.
  void declare_initial_stress(dealii::ParameterHandler &prm);

  /// 'body k/initial stress' of every body; 'K0 = auto' reads the friction
  /// angle of the body's Mohr-Coulomb material ('material m/<model>/friction
  /// angle'). InputError naming the entry for a procedure without gravity, a
  /// negative K0, 'auto' on another model. At the top level of `prm`.
  template <int dim>
  std::vector<InitialStress> parse_initial_stress(dealii::ParameterHandler                &prm,
                                                  const std::vector<BodyDescription<dim>> &bodies,
                                                  const dealii::Tensor<1, dim>            &gravity);

  /// Whether any body runs the K0 procedure.
  bool any_initial_stress(const std::vector<InitialStress> &settings);
  /// InputError naming 'body k/initial stress/water level' of the first body
  /// with one, for a family (`tool`) whose points of that body carry no pore
  /// water (`reason`).
  void refuse_water_level(const std::vector<InitialStress> &settings, const std::string &tool,
                          const std::string &reason);

  /// Where a point lies in its body's geostatic column.
  struct GeostaticDepths
  {
    double depth     = 0; ///< below the surface level (>= 0)
    double dry       = 0; ///< the part of `depth` above the water level
    double submerged = 0; ///< the part of `depth` below the water level
    double water     = 0; ///< below the water level (>= 0; also in water ponding above the surface)
  };

  /// The geostatic column of every body with the K0 procedure: the upward axis
  /// (against gravity), the surface levels (given, or the top of the body's
  /// points), and a point's depths and stress.
  template <int dim>
  class GeostaticState
  {
  public:
    GeostaticState(const std::vector<InitialStress> &settings, const dealii::Tensor<1, dim> &gravity);

    /// The top of every enabled body without a surface level: the largest
    /// x.e + half a point spacing over the points of `sets` (property `body`).
    /// Collective.
    void find_body_tops(const std::vector<const MaterialPointSet<dim> *> &sets, const BackgroundGrid<dim> &grid,
                        const std::vector<BodyDescription<dim>> &bodies, MPI_Comm comm);

    bool
    applies(const unsigned int body) const
    {
      return body < settings.size() && settings[body].enabled;
    }
    const InitialStress &
    of(const unsigned int body) const
    {
      return settings[body];
    }
    /// the unit vector against gravity
    const dealii::Tensor<1, dim> &
    up_direction() const
    {
      return up;
    }
    /// |g| [m/s^2]
    double
    gravity_norm() const
    {
      return g;
    }
    GeostaticDepths depths(unsigned int body, const dealii::Point<dim> &x) const;
    /// The stress with `sigma_v` along the gravity axis and K0 sigma_v across
    /// it (tension positive), as the 3x3 tensor of the points.
    dealii::SymmetricTensor<2, 3> stress(unsigned int body, double sigma_v) const;
    /// The K0 stress of a one-phase point of bulk `density` at `x`:
    /// sigma_v = -(density |g| depth + surcharge).
    dealii::SymmetricTensor<2, 3> one_phase_stress(unsigned int body, const dealii::Point<dim> &x,
                                                   double density) const;

  private:
    std::vector<InitialStress> settings;
    double                     g = 0;
    dealii::Tensor<1, dim>     up;
    unsigned int               up_axis = dim - 1;
    std::vector<double>        surface, water; ///< per body, along `up`
  };
} // namespace talus
