// talus-element — single-element (material point) driver for one constitutive
// model along a laboratory path: oedometer, isotropic compression, drained and
// undrained triaxial compression/extension, simple shear. Small-strain (rate)
// form through Material::update_stress, finite-strain form through
// Material::finite_strain_update (seed 002 App. B.2). Writes a CSV and PNG plots
// (q-eps_a, q-p', eps_v-eps_a) through gnuplot.
//
// Exit status: 0 ok, 1 internal error, 2 bad input, 3 the path could not be
// followed (non-converged mixed control, non-finite stress).
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/materials/material.h>
#include <talus/materials/single_element.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/parameter_handler.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

using namespace talus;
using namespace talus::materials;

namespace
{
  const char *summary = "Runs one constitutive model (subsection 'material') along a homogeneous\n"
                        "laboratory path (subsection 'test') and writes a CSV of strains, stresses,\n"
                        "invariants and history variables plus PNG plots through gnuplot.\n"
                        "Conventions: axis x is the axial direction; stresses sig_* and strains eps_*\n"
                        "in the CSV are tension positive; eps_a, eps_v, p and q are geotechnical\n"
                        "(compression positive), p = -tr(sigma)/3, q = sqrt(3 J2).";

  void
  declare(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("test");
    prm.declare_entry("path", "drained triaxial compression", dealii::Patterns::Selection(element_path_names()),
                      "Loading path (must be set). Triaxial and oedometer: axial strain along x controlled; "
                      "drained triaxial: lateral stresses held at their initial value (Newton "
                      "loop on the lateral strains); undrained: isochoric; simple shear: "
                      "grad u = gamma e_x (x) e_y (with its spin).",
                      /*has_to_be_set=*/true);
    prm.declare_entry("strain form", "small", dealii::Patterns::Selection("small|finite"),
                      "small: rate form (update_stress with d_eps, d_omega); finite: "
                      "finite_strain_update with dF (only models with a finite-strain form).");
    prm.declare_entry("target strain", "0.1", dealii::Patterns::Double(0),
                      "Final magnitude (> 0) of the controlled strain [-]: axial strain "
                      "(triaxial, oedometer), volumetric strain (isotropic compression), "
                      "engineering shear strain gamma (simple shear). Logarithmic in the "
                      "finite-strain form.");
    prm.declare_entry("number of increments", "1000", dealii::Patterns::Integer(1),
                      "Number of equal strain increments (>= 1).");
    prm.declare_entry("time increment", "1e-3", dealii::Patterns::Double(0),
                      "Time per increment dt [s], > 0 (sets the strain rate of the "
                      "rate-dependent liquid models).");
    prm.declare_entry("initial mean effective stress", "100e3", dealii::Patterns::Double(),
                      "Initial mean effective stress p0' [Pa], compression positive.");
    prm.declare_entry("initial stress ratio", "1", dealii::Patterns::Double(0),
                      "Initial lateral / axial effective stress ratio K0 [-], > 0 (1: isotropic).");
    prm.declare_entry("newton tolerance", "1e-11", dealii::Patterns::Double(0),
                      "Relative tolerance of the drained (mixed-control) Newton loop on the "
                      "lateral stresses.");
    prm.declare_entry("max newton iterations", "50", dealii::Patterns::Integer(1),
                      "Iteration limit of the drained Newton loop per increment.");
    prm.leave_subsection();

    prm.enter_subsection("output");
    prm.declare_entry("csv file", "element.csv", dealii::Patterns::FileName(dealii::Patterns::FileName::output),
                      "Result table (one row per increment, plus the initial state). "
                      "Written to a temporary name and renamed when complete.");
    prm.declare_entry("plots", "true", dealii::Patterns::Bool(),
                      "Write PNG plots next to the CSV (<csv stem>_q_eps.png, _q_p.png, "
                      "_epsv_eps.png) with gnuplot; skipped with a warning if gnuplot is "
                      "not available.");
    prm.leave_subsection();

    prm.enter_subsection("material");
    declare_material_parameters(prm);
    prm.leave_subsection();
  }

  std::string
  column_name(std::string s)
  {
    for (char &c : s)
      if (c == ' ' || c == ',' || c == '-')
        c = '_';
    return s;
  }

