// talus — results files: reading and comparing (see results.h).
#include <talus/base/errors.h>
#include <talus/io/hdf5.h>
#include <talus/io/results.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <regex>
#include <sstream>

namespace talus::io
{
  namespace
  {
    std::vector<std::string>
    split(const std::string &s, const char sep)
    {
      std::vector<std::string> r;
      std::string              cur;
      std::istringstream       is(s);
      while (std::getline(is, cur, sep))
        if (!cur.empty())
          r.push_back(cur);
      return r;
    }

    Table
    read_table(const H5File &f, const std::string &name)
    {
      Table t;
      t.cols = f.shape(name).second;
      t.data = f.read_all(name);
      return t;
    }

    const std::vector<std::string> &
    component_names(const unsigned int dim, const unsigned int cols)
    {
      static const std::vector<std::string> vec = {"x", "y", "z"};
      static const std::vector<std::string> s2  = {"xx", "yy", "zz", "xy"};
      static const std::vector<std::string> s3  = {"xx", "yy", "zz", "xy", "yz", "xz"};
      if (cols == dim)
        return vec;
      return dim == 2 ? s2 : s3;
    }
  } // namespace

  Results
  read_results(const std::string &path)
  {
    Results r;
    r.path = path;
    H5File f(path, H5File::Mode::read, MPI_COMM_SELF);
    if (!f.has_attribute("format") || f.get_string("format") != results_format)
      throw InputError("HDF5 file '" + path + "': not a talus results file (attribute 'format' is not '" +
                       std::string(results_format) + "'; write one with output/results file)");
    if (f.get_int("version") != results_version)
      throw InputError("HDF5 file '" + path + "': results version " + std::to_string(f.get_int("version")) +
                       ", this tool reads version " + std::to_string(results_version));
    r.dim          = static_cast<unsigned int>(f.get_int("dimension"));
    r.integration  = f.get_string("integration");
    r.time         = f.get_double("time");
    r.series_names = split(f.get_string("series columns"), ',');
    for (const auto &n : r.series_names)
      r.series.push_back(f.read_all("series/" + n));
    r.grid_vertices     = read_table(f, "grid/vertices");
    r.grid_mass         = read_table(f, "grid/mass");
    r.grid_displacement = read_table(f, "grid/displacement");
    r.grid_velocity     = read_table(f, "grid/velocity");
    r.grid_stress       = read_table(f, "grid/stress");
    for (const auto v : f.read_rows_u64("particles/id", 0, f.shape("particles/id").first))
      r.particle_id.push_back(v);
    r.particle_position         = read_table(f, "particles/position");
    r.particle_initial_position = read_table(f, "particles/initial_position");
    r.particle_displacement     = read_table(f, "particles/displacement");
    r.particle_velocity         = read_table(f, "particles/velocity");
    r.particle_stress           = read_table(f, "particles/stress");
    r.particle_volume           = read_table(f, "particles/volume");
    return r;
  }

  double
  Difference::relative_l2() const
  {
    if (ref_l2 > 0)
      return l2 / ref_l2;
    return l2 == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  }

  double
  Difference::relative_linf() const
  {
    if (ref_linf > 0)
      return linf / ref_linf;
    return linf == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  }

  double
  Difference::value(const CompareOptions::Norm norm) const
  {
    switch (norm)
      {
        case CompareOptions::Norm::relative_l2:
          return relative_l2();
        case CompareOptions::Norm::relative_linf:
          return relative_linf();
        case CompareOptions::Norm::l2:
          return l2;
        case CompareOptions::Norm::linf:
          return linf;
      }
    return l2;
  }

  std::string
  quantity_help()
  {
    return "energies (kinetic, strain, gravity potential, external work, total), momentum, probes (displacement, "
           "velocity and stress of every probe, one item per probe and field, norms of the vector/tensor over "
           "time), probe_displacements, probe_velocities, probe_stresses, any series.csv column by name "
           "(e.g. probe0_uy, kinetic_energy; also written series:NAME), grid:displacement, grid:velocity, "
           "grid:stress, grid:mass (final fields mapped to the grid nodes; one component: grid:displacement_y, "
           "grid:stress_xx, ...), particles:position, particles:initial_position, particles:displacement, "
           "particles:velocity, particles:stress, particles:volume (matched by id; only between runs with the "
           "same points)";
  }

