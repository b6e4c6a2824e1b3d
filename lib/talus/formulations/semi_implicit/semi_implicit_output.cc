// talus — the semi-implicit Solver's diagnostics and files
// (semi_implicit_solver.h): the stability check, the series columns and values,
// the points' .vtu/.pvd files, the final particle tables and the run's summary
// with its phase timings.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/formulations/common/diagnostics.h>
#include <talus/formulations/common/results_file.h>
#include <talus/formulations/semi_implicit/semi_implicit_solver.h>
#include <talus/io/hdf5.h>
#include <talus/io/output.h>
#include <talus/io/vtu.h>
#include <talus/loads/rigid_plate.h>
#include <talus/transfer/stencil_ops.h>

#include <deal.II/base/mpi.h>
#include <deal.II/particles/data_out.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

namespace talus::semi_implicit
{
  template <int dim>
  void
  Solver<dim>::check_stability() const
  {
    bool bad = false;
    for (const Vector *v : {&vs_new, &vw_new, &p_node})
      for (unsigned int i = 0; i < v->locally_owned_size(); ++i)
        bad = bad || !std::isfinite(v->local_element(i));
    if (dealii::Utilities::MPI::max(bad ? 1 : 0, comm))
      throw InstabilityError("a nodal velocity or pore pressure became non-finite");
  }