  bool
  have_gnuplot(std::string &terminal)
  {
    if (std::system("gnuplot -e \"set terminal pngcairo\" > /dev/null 2>&1") == 0)
      terminal = "pngcairo size 800,600";
    else if (std::system("gnuplot -e \"set terminal png\" > /dev/null 2>&1") == 0)
      terminal = "png size 800,600";
    else
      return false;
    return true;
  }

  void
  write_plots(const std::filesystem::path &csv, const bool shear_path, const std::string &title)
  {
    std::string terminal;
    if (!have_gnuplot(terminal))
      {
        std::cerr << "talus-element: warning: gnuplot not found, plots skipped\n";
        return;
      }
    const std::string stem = (csv.parent_path() / csv.stem()).string();
    const std::string xcol = shear_path ? "gamma" : "eps_a";
    const std::string xlab = shear_path ? "shear strain gamma [-]" : "axial strain eps_a [-]";
    struct Plot
    {
      std::string file, x, y, xlabel, ylabel;
    };
    const Plot        plots[] = {{stem + "_q_eps.png", xcol, "q", xlab, "q [kPa]"},
                                 {stem + "_q_p.png", "p", "q", "p' [kPa] (compression +)", "q [kPa]"},
                                 {stem + "_epsv_eps.png", xcol, "eps_v", xlab, "volumetric strain eps_v [-] (compression +)"}};
    const std::string script  = stem + ".gp.tmp";
    {
      std::ofstream gp(script);
      gp << "set datafile separator ','\nset datafile columnheaders\nset terminal " << terminal << "\nset grid\n"
         << "set key off\nset title \"" << title << "\" noenhanced\n";
      for (const auto &p : plots)
        {
          auto col = [](const std::string &n) {
            return "column('" + n + "')" + ((n == "p" || n == "q") ? "/1000.0" : "");
          };
          gp << "set output '" << p.file << ".tmp'\n"
             << "set xlabel \"" << p.xlabel << "\" noenhanced\nset ylabel \"" << p.ylabel << "\" noenhanced\n"
             << "plot '" << csv.string() << "' using (" << col(p.x) << "):(" << col(p.y) << ") with lines lw 2\n";
        }
      gp << "unset output\n";
    }
    const int rc = std::system(("gnuplot '" + script + "' 2> '" + script + ".log'").c_str());
    if (rc != 0)
      {
        std::ifstream     l(script + ".log");
        std::stringstream ss;
        ss << l.rdbuf();
        std::cerr << "talus-element: warning: gnuplot failed, plots skipped:\n" << ss.str();
        for (const auto &p : plots)
          std::filesystem::remove(p.file + ".tmp");
      }
    else
      for (const auto &p : plots)
        {
          std::filesystem::rename(p.file + ".tmp", p.file);
          std::cout << "wrote " << p.file << "\n";
        }
    std::filesystem::remove(script);
    std::filesystem::remove(script + ".log");
  }

  /// Everything the run needs, read and validated from the parsed .prm
  /// (no file is touched).
  struct Setup
  {
    ElementTestSettings       set;
    std::string               path_name;
    std::filesystem::path     csv;
    bool                      plots = true;
    std::unique_ptr<Material> m;
  };

  Setup
  parse(dealii::ParameterHandler &prm)
  {
    Setup u;
    auto &set = u.set;
    prm.enter_subsection("test");
    set.path                  = element_path_from_name(prm.get("path"));
    set.finite_strain         = prm.get("strain form") == "finite";
    set.target_strain         = prm.get_double("target strain");
    set.n_increments          = prm.get_integer("number of increments");
    set.time_increment        = prm.get_double("time increment");
    set.initial_pressure      = prm.get_double("initial mean effective stress");
    set.k0                    = prm.get_double("initial stress ratio");
    set.newton_tolerance      = prm.get_double("newton tolerance");
    set.max_newton_iterations = prm.get_integer("max newton iterations");
    u.path_name               = prm.get("path");
    prm.leave_subsection();
    require(set.target_strain > 0, "test/target strain", "must be > 0 (got " + std::to_string(set.target_strain) + ")");
    require(set.time_increment > 0, "test/time increment",
            "must be > 0 (got " + std::to_string(set.time_increment) + ")");
    require(set.k0 > 0, "test/initial stress ratio", "must be > 0 (got " + std::to_string(set.k0) + ")");
    require(set.newton_tolerance > 0, "test/newton tolerance",
            "must be > 0 (got " + std::to_string(set.newton_tolerance) + ")");

    prm.enter_subsection("output");
    u.csv   = prm.get("csv file");
    u.plots = prm.get_bool("plots");
    prm.leave_subsection();
    require_output_file(u.csv.string(), "output/csv file");

    prm.enter_subsection("material");
    u.m = create_material(prm, "material", 0);
    prm.leave_subsection();
    require(!set.finite_strain || u.m->has_finite_strain_form(), "test/strain form",
            "model '" + u.m->model_name() + "' has no finite-strain form (allowed for it: small)");
    return u;
  }

