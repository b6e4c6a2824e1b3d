// talus — mesh preparation (prepare.h).
#include <talus/base/errors.h>
#include <talus/loads/k0.h>
#include <talus/mesh/prepare.h>

#include <deal.II/base/quadrature_lib.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_map>

namespace talus::mesh
{
  namespace
  {
    constexpr unsigned int lex_gmsh[8] = {0, 1, 3, 2, 4, 5, 7, 6};

    std::string
    fmt_point(const double *x, const unsigned int dim)
    {
      std::ostringstream os;
      os << std::setprecision(10) << "(";
      for (unsigned int d = 0; d < dim; ++d)
        os << (d ? ", " : "") << x[d];
      os << ")";
      return os.str();
    }

    std::string
    element_name(const int type)
    {
      switch (type)
        {
          case 1:
            return "line";
          case 2:
            return "triangle";
          case 3:
            return "quadrangle";
          case 4:
            return "tetrahedron";
          case 5:
            return "hexahedron";
          case 6:
            return "prism";
          case 7:
            return "pyramid";
          case 15:
            return "point";
          default:
            return "type " + std::to_string(type);
        }
    }

    /// 1D rule on [0, 1]: cell-centred regular positions or Gauss-Legendre.
    void
    rule_1d(const unsigned int n, const bool gauss, std::vector<double> &x, std::vector<double> &w)
    {
      x.resize(n);
      w.resize(n);
      if (gauss)
        {
          const dealii::QGauss<1> q(n);
          for (unsigned int i = 0; i < n; ++i)
            x[i] = q.point(i)[0], w[i] = q.weight(i);
        }
      else
        for (unsigned int i = 0; i < n; ++i)
          x[i] = (i + 0.5) / n, w[i] = 1.0 / n;
    }

    /// Multilinear map of a quad/hex (vertices in lexicographic order): x(xi), det J(xi).
    template <int dim>
    void
    multilinear(const std::array<double, 3> *X[], const double *xi, double *x, double &det)
    {
      constexpr unsigned int nv      = 1u << dim;
      double                 J[3][3] = {};
      for (unsigned int k = 0; k < 3; ++k)
        x[k] = 0;
      for (unsigned int v = 0; v < nv; ++v)
        {
          double N = 1, dN[3] = {1, 1, 1};
          for (unsigned int d = 0; d < dim; ++d)
            {
              const bool   hi = (v >> d) & 1u;
              const double f  = hi ? xi[d] : 1 - xi[d];
              N *= f;
              for (unsigned int e = 0; e < dim; ++e)
                dN[e] *= (e == d) ? (hi ? 1.0 : -1.0) : f;
            }
          for (unsigned int k = 0; k < dim; ++k)
            {
              x[k] += N * (*X[v])[k];
              for (unsigned int e = 0; e < dim; ++e)
                J[k][e] += dN[e] * (*X[v])[k];
            }
        }
      det = dim == 2
              ? J[0][0] * J[1][1] - J[0][1] * J[1][0]
              : J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                  J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    }

    double
    max_edge(const std::vector<const std::array<double, 3> *> &X)
    {
      double h = 0;
      for (std::size_t a = 0; a < X.size(); ++a)
        for (std::size_t b = a + 1; b < X.size(); ++b)
          {
            double l = 0;
            for (unsigned int k = 0; k < 3; ++k)
              l += ((*X[a])[k] - (*X[b])[k]) * ((*X[a])[k] - (*X[b])[k]);
            h = std::max(h, std::sqrt(l));
          }
      return h;
    }

    /// Id a physical group carries: the .prm map by name first, then the naming
    /// convention "<kind> <id> [label]", then (unnamed groups) its tag; -1: a
    /// plain label.
    long
    group_id(const GmshGroup &g, const std::string &kind, const std::map<std::string, unsigned int> &map)
    {
      if (g.name.empty())
        return g.tag;
      const auto it = map.find(normalise_name(g.name));
      if (it != map.end())
        return it->second;
      return convention_id(g.name, kind);
    }

    /// entity tag -> physical groups of dimension d that contain it
    std::map<int, std::vector<const GmshGroup *>>
    groups_by_entity(const GmshModel &m, const int d)
    {
      std::map<int, std::vector<const GmshGroup *>> r;
      for (const auto &g : m.groups)
        if (g.dim == d)
          for (const int e : g.entities)
            r[e].push_back(&g);
      return r;
    }

    const GmshGroup &
    require_group(const GmshModel &m, const int d, const std::string &ref, const std::string &where)
    {
      const GmshGroup *g = m.find(d, ref);
      if (!g)
        throw InputError(where + ": physical group '" + ref + "' of dimension " + std::to_string(d) +
                         " does not exist in '" + m.file + "' (groups of dimension " + std::to_string(d) + ": " +
                         m.list_groups(d) + ")");
      return *g;
    }

    template <int dim>
    void
    check_maps(const Settings<dim> &s, const GmshModel &m)
    {
      for (const auto &[name, id] : s.boundary_map)
        require_group(m, dim - 1, name, "grid/boundary groups");
      for (const auto &[name, id] : s.material_map)
        require_group(m, dim, name, "grid/material groups");
    }

    struct GridBuild
    {
      io::GridMesh     mesh;
      std::vector<int> cell_entity; ///< gmsh entity of each cell; empty for a box
      bool             boxes = true;
    };

