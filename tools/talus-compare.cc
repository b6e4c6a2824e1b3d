// talus-compare: differences of chosen quantities between two HDF5 results files
// (output/results file of talus-explicit / talus-fem) as norms; the exit status
// says whether they are within the tolerance (for MPM-vs-FEM studies and
// regression checks in makefiles). See docs/fem.md.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/io/output.h>
#include <talus/io/results.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <cmath>
#include <cstring>
#include <iomanip>
#include <sstream>

namespace
{
  using namespace talus;

  void
  declare(dealii::ParameterHandler &prm, const std::string &)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("compare");
    prm.declare_entry("file a", "", Anything(),
                      "Results file (HDF5, written by output/results file) to check; command line: --a=FILE or "
                      "the first file argument.");
    prm.declare_entry("file b", "", Anything(),
                      "Reference results file; relative norms are taken with respect to it. Command line: "
                      "--b=FILE or the second file argument.");
    prm.declare_entry("quantities", "probes, energies", Anything(),
                      "Comma-separated quantities: " + io::quantity_help() + ".");
    prm.declare_entry("time", "all", Selection("all|final"),
                      "Series (energies, probes): 'all' compares over the common time range, file b linearly "
                      "interpolated at the times of file a; 'final' compares the last rows only (end states, e.g. "
                      "of quasi-static runs that converged at different times).");
    prm.declare_entry("norm", "relative-l2", Selection("relative-l2|relative-linf|l2|linf"),
                      "Norm checked against the tolerance. l2 = root mean square of a - b over the samples "
                      "(times, nodes or points; vector fields: of the vector length), linf = max |a - b|; "
                      "relative = divided by the same norm of b.");
    prm.declare_entry("tolerance", "0.01", Double(0), "Every compared item must have norm <= tolerance.");
    prm.declare_entry("report file", "", Anything(),
                      "Optional CSV of the differences (one row per item), written atomically; command line "
                      "--report=FILE.");
    prm.leave_subsection();
  }

  struct Settings
  {
    std::string        a, b, report;
    io::CompareOptions options;
    std::string        norm_name, time_name;
  };

  Settings
  settings(dealii::ParameterHandler &prm)
  {
    Settings s;
    prm.enter_subsection("compare");
    s.a             = tool_option_value("--a", prm.get("file a"));
    s.b             = tool_option_value("--b", prm.get("file b"));
    s.report        = tool_option_value("--report", prm.get("report file"));
    std::string q   = tool_option_value("--quantities", prm.get("quantities"));
    s.time_name     = tool_option_value("--time", prm.get("time"));
    s.norm_name     = tool_option_value("--norm", prm.get("norm"));
    std::string tol = tool_option_value("--tolerance", prm.get("tolerance"));
    prm.leave_subsection();
    for (const auto &x : dealii::Utilities::split_string_list(q, ','))
      s.options.quantities.push_back(x);
    require(!s.options.quantities.empty(), "compare/quantities",
            "must name at least one quantity (allowed: " + io::quantity_help() + ")");
    if (s.time_name == "all")
      s.options.time = io::CompareOptions::Time::all;
    else if (s.time_name == "final")
      s.options.time = io::CompareOptions::Time::final;
    else
      throw InputError("compare/time (--time): '" + s.time_name + "' is not allowed (allowed: all, final)");
    const char *norms[] = {"relative-l2", "relative-linf", "l2", "linf"};
    bool        found   = false;
    for (unsigned int k = 0; k < 4; ++k)
      if (s.norm_name == norms[k])
        {
          s.options.norm = static_cast<io::CompareOptions::Norm>(k);
          found          = true;
        }
    require(found, "compare/norm (--norm)",
            "'" + s.norm_name + "' is not allowed (allowed: relative-l2, relative-linf, l2, linf)");
    {
      char        *end = nullptr;
      const double t   = std::strtod(tol.c_str(), &end);
      require(!tol.empty() && end && *end == '\0' && std::isfinite(t) && t >= 0, "compare/tolerance (--tolerance)",
              "'" + tol + "' is not a number >= 0");
      s.options.tolerance = t;
    }
    require_input_file(s.a, "compare/file a (--a, first file argument)");
    require_input_file(s.b, "compare/file b (--b, second file argument)");
    if (!s.report.empty())
      require_output_file(s.report, "compare/report file (--report)");
    return s;
  }

  void
  check(dealii::ParameterHandler &prm, const std::string &)
  {
    settings(prm);
  }

  int
  run(dealii::ParameterHandler &prm, const std::string &)
  {
    const Settings s = settings(prm);
    const auto     a = io::read_results(s.a);
    const auto     b = io::read_results(s.b);
    const auto     d = io::compare(a, b, s.options);
    std::ostream  &o = log();
    o << "talus-compare: a = " << s.a << " (" << a.integration << ", t = " << a.time << " s), b = " << s.b << " ("
      << b.integration << ", t = " << b.time << " s)\n"
      << "  time = " << s.time_name << ", norm = " << s.norm_name << ", tolerance = " << s.options.tolerance << "\n";
    o << "  " << std::left << std::setw(28) << "quantity" << std::right << std::setw(8) << "n" << std::setw(13)
      << "L2(a-b)" << std::setw(13) << "Linf(a-b)" << std::setw(13) << "L2(b)" << std::setw(13) << "rel L2"
      << std::setw(13) << "rel Linf"
      << "  status\n";
    unsigned int n_bad = 0;
    for (const auto &x : d)
      {
        const bool ok = x.value(s.options.norm) <= s.options.tolerance;
        n_bad += ok ? 0 : 1;
        o << "  " << std::left << std::setw(28) << x.name << std::right << std::setw(8) << x.n << std::setprecision(4)
          << std::scientific << std::setw(13) << x.l2 << std::setw(13) << x.linf << std::setw(13) << x.ref_l2
          << std::setw(13) << x.relative_l2() << std::setw(13) << x.relative_linf() << std::defaultfloat << "  "
          << (ok ? "ok" : "EXCEEDS") << "\n";
      }
    if (!s.report.empty() && dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        io::AtomicFile f(s.report);
        f.stream() << "quantity,n,l2,linf,ref_l2,ref_linf,relative_l2,relative_linf,within_tolerance\n"
                   << std::setprecision(12);
        for (const auto &x : d)
          f.stream() << x.name << "," << x.n << "," << x.l2 << "," << x.linf << "," << x.ref_l2 << "," << x.ref_linf
                     << "," << x.relative_l2() << "," << x.relative_linf() << ","
                     << (x.value(s.options.norm) <= s.options.tolerance ? 1 : 0) << "\n";
        f.commit();
      }
    if (n_bad)
      {
        o << "talus-compare: " << n_bad << " of " << d.size() << " item(s) exceed the tolerance " << s.options.tolerance
          << " (" << s.norm_name << ")" << std::endl;
        return 1;
      }
    o << "talus-compare: all " << d.size() << " item(s) within the tolerance " << s.options.tolerance << " ("
      << s.norm_name << ")" << std::endl;
    return exit_ok;
  }
} // namespace