  int
  run(dealii::ParameterHandler &prm)
  {
    const Setup u         = parse(prm);
    const auto &set       = u.set;
    const auto &csv       = u.csv;
    const auto &plots     = u.plots;
    const auto &m         = u.m;
    const auto &path_name = u.path_name;

    if (!csv.parent_path().empty())
      std::filesystem::create_directories(csv.parent_path());
    const std::filesystem::path tmp = csv.string() + ".tmp";
    try
      {
        std::ofstream f(tmp);
        require(static_cast<bool>(f), "output/csv file", "cannot write '" + tmp.string() + "'");
        f << std::setprecision(12);
        f << "step,time,eps_xx,eps_yy,eps_zz,eps_xy,eps_yz,eps_xz,sig_xx,sig_yy,sig_zz,sig_xy,"
             "sig_yz,sig_xz,eps_a,eps_v,gamma,p,q,newton_iterations";
        for (const auto &n : m->history_names())
          f << "," << column_name(n);
        f << "\n";
        ElementRecord last;
        run_element_test(*m, set, [&](const ElementRecord &r) {
          const auto &e = r.eps;
          const auto &s = r.sigma;
          f << r.step << "," << r.time << "," << e[0][0] << "," << e[1][1] << "," << e[2][2] << "," << e[0][1] << ","
            << e[1][2] << "," << e[0][2] << "," << s[0][0] << "," << s[1][1] << "," << s[2][2] << "," << s[0][1] << ","
            << s[1][2] << "," << s[0][2] << "," << r.eps_axial() << "," << r.eps_vol() << "," << r.gamma << "," << r.p()
            << "," << r.q() << "," << r.newton_iterations;
          for (const double h : r.history)
            f << "," << h;
          f << "\n";
          last = r;
        });
        f.close();
        require(!f.fail(), "output/csv file", "error while writing '" + tmp.string() + "'");
        std::filesystem::rename(tmp, csv);
        std::cout << "talus-element: " << m->model_name() << ", " << path_name << " ("
                  << (set.finite_strain ? "finite" : "small") << " strain), " << set.n_increments
                  << " increments: final p' = " << last.p() << " Pa, q = " << last.q()
                  << " Pa, eps_a = " << last.eps_axial() << ", eps_v = " << last.eps_vol() << "\nwrote " << csv.string()
                  << "\n";
      }
    catch (...)
      {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
      }
    if (plots)
      write_plots(csv, set.path == ElementPath::simple_shear, m->model_name() + ": " + path_name);
    return 0;
  }
} // namespace

int
main(int argc, char **argv)
{
  std::string models;
  for (const auto &n : registered_models())
    models += (models.empty() ? "'" : ", '") + n + "'";
  talus::ToolDescription tool;
  tool.name    = "talus-element";
  tool.summary = std::string(summary) + "\nModels: " + models +
                 ".\nExit status 3 here: the path could not be followed (non-converged mixed control, "
                 "non-finite stress).";
  tool.declare = [](dealii::ParameterHandler &prm, const std::string &) { declare(prm); };
  tool.check   = [](dealii::ParameterHandler &prm, const std::string &) { parse(prm); };
  tool.run     = [](dealii::ParameterHandler &prm, const std::string &) { return run(prm); };
  return talus::run_tool(argc, argv, tool);
}
