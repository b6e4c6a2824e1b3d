// talus — `output/png snapshots`: a run draws its own pictures with talus-plot.
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/io/output.h>
#include <talus/io/png_snapshots.h>
#include <talus/materials/material.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <string>
#include <vector>

extern char **environ;

namespace talus::io
{
  namespace
  {
    // the field names of talus-plot (tools/talus-plot, FIELDS)
    const std::vector<std::string> png_fields = {"displacement magnitude",
                                                 "displacement x",
                                                 "displacement y",
                                                 "displacement z",
                                                 "velocity magnitude",
                                                 "velocity x",
                                                 "velocity y",
                                                 "velocity z",
                                                 "stress xx",
                                                 "stress yy",
                                                 "stress zz",
                                                 "stress xy",
                                                 "stress yz",
                                                 "stress xz",
                                                 "mean stress",
                                                 "von mises stress",
                                                 "pore pressure",
                                                 "plastic strain",
                                                 "material id",
                                                 "body id",
                                                 "free surface"};

    std::filesystem::path
    plot_tool()
    {
      std::error_code ec;
      const auto      exe = std::filesystem::read_symlink("/proc/self/exe", ec);
      return ec ? std::filesystem::path() : exe.parent_path() / "talus-plot";
    }

    bool
    on_path(const std::string &name)
    {
      const char *path = std::getenv("PATH");
      if (!path)
        return false;
      std::string rest = path;
      for (std::size_t b = 0; b <= rest.size();)
        {
          const std::size_t e   = std::min(rest.find(':', b), rest.size());
          const std::string dir = rest.substr(b, e - b);
          if (!dir.empty() && access((dir + "/" + name).c_str(), X_OK) == 0)
            return true;
          b = e + 1;
        }
      return false;
    }
  } // namespace

  void
  declare_png_snapshot_parameters(dealii::ParameterHandler &prm, const unsigned int dim,
                                  const std::vector<std::string> &not_written)
  {
    std::string fields;
    for (const auto &f : png_fields)
      {
        // a 2D run has stress zz (plane strain) but no z displacement, velocity or shear
        const bool z_component = f == "displacement z" || f == "velocity z" || f == "stress yz" || f == "stress xz";
        if ((dim == 2 && z_component) || std::find(not_written.begin(), not_written.end(), f) != not_written.end())
          continue;
        fields += (fields.empty() ? "" : "|") + f;
      }
    prm.declare_entry("png snapshots", "none", dealii::Patterns::Selection("none|final|every output"),
                      "PNG pictures drawn by talus-plot (next to this executable; needs gnuplot) when the run "
                      "has completed: 'final' the last particle output, 'every output' every VTU output, plus "
                      "the time-series plots of series.csv, in <output directory>/png. A failure to draw is a "
                      "warning: the run still exits 0 (docs/plot.md).");
    prm.declare_entry("png field", "displacement magnitude", dealii::Patterns::Selection(fields),
                      "Field the points of the PNG snapshots are coloured by (talus-plot --field); the fields "
                      "this tool's runs can have in this dimension. A run with several point sets (talus-semi-"
                      "implicit: soil and water) draws it on every set that has it (pore pressure: the water).");
  }

  void
  check_png_snapshot_parameters(dealii::ParameterHandler &prm)
  {
    if (prm.get("png snapshots") == "none")
      return;
    const auto tool = plot_tool();
    require(!tool.empty() && access(tool.c_str(), X_OK) == 0, "output/png snapshots",
            "= " + prm.get("png snapshots") + " needs talus-plot next to the solver executable (" + tool.string() +
              " is missing; build the target talus-plot-script), or set 'none'");
    require(on_path("gnuplot"), "output/png snapshots",
            "= " + prm.get("png snapshots") +
              " needs gnuplot on PATH (scripts/install-deps.sh installs gnuplot-nox), or set 'none'");
  }

  void
  draw_png_snapshots(dealii::ParameterHandler &prm, MPI_Comm comm)
  {
    // every rank's VTU piece of the last output is complete before rank 0 reads them
    MPI_Barrier(comm);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::string dir, mode, field;
    try
      {
        prm.enter_subsection("output");
        dir   = prm.get("directory");
        mode  = prm.get("png snapshots");
        field = prm.get("png field");
        prm.leave_subsection();
        // fields.txt: what the generic VTU names (history_k) mean per material
        AtomicFile f(dir + "/fields.txt");
        auto      &s = f.stream();
        s << "# talus: meaning of the particle fields of this run (read by talus-plot)\n"
          << "dimension = " << prm.get("dimension") << "\n";
        // FEM / UL-FEM points are drawn at X + u; families without the entry
        // 'numerics/integration' are MPM (every family has a 'numerics'
        // subsection, for the shared 'shape function')
        std::string integration = "mpm";
        try
          {
            integration = prm.get({"numerics"}, "integration");
          }
        catch (const dealii::ExceptionBase &)
          {
          }
        if (integration.empty()) // deal.II 9.4 answers "" for an entry a path does not declare
          integration = "mpm";
        s << "integration = " << integration << "\n";
        const unsigned int n = prm.get_integer("number of materials");
        for (unsigned int k = 0; k < n; ++k)
          {
            const std::string where = "material " + std::to_string(k);
            prm.enter_subsection(where);
            const auto m = materials::create_material(prm, where, k);
            s << where << " = " << prm.get("model") << ":";
            const auto names = m->history_names();
            for (unsigned int i = 0; i < names.size(); ++i)
              s << (i ? ", " : " ") << names[i];
            s << "\n";
            prm.leave_subsection();
          }
        f.commit();
      }
    catch (const std::exception &e)
      {
        err() << "  warning: could not write " << dir << "/fields.txt (" << exception_text(e)
              << "); talus-plot cannot show plastic strain of this run" << std::endl;
      }
    if (mode == "none" || mode.empty())
      return;

    const std::string        tool = plot_tool().string();
    std::vector<std::string> args = {tool, "--run-directory=" + dir,
                                     std::string("--frames=") + (mode == "final" ? "last" : "all"), "--field=" + field};
    std::vector<char *>      argv;
    for (auto &a : args)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    std::cout.flush();
    std::cerr.flush();
    pid_t pid    = 0;
    int   status = 0;
    int   rc     = posix_spawn(&pid, tool.c_str(), nullptr, nullptr, argv.data(), environ);
    if (rc == 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0)
      return;
    const std::string why = rc != 0             ? "could not start " + tool + " (" + std::strerror(rc) + ")"
                            : WIFEXITED(status) ? "talus-plot exited with status " + std::to_string(WEXITSTATUS(status))
                                                : std::string("talus-plot was killed");
    std::cerr << "talus: warning: output/png snapshots = " << mode << ": the pictures were not drawn: " << why
              << ". The run itself is complete (exit 0); its results are in " << dir << "/. Draw them later with "
              << tool << " " << dir << std::endl;
  }
} // namespace talus::io