int
main(int argc, char **argv)
{
  // "talus-compare [options] A.h5 B.h5": file arguments that are not a .prm
  // become --a / --b
  std::vector<std::string> args;
  unsigned int             n_files = 0;
  for (int i = 1; i < argc; ++i)
    {
      const std::string x          = argv[i];
      const bool        positional = !x.empty() && x[0] != '-' && (x.size() < 4 || x.substr(x.size() - 4) != ".prm");
      const bool        value_of_option = i > 1 && std::string(argv[i - 1]).rfind("--", 0) == 0 &&
                                   std::string(argv[i - 1]).find('=') == std::string::npos &&
                                   std::string(argv[i - 1]) != "--check" && std::string(argv[i - 1]) != "--help" &&
                                   std::string(argv[i - 1]) != "--print-parameters";
      if (positional && !value_of_option && n_files < 2)
        args.push_back((n_files++ == 0 ? "--a=" : "--b=") + x);
      else
        args.push_back(x);
    }
  std::vector<char *> av = {argv[0]};
  for (auto &x : args)
    av.push_back(x.data());
  av.push_back(nullptr);

  talus::ToolDescription tool;
  tool.name    = "talus-compare";
  tool.summary = "Compare two HDF5 results files (output/results file of talus-explicit / talus-fem):\n"
                 "  talus-compare [options] A.h5 B.h5      or      talus-compare [options] compare.prm\n"
                 "Reports, per compared item, L2 (rms) and Linf norms of a - b, the L2 norm of b and the\n"
                 "relative norms (b is the reference). Quantities: " +
                 talus::io::quantity_help() +
                 ".\n"
                 "Exit status: 0 every item within the tolerance, 1 some item exceeds it (as for internal\n"
                 "errors), 2 bad input "
                 "(missing or unreadable file, unknown quantity, mismatched grids, ...).";
  tool.declare      = &declare;
  tool.check        = &check;
  tool.run          = &run;
  tool.prm_optional = true;
  tool.options      = {{"--a=", "results file a (checked)"},
                       {"--b=", "results file b (reference)"},
                       {"--quantities=", "comma-separated quantities (default: probes, energies)"},
                       {"--time=", "all | final (series)"},
                       {"--norm=", "relative-l2 | relative-linf | l2 | linf"},
                       {"--tolerance=", "largest allowed norm (default 0.01)"},
                       {"--report=", "CSV file of the differences"}};
  return talus::run_tool(static_cast<int>(av.size() - 1), av.data(), tool);
}
