#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/initial_stress.h>
#include <talus/loads/k0.h>

#include <deal.II/base/mpi.h>

#include <algorithm>

namespace talus
{
  void
  declare_initial_stress(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("initial stress");
    prm.declare_entry("K0 procedure", "false", Bool(),
                      "Initial geostatic state at setup (every family): the effective vertical stress "
                      "sigma_v = -(unit weight x depth + surcharge) along the gravity direction, sigma_h = K0 "
                      "sigma_v in the other normal directions. One-phase points: the bulk unit weight. Two-phase "
                      "points: the buoyant weight (1 - n)(rho_S - rho_L)|g| below the water level, (1 - n) rho_S "
                      "|g| above it, and the hydrostatic pore pressure rho_L |g| (water level - z).");
    prm.declare_entry("K0", "auto", Anything(),
                      "Lateral stress ratio; 'auto' = 1 - sin(phi) for Mohr-Coulomb materials (error otherwise).");
    prm.declare_entry("surface level", "", Anything(),
                      "Level of the free surface along -g [m]; empty = top of this body.");
    prm.declare_entry("water level", "", Anything(),
                      "Level of the free water along -g [m] (two-phase points: talus-semi-implicit, and talus-explicit "
                      "with 'pore liquid/drainage = coupled'); empty = the surface level (saturated to the surface). "
                      "Above the surface it ponds (pore pressure at the surface rho_L |g| (water level - surface)); "
                      "below it the soil above is dry. One-phase bodies refuse it.");
    prm.declare_entry("surcharge", "0", Double(0),
                      "Vertical pressure on the surface [Pa] (overburden of layers above).");
    prm.leave_subsection();
  }

  template <int dim>
  std::vector<InitialStress>
  parse_initial_stress(dealii::ParameterHandler &prm, const std::vector<BodyDescription<dim>> &bodies,
                       const dealii::Tensor<1, dim> &gravity)
  {
    std::vector<InitialStress> all;
    for (unsigned int k = 0; k < bodies.size(); ++k)
      {
        const std::string where = "body " + std::to_string(k) + "/initial stress";
        prm.enter_subsection("body " + std::to_string(k));
        prm.enter_subsection("initial stress");
        InitialStress z;
        z.enabled            = prm.get_bool("K0 procedure");
        const std::string k0 = prm.get("K0"), level = prm.get("surface level"), water = prm.get("water level");
        z.surcharge = prm.get_double("surcharge");
        if (!level.empty())
          z.surface_level = parse_doubles(level, where + "/surface level").at(0);
        if (!water.empty())
          z.water_level = parse_doubles(water, where + "/water level").at(0);
        prm.leave_subsection();
        prm.leave_subsection();
        if (z.enabled)
          {
            require(gravity.norm() > 0, where, "the K0 procedure needs a non-zero gravity/acceleration");
            if (k0 == "auto")
              {
                const std::string mat = "material " + std::to_string(bodies[k].material_id);
                prm.enter_subsection(mat);
                const std::string model = prm.get("model");
                double            phi   = -1;
                if (model == "mohr coulomb" || model == "hencky mohr coulomb")
                  {
                    prm.enter_subsection(model);
                    phi = prm.get_double("friction angle");
                    prm.leave_subsection();
                  }
                prm.leave_subsection();
                require(phi >= 0, where + "/K0",
                        "'auto' (1 - sin phi) needs a Mohr-Coulomb material; " + mat + " is '" + model +
                          "': give K0 as a number");
                z.K0 = loads::jaky_k0(phi);
              }
            else
              z.K0 = parse_doubles(k0, where + "/K0").at(0);
            require(z.K0 >= 0, where + "/K0", "must be >= 0");
          }
        all.push_back(z);
      }
    return all;
  }

  bool
  any_initial_stress(const std::vector<InitialStress> &settings)
  {
    for (const auto &s : settings)
      if (s.enabled)
        return true;
    return false;
  }

  void
  refuse_water_level(const std::vector<InitialStress> &settings, const std::string &tool, const std::string &reason)
  {
    for (unsigned int k = 0; k < settings.size(); ++k)
      require(!settings[k].enabled || !settings[k].has_water_level(),
              "body " + std::to_string(k) + "/initial stress/water level", tool + " cannot honour it: " + reason);
  }

