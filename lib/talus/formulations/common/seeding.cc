#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/seeding.h>

#include <sstream>

namespace talus
{
  template <int dim>
  std::vector<double>
  material_densities(const SceneParameters<dim> &scene)
  {
    std::vector<double> density;
    for (const auto &m : scene.materials)
      density.push_back(m->density());
    return density;
  }

  template <int dim>
  void
  require_seeded(const std::vector<BodyDescription<dim>> &bodies, const std::vector<double> &volume_per_body,
                 const std::string &what, const std::vector<unsigned int> &body_index)
  {
    for (unsigned int k = 0; k < bodies.size(); ++k)
      require(volume_per_body[k] > 0,
              "body " + std::to_string(body_index.empty() ? k : body_index[k]) + " ('" + bodies[k].name + "')",
              "contains no " + what + ": it lies outside the grid or is smaller than one sub-cell");
  }

  template <int dim>
  SeedingResult
  seed_scene_bodies(const BackgroundGrid<dim> &grid, const std::vector<BodyDescription<dim>> &bodies,
                    const std::vector<double> &density_of_material, MaterialPointSet<dim> &set, const std::string &what,
                    const SceneParameters<dim> *scene, const std::vector<unsigned int> &body_index,
                    const bool allow_empty)
  {
    SeedingResult seeded = seed_bodies(grid, bodies, density_of_material, set.layout, set.handler);
    const auto    filed =
      insert_file_bodies(grid, bodies, density_of_material, set.layout, set.handler, seeded.n_particles);
    if (scene)
      log_clipping(*scene, bodies, seeded, filed, body_index);
    for (unsigned int k = 0; k < bodies.size(); ++k)
      seeded.volume_per_body[k] += filed.volume_per_body[k];
    if (!allow_empty)
      require_seeded(bodies, seeded.volume_per_body, what, body_index);
    return seeded;
  }

  template <int dim>
  void
  initialize_point_histories(const std::vector<std::shared_ptr<const materials::Material>> &materials,
                             MaterialPointSet<dim> &set, const unsigned int history_offset)
  {
    using L = PropertyLayout<dim>;
    for (auto &pt : set.handler)
      {
        auto        P = pt.get_properties();
        const auto &m = *materials[static_cast<unsigned int>(P[L::material])];
        if (m.n_history() > 0)
          m.initialize_history(L::get_stress(P.data()),
                               dealii::ArrayView<double>(P.data() + history_offset, m.n_history()));
      }
  }

  template <int dim>
  void
  log_clipping(const SceneParameters<dim> &p, const std::vector<BodyDescription<dim>> &bodies,
               const SeedingResult &seeded, const SeedingResult &filed, const std::vector<unsigned int> &body_index)
  {
    for (unsigned int k = 0; k < bodies.size(); ++k)
      {
        const auto &b = bodies[k];
        if (!b.clip_to_grid)
          continue;
        std::ostringstream os;
        os.precision(10);
        os << "  body " << (body_index.empty() ? k : body_index[k]) << " ('" << b.name << "'), clip to grid: ";
        if (b.shape == BodyDescription<dim>::Shape::file)
          {
            const double n = k < filed.dropped_points.size() ? filed.dropped_points[k] : 0;
            const double v = k < filed.dropped_volume.size() ? filed.dropped_volume[k] : 0;
            os << n << " material points of '" << b.particle_file << "' outside the grid dropped, volume lost " << v;
          }
        else if (!p.grid_mesh)
          {
            const auto c = clipped_by_box_grid(b, p.grid_lower, p.grid_upper, p.grid_cells);
            if (c.counted)
              os << c.points << " seeding positions outside the grid dropped, volume lost " << c.volume;
            else
              os << "the positions outside the grid were not counted (more than 5e7)";
          }
        else
          {
            const double v = b.volume();
            os << "volume lost about " << v - seeded.volume_per_body[k] - filed.volume_per_body[k]
               << " (the shape's volume minus the seeded volume; grid from a file)";
          }
        os << "; seeded volume " << seeded.volume_per_body[k] + filed.volume_per_body[k] << " (" << b.name << ")";
        log() << os.str() << std::endl;
      }
  }

#define TALUS_SEEDING(dim)                                                                                                  \
  template SeedingResult       seed_scene_bodies(const BackgroundGrid<dim> &, const std::vector<BodyDescription<dim>> &,    \
                                                 const std::vector<double> &, MaterialPointSet<dim> &, const std::string &, \
                                                 const SceneParameters<dim> *, const std::vector<unsigned int> &, bool);    \
  template std::vector<double> material_densities(const SceneParameters<dim> &);                                            \
  template void                require_seeded(const std::vector<BodyDescription<dim>> &, const std::vector<double> &,       \
                                              const std::string &, const std::vector<unsigned int> &);                      \
  template void initialize_point_histories(const std::vector<std::shared_ptr<const materials::Material>> &,                 \
                                           MaterialPointSet<dim> &, unsigned int);                                          \
  template void log_clipping(const SceneParameters<dim> &, const std::vector<BodyDescription<dim>> &,                       \
                             const SeedingResult &, const SeedingResult &, const std::vector<unsigned int> &)
  TALUS_SEEDING(2);
  TALUS_SEEDING(3);
#undef TALUS_SEEDING
} // namespace talus
