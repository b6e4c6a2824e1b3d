// talus — plain quad/hex grid, its checks and its MSH 2.2 ASCII file (grid_mesh.h).
#include <talus/base/errors.h>
#include <talus/io/grid_mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <type_traits>
#include <unordered_map>

namespace talus::io
{
  namespace
  {
    std::string
    fmt_vertex(const std::array<double, 3> &x, const unsigned int dim)
    {
      std::ostringstream os;
      os << std::setprecision(10) << "(";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? ", " : "") << x[d];
      os << ")";
      return os.str();
    }

    /// Numbers of one line, read with strtod/strtoll (an istringstream per line
    /// cost most of the time of reading a large grid file).
    struct Tokens
    {
      const char *p;
      bool        ok = true;
      template <typename T>
      Tokens &
      operator>>(T &x)
      {
        char *end = nullptr;
        if constexpr (std::is_floating_point_v<T>)
          x = std::strtod(p, &end);
        else if constexpr (std::is_signed_v<T>)
          x = static_cast<T>(std::strtoll(p, &end, 10));
        else
          {
            while (*p == ' ' || *p == '\t')
              ++p;
            if (*p == '-')
              ok = false;
            x = static_cast<T>(std::strtoull(p, &end, 10));
          }
        if (end == p)
          ok = false;
        p = end;
        return *this;
      }
      explicit operator bool() const { return ok; }
    };

    // deal.II lexicographic <-> gmsh (counter-clockwise) vertex order; the
    // permutation is its own inverse
    constexpr unsigned int lex_gmsh[8] = {0, 1, 3, 2, 4, 5, 7, 6};

    /// Jacobian determinants of the multilinear map at the 2^dim corners.
    std::vector<double>
    corner_jacobians(const GridMesh &m, const std::size_t c, double &scale)
    {
      const unsigned int nv = m.n_cell_vertices();
      const auto         X  = [&](const unsigned int v) -> const std::array<double, 3>          &{
        return m.vertices[m.cells[c * nv + v]];
      };
      std::vector<double> det(nv);
      scale = 0;
      for (unsigned int v = 0; v < nv; ++v)
        {
          double e[3][3] = {};
          for (unsigned int d = 0; d < m.dim; ++d)
            {
              const unsigned int lo = v & ~(1u << d), hi = v | (1u << d);
              for (unsigned int k = 0; k < 3; ++k)
                e[d][k] = X(hi)[k] - X(lo)[k];
              double len = 0;
              for (unsigned int k = 0; k < 3; ++k)
                len += e[d][k] * e[d][k];
              scale = std::max(scale, std::sqrt(len));
            }
          if (m.dim == 2)
            det[v] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
          else
            det[v] = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        }
      return det;
    }