  namespace
  {
    struct Accumulator
    {
      Difference d;
      double     s2 = 0, r2 = 0;
      void
      add(const double a, const double b)
      {
        const double e = a - b;
        s2 += e * e;
        r2 += b * b;
        d.linf     = std::max(d.linf, std::abs(e));
        d.ref_linf = std::max(d.ref_linf, std::abs(b));
        ++d.n;
        if (!std::isfinite(a) || !std::isfinite(b))
          d.linf = std::numeric_limits<double>::infinity();
      }
      Difference
      result()
      {
        d.l2     = d.n ? std::sqrt(s2 / d.n) : 0.0;
        d.ref_l2 = d.n ? std::sqrt(r2 / d.n) : 0.0;
        if (std::isinf(d.linf))
          d.l2 = d.linf;
        return d;
      }
    };

    int
    column_index(const Results &r, const std::string &name)
    {
      const auto it = std::find(r.series_names.begin(), r.series_names.end(), name);
      return it == r.series_names.end() ? -1 : static_cast<int>(it - r.series_names.begin());
    }

    /// One item made of one or more series columns (the components of a
    /// vector or tensor: norms of the vector per time).
    Difference
    compare_series(const Results &a, const Results &b, const std::string &name, const std::vector<std::string> &cols,
                   const CompareOptions &o)
    {
      std::vector<const std::vector<double> *> xa, xb;
      for (const auto &c : cols)
        {
          const int ia = column_index(a, c), ib = column_index(b, c);
          if (ia < 0)
            throw InputError("results file '" + a.path + "': no series column '" + c + "'");
          if (ib < 0)
            throw InputError("results file '" + b.path + "': no series column '" + c + "' (file '" + a.path +
                             "' has it)");
          xa.push_back(&a.series[ia]);
          xb.push_back(&b.series[ib]);
        }
      const int ta = column_index(a, "time"), tb = column_index(b, "time");
      if (ta < 0 || tb < 0)
        throw InputError("results file '" + (ta < 0 ? a.path : b.path) + "': no series column 'time'");
      const auto &Ta = a.series[ta], &Tb = b.series[tb];
      if (Ta.empty() || Tb.empty())
        throw InputError("results file '" + (Ta.empty() ? a.path : b.path) + "': the series is empty");
      Accumulator acc;
      acc.d.name               = name;
      const std::size_t nc     = cols.size();
      const auto        finish = [&]() {
        Difference d = acc.result();
        if (nc > 1 && d.n > 0) // rms over times of the vector length
          {
            const double f = std::sqrt(double(nc));
            d.l2 *= f;
            d.ref_l2 *= f;
            d.n /= nc;
          }
        return d;
      };
      if (o.time == CompareOptions::Time::final)
        {
          for (std::size_t c = 0; c < nc; ++c)
            acc.add(xa[c]->back(), xb[c]->back());
          return finish();
        }
      const double t0 = std::max(Ta.front(), Tb.front()), t1 = std::min(Ta.back(), Tb.back());
      const double eps = 1e-9 * std::max({std::abs(t1), std::abs(t0), 1e-300});
      std::size_t  j   = 0;
      for (std::size_t i = 0; i < Ta.size(); ++i)
        {
          const double t = Ta[i];
          if (t < t0 - eps || t > t1 + eps)
            continue;
          while (j + 1 < Tb.size() && Tb[j + 1] <= t)
            ++j;
          for (std::size_t c = 0; c < nc; ++c)
            {
              const auto &y = *xb[c];
              double      vb;
              if (t == Tb[j])
                vb = y[j]; // same time: exact (identical files compare to 0)
              else if (j + 1 < Tb.size() && Tb[j + 1] > Tb[j] && t >= Tb[j])
                {
                  const double s = std::min(1.0, (t - Tb[j]) / (Tb[j + 1] - Tb[j]));
                  vb             = y[j] + s * (y[j + 1] - y[j]);
                }
              else
                vb = (j + 1 < Tb.size() && std::abs(Tb[j + 1] - t) <= eps) ? y[j + 1] : y[j];
              acc.add((*xa[c])[i], vb);
            }
        }
      if (acc.d.n == 0)
        throw InputError("results files '" + a.path + "' and '" + b.path + "' have no common times (" +
                         std::to_string(Ta.front()) + ".." + std::to_string(Ta.back()) + " s vs " +
                         std::to_string(Tb.front()) + ".." + std::to_string(Tb.back()) + " s)");
      return finish();
    }

