// talus — gmsh model through the gmsh C++ API (gmsh_model.h).
#include <talus/base/errors.h>
#include <talus/mesh/gmsh_model.h>

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <unordered_map>

namespace talus::mesh
{
  std::string
  normalise_name(const std::string &name)
  {
    std::string out;
    bool        blank = false;
    for (const char c : name)
      {
        if (std::isspace(static_cast<unsigned char>(c)))
          {
            blank = !out.empty();
            continue;
          }
        if (blank)
          out += ' ';
        blank = false;
        out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      }
    return out;
  }

  long
  convention_id(const std::string &name, const std::string &kind)
  {
    const std::string n = normalise_name(name);
    if (n.rfind(kind + " ", 0) != 0)
      return -1;
    std::size_t i = kind.size() + 1, j = i;
    while (j < n.size() && std::isdigit(static_cast<unsigned char>(n[j])))
      ++j;
    if (j == i || j - i > 5 || (j < n.size() && n[j] != ' '))
      return -1;
    const long id = std::stol(n.substr(i, j - i));
    return id <= 65535 ? id : -1;
  }

  std::string
  GmshGroup::describe() const
  {
    std::ostringstream os;
    if (name.empty())
      os << "unnamed group";
    else
      os << "'" << name << "'";
    os << " (dimension " << dim << ", tag " << tag << ")";
    return os.str();
  }

