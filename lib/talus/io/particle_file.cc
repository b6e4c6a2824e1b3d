// talus — material-point file (particle_file.h).
#include <talus/base/errors.h>
#include <talus/io/hdf5.h>
#include <talus/io/particle_file.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace talus::io
{
  void
  write_particle_file(const std::string &path, const ParticleTable &t, MPI_Comm comm)
  {
    H5File f(path, H5File::Mode::create, comm);
    f.set_attribute("format", std::string("talus particles"));
    f.set_attribute("version", std::int64_t(1));
    f.set_attribute("dimension", std::int64_t(t.dim));
    int has_stress = t.stress.empty() ? 0 : 1, any = 0;
    MPI_Allreduce(&has_stress, &any, 1, MPI_INT, MPI_MAX, comm);
    f.set_attribute("stress components", std::string(t.dim == 2 ? "xx,yy,zz,xy" : "xx,yy,zz,xy,yz,xz"));
    f.write_rows("position", t.position, t.dim);
    f.write_rows("volume", t.volume, 1);
    f.write_rows("material_id", t.material, 1);
    f.write_rows("body_id", t.body, 1);
    if (any)
      {
        std::vector<double> s = t.stress;
        if (s.empty())
          s.assign(t.size() * t.n_stress(), 0.0);
        f.write_rows("stress", s, t.n_stress());
      }
    f.commit();
  }

  namespace
  {
    void
    check_header(const H5File &f, const unsigned int dim, const std::string &where)
    {
      const std::string w = where + ": particle file '" + f.path() + "'";
      if (!f.has_attribute("format") || f.get_string("format") != "talus particles")
        throw InputError(w + " is not a talus particle file (no attribute format = 'talus particles'; "
                             "write it with talus-mesh)");
      if (!f.has_attribute("dimension") || f.get_int("dimension") != dim)
        throw InputError(w + " is " + (f.has_attribute("dimension") ? std::to_string(f.get_int("dimension")) : "?") +
                         "D, the scene " + std::to_string(dim) + "D");
      for (const char *name : {"position", "volume", "material_id", "body_id"})
        if (!f.exists(name))
          throw InputError(w + " has no dataset '" + name + "'");
      const auto n           = f.shape("volume").first;
      const auto check_shape = [&](const std::string &name, unsigned int cols) {
        const auto s = f.shape(name);
        if (s.first != n || s.second != cols)
          throw InputError(w + ": dataset '" + name + "' has shape " + std::to_string(s.first) + " x " +
                           std::to_string(s.second) + ", expected " + std::to_string(n) + " x " + std::to_string(cols));
      };
      check_shape("position", dim);
      check_shape("material_id", 1);
      check_shape("body_id", 1);
      if (f.exists("stress"))
        check_shape("stress", dim == 2 ? 4 : 6);
    }
  } // namespace

  ParticleFileInfo
  particle_file_info(const std::string &path, const unsigned int dim, MPI_Comm comm, const std::string &where)
  {
    H5File f(path, H5File::Mode::read, comm);
    check_header(f, dim, where);
    ParticleFileInfo info;
    info.dim            = dim;
    info.n              = f.shape("volume").first;
    info.has_stress     = f.exists("stress");
    const auto body     = f.read_rows_u64("body_id", 0, info.n);
    const auto material = f.read_rows_u64("material_id", 0, info.n);
    for (const auto b : body)
      {
        if (b >= 65536)
          throw InputError(where + ": particle file '" + path + "': body id " + std::to_string(b) + " out of range");
        if (b >= info.rows_per_body.size())
          info.rows_per_body.resize(b + 1, 0);
        ++info.rows_per_body[b];
      }
    std::vector<std::set<std::uint64_t>> materials(info.rows_per_body.size());
    for (std::uint64_t i = 0; i < info.n; ++i)
      {
        info.max_material = std::max(info.max_material, material[i]);
        materials[body[i]].insert(material[i]);
      }
    for (const auto &m : materials)
      info.materials_per_body.emplace_back(m.begin(), m.end());
    return info;
  }

  ParticleTable
  read_particle_file(const std::string &path, const unsigned int dim, MPI_Comm comm, const std::string &where)
  {
    H5File f(path, H5File::Mode::read, comm);
    check_header(f, dim, where);
    ParticleTable t;
    t.dim        = dim;
    const auto n = f.shape("volume").first;
    t.position   = f.read_rows("position", 0, n);
    t.volume     = f.read_rows("volume", 0, n);
    t.material   = f.read_rows_u64("material_id", 0, n);
    t.body       = f.read_rows_u64("body_id", 0, n);
    if (f.exists("stress"))
      t.stress = f.read_rows("stress", 0, n);
    for (std::uint64_t i = 0; i < n; ++i)
      {
        bool ok = std::isfinite(t.volume[i]) && t.volume[i] > 0;
        for (unsigned int d = 0; d < dim; ++d)
          ok = ok && std::isfinite(t.position[i * dim + d]);
        if (!ok)
          throw InputError(where + ": particle file '" + path + "': material point " + std::to_string(i) +
                           " has a non-finite position or a volume <= 0");
      }
    for (const double s : t.stress)
      if (!std::isfinite(s))
        throw InputError(where + ": particle file '" + path + "': non-finite initial stress");
    return t;
  }
} // namespace talus::io