    Difference
    compare_series(const Results &a, const Results &b, const std::string &name, const CompareOptions &o)
    {
      return compare_series(a, b, name, std::vector<std::string>{name}, o);
    }

    /// permutation sorting the rows of a table lexicographically
    std::vector<std::size_t>
    sorted_rows(const Table &t)
    {
      std::vector<std::size_t> p(t.rows());
      std::iota(p.begin(), p.end(), 0);
      std::sort(p.begin(), p.end(), [&](const std::size_t i, const std::size_t j) {
        for (unsigned int c = 0; c < t.cols; ++c)
          if (t.data[i * t.cols + c] != t.data[j * t.cols + c])
            return t.data[i * t.cols + c] < t.data[j * t.cols + c];
        return false;
      });
      return p;
    }

    /// node pairs (row in a, row in b) of matching vertices; InputError otherwise
    std::vector<std::pair<std::size_t, std::size_t>>
    match_grids(const Results &a, const Results &b)
    {
      const Table &va = a.grid_vertices, &vb = b.grid_vertices;
      if (a.dim != b.dim || va.rows() != vb.rows())
        throw InputError("mismatched grids: '" + a.path + "' has " + std::to_string(va.rows()) + " nodes (" +
                         std::to_string(a.dim) + "D), '" + b.path + "' has " + std::to_string(vb.rows()) + " nodes (" +
                         std::to_string(b.dim) + "D); grid fields can only be compared on the same grid");
      double extent = 0;
      for (const double x : va.data)
        extent = std::max(extent, std::abs(x));
      const double tol = 1e-9 * std::max(extent, 1e-300);
      // round to the tolerance before sorting so that round-off does not reorder
      Table ra = va, rb = vb;
      for (auto &x : ra.data)
        x = std::round(x / tol);
      for (auto &x : rb.data)
        x = std::round(x / tol);
      const auto                                       pa = sorted_rows(ra), pb = sorted_rows(rb);
      std::vector<std::pair<std::size_t, std::size_t>> r;
      for (std::size_t k = 0; k < pa.size(); ++k)
        {
          for (unsigned int c = 0; c < va.cols; ++c)
            if (std::abs(va.data[pa[k] * va.cols + c] - vb.data[pb[k] * vb.cols + c]) > 10 * tol)
              {
                std::ostringstream os;
                os << "mismatched grids: node (";
                for (unsigned int d = 0; d < va.cols; ++d)
                  os << (d ? ", " : "") << va.data[pa[k] * va.cols + d];
                os << ") of '" << a.path << "' has no counterpart in '" << b.path
                   << "'; grid fields can only be compared on the same grid";
                throw InputError(os.str());
              }
          r.emplace_back(pa[k], pb[k]);
        }
      return r;
    }

    Difference
    compare_table(const std::string &name, const Table &ta, const Table &tb,
                  const std::vector<std::pair<std::size_t, std::size_t>> &pairs, const int component,
                  const std::vector<unsigned char> &use)
    {
      Accumulator acc;
      acc.d.name = name;
      for (std::size_t k = 0; k < pairs.size(); ++k)
        {
          if (!use.empty() && !use[k])
            continue;
          const auto [i, j] = pairs[k];
          for (unsigned int c = 0; c < ta.cols; ++c)
            if (component < 0 || int(c) == component)
              acc.add(ta.data[i * ta.cols + c], tb.data[j * tb.cols + c]);
        }
      // rms over samples (rows), not over scalar entries
      Difference d = acc.result();
      if (component < 0 && ta.cols > 1 && d.n > 0)
        {
          const double f = std::sqrt(double(ta.cols));
          d.l2 *= f;
          d.ref_l2 *= f;
          d.n /= ta.cols;
        }
      return d;
    }