    /// Sorts the first n (2 or 4) vertices of a face key. An insertion sort:
    /// std::sort on the 4-entry array makes gcc 12 warn (-Warray-bounds) about
    /// its branch for more than 16 entries, which is never taken.
    void
    sort_face_key(std::array<unsigned int, 4> &key, const unsigned int n)
    {
      for (unsigned int i = 1; i < n; ++i)
        for (unsigned int j = i; j > 0 && key[j - 1] > key[j]; --j)
          std::swap(key[j - 1], key[j]);
    }
  } // namespace

  std::string
  GridMesh::describe_cell(const std::size_t c) const
  {
    std::ostringstream os;
    os << "cell " << c;
    if (c < cell_tag.size())
      os << " (gmsh element " << cell_tag[c] << ")";
    os << " with vertices ";
    for (unsigned int v = 0; v < n_cell_vertices(); ++v)
      os << (v ? ", " : "") << fmt_vertex(vertices[cells[c * n_cell_vertices() + lex_gmsh[v]]], dim);
    return os.str();
  }

  std::vector<unsigned int>
  GridMesh::boundary_ids() const
  {
    std::set<unsigned int> s(face_boundary.begin(), face_boundary.end());
    return {s.begin(), s.end()};
  }

  std::vector<unsigned int>
  GridMesh::material_ids() const
  {
    std::set<unsigned int> s(cell_material.begin(), cell_material.end());
    return {s.begin(), s.end()};
  }

  void
  GridMesh::bounding_box(double lower[3], double upper[3]) const
  {
    for (unsigned int d = 0; d < 3; ++d)
      {
        lower[d] = std::numeric_limits<double>::max();
        upper[d] = -std::numeric_limits<double>::max();
      }
    for (const auto &x : vertices)
      for (unsigned int d = 0; d < 3; ++d)
        {
          lower[d] = std::min(lower[d], x[d]);
          upper[d] = std::max(upper[d], x[d]);
        }
  }

  double
  GridMesh::min_edge() const
  {
    double             h  = std::numeric_limits<double>::max();
    const unsigned int nv = n_cell_vertices();
    for (std::size_t c = 0; c < n_cells(); ++c)
      for (unsigned int v = 0; v < nv; ++v)
        for (unsigned int d = 0; d < dim; ++d)
          if (!(v & (1u << d)))
            {
              const auto &a = vertices[cells[c * nv + v]], &b = vertices[cells[c * nv + (v | (1u << d))]];
              double      l = 0;
              for (unsigned int k = 0; k < 3; ++k)
                l += (a[k] - b[k]) * (a[k] - b[k]);
              h = std::min(h, std::sqrt(l));
            }
    return h;
  }

  GridMesh
  make_box_mesh(const unsigned int dim, const double lower[3], const double upper[3],
                const std::vector<unsigned int> &n)
  {
    GridMesh m;
    m.dim              = dim;
    unsigned int nn[3] = {1, 1, 1}, nc[3] = {1, 1, 1};
    for (unsigned int d = 0; d < dim; ++d)
      {
        require(n[d] > 0, "grid/cells", "every entry must be > 0");
        require(upper[d] > lower[d], "grid/upper corner", "must exceed 'lower corner' in every direction");
        nc[d] = n[d];
        nn[d] = n[d] + 1;
      }
    const auto vid = [&](unsigned int i, unsigned int j, unsigned int k) { return i + nn[0] * (j + nn[1] * k); };
    for (unsigned int k = 0; k < nn[2]; ++k)
      for (unsigned int j = 0; j < nn[1]; ++j)
        for (unsigned int i = 0; i < nn[0]; ++i)
          {
            const unsigned int    idx[3] = {i, j, k};
            std::array<double, 3> x{};
            for (unsigned int d = 0; d < dim; ++d)
              x[d] = idx[d] == nc[d] ? upper[d] : lower[d] + (upper[d] - lower[d]) * idx[d] / nc[d];
            m.vertices.push_back(x);
          }
    for (unsigned int k = 0; k < nc[2]; ++k)
      for (unsigned int j = 0; j < nc[1]; ++j)
        for (unsigned int i = 0; i < nc[0]; ++i)
          {
            for (unsigned int v = 0; v < m.n_cell_vertices(); ++v)
              m.cells.push_back(vid(i + (v & 1), j + ((v >> 1) & 1), k + ((v >> 2) & 1)));
            m.cell_material.push_back(0);
            // boundary faces of this cell
            const unsigned int idx[3] = {i, j, k};
            for (unsigned int d = 0; d < dim; ++d)
              for (unsigned int side = 0; side < 2; ++side)
                {
                  if (idx[d] != (side ? nc[d] - 1 : 0))
                    continue;
                  for (unsigned int v = 0; v < m.n_cell_vertices(); ++v)
                    if (((v >> d) & 1u) == side)
                      m.faces.push_back(m.cells[m.cells.size() - m.n_cell_vertices() + v]);
                  m.face_boundary.push_back(2 * d + side);
                }
          }
    // faces were pushed in lexicographic order; make them cyclic (quads in 3D)
    if (dim == 3)
      for (std::size_t f = 0; f < m.n_faces(); ++f)
        std::swap(m.faces[4 * f + 2], m.faces[4 * f + 3]);
    return m;
  }

  void
  check_cells(const GridMesh &m, const std::string &where)
  {
    for (std::size_t c = 0; c < m.n_cells(); ++c)
      {
        double       scale = 0;
        const auto   det   = corner_jacobians(m, c, scale);
        const double tol   = 1e-12 * std::pow(scale, m.dim);
        unsigned int n_pos = 0, n_neg = 0;
        for (const double j : det)
          {
            n_pos += j > tol;
            n_neg += j < -tol;
          }
        if (n_pos == det.size())
          continue;
        if (n_neg == det.size())
          throw InputError(where + ": " + m.describe_cell(c) +
                           " is inverted (negative Jacobian determinant at every corner: its vertices are "
                           "ordered clockwise" +
                           (m.dim == 3 ? " / mirrored" : "") + ")");
        throw InputError(where + ": " + m.describe_cell(c) +
                         " is degenerate (the Jacobian determinant is zero or changes sign between its corners: "
                         "collapsed, non-convex or self-intersecting cell)");
      }
  }

  void
  normalise_boxes(GridMesh &m, const std::string &where)
  {
    const unsigned int        nv = m.n_cell_vertices();
    std::vector<unsigned int> tmp(nv);
    for (std::size_t c = 0; c < m.n_cells(); ++c)
      {
        double lo[3], hi[3];
        for (unsigned int d = 0; d < m.dim; ++d)
          {
            lo[d] = std::numeric_limits<double>::max();
            hi[d] = -lo[d];
            for (unsigned int v = 0; v < nv; ++v)
              {
                lo[d] = std::min(lo[d], m.vertices[m.cells[c * nv + v]][d]);
                hi[d] = std::max(hi[d], m.vertices[m.cells[c * nv + v]][d]);
              }
          }
        unsigned int seen = 0;
        bool         ok   = true;
        for (unsigned int v = 0; v < nv && ok; ++v)
          {
            const auto  &x    = m.vertices[m.cells[c * nv + v]];
            unsigned int bits = 0;
            for (unsigned int d = 0; d < m.dim && ok; ++d)
              {
                const double h   = hi[d] - lo[d];
                const double tol = 1e-10 * h;
                if (!(h > 0))
                  ok = false;
                else if (std::abs(x[d] - hi[d]) <= tol)
                  bits |= 1u << d;
                else if (std::abs(x[d] - lo[d]) > tol)
                  ok = false;
              }
            if (ok && (seen & (1u << bits)))
              ok = false;
            seen |= 1u << bits;
            tmp[bits] = m.cells[c * nv + v];
          }
        if (!ok)
          throw InputError(where + ": " + m.describe_cell(c) +
                           " is not an axis-aligned box. The MPM background grid must consist of axis-aligned "
                           "rectangles/boxes (the Q1 kernel and MappingCartesian of the explicit solver assume "
                           "them; a known limitation, see docs/mesh.md): mesh the background as a structured "
                           "(transfinite) grid aligned with the axes");
        std::copy(tmp.begin(), tmp.end(), m.cells.begin() + c * nv);
      }
  }

  void
  check_faces(const GridMesh &m, const std::string &where)
  {
    const unsigned int nv = m.n_cell_vertices(), nf = m.n_face_vertices();
    using Key = std::array<unsigned int, 4>;
    std::vector<Key> cell_faces;
    cell_faces.reserve(m.n_cells() * 2 * m.dim);
    for (std::size_t c = 0; c < m.n_cells(); ++c)
      for (unsigned int d = 0; d < m.dim; ++d)
        for (unsigned int side = 0; side < 2; ++side)
          {
            Key          key{};
            unsigned int k = 0;
            for (unsigned int v = 0; v < nv; ++v)
              if (((v >> d) & 1u) == side)
                key[k++] = m.cells[c * nv + v];
            sort_face_key(key, nf);
            cell_faces.push_back(key);
          }
    std::sort(cell_faces.begin(), cell_faces.end());
    for (std::size_t k = 0; k < m.n_faces(); ++k)
      {
        Key key{};
        std::copy(m.faces.begin() + k * nf, m.faces.begin() + (k + 1) * nf, key.begin());
        sort_face_key(key, nf);
        const auto range = std::equal_range(cell_faces.begin(), cell_faces.end(), key);
        const auto count = range.second - range.first;
        if (count != 1)
          {
            std::ostringstream os;
            os << where << ": boundary face " << k << " (boundary id " << m.face_boundary[k] << ", vertices";
            for (unsigned int v = 0; v < nf; ++v)
              os << " " << fmt_vertex(m.vertices[key[v]], m.dim);
            os << ") is " << (count == 0 ? "not a face of any cell" : "inside the grid (between two cells)");
            throw InputError(os.str());
          }
      }
  }

  void
  write_msh(const GridMesh &m, const std::string &path)
  {
    const std::string tmp = path + ".part";
    {
      std::ofstream f(tmp);
      if (!f)
        throw InputError("cannot write grid file '" + tmp + "'");
      f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
      f << "$Nodes\n" << m.vertices.size() << "\n" << std::setprecision(17);
      for (std::size_t i = 0; i < m.vertices.size(); ++i)
        f << i + 1 << " " << m.vertices[i][0] << " " << m.vertices[i][1] << " " << m.vertices[i][2] << "\n";
      f << "$EndNodes\n$Elements\n" << m.n_faces() + m.n_cells() << "\n";
      std::size_t        id        = 1;
      const int          face_type = m.dim == 2 ? 1 : 3;
      const int          cell_type = m.dim == 2 ? 3 : 5;
      const unsigned int nf = m.n_face_vertices(), nv = m.n_cell_vertices();
      // physical tag = boundary id / material id; elementary tag = the same + 1
      for (std::size_t k = 0; k < m.n_faces(); ++k)
        {
          f << id++ << " " << face_type << " 2 " << m.face_boundary[k] << " " << m.face_boundary[k] + 1;
          for (unsigned int v = 0; v < nf; ++v)
            f << " " << m.faces[k * nf + v] + 1;
          f << "\n";
        }
      for (std::size_t c = 0; c < m.n_cells(); ++c)
        {
          f << id++ << " " << cell_type << " 2 " << m.cell_material[c] << " " << m.cell_material[c] + 1;
          for (unsigned int v = 0; v < nv; ++v)
            f << " " << m.cells[c * nv + lex_gmsh[v]] + 1;
          f << "\n";
        }
      f << "$EndElements\n";
      f.close();
      if (!f)
        throw InputError("error while writing grid file '" + tmp + "'");
    }
    std::filesystem::rename(tmp, path);
  }

  GridMesh
  read_msh(const std::string &path, const unsigned int dim)
  {
    std::ifstream f(path);
    if (!f)
      throw InputError("grid file '" + path + "' cannot be opened");
    GridMesh m;
    m.dim = dim;
    std::string  line;
    unsigned int lineno = 0;
    const auto   bad    = [&](const std::string &what) {
      throw InputError("grid file '" + path + "', line " + std::to_string(lineno) + ": " + what);
    };
    const auto next = [&]() -> std::string & {
      if (!std::getline(f, line))
        bad("unexpected end of file");
      ++lineno;
      if (!line.empty() && line.back() == '\r')
        line.pop_back();
      return line;
    };
    std::unordered_map<std::uint64_t, unsigned int> node_index;
    bool                                            have_format = false, have_nodes = false, have_elements = false;
    while (std::getline(f, line))
      {
        ++lineno;
        if (!line.empty() && line.back() == '\r')
          line.pop_back();
        if (line == "$MeshFormat")
          {
            std::istringstream is(next());
            double             version = 0;
            int                type    = -1;
            is >> version >> type;
            if (!is || version < 2 || version >= 3)
              bad("MSH format '" + line +
                  "' is not supported: talus grid files are MSH 2.2 ASCII (written by "
                  "talus-mesh, or by gmsh with -format msh22)");
            if (type != 0)
              bad("binary MSH is not supported (ASCII MSH 2.2 only)");
            have_format = true;
          }
        else if (line == "$Nodes")
          {
            std::size_t n = 0;
            std::istringstream(next()) >> n;
            node_index.reserve(n);
            m.vertices.reserve(n);
            for (std::size_t i = 0; i < n; ++i)
              {
                Tokens                is{next().c_str()};
                std::uint64_t         tag = 0;
                std::array<double, 3> x{};
                is >> tag >> x[0] >> x[1] >> x[2];
                if (!is || !std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
                  bad("cannot read node '" + line + "' (expected: tag x y z)");
                if (!node_index.emplace(tag, m.vertices.size()).second)
                  bad("node " + std::to_string(tag) + " is defined twice");
                m.vertices.push_back(x);
              }
            have_nodes = true;
          }
        else if (line == "$Elements")
          {
            if (!have_nodes)
              bad("$Elements before $Nodes");
            std::size_t n = 0;
            std::istringstream(next()) >> n;
            for (std::size_t i = 0; i < n; ++i)
              {
                Tokens        is{next().c_str()};
                std::uint64_t tag  = 0;
                int           type = 0, n_tags = 0;
                is >> tag >> type >> n_tags;
                std::vector<long> tags(std::max(0, n_tags));
                for (auto &t : tags)
                  is >> t;
                if (!is)
                  bad("cannot read element '" + line + "'");
                unsigned int nn   = 0;
                bool         cell = false;
                if (type == 15)
                  continue; // point
                if (dim == 2 && type == 1)
                  nn = 2;
                else if (dim == 2 && type == 3)
                  nn = 4, cell = true;
                else if (dim == 3 && type == 3)
                  nn = 4;
                else if (dim == 3 && type == 5)
                  nn = 8, cell = true;
                else if (dim == 3 && type == 1)
                  continue; // edges of a 3D mesh carry nothing for talus
                else
                  bad("element " + std::to_string(tag) + " has gmsh type " + std::to_string(type) + ", which a " +
                      std::to_string(dim) + "D talus grid file cannot hold (allowed: first-order " +
                      (dim == 2 ? "quadrangles (3) and boundary lines (1)"
                                : "hexahedra (5) and boundary quadrangles (3)") +
                      "; second-order or simplex elements are not supported)");
                const long phys = tags.empty() ? 0 : tags[0];
                if (phys < 0 || phys > 65535)
                  bad("physical tag " + std::to_string(phys) + " out of range 0..65535");
                std::vector<unsigned int> v(nn);
                for (auto &x : v)
                  {
                    std::uint64_t nt = 0;
                    is >> nt;
                    const auto it = node_index.find(nt);
                    if (!is || it == node_index.end())
                      bad("element " + std::to_string(tag) + " refers to an undefined node");
                    x = it->second;
                  }
                if (cell)
                  {
                    for (unsigned int k = 0; k < nn; ++k)
                      m.cells.push_back(v[lex_gmsh[k]]);
                    m.cell_material.push_back(phys);
                    m.cell_tag.push_back(tag);
                  }
                else
                  {
                    m.faces.insert(m.faces.end(), v.begin(), v.end());
                    m.face_boundary.push_back(phys);
                  }
              }
            have_elements = true;
          }
      }
    {
      // a cell listed twice (gmsh lists an element once per physical group it is in)
      const unsigned int                                               nv = m.n_cell_vertices();
      std::vector<std::pair<std::array<unsigned int, 8>, std::size_t>> keys(m.n_cells());
      for (std::size_t c = 0; c < m.n_cells(); ++c)
        {
          keys[c].first.fill(0);
          std::copy(m.cells.begin() + c * nv, m.cells.begin() + (c + 1) * nv, keys[c].first.begin());
          std::sort(keys[c].first.begin(), keys[c].first.begin() + nv);
          keys[c].second = c;
        }
      std::sort(keys.begin(), keys.end());
      for (std::size_t k = 1; k < keys.size(); ++k)
        if (keys[k].first == keys[k - 1].first)
          throw InputError("grid file '" + path + "': elements " + std::to_string(m.cell_tag[keys[k - 1].second]) +
                           " and " + std::to_string(m.cell_tag[keys[k].second]) +
                           " are the same cell (gmsh writes an element once per physical group it belongs to: "
                           "put every cell in one group of its dimension, or write the grid with talus-mesh)");
    }
    if (!have_format || !have_nodes || !have_elements)
      throw InputError("grid file '" + path + "': not a MSH 2.2 ASCII file (missing $MeshFormat, $Nodes or $Elements)");
    if (m.n_cells() == 0)
      throw InputError("grid file '" + path + "': contains no " + (dim == 2 ? "quadrangles" : "hexahedra") +
                       " (is the dimension " + std::to_string(dim) + " right?)");
    return m;
  }
} // namespace talus::io