  template <int dim>
  GeostaticState<dim>::GeostaticState(const std::vector<InitialStress> &settings, const dealii::Tensor<1, dim> &gravity)
      : settings(settings)
      , g(gravity.norm())
  {
    if (g > 0)
      up = -gravity / g;
    for (unsigned int d = 1; d < dim; ++d)
      if (std::abs(up[d]) > std::abs(up[up_axis]))
        up_axis = d;
    surface.resize(settings.size());
    water.resize(settings.size());
    for (unsigned int b = 0; b < settings.size(); ++b)
      {
        surface[b] = settings[b].surface_level;
        water[b]   = settings[b].water_level;
      }
  }

  template <int dim>
  void
  GeostaticState<dim>::find_body_tops(const std::vector<const MaterialPointSet<dim> *> &sets,
                                      const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                                      MPI_Comm comm)
  {
    using L               = PropertyLayout<dim>;
    const unsigned int  n = settings.size();
    std::vector<double> top(n, -std::numeric_limits<double>::max());
    for (const auto *set : sets)
      for (const auto &pt : set->handler)
        {
          const auto         P = pt.get_properties();
          const unsigned int b = static_cast<unsigned int>(P[L::body]);
          if (!applies(b) || !std::isnan(settings[b].surface_level))
            continue;
          const auto  &cc = grid.cells[pt.get_surrounding_cell()->active_cell_index()];
          const double z  = pt.get_location() * up;
          top[b]          = std::max(top[b], z + 0.5 * cc.h[up_axis] / bodies[b].particles_per_direction);
        }
    std::vector<double> all(n);
    dealii::Utilities::MPI::max(dealii::ArrayView<const double>(top), comm, dealii::ArrayView<double>(all));
    for (unsigned int b = 0; b < n; ++b)
      {
        if (std::isnan(surface[b]))
          surface[b] = all[b];
        if (std::isnan(water[b]))
          water[b] = surface[b];
      }
  }

  template <int dim>
  GeostaticDepths
  GeostaticState<dim>::depths(const unsigned int body, const dealii::Point<dim> &x) const
  {
    const double    z = x * up, s = surface[body], w = water[body];
    GeostaticDepths d;
    d.depth     = std::max(0.0, s - z);
    d.dry       = std::max(0.0, s - std::max(z, w));
    d.submerged = std::max(0.0, std::min(s, w) - z);
    d.water     = std::max(0.0, w - z);
    return d;
  }

  template <int dim>
  dealii::SymmetricTensor<2, 3>
  GeostaticState<dim>::stress(const unsigned int body, const double sigma_v) const
  {
    const double                  sh = settings[body].K0 * sigma_v;
    dealii::SymmetricTensor<2, 3> sigma;
    if (std::abs(up[up_axis]) == 1.0) // gravity along a grid axis: sigma_v exactly on the diagonal
      {
        for (unsigned int i = 0; i < 3; ++i)
          sigma[i][i] = sh;
        sigma[up_axis][up_axis] = sigma_v;
        return sigma;
      }
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = i; j < 3; ++j)
        {
          const double ei = i < dim ? up[i] : 0.0, ej = j < dim ? up[j] : 0.0;
          sigma[i][j] = (i == j ? sh : 0.0) + (sigma_v - sh) * ei * ej;
        }
    return sigma;
  }

  template <int dim>
  dealii::SymmetricTensor<2, 3>
  GeostaticState<dim>::one_phase_stress(const unsigned int body, const dealii::Point<dim> &x,
                                        const double density) const
  {
    return stress(body, -(density * g * depths(body, x).depth + settings[body].surcharge));
  }

#define TALUS_INSTANTIATE(dim)                                                                              \
  template std::vector<InitialStress> parse_initial_stress<dim>(                                            \
    dealii::ParameterHandler &, const std::vector<BodyDescription<dim>> &, const dealii::Tensor<1, dim> &); \
  template class GeostaticState<dim>;
  TALUS_INSTANTIATE(2)
  TALUS_INSTANTIATE(3)
#undef TALUS_INSTANTIATE
} // namespace talus