  template <int dim>
  std::vector<std::string>
  Solver<dim>::series_columns() const
  {
    std::vector<std::string> c = {"kinetic_energy_soil",
                                  "kinetic_energy_water",
                                  "max_speed_soil",
                                  "max_speed_water",
                                  "min_pore_pressure",
                                  "pressure_cg_iterations",
                                  "pressure_relative_residual",
                                  "soil_volume",
                                  "load_settlement",
                                  "pressure_amg_setups"};
    for (const auto &name : loads::rigid_plate_series_columns(prm.rigid_plates))
      c.push_back(name);
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k) // this family's check that the nodes move as one
      {
        c.push_back("plate_" + std::to_string(k) + "_node_spread");
        c.push_back("plate_" + std::to_string(k) + "_node_slip");
      }
    for (const auto &name : bloads.series_columns()) // velocity_k_reaction_x, ...
      c.push_back(name);
    probes.add_columns(c, soil.layout); // probe<k>_ux, ..., probe<k>_stress_xx, ... of the soil
    for (unsigned int k = 0; k < water_probes.ids.size(); ++k)
      c.push_back("probe" + std::to_string(k) + "_pore_pressure");
    balance.add_series_column(c);
    return c;
  }

  template <int dim>
  std::vector<double>
  Solver<dim>::series_values(const bool)
  {
    auto   ek = diagnostics::sum_points(soil), ew = diagnostics::sum_points(water); // kinetic energies
    double vmax[2] = {0, 0}, pmin = 0, soil_volume = 0, fu = 0, fsum = 0;
    if (prm.one_set) // the water the soil points carry (the water set is empty)
      for (const auto &pt : soil.handler)
        {
          const auto P = pt.get_properties();
          if (!(P[fs.water_mass] > 0))
            continue;
          double v2 = 0;
          for (unsigned int d = 0; d < dim; ++d)
            v2 += P[fs.water_velocity + d] * P[fs.water_velocity + d];
          ew.kinetic += 0.5 * P[fs.water_mass] * v2;
          vmax[1] = std::max(vmax[1], std::sqrt(v2));
          pmin    = std::min(pmin, P[fs.pressure]);
        }
    diagnostics::sum_over_ranks<dim>({&ek, &ew}, comm);
    for (const bool is_soil : {true, false})
      for (const auto &pt : (is_soil ? soil : water).handler)
        {
          const auto P  = pt.get_properties();
          double     v2 = 0;
          for (unsigned int d = 0; d < dim; ++d)
            v2 += P[L::velocity + d] * P[L::velocity + d];
          vmax[is_soil ? 0 : 1] = std::max(vmax[is_soil ? 0 : 1], std::sqrt(v2));
          if (!is_soil)
            pmin = std::min(pmin, P[fw.pressure]);
          else // the mixture volume of the skeleton: a 1D column's height x its width
            {
              soil_volume += P[L::volume];
              // the points carrying a traction: their force-weighted mean
              // displacement along the force (the settlement
              // conjugate to the load)
              double fdu, f;
              bloads.settlement_weights(P.data(), fdu, f);
              fu += fdu;
              fsum += f;
            }
        }
    fu                    = dealii::Utilities::MPI::sum(fu, comm);
    fsum                  = dealii::Utilities::MPI::sum(fsum, comm);
    std::vector<double> v = {ek.kinetic,
                             ew.kinetic,
                             dealii::Utilities::MPI::max(vmax[0], comm),
                             dealii::Utilities::MPI::max(vmax[1], comm),
                             dealii::Utilities::MPI::min(pmin, comm),
                             static_cast<double>(last_solve.iterations),
                             last_solve.relative_residual,
                             dealii::Utilities::MPI::sum(soil_volume, comm),
                             fsum > 0 ? fu / fsum : 0.0,
                             static_cast<double>(pressure_solver.n_setups())};
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        v.push_back(plate_state[k].displacement);
        v.push_back(plate_state[k].force);
        if (prm.rigid_plates[k].rough)
          v.push_back(plate_state[k].tangential);
      }
    for (unsigned int k = 0; k < prm.rigid_plates.size(); ++k)
      {
        v.push_back(plate_state[k].node_spread);
        v.push_back(plate_state[k].node_slip);
      }
    bloads.series_values(v);
    probes.sample(soil);
    probes.add_values(v, comm);
    if (!water_probes.ids.empty())
      {
        std::vector<double> p(water_probes.ids.size(), 0.0), sum(p.size());
        for (const auto &pt : (prm.one_set ? soil : water).handler)
          for (unsigned int k = 0; k < p.size(); ++k)
            if (pt.get_id() == water_probes.ids[k])
              p[k] = pt.get_properties()[prm.one_set ? fs.pressure : fw.pressure];
        dealii::Utilities::MPI::sum(dealii::ArrayView<const double>(p), comm, dealii::ArrayView<double>(sum));
        v.insert(v.end(), sum.begin(), sum.end());
      }
    balance.add_series_value(v);
    return v;
  }

  template <int dim>
  void
  Solver<dim>::write_vtu(const unsigned int counter)
  {
    this->write_point_sets(counter); // soil-<n>, water-<n>; soil.pvd, water.pvd for ParaView
  }

  template <int dim>
  void
  Solver<dim>::rewrite_records()
  {
    this->rewrite_point_set_records();
  }

  template <int dim>
  void
  Solver<dim>::finish(const std::string &series_csv)
  {
    if (!prm.results_file.empty())
      {
        // the soil set as particles/ (probes, grid/ likewise), the water set as
        // water/ with its pore pressure (docs/fem.md, "Results file")
        ResultsFileInfo info;
        info.path        = prm.results_file;
        info.integration = "semi-implicit";
        info.time        = time;
        info.steps       = step_number;
        write_results_file(info, grid, soil, probes.ids, series_csv, comm, [&](io::H5File &out) {
          if (prm.one_set) // the pore pressure of the points (one set: no water/ group)
            {
              std::vector<double> p;
              for (const auto &pt : soil.handler)
                p.push_back(pt.get_properties()[fs.pressure]);
              out.write_rows("particles/pore_pressure", p, 1);
              return;
            }
          if (water.handler.n_global_particles() == 0)
            return;
          write_point_table(out, "water", water);
          std::vector<double> p;
          for (const auto &pt : water.handler)
            p.push_back(pt.get_properties()[fw.pressure]);
          out.write_rows("water/pore_pressure", p, 1);
          out.set_attribute("water points", std::int64_t(water.handler.n_global_particles()));
        });
      }
    if (!prm.final_particles_csv)
      return;
    // <set>_final.csv: x, (y, z,) then the properties; rank 0 gathers, writes
    // under a temporary name and renames
    for (const bool is_soil : {true, false})
      {
        const MaterialPointSet<dim> &set = is_soil ? soil : water;
        std::ostringstream           rows;
        rows << std::setprecision(12);
        for (const auto &pt : set.handler)
          {
            const auto x = pt.get_location();
            for (unsigned int d = 0; d < dim; ++d)
              rows << x[d] << ",";
            const auto P = pt.get_properties();
            for (unsigned int k = 0; k < P.size(); ++k)
              rows << P[k] << (k + 1 < P.size() ? "," : "\n");
          }
        const auto all = dealii::Utilities::MPI::gather(comm, rows.str(), 0);
        if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
          {
            const std::string path = prm.output_directory + "/" + set.name() + "_final.csv";
            {
              std::ofstream f(path + ".tmp");
              const char   *xyz[] = {"x", "y", "z"};
              for (unsigned int d = 0; d < dim; ++d)
                f << "pos_" << xyz[d] << ",";
              // vector properties get their component as suffix (velocity_x,
              // pore_pressure_gradient_y, ...)
              const auto       names = set.layout.names();
              std::vector<int> component(names.size(), -1);
              for (unsigned int k = L::velocity; k < L::stress; ++k)
                component[k] = (k - L::velocity) % dim;
              for (const auto &e : set.layout.extras)
                if (e.vector)
                  for (unsigned int i = 0; i < e.size; ++i)
                    component[e.offset + i] = i % dim;
              for (unsigned int k = 0; k < names.size(); ++k)
                {
                  f << names[k];
                  if (component[k] >= 0)
                    f << "_" << xyz[component[k]];
                  f << (k + 1 < names.size() ? "," : "\n");
                }
              for (const auto &r : all)
                f << r;
            }
            std::filesystem::rename(path + ".tmp", path);
          }
      }
  }

  template <int dim>
  void
  Solver<dim>::summary(const LoopTimings &timings)
  {
    log() << "talus-semi-implicit: done: " << step_number << " steps, dt " << dt << " s, wall " << timings.total
          << " s (pressure solves " << seconds_solve << " s, " << n_solves << " solves, " << solver_iterations
          << " CG iterations, mean " << (n_solves ? double(solver_iterations) / n_solves : 0.0)
          << " CG iterations; AMG set-ups " << pressure_solver.n_setups() << " (interval "
          << prm.pressure_rebuild_interval << ", fallbacks " << pressure_solver.n_fallbacks() << ", after slow solves "
          << pressure_solver.n_slow_solves() << "), pressure DoF set rebuilds " << n_pattern_changes << " ("
          << n_pattern_window_changes << " for a stencil outside the kept pattern)), lost points " << lost_points()
          << balance.summary() << ", output in " << prm.output_directory << "/" << std::endl;
    // per-phase wall clock (rank 0's; the step's point passes: 7 walks of each
    // set per step, 8-9 of the soil with F-bar)
    // the timing walk only when asked (make bench passes --time-shape-walk): it is work of its own
    const bool   time_walk = tool_option_given("--time-shape-walk");
    const double walk      = !time_walk      ? 0.0
                             : prm.bspline() ? shape_walk_seconds<shape::BSpline2Box<dim>>()
                                             : shape_walk_seconds<shape::Q1Box<dim>>();
    log() << std::setprecision(4) << "  breakdown [s]: P2N " << phase.p2n << ", grid " << phase.grid
          << ", Poisson assembly " << phase.poisson << ", pressure solve " << seconds_solve << " (AMG set-up "
          << pressure_solver.setup_seconds() << "), N2P " << phase.n2p << ", update+stress " << phase.stress
          << ", relocation " << phase.relocation << "; points soil " << soil.handler.n_global_particles() << " water "
          << water.handler.n_global_particles();
    if (time_walk)
      log() << "; shape functions: one stencil walk over both sets " << walk << " s";
    log() << std::endl;
  }

  template <int dim>
  template <class K>
  double
  Solver<dim>::shape_walk_seconds()
  {
    // the cost of finding every point's cell and evaluating its stencil (values
    // and gradients), with one interpolation per point so that it is not
    // optimised away: each point pass of the step pays this once. The least
    // of 5 walks (one walk is short: a shared machine's hiccup would dominate)
    double        sum = 0, t = std::numeric_limits<double>::max();
    const double *nn = n_node.begin();
    for (unsigned int repeat = 0; repeat < 5; ++repeat)
      {
        const auto t0 = Clock::now();
        for (MaterialPointSet<dim> *set : {&soil, &water})
          transfer::for_each_point_stencil<dim, K>(
            grid, *set, [&](unsigned int, transfer::PointIterator<dim> &, const transfer::PointStencil<dim, K> &s) {
              sum += s.value(nn);
            });
        t = std::min(t, seconds_since(t0));
      }
    volatile double keep = sum;
    (void)keep;
    return t;
  }

  template void                     Solver<2>::check_stability() const;
  template std::vector<std::string> Solver<2>::series_columns() const;
  template std::vector<double>      Solver<2>::series_values(const bool);
  template void                     Solver<2>::write_vtu(const unsigned int);
  template void                     Solver<2>::rewrite_records();
  template void                     Solver<2>::finish(const std::string &);
  template void                     Solver<2>::summary(const LoopTimings &);
  template void                     Solver<3>::check_stability() const;
  template std::vector<std::string> Solver<3>::series_columns() const;
  template std::vector<double>      Solver<3>::series_values(const bool);
  template void                     Solver<3>::write_vtu(const unsigned int);
  template void                     Solver<3>::rewrite_records();
  template void                     Solver<3>::finish(const std::string &);
  template void                     Solver<3>::summary(const LoopTimings &);
} // namespace talus::semi_implicit