  const GmshGroup *
  GmshModel::find(const int d, const std::string &ref) const
  {
    const std::string r = normalise_name(ref);
    bool              numeric =
      !r.empty() && std::all_of(r.begin(), r.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
    for (const auto &g : groups)
      if (g.dim == d && !g.name.empty() && normalise_name(g.name) == r)
        return &g;
    if (numeric && r.size() < 9)
      for (const auto &g : groups)
        if (g.dim == d && g.tag == std::stoi(r))
          return &g;
    return nullptr;
  }

  std::string
  GmshModel::list_groups(const int d) const
  {
    std::string s;
    for (const auto &g : groups)
      if (g.dim == d)
        s += (s.empty() ? "" : ", ") + g.describe();
    return s.empty() ? "none" : s;
  }

  namespace
  {
    /// gmsh session: initialised once per process, a fresh model per load.
    struct Session
    {
      Session()
      {
        gmsh::initialize(0, nullptr, false);
        gmsh::option::setNumber("General.Terminal", 0);
      }
      ~Session() { gmsh::finalize(); }
    };

    std::string
    last_error()
    {
      std::string e;
      try
        {
          gmsh::logger::getLastError(e);
        }
      catch (...)
        {
        }
      return e.empty() ? "unknown gmsh error" : e;
    }
  } // namespace

  GmshModel
  load_gmsh(const std::string &file, const unsigned int dim, const GmshOptions &opt, const std::string &where)
  {
    static Session    session;
    const std::string w = where + ": '" + file + "'";
    GmshModel         m;
    m.dim                 = dim;
    m.file                = file;
    const std::string ext = std::filesystem::path(file).extension().string();
    if (ext != ".geo" && ext != ".msh")
      throw InputError(w + ": unknown extension '" + ext + "' (allowed: .geo, meshed by gmsh; .msh)");
    try
      {
        // options persist between models of one gmsh session: set all of them
        // before every open (a .geo may still set its own)
        gmsh::clear();
        gmsh::option::setNumber("General.AbortOnError", 2);
        gmsh::option::setNumber("Mesh.ElementOrder", 1);
        gmsh::option::setNumber("Mesh.RecombineAll", opt.recombine ? 1 : 0);
        gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", opt.subdivide ? (dim == 2 ? 1 : 2) : 0);
        gmsh::open(file);
        if (ext == ".geo" && opt.generate)
          gmsh::model::mesh::generate(dim);
        m.meshed = ext == ".msh" || opt.generate;

        gmsh::vectorpair dim_tags;
        gmsh::model::getPhysicalGroups(dim_tags, -1);
        for (const auto &[d, t] : dim_tags)
          {
            GmshGroup g;
            g.dim = d;
            g.tag = t;
            gmsh::model::getPhysicalName(d, t, g.name);
            gmsh::model::getEntitiesForPhysicalGroup(d, t, g.entities);
            m.groups.push_back(g);
          }
        if (!m.meshed)
          return m;

        std::vector<int> types;
        gmsh::model::mesh::getElementTypes(types, -1, -1);
        for (const int type : types)
          {
            std::string         name;
            int                 edim = 0, order = 0, n_nodes = 0, n_primary = 0;
            std::vector<double> local;
            gmsh::model::mesh::getElementProperties(type, name, edim, order, n_nodes, local, n_primary);
            if (order > 1)
              throw InputError(w + " contains elements of order " + std::to_string(order) + " (gmsh type " +
                               std::to_string(type) + ", '" + name +
                               "'): only first-order elements are supported (set Mesh.ElementOrder = 1)");
          }

        std::vector<std::size_t> node_tags;
        std::vector<double>      coord, param;
        gmsh::model::mesh::getNodes(node_tags, coord, param, -1, -1, false, false);
        std::unordered_map<std::size_t, unsigned int> index;
        for (std::size_t i = 0; i < node_tags.size(); ++i)
          {
            index[node_tags[i]] = m.nodes.size();
            m.nodes.push_back({{coord[3 * i], coord[3 * i + 1], coord[3 * i + 2]}});
          }
        if (opt.round_coordinates && !m.nodes.empty())
          {
            double extent = 0;
            for (unsigned int k = 0; k < 3; ++k)
              {
                double lo = m.nodes[0][k], hi = lo;
                for (const auto &x : m.nodes)
                  lo = std::min(lo, x[k]), hi = std::max(hi, x[k]);
                extent = std::max(extent, hi - lo);
              }
            if (extent > 0)
              {
                // multiples of 10^-e, e = 10 - floor(log10(extent)); n / 10^e is the double
                // nearest to the decimal number
                const int    e     = std::max(-300, std::min(22, 10 - int(std::floor(std::log10(extent)))));
                const double scale = std::pow(10.0, std::abs(e));
                for (auto &x : m.nodes)
                  for (auto &c : x)
                    c = e >= 0 ? std::round(c * scale) / scale : std::round(c / scale) * scale;
              }
          }
        for (const int d : {int(dim), int(dim) - 1})
          {
            gmsh::vectorpair entities;
            gmsh::model::getEntities(entities, d);
            for (const auto &[ed, et] : entities)
              {
                std::vector<int>                      etypes;
                std::vector<std::vector<std::size_t>> etags, enodes;
                gmsh::model::mesh::getElements(etypes, etags, enodes, ed, et);
                for (std::size_t k = 0; k < etypes.size(); ++k)
                  {
                    std::string         name;
                    int                 edim = 0, order = 0, n_nodes = 0, n_primary = 0;
                    std::vector<double> local;
                    gmsh::model::mesh::getElementProperties(etypes[k], name, edim, order, n_nodes, local, n_primary);
                    for (std::size_t e = 0; e < etags[k].size(); ++e)
                      {
                        GmshElement el;
                        el.type   = etypes[k];
                        el.tag    = etags[k][e];
                        el.entity = et;
                        for (int v = 0; v < n_nodes; ++v)
                          el.nodes.push_back(index.at(enodes[k][e * n_nodes + v]));
                        (d == int(dim) ? m.cells : m.facets).push_back(std::move(el));
                      }
                  }
              }
          }
      }
    catch (const InputError &)
      {
        throw;
      }
    catch (...)
      {
        throw InputError(w + ": gmsh: " + last_error());
      }
    // drop repeated elements (same sorted nodes), keeping the first
    for (auto *list : {&m.cells, &m.facets})
      {
        std::vector<std::pair<std::vector<unsigned int>, std::size_t>> keys;
        for (std::size_t i = 0; i < list->size(); ++i)
          {
            auto k = (*list)[i].nodes;
            std::sort(k.begin(), k.end());
            keys.emplace_back(std::move(k), i);
          }
        std::sort(keys.begin(), keys.end());
        std::vector<char> drop(list->size(), 0);
        for (std::size_t i = 1; i < keys.size(); ++i)
          if (keys[i].first == keys[i - 1].first)
            drop[keys[i].second] = 1;
        std::vector<GmshElement> kept;
        for (std::size_t i = 0; i < list->size(); ++i)
          if (!drop[i])
            kept.push_back(std::move((*list)[i]));
        m.duplicates += list->size() - kept.size();
        *list = std::move(kept);
      }
    if (m.cells.empty())
      throw InputError(w + " contains no elements of dimension " + std::to_string(dim) +
                       (ext == ".geo"
                          ? " after meshing (does it define a " + std::string(dim == 2 ? "surface" : "volume") + "?)"
                          : ""));
    return m;
  }
} // namespace talus::mesh