    template <int dim>
    GridBuild
    grid_from_gmsh(const Settings<dim> &s, const GmshModel &m, Summary &summary)
    {
      const std::string      where = "grid/file '" + s.grid_file + "'";
      constexpr unsigned int nv = 1u << dim, nf = 1u << (dim - 1);
      const int              cell_type = dim == 2 ? 3 : 5, face_type = dim == 2 ? 1 : 3;
      GridBuild              b;
      auto                  &g = b.mesh;
      g.dim                    = dim;
      // cells must be quads/hexes
      std::map<int, std::size_t> other;
      const GmshElement         *first_other = nullptr;
      for (const auto &e : m.cells)
        if (e.type != cell_type)
          {
            if (!first_other)
              first_other = &e;
            ++other[e.type];
          }
      if (first_other)
        {
          std::string counts;
          for (const auto &[t, n] : other)
            counts += (counts.empty() ? "" : ", ") + std::to_string(n) + " " + element_name(t) + "(s)";
          throw InputError(where + ": the background grid must consist of " + (dim == 2 ? "quadrangles" : "hexahedra") +
                           ", but the mesh has " + counts + " (first: gmsh element " +
                           std::to_string(first_other->tag) +
                           "). Use Recombine/Transfinite in the .geo, 'recombine = true', or 'subdivide = true'");
        }
      // compact vertex numbering: the nodes the cells use, in first-use order
      std::vector<unsigned int> index(m.nodes.size(), dealii::numbers::invalid_unsigned_int);
      for (const auto &e : m.cells)
        for (unsigned int v = 0; v < nv; ++v)
          {
            auto &i = index[e.nodes[lex_gmsh[v]]];
            if (i == dealii::numbers::invalid_unsigned_int)
              {
                i = g.vertices.size();
                g.vertices.push_back(m.nodes[e.nodes[lex_gmsh[v]]]);
              }
            g.cells.push_back(i);
          }
      for (const auto &e : m.cells)
        {
          g.cell_tag.push_back(e.tag);
          b.cell_entity.push_back(e.entity);
        }
      // material ids from the groups of dimension dim
      const auto cell_groups = groups_by_entity(m, dim);
      g.cell_material.assign(m.cells.size(), 0);
      std::map<int, unsigned int> entity_material;
      for (const auto &[entity, groups] : cell_groups)
        {
          long             id    = -1;
          const GmshGroup *first = nullptr;
          for (const auto *gr : groups)
            {
              const long k = group_id(*gr, "material", s.material_map);
              if (k < 0)
                continue;
              if (id >= 0 && k != id)
                throw InputError(where + ": surface/volume " + std::to_string(entity) + " is in two material groups, " +
                                 first->describe() + " (material " + std::to_string(id) + ") and " + gr->describe() +
                                 " (material " + std::to_string(k) + ")");
              id = k, first = gr;
            }
          if (id >= 0)
            entity_material[entity] = id;
        }
      for (std::size_t c = 0; c < m.cells.size(); ++c)
        {
          const auto it = entity_material.find(m.cells[c].entity);
          if (it != entity_material.end())
            g.cell_material[c] = it->second;
        }
      // 2D: a surface whose cells are all clockwise (oriented along -z) is reoriented
      if (dim == 2)
        {
          std::map<int, std::pair<std::size_t, std::size_t>> cw; // entity -> (clockwise cells, cells)
          for (std::size_t c = 0; c < g.n_cells(); ++c)
            {
              const auto &X0 = g.vertices[g.cells[4 * c]], &X1 = g.vertices[g.cells[4 * c + 1]],
                         &X2   = g.vertices[g.cells[4 * c + 2]];
              const double det = (X1[0] - X0[0]) * (X2[1] - X0[1]) - (X1[1] - X0[1]) * (X2[0] - X0[0]);
              auto        &p   = cw[b.cell_entity[c]];
              p.first += det < 0;
              ++p.second;
            }
          for (const auto &[entity, p] : cw)
            if (p.first == p.second)
              {
                for (std::size_t c = 0; c < g.n_cells(); ++c)
                  if (b.cell_entity[c] == entity)
                    {
                      std::swap(g.cells[4 * c], g.cells[4 * c + 2]);
                      std::swap(g.cells[4 * c + 1], g.cells[4 * c + 3]);
                    }
                summary.notes.push_back("surface " + std::to_string(entity) +
                                        ": cells ordered clockwise (surface oriented along -z), reoriented");
              }
        }
      io::check_cells(g, where);

      // faces of the cells: sorted vertex key -> (number of cells, face vertices in cyclic order)
      std::map<std::array<unsigned int, nf>, std::pair<unsigned int, std::array<unsigned int, nf>>> faces;
      for (std::size_t c = 0; c < g.n_cells(); ++c)
        for (unsigned int d = 0; d < dim; ++d)
          for (unsigned int side = 0; side < 2; ++side)
            {
              std::array<unsigned int, nf> f;
              unsigned int                 k = 0;
              for (unsigned int v = 0; v < nv; ++v)
                if (((v >> d) & 1u) == side)
                  f[k++] = g.cells[c * nv + v];
              if (nf == 4)
                std::swap(f[2], f[3]);
              auto key = f;
              std::sort(key.begin(), key.end());
              auto &entry = faces[key];
              ++entry.first;
              entry.second = f;
            }
      // boundary ids from the groups of dimension dim - 1
      const auto          facet_groups = groups_by_entity(m, dim - 1);
      std::map<int, long> entity_boundary;
      for (const auto &[entity, groups] : facet_groups)
        for (const auto *gr : groups)
          {
            const long k = group_id(*gr, "boundary", s.boundary_map);
            if (k < 0)
              throw InputError(where + ": physical group " + gr->describe() +
                               " has no boundary id: name it 'boundary <id>' (e.g. 'boundary 3' or 'boundary 3 "
                               "top'), give it a number only, or map it in grid/boundary groups ('" +
                               gr->name + " = <id>')");
            const auto it = entity_boundary.find(entity);
            if (it != entity_boundary.end() && it->second != k)
              throw InputError(where + ": curve/surface " + std::to_string(entity) +
                               " is in two boundary groups with ids " + std::to_string(it->second) + " and " +
                               std::to_string(k));
            entity_boundary[entity] = k;
          }
      std::map<std::array<unsigned int, nf>, unsigned int> face_id;
      for (const auto &e : m.facets)
        {
          const auto it = entity_boundary.find(e.entity);
          if (it == entity_boundary.end())
            continue;
          if (e.type != face_type)
            throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " (a " + element_name(e.type) +
                             ") of a boundary group is not a face of a " + (dim == 2 ? "quadrangle" : "hexahedron"));
          std::array<unsigned int, nf> key;
          bool                         ok = true;
          for (unsigned int v = 0; v < nf; ++v)
            {
              key[v] = index[e.nodes[v]];
              ok     = ok && key[v] != dealii::numbers::invalid_unsigned_int;
            }
          std::sort(key.begin(), key.end());
          const auto f = ok ? faces.find(key) : faces.end();
          if (f == faces.end())
            throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " of boundary id " +
                             std::to_string(it->second) + " is not a face of any grid cell");
          if (f->second.first != 1)
            throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " of boundary id " +
                             std::to_string(it->second) +
                             " lies inside the domain (between two cells); boundary groups must lie on the boundary");
          face_id[key] = it->second;
        }
      std::size_t unlabelled = 0;
      for (const auto &[key, entry] : faces)
        if (entry.first == 1)
          {
            const auto it = face_id.find(key);
            g.faces.insert(g.faces.end(), entry.second.begin(), entry.second.end());
            g.face_boundary.push_back(it == face_id.end() ? 0 : it->second);
            unlabelled += it == face_id.end();
          }
      if (unlabelled > 0)
        summary.notes.push_back(std::to_string(unlabelled) +
                                " boundary faces are in no boundary group: they get boundary id 0");
      for (const auto &gr : m.groups)
        if (gr.dim == dim && group_id(gr, "material", s.material_map) < 0)
          summary.notes.push_back("physical group " + gr.describe() + " carries no material id (a label for bodies)");
      return b;
    }

    struct SeedPoint
    {
      double        x[3];
      double        volume;
      unsigned int  body, material;
      double        scale;     ///< largest edge of the cell/element it came from
      double        half_up;   ///< half the point spacing along the vertical axis
      bool          from_grid; ///< seeded in a grid cell (else: body-mesh element)
      std::uint64_t origin;    ///< grid cell index / gmsh element tag
    };

    template <int dim>
    std::string
    describe_point(const std::vector<SeedPoint> &pts, const std::size_t i, const Settings<dim> &s)
    {
      const auto        &p = pts[i];
      std::ostringstream os;
      os << "material point " << i << " at " << fmt_point(p.x, dim) << " (body " << p.body << " '"
         << s.bodies[p.body].name << "', ";
      if (p.from_grid)
        os << "grid cell " << p.origin << ")";
      else
        os << "gmsh element " << p.origin << " of '" << s.bodies[p.body].file << "')";
      return os.str();
    }

    /// Point location in the grid: buckets of cell bounding boxes, then the box
    /// test (axis-aligned grids) or a Newton inversion of the multilinear map.
    template <int dim>
    class Locator
    {
    public:
      Locator(const io::GridMesh &g, const bool boxes)
          : g(g)
          , boxes(boxes)
      {
        constexpr unsigned int nv = 1u << dim;
        lo.assign(g.n_cells() * dim, 0);
        hi.assign(g.n_cells() * dim, 0);
        double h = 0;
        for (unsigned int d = 0; d < dim; ++d)
          L[d] = std::numeric_limits<double>::max(), U[d] = -L[d];
        for (std::size_t c = 0; c < g.n_cells(); ++c)
          for (unsigned int d = 0; d < dim; ++d)
            {
              double a = std::numeric_limits<double>::max(), b = -a;
              for (unsigned int v = 0; v < nv; ++v)
                a = std::min(a, g.vertices[g.cells[c * nv + v]][d]),
                b = std::max(b, g.vertices[g.cells[c * nv + v]][d]);
              lo[c * dim + d] = a, hi[c * dim + d] = b;
              L[d] = std::min(L[d], a), U[d] = std::max(U[d], b);
              h += b - a;
            }
        size              = h / (dim * std::max<std::size_t>(1, g.n_cells()));
        std::size_t total = 1;
        for (unsigned int d = 0; d < dim; ++d)
          {
            n[d] = std::max(1, int(std::min(2e6, std::ceil((U[d] - L[d]) / size))));
            total *= n[d];
          }
        require(total < 1e8, "grid", "cells too unequal in size for the point location (bucket grid)");
        buckets.resize(total);
        for (std::size_t c = 0; c < g.n_cells(); ++c)
          {
            int b0[3] = {0, 0, 0}, b1[3] = {0, 0, 0};
            for (unsigned int d = 0; d < dim; ++d)
              {
                const double tol = 1e-10 * (hi[c * dim + d] - lo[c * dim + d]);
                b0[d]            = bucket(lo[c * dim + d] - tol, d);
                b1[d]            = bucket(hi[c * dim + d] + tol, d);
              }
            for (int k = b0[2]; k <= b1[2]; ++k)
              for (int j = b0[1]; j <= b1[1]; ++j)
                for (int i = b0[0]; i <= b1[0]; ++i)
                  buckets[i + n[0] * (j + std::size_t(n[1]) * k)].push_back(c);
          }
      }

      /// Cell containing x, or -1.
      long
      find(const double *x) const
      {
        int b[3] = {0, 0, 0};
        for (unsigned int d = 0; d < dim; ++d)
          {
            if (x[d] < L[d] - 1e-10 * size || x[d] > U[d] + 1e-10 * size)
              return -1;
            b[d] = bucket(x[d], d);
          }
        for (const auto c : buckets[b[0] + n[0] * (b[1] + std::size_t(n[1]) * b[2])])
          if (inside(c, x))
            return c;
        return -1;
      }

    private:
      int
      bucket(const double x, const unsigned int d) const
      {
        return std::max(0, std::min(n[d] - 1, int(std::floor((x - L[d]) / size))));
      }

      bool
      inside(const std::size_t c, const double *x) const
      {
        constexpr unsigned int nv = 1u << dim;
        for (unsigned int d = 0; d < dim; ++d)
          {
            const double tol = 1e-10 * (hi[c * dim + d] - lo[c * dim + d]);
            if (x[d] < lo[c * dim + d] - tol || x[d] > hi[c * dim + d] + tol)
              return false;
          }
        if (boxes)
          return true;
        // Newton on the multilinear map
        const std::array<double, 3> *X[8];
        for (unsigned int v = 0; v < nv; ++v)
          X[v] = &g.vertices[g.cells[c * nv + v]];
        double xi[3] = {0.5, 0.5, 0.5};
        for (unsigned int it = 0; it < 30; ++it)
          {
            double y[3], det, J[3][3];
            multilinear<dim>(X, xi, y, det);
            // finite-difference Jacobian (robust and cheap enough here)
            for (unsigned int e = 0; e < dim; ++e)
              {
                double xp[3] = {xi[0], xi[1], xi[2]}, yp[3], dd;
                xp[e] += 1e-7;
                multilinear<dim>(X, xp, yp, dd);
                for (unsigned int k = 0; k < dim; ++k)
                  J[k][e] = (yp[k] - y[k]) / 1e-7;
              }
            double r[3] = {x[0] - y[0], x[1] - y[1], dim == 3 ? x[2] - y[2] : 0}, dx[3] = {0, 0, 0};
            if (dim == 2)
              {
                const double D = J[0][0] * J[1][1] - J[0][1] * J[1][0];
                dx[0]          = (J[1][1] * r[0] - J[0][1] * r[1]) / D;
                dx[1]          = (-J[1][0] * r[0] + J[0][0] * r[1]) / D;
              }
            else
              {
                // Cramer's rule
                const auto det3 = [](double a[3][3]) {
                  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                         a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
                };
                const double D = det3(J);
                for (unsigned int e = 0; e < 3; ++e)
                  {
                    double A[3][3];
                    for (unsigned int i = 0; i < 3; ++i)
                      for (unsigned int j = 0; j < 3; ++j)
                        A[i][j] = j == e ? r[i] : J[i][j];
                    dx[e] = det3(A) / D;
                  }
              }
            double step = 0;
            for (unsigned int d = 0; d < dim; ++d)
              xi[d] += dx[d], step = std::max(step, std::abs(dx[d]));
            if (step < 1e-13)
              break;
          }
        for (unsigned int d = 0; d < dim; ++d)
          if (!(xi[d] >= -1e-10 && xi[d] <= 1 + 1e-10))
            return false;
        return true;
      }

      const io::GridMesh                   &g;
      const bool                            boxes;
      std::vector<double>                   lo, hi;
      double                                L[3] = {0, 0, 0}, U[3] = {0, 0, 0}, size = 1;
      int                                   n[3] = {1, 1, 1};
      std::vector<std::vector<std::size_t>> buckets;
    };

    template <int dim>
    bool
    grid_body(const BodySpec<dim> &b)
    {
      return b.source != BodySpec<dim>::Source::gmsh;
    }

    /// Points of the grid-seeded bodies (shapes and grid regions), cell by cell,
    /// bodies in order, first body wins (as seed_bodies() of the solvers).
    template <int dim>
    void
    seed_in_grid(const Settings<dim> &s, const GridBuild &gb, const GmshModel *grid_model, std::vector<SeedPoint> &pts)
    {
      constexpr unsigned int nv = 1u << dim;
      const auto            &g  = gb.mesh;
      // per grid-region body: the entities it covers (empty set + flag: all cells)
      std::vector<std::set<int>> entities(s.bodies.size());
      std::vector<char>          all(s.bodies.size(), 0);
      for (unsigned int b = 0; b < s.bodies.size(); ++b)
        if (s.bodies[b].source == BodySpec<dim>::Source::grid)
          {
            if (s.bodies[b].groups.empty())
              all[b] = 1;
            for (const auto &ref : s.bodies[b].groups)
              {
                const std::string where = "body " + std::to_string(b) + "/groups";
                if (!grid_model)
                  throw InputError(where + ": grid/source = box has no physical groups (leave 'groups' empty for "
                                           "the whole grid, or use a gmsh grid)");
                const auto &gr = require_group(*grid_model, dim, ref, where);
                entities[b].insert(gr.entities.begin(), gr.entities.end());
              }
          }
      const auto in_body = [&](const unsigned int b, const std::size_t c, const double *x) {
        const auto &spec = s.bodies[b];
        if (spec.source == BodySpec<dim>::Source::grid)
          return all[b] || entities[b].count(gb.cell_entity[c]) > 0;
        dealii::Point<dim> p;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = x[d];
        return spec.shape.contains(p);
      };
      std::vector<double> rx, rw;
      for (std::size_t c = 0; c < g.n_cells(); ++c)
        {
          const std::array<double, 3>               *X[8];
          std::vector<const std::array<double, 3> *> Xv;
          for (unsigned int v = 0; v < nv; ++v)
            X[v] = &g.vertices[g.cells[c * nv + v]], Xv.push_back(X[v]);
          const double scale = max_edge(Xv);
          double       lower[3], h[3], cell_volume = 1;
          for (unsigned int d = 0; d < dim; ++d)
            {
              lower[d] = (*X[0])[d];
              h[d]     = (*X[nv - 1])[d] - lower[d];
              cell_volume *= h[d];
            }
          for (unsigned int b = 0; b < s.bodies.size(); ++b)
            {
              const auto &spec = s.bodies[b];
              if (!grid_body(spec))
                continue;
              rule_1d(spec.n, spec.gauss, rx, rw);
              unsigned int total = 1;
              for (unsigned int d = 0; d < dim; ++d)
                total *= spec.n;
              for (unsigned int k = 0; k < total; ++k)
                {
                  double       xi[3] = {0, 0, 0}, w = 1, x[3] = {0, 0, 0}, volume;
                  unsigned int r = k;
                  for (unsigned int d = 0; d < dim; ++d)
                    {
                      xi[d] = rx[r % spec.n];
                      w *= rw[r % spec.n];
                      r /= spec.n;
                    }
                  if (gb.boxes)
                    {
                      // exactly the arithmetic of the solvers' seed_bodies()
                      for (unsigned int d = 0; d < dim; ++d)
                        x[d] = lower[d] + xi[d] * h[d];
                      volume = spec.gauss ? cell_volume * w : cell_volume / total;
                    }
                  else
                    {
                      double det = 0;
                      multilinear<dim>(X, xi, x, det);
                      volume = det * w;
                    }
                  if (!in_body(b, c, x))
                    continue;
                  bool claimed = false;
                  for (unsigned int e = 0; e < b && !claimed; ++e)
                    claimed = grid_body(s.bodies[e]) && in_body(e, c, x);
                  if (claimed)
                    continue;
                  SeedPoint p;
                  std::copy(x, x + 3, p.x);
                  p.volume    = volume;
                  p.body      = b;
                  p.material  = spec.material >= 0 ? spec.material : g.cell_material[c];
                  p.scale     = scale;
                  p.half_up   = 0.5 * std::abs(h[dim - 1]) / spec.n;
                  p.from_grid = true;
                  p.origin    = c;
                  pts.push_back(p);
                }
            }
        }
    }

    /// Points of a gmsh body mesh: per element of dimension dim, n per direction
    /// (quads/hexes: regular or Gauss; triangles: regular sub-triangle centroids
    /// or Gauss; tetrahedra: Gauss), volume = |det J| x weight.
    template <int dim>
    void
    seed_body_mesh(const Settings<dim> &s, const unsigned int b, const GmshModel &m, std::vector<SeedPoint> &pts)
    {
      const auto       &spec  = s.bodies[b];
      const std::string where = "body " + std::to_string(b) + " ('" + spec.name + "')";
      std::set<int>     selected;
      for (const auto &ref : spec.groups)
        {
          const auto &gr = require_group(m, dim, ref, "body " + std::to_string(b) + "/groups");
          selected.insert(gr.entities.begin(), gr.entities.end());
        }
      const auto                  groups = groups_by_entity(m, dim);
      std::map<int, unsigned int> entity_material;
      if (spec.material < 0)
        for (const auto &[entity, gl] : groups)
          for (const auto *gr : gl)
            {
              const long k = group_id(*gr, "material", s.material_map);
              if (k >= 0)
                entity_material[entity] = k;
            }
      // reference rules
      std::vector<double> rx, rw;
      rule_1d(spec.n, spec.gauss, rx, rw);
      std::vector<std::array<double, 3>> simplex_points;
      std::vector<double>                simplex_weights;
      if (spec.gauss)
        {
          const dealii::QGaussSimplex<dim> q(spec.n);
          for (unsigned int i = 0; i < q.size(); ++i)
            {
              simplex_points.push_back({{q.point(i)[0], q.point(i)[1], dim == 3 ? q.point(i)[dim - 1] : 0.0}});
              simplex_weights.push_back(q.weight(i));
            }
        }
      else if (dim == 2)
        {
          const unsigned int n = spec.n;
          for (unsigned int j = 0; j < n; ++j)
            for (unsigned int i = 0; i + j < n; ++i)
              {
                simplex_points.push_back({{(i + 1.0 / 3) / n, (j + 1.0 / 3) / n, 0}});
                simplex_weights.push_back(0.5 / (n * n));
                if (i + j + 1 < n)
                  {
                    simplex_points.push_back({{(i + 2.0 / 3) / n, (j + 2.0 / 3) / n, 0}});
                    simplex_weights.push_back(0.5 / (n * n));
                  }
              }
        }
      const int   simplex_type = dim == 2 ? 2 : 4, cube_type = dim == 2 ? 3 : 5;
      std::size_t n_used = 0;
      for (const auto &e : m.cells)
        {
          if (!selected.empty() && !selected.count(e.entity))
            continue;
          ++n_used;
          unsigned int material = spec.material;
          if (spec.material < 0)
            {
              const auto it = entity_material.find(e.entity);
              if (it == entity_material.end())
                throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " of '" + spec.file +
                                 "' is in no material group ('material <id>' or an unnamed group), but the body "
                                 "takes its material ids from the groups (material = groups)");
              material = it->second;
            }
          std::vector<const std::array<double, 3> *> X;
          for (const auto v : e.nodes)
            X.push_back(&m.nodes[v]);
          const double scale = max_edge(X);
          double       zmin = std::numeric_limits<double>::max(), zmax = -zmin;
          for (const auto *x : X)
            zmin = std::min(zmin, (*x)[dim - 1]), zmax = std::max(zmax, (*x)[dim - 1]);
          const auto push = [&](const double *x, const double volume) {
            SeedPoint p;
            std::copy(x, x + 3, p.x);
            p.volume    = volume;
            p.body      = b;
            p.material  = material;
            p.scale     = scale;
            p.half_up   = 0.5 * (zmax - zmin) / spec.n;
            p.from_grid = false;
            p.origin    = e.tag;
            pts.push_back(p);
          };
          if (e.type == simplex_type)
            {
              if (simplex_points.empty())
                throw InputError(where + ": regular positions are not available on tetrahedra (gmsh element " +
                                 std::to_string(e.tag) + "): use positions = gauss");
              double J[3][3] = {};
              for (unsigned int k = 0; k < dim; ++k)
                for (unsigned int d = 0; d < dim; ++d)
                  J[k][d] = (*X[d + 1])[k] - (*X[0])[k];
              const double det = dim == 2 ? J[0][0] * J[1][1] - J[0][1] * J[1][0]
                                          : J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                                              J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                                              J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
              for (std::size_t q = 0; q < simplex_points.size(); ++q)
                {
                  double x[3] = {0, 0, 0};
                  for (unsigned int k = 0; k < dim; ++k)
                    {
                      x[k] = (*X[0])[k];
                      for (unsigned int d = 0; d < dim; ++d)
                        x[k] += J[k][d] * simplex_points[q][d];
                    }
                  push(x, std::abs(det) * simplex_weights[q]);
                }
            }
          else if (e.type == cube_type)
            {
              constexpr unsigned int       nv = 1u << dim;
              const std::array<double, 3> *L[8];
              for (unsigned int v = 0; v < nv; ++v)
                L[v] = X[lex_gmsh[v]];
              // the sign of det J must not change inside the element
              int sign = 0;
              for (unsigned int v = 0; v < nv; ++v)
                {
                  double xi[3] = {double(v & 1), double((v >> 1) & 1), double((v >> 2) & 1)}, y[3], det;
                  multilinear<dim>(L, xi, y, det);
                  const int sv = det > 1e-12 * std::pow(scale, dim) ? 1 : det < -1e-12 * std::pow(scale, dim) ? -1 : 0;
                  if (sv == 0 || (sign != 0 && sv != sign))
                    throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " of '" + spec.file +
                                     "' is degenerate (its Jacobian determinant is zero or changes sign)");
                  sign = sv;
                }
              unsigned int total = 1;
              for (unsigned int d = 0; d < dim; ++d)
                total *= spec.n;
              for (unsigned int k = 0; k < total; ++k)
                {
                  double       xi[3] = {0, 0, 0}, w = 1, x[3], det;
                  unsigned int r = k;
                  for (unsigned int d = 0; d < dim; ++d)
                    {
                      xi[d] = rx[r % spec.n];
                      w *= rw[r % spec.n];
                      r /= spec.n;
                    }
                  multilinear<dim>(L, xi, x, det);
                  push(x, std::abs(det) * w);
                }
            }
          else
            throw InputError(where + ": gmsh element " + std::to_string(e.tag) + " of '" + spec.file + "' is a " +
                             element_name(e.type) + "; a " + std::to_string(dim) + "D body mesh may hold " +
                             (dim == 2 ? "triangles and quadrangles" : "tetrahedra and hexahedra"));
        }
      if (n_used == 0)
        throw InputError(where + ": the selected groups of '" + spec.file + "' contain no elements of dimension " +
                         std::to_string(dim));
    }
  } // namespace

  template <int dim>
  void
  check_groups(const Settings<dim> &s)
  {
    GmshOptions geometry_only = s.grid_options;
    geometry_only.generate    = false;
    if (s.grid_from_gmsh)
      {
        const auto m = load_gmsh(s.grid_file, dim, geometry_only, "grid/file");
        check_maps(s, m);
        for (unsigned int b = 0; b < s.bodies.size(); ++b)
          if (s.bodies[b].source == BodySpec<dim>::Source::grid)
            for (const auto &ref : s.bodies[b].groups)
              require_group(m, dim, ref, "body " + std::to_string(b) + "/groups");
      }
    else
      {
        require(s.boundary_map.empty() && s.material_map.empty(), "grid/boundary groups, grid/material groups",
                "a box grid has no physical groups (leave these entries empty)");
        for (unsigned int b = 0; b < s.bodies.size(); ++b)
          require(s.bodies[b].source != BodySpec<dim>::Source::grid || s.bodies[b].groups.empty(),
                  "body " + std::to_string(b) + "/groups",
                  "grid/source = box has no physical groups (leave 'groups' empty for the whole grid)");
      }
    for (unsigned int b = 0; b < s.bodies.size(); ++b)
      if (s.bodies[b].source == BodySpec<dim>::Source::gmsh)
        {
          GmshOptions o;
          o.recombine  = false;
          o.generate   = false;
          const auto m = load_gmsh(s.bodies[b].file, dim, o, "body " + std::to_string(b) + "/file");
          for (const auto &ref : s.bodies[b].groups)
            require_group(m, dim, ref, "body " + std::to_string(b) + "/groups");
        }
  }

  template <int dim>
  Result<dim>
  prepare(const Settings<dim> &s)
  {
    Result<dim> r;
    auto       &summary = r.summary;
    check_groups(s);

    // ---- grid
    GridBuild                  gb;
    std::unique_ptr<GmshModel> grid_model;
    if (s.grid_from_gmsh)
      {
        grid_model = std::make_unique<GmshModel>(load_gmsh(s.grid_file, dim, s.grid_options, "grid/file"));
        check_maps(s, *grid_model);
        gb = grid_from_gmsh(s, *grid_model, summary);
        if (grid_model->duplicates)
          summary.notes.push_back("grid/file: " + std::to_string(grid_model->duplicates) +
                                  " repeated elements counted once (a MSH 2.2 file lists an element once per physical "
                                  "group it is in)");
      }
    else
      {
        gb.mesh = io::make_box_mesh(dim, s.lower, s.upper, s.cells);
        gb.cell_entity.assign(gb.mesh.n_cells(), -1);
      }
    if (!s.allow_distorted)
      io::normalise_boxes(gb.mesh, s.grid_from_gmsh ? "grid/file '" + s.grid_file + "'" : "grid");
    else
      {
        io::GridMesh copy = gb.mesh;
        try
          {
            io::normalise_boxes(copy, "grid");
            gb.mesh = copy;
          }
        catch (const InputError &)
          {
            gb.boxes = false;
            summary.notes.push_back("the grid has cells that are not axis-aligned boxes: fine for talus-mesh, "
                                    "refused by the MPM solvers");
          }
      }
    for (const auto id : gb.mesh.face_boundary)
      ++summary.faces_per_boundary[id];
    for (const auto id : gb.mesh.cell_material)
      ++summary.cells_per_material[id];

    // ---- points
    std::vector<SeedPoint> pts;
    // shape bodies must lie wholly inside the grid unless 'clip to grid' (then noted)
    std::vector<std::string> clip_notes(s.bodies.size());
    {
      double glo[3], ghi[3];
      gb.mesh.bounding_box(glo, ghi);
      dealii::Point<dim> lo, hi;
      for (unsigned int d = 0; d < dim; ++d)
        lo[d] = glo[d], hi[d] = ghi[d];
      for (unsigned int b = 0; b < s.bodies.size(); ++b)
        {
          const auto &spec = s.bodies[b];
          if (spec.source != BodySpec<dim>::Source::box && spec.source != BodySpec<dim>::Source::ball &&
              spec.source != BodySpec<dim>::Source::polygon)
            continue;
          const std::string where = "body " + std::to_string(b) + " ('" + spec.name + "')";
          if (!spec.shape.clip_to_grid)
            {
              const std::string out = outside_extent(spec.shape, lo, hi);
              require(out.empty(), where,
                      out + "; a body must lie wholly inside the grid (allowed: move or shrink the body, enlarge "
                            "the grid, or set 'clip to grid = true' to drop the points outside)");
            }
          else if (!s.grid_from_gmsh)
            {
              std::vector<unsigned int> cells(s.cells.begin(), s.cells.end());
              const auto                c = clipped_by_box_grid(spec.shape, lo, hi, cells);
              std::ostringstream        os;
              os.precision(10);
              os << where << ", clip to grid: ";
              if (c.counted)
                os << c.points << " seeding positions outside the grid dropped, volume lost " << c.volume;
              else
                os << "the positions outside the grid were not counted (more than 5e7)";
              clip_notes[b] = os.str();
            }
          else
            clip_notes[b] = where + ", clip to grid: volume lost about @"; // completed after seeding
        }
    }
    seed_in_grid(s, gb, grid_model.get(), pts);
    for (unsigned int b = 0; b < s.bodies.size(); ++b)
      if (s.bodies[b].source == BodySpec<dim>::Source::gmsh)
        {
          GmshOptions o;
          o.recombine         = false;
          o.round_coordinates = s.grid_options.round_coordinates;
          const auto m        = load_gmsh(s.bodies[b].file, dim, o, "body " + std::to_string(b) + "/file");
          seed_body_mesh(s, b, m, pts);
          if (m.duplicates)
            summary.notes.push_back("body " + std::to_string(b) + "/file: " + std::to_string(m.duplicates) +
                                    " repeated elements counted once (MSH 2.2: one copy per physical group)");
        }
    // body order (stable): the grid-seeded points come cell by cell
    std::stable_sort(pts.begin(), pts.end(), [](const SeedPoint &a, const SeedPoint &b) { return a.body < b.body; });

    // ---- checks
    summary.points_per_body.assign(s.bodies.size(), 0);
    summary.volume_per_body.assign(s.bodies.size(), 0.0);
    for (std::size_t i = 0; i < pts.size(); ++i)
      {
        const auto &p = pts[i];
        if (!(p.volume > 1e-12 * std::pow(p.scale, dim)) || !std::isfinite(p.volume))
          {
            std::ostringstream os;
            os << describe_point(pts, i, s) << " has zero volume (" << p.volume << " m^" << dim
               << "): its cell or element is degenerate";
            throw InputError(os.str());
          }
        ++summary.points_per_body[p.body];
        summary.volume_per_body[p.body] += p.volume;
      }
    for (unsigned int b = 0; b < s.bodies.size(); ++b)
      require(summary.points_per_body[b] > 0, "body " + std::to_string(b) + " ('" + s.bodies[b].name + "')",
              "contains no material point (outside the grid, or smaller than one point spacing)");
    for (unsigned int b = 0; b < s.bodies.size(); ++b)
      if (!clip_notes[b].empty())
        {
          std::string note = clip_notes[b];
          if (note.back() == '@')
            {
              std::ostringstream os;
              os.precision(10);
              os << s.bodies[b].shape.volume() - summary.volume_per_body[b]
                 << " (the shape's volume minus the seeded volume; gmsh grid)";
              note.pop_back();
              note += os.str();
            }
          summary.notes.push_back(note);
        }
    {
      const Locator<dim> locate(gb.mesh, gb.boxes);
      for (std::size_t i = 0; i < pts.size(); ++i)
        if (!pts[i].from_grid && locate.find(pts[i].x) < 0)
          throw InputError(describe_point(pts, i, s) + " lies outside the background grid");
    }
    {
      // duplicated points: hash on a lattice of spacing tol, check neighbour bins
      const double tol = 1e-9 * gb.mesh.min_edge();
      struct Hash
      {
        std::size_t
        operator()(const std::array<long long, 3> &k) const
        {
          return std::hash<long long>()(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
        }
      };
      std::unordered_map<std::array<long long, 3>, std::vector<std::size_t>, Hash> bins;
      const auto                                                                   key = [&](const double *x) {
        std::array<long long, 3> k{};
        for (unsigned int d = 0; d < dim; ++d)
          k[d] = static_cast<long long>(std::floor(x[d] / tol));
        return k;
      };
      for (std::size_t i = 0; i < pts.size(); ++i)
        bins[key(pts[i].x)].push_back(i);
      for (std::size_t i = 0; i < pts.size(); ++i)
        {
          const auto k0 = key(pts[i].x);
          for (int a = -1; a <= 1; ++a)
            for (int b = -1; b <= 1; ++b)
              for (int c = (dim == 3 ? -1 : 0); c <= (dim == 3 ? 1 : 0); ++c)
                {
                  const auto it = bins.find({{k0[0] + a, k0[1] + b, k0[2] + c}});
                  if (it == bins.end())
                    continue;
                  for (const auto j : it->second)
                    {
                      if (j <= i)
                        continue;
                      double dist = 0;
                      for (unsigned int d = 0; d < dim; ++d)
                        dist += (pts[i].x[d] - pts[j].x[d]) * (pts[i].x[d] - pts[j].x[d]);
                      if (std::sqrt(dist) <= tol)
                        {
                          std::ostringstream os;
                          os << describe_point(pts, i, s) << " and " << describe_point(pts, j, s)
                             << " are duplicated points (distance " << std::sqrt(dist)
                             << " m): overlapping bodies, or duplicated elements at other nodes";
                          throw InputError(os.str());
                        }
                    }
                }
        }
    }

    // ---- K0 initial stresses (vertical axis = last coordinate, tension positive)
    bool any_k0 = false;
    for (const auto &b : s.bodies)
      any_k0 = any_k0 || b.k0 > 0;
    auto &t = r.particles;
    t.dim   = dim;
    std::vector<double> top(s.bodies.size(), -std::numeric_limits<double>::max());
    for (const auto &p : pts)
      top[p.body] = std::max(top[p.body], p.x[dim - 1] + p.half_up);
    for (const auto &p : pts)
      {
        for (unsigned int d = 0; d < dim; ++d)
          t.position.push_back(p.x[d]);
        t.volume.push_back(p.volume);
        t.material.push_back(p.material);
        t.body.push_back(p.body);
        if (!any_k0)
          continue;
        const auto &spec   = s.bodies[p.body];
        double      sig[6] = {0, 0, 0, 0, 0, 0};
        if (spec.k0 > 0)
          {
            const double level = std::isnan(spec.surface_level) ? top[p.body] : spec.surface_level;
            const auto   k0 =
              loads::k0_stress(spec.k0_density * spec.k0_gravity, std::max(0.0, level - p.x[dim - 1]), 0.0, spec.k0);
            const double sv = k0.vertical, sh = k0.horizontal;
            sig[0] = sig[1] = sig[2] = sh;
            sig[dim - 1]             = sv;
          }
        t.stress.insert(t.stress.end(), sig, sig + t.n_stress());
      }
    r.grid = std::move(gb.mesh);
    return r;
  }

  template struct BodySpec<2>;
  template struct BodySpec<3>;
  template Result<2> prepare<2>(const Settings<2> &);
  template Result<3> prepare<3>(const Settings<3> &);
  template void      check_groups<2>(const Settings<2> &);
  template void      check_groups<3>(const Settings<3> &);
} // namespace talus::mesh