    /// "field" or "field_comp" of the grid/particle tables
    std::pair<std::string, std::string>
    split_component(const std::string &s, const std::vector<std::string> &fields)
    {
      for (const auto &f : fields)
        {
          if (s == f)
            return {f, ""};
          if (s.rfind(f + "_", 0) == 0)
            return {f, s.substr(f.size() + 1)};
        }
      return {"", ""};
    }
  } // namespace

  std::vector<Difference>
  compare(const Results &a, const Results &b, const CompareOptions &o)
  {
    if (a.dim != b.dim)
      throw InputError("results files '" + a.path + "' (" + std::to_string(a.dim) + "D) and '" + b.path + "' (" +
                       std::to_string(b.dim) + "D) have different dimensions");
    if (o.quantities.empty())
      throw InputError("no quantity to compare given (allowed: " + quantity_help() + ")");
    std::vector<Difference> out;
    const auto              series_matching = [&](const std::regex &re) {
      std::vector<std::string> cols;
      for (const auto &n : a.series_names)
        if (std::regex_match(n, re))
          cols.push_back(n);
      return cols;
    };
    const auto add_series = [&](const std::vector<std::string> &cols, const std::string &q) {
      if (cols.empty())
        throw InputError("quantity '" + q + "': results file '" + a.path + "' has no such series columns");
      for (const auto &c : cols)
        out.push_back(compare_series(a, b, c, o));
    };
    for (const auto &q : o.quantities)
      {
        if (q == "energies")
          {
            std::vector<std::string> cols;
            for (const char *n :
                 {"kinetic_energy", "strain_energy", "gravity_potential_energy", "external_work", "total_energy"})
              if (column_index(a, n) >= 0)
                cols.push_back(n);
            add_series(cols, q);
          }
        else if (q == "momentum")
          add_series(series_matching(std::regex("momentum_[xyz]")), q);
        else if (q == "probes" || q == "probe_displacements" || q == "probe_velocities" || q == "probe_stresses")
          {
            // one item per probe and vector/tensor (norms of the vector per time)
            const std::vector<std::pair<std::string, std::string>> kinds = {
              {"u", "probe([0-9]+)_u[xyz]"}, {"v", "probe([0-9]+)_v[xyz]"}, {"stress", "probe([0-9]+)_stress_.*"}};
            bool any = false;
            for (const auto &[kind, pattern] : kinds)
              {
                if ((q == "probe_displacements" && kind != "u") || (q == "probe_velocities" && kind != "v") ||
                    (q == "probe_stresses" && kind != "stress"))
                  continue;
                const auto               cols = series_matching(std::regex(pattern));
                std::vector<std::string> ids;
                for (const auto &c : cols)
                  {
                    const std::string id = c.substr(5, c.find('_') - 5);
                    if (std::find(ids.begin(), ids.end(), id) == ids.end())
                      ids.push_back(id);
                  }
                for (const auto &id : ids)
                  {
                    std::vector<std::string> mine;
                    for (const auto &c : cols)
                      if (c.rfind("probe" + id + "_", 0) == 0)
                        mine.push_back(c);
                    out.push_back(compare_series(a, b, "probe" + id + "_" + kind, mine, o));
                    any = true;
                  }
              }
            if (!any)
              throw InputError("quantity '" + q + "': results file '" + a.path + "' has no probes (output/probes)");
          }
        else if (q.rfind("series:", 0) == 0)
          out.push_back(compare_series(a, b, q.substr(7), o));
        else if (q.rfind("grid:", 0) == 0)
          {
            const auto [field, comp] = split_component(q.substr(5), {"displacement", "velocity", "stress", "mass"});
            if (field.empty())
              throw InputError("unknown quantity '" + q +
                               "' (allowed grid fields: grid:displacement, "
                               "grid:velocity, grid:stress, grid:mass, optionally with a component: "
                               "grid:displacement_y, grid:stress_xx, ...)");
            const auto pairs = match_grids(a, b);
            const auto pick  = [&](const Results &r) -> const Table  &{
              return field == "displacement" ? r.grid_displacement
                      : field == "velocity"   ? r.grid_velocity
                      : field == "stress"     ? r.grid_stress
                                              : r.grid_mass;
            };
            int c = -1;
            if (!comp.empty())
              {
                const auto &names = component_names(a.dim, pick(a).cols);
                const auto  it    = std::find(names.begin(), names.end(), comp);
                if (it == names.end() || pick(a).cols == 1)
                  {
                    std::string allowed;
                    for (const auto &n : names)
                      allowed += (allowed.empty() ? "" : ", ") + field + "_" + n;
                    throw InputError("unknown quantity '" + q + "' (allowed components: " +
                                     (pick(a).cols == 1 ? std::string("none") : allowed) + ")");
                  }
                c = static_cast<int>(it - names.begin());
              }
            // nodes carrying mass in either run
            std::vector<unsigned char> use(pairs.size(), 0);
            for (std::size_t k = 0; k < pairs.size(); ++k)
              use[k] = a.grid_mass.data[pairs[k].first] > 0 || b.grid_mass.data[pairs[k].second] > 0;
            out.push_back(compare_table(q, pick(a), pick(b), pairs, c, use));
          }
        else if (q.rfind("particles:", 0) == 0)
          {
            const auto [field, comp] = split_component(
              q.substr(10), {"initial_position", "position", "displacement", "velocity", "stress", "volume"});
            if (field.empty())
              throw InputError("unknown quantity '" + q +
                               "' (allowed particle fields: particles:position, "
                               "particles:initial_position, particles:displacement, particles:velocity, "
                               "particles:stress, particles:volume)");
            if (a.particle_id.size() != b.particle_id.size())
              throw InputError("particle fields cannot be compared: '" + a.path + "' has " +
                               std::to_string(a.particle_id.size()) + " material points, '" + b.path + "' has " +
                               std::to_string(b.particle_id.size()) + " (use grid: fields for different seedings)");
            std::vector<std::size_t> pa(a.particle_id.size()), pb(b.particle_id.size());
            std::iota(pa.begin(), pa.end(), 0);
            std::iota(pb.begin(), pb.end(), 0);
            std::sort(pa.begin(), pa.end(), [&](auto i, auto j) { return a.particle_id[i] < a.particle_id[j]; });
            std::sort(pb.begin(), pb.end(), [&](auto i, auto j) { return b.particle_id[i] < b.particle_id[j]; });
            std::vector<std::pair<std::size_t, std::size_t>> pairs;
            for (std::size_t k = 0; k < pa.size(); ++k)
              {
                if (a.particle_id[pa[k]] != b.particle_id[pb[k]])
                  throw InputError("particle fields cannot be compared: the material point ids of '" + a.path +
                                   "' and '" + b.path + "' differ (id " + std::to_string(a.particle_id[pa[k]]) +
                                   " vs " + std::to_string(b.particle_id[pb[k]]) + ")");
                pairs.emplace_back(pa[k], pb[k]);
              }
            const auto pick = [&](const Results &r) -> const Table & {
              return field == "position"           ? r.particle_position
                     : field == "initial_position" ? r.particle_initial_position
                     : field == "displacement"     ? r.particle_displacement
                     : field == "velocity"         ? r.particle_velocity
                     : field == "stress"           ? r.particle_stress
                                                   : r.particle_volume;
            };
            int c = -1;
            if (!comp.empty())
              {
                const auto &names = component_names(a.dim, pick(a).cols);
                const auto  it    = std::find(names.begin(), names.end(), comp);
                if (it == names.end() || pick(a).cols == 1)
                  throw InputError("unknown quantity '" + q + "' (unknown component '" + comp + "')");
                c = static_cast<int>(it - names.begin());
              }
            out.push_back(compare_table(q, pick(a), pick(b), pairs, c, {}));
          }
        else if (column_index(a, q) >= 0)
          out.push_back(compare_series(a, b, q, o));
        else
          {
            std::string cols;
            for (const auto &n : a.series_names)
              cols += (cols.empty() ? "" : ", ") + n;
            throw InputError("unknown quantity '" + q + "' (allowed: " + quantity_help() + "; series columns of '" +
                             a.path + "': " + cols + ")");
          }
      }
    return out;
  }
} // namespace talus::io
