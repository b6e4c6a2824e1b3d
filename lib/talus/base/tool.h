// talus — the common frame of every command-line tool: MPI start-up, command line
// (--help, --print-parameters, one .prm file), strict .prm parsing with messages
// that name the file, line and allowed values, and one clear error per failure
// with a non-zero exit status.
#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace talus
{
  /// Exit codes shared by every tool.
  enum ExitCode : int
  {
    exit_ok          = 0,
    exit_failure     = 1, ///< unexpected internal error
    exit_input_error = 2, ///< bad command line, .prm, mesh or data file
    exit_unstable    = 3, ///< the run went unstable and was stopped
  };

  struct ToolDescription
  {
    std::string name;    ///< e.g. "talus-explicit"
    std::string summary; ///< one paragraph for --help
    /// Declare every entry. `prm_file` is the file about to be parsed, or empty
    /// when printing defaults; tools whose entries depend on counts in the file
    /// (number of bodies, materials) read those with peek_entry().
    std::function<void(dealii::ParameterHandler &, const std::string &prm_file)> declare;
    /// Validate the parsed parameters completely (values, consistency between
    /// entries, input files, where output will go) WITHOUT heavy work (no grid,
    /// no particles, no output): throws InputError naming the entry or entity and
    /// the allowed values. Called before run(); `--check` stops after it with
    /// exit 0. May be empty when run() has nothing to check beyond the patterns.
    std::function<void(dealii::ParameterHandler &, const std::string &prm_file)> check;
    /// Run with the parsed parameters; returns the exit code.
    std::function<int(dealii::ParameterHandler &, const std::string &prm_file)> run;
    /// false: the tool reads no .prm (micro-benchmarks driven by options only);
    /// declare() is not called and run() gets an empty handler and file name.
    bool reads_prm = true;
    /// With reads_prm: the .prm may be omitted; the declared defaults (changed
    /// by the tool's options in check()/run()) are used then.
    bool prm_optional = false;
    /// Extra command-line options this tool accepts besides --help, --check and
    /// --print-parameters, with a one-line description each. An option written
    /// "--name=" takes a value ("--name=VALUE" or "--name VALUE").
    std::vector<std::pair<std::string, std::string>> options;
  };

  /// The extra options given on the command line (as written, e.g. "--probe",
  /// "--csv=out.csv"), valid while run_tool() runs.
  const std::vector<std::string> &tool_options();

  /// Value of "--name=VALUE" among tool_options(), or `fallback`.
  std::string tool_option_value(const std::string &name, const std::string &fallback);
  bool        tool_option_given(const std::string &name);
  /// Integer value of "--name=VALUE" in [min, max], or `fallback` when absent;
  /// InputError naming the option and the allowed range otherwise.
  unsigned long tool_option_uint(const std::string &name, unsigned long fallback, unsigned long min, unsigned long max);
  /// True while run_tool() runs with --check (parse and validate only).
  bool check_only();

  /// InputError unless `path` names an existing, readable regular file.
  /// `where` is the .prm entry that names it (e.g. "grid/mesh file").
  void require_input_file(const std::string &path, const std::string &where);
  /// InputError unless output can go to directory `dir`: it is a writable
  /// directory, or it does not exist and its nearest existing ancestor is a
  /// writable directory. Creates nothing.
  void require_output_directory(const std::string &dir, const std::string &where);
  /// Same for an output file: not a directory, and its directory usable as above.
  void require_output_file(const std::string &file, const std::string &where);
  /// Memory available to this process [bytes]: MemAvailable of /proc/meminfo
  /// (the node this rank runs on), lowered to the cgroup v2 limit
  /// (memory.max - memory.current) where one is set; < 0 when unknown.
  double available_memory_bytes();

  /// InputError unless x is finite (not NaN, not +-inf).
  void require_finite(double x, const std::string &where);

  /// The comma-separated numbers of a .prm value; InputError naming `where` and the
  /// offending item unless every item is a finite number.
  std::vector<double> parse_doubles(const std::string &text, const std::string &where);
  /// A point given as exactly dim comma-separated finite numbers (InputError otherwise).
  /// Instantiated for dim = 1, 2, 3.
  template <int dim>
  dealii::Point<dim> parse_point(const std::string &text, const std::string &where);
  /// The default text of a dim-vector entry: "0, 0, <last>" (dim entries).
  std::string zeros_text(unsigned int dim, const std::string &last = "0");

  /// Wall-clock timing of phases (timers, progress, checkpoint cadence).
  using Clock = std::chrono::steady_clock;
  inline double
  seconds_since(const Clock::time_point &t0)
  {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }
  /// CPU time of the calling thread [s] (a phase's cost on a shared machine,
  /// where the wall clock also counts the waits for a core).
  double thread_cpu_seconds();

  /// main() of a tool: `return talus::run_tool(argc, argv, description);`
  /// Command line: [--help] [--print-parameters] [--check] [tool options] FILE.prm.
  /// The .prm is parsed strictly (unknown entries/subsections, wrong types and
  /// unbalanced subsections are errors naming the file and line), then
  /// tool.check() validates it; only then tool.run() starts. Every error exits
  /// with one message and status 2 before any output is written.
  int run_tool(int argc, char **argv, const ToolDescription &tool);

  /// Read one entry from a .prm file before the full declaration exists
  /// (everything else in the file is ignored). `subsection_path` is a list of
  /// nested subsections separated by '/', empty for the top level. Returns
  /// `default_value` when the entry is absent.
  std::string peek_entry(const std::string &prm_file, const std::string &subsection_path, const std::string &entry,
                         const std::string &default_value, const dealii::Patterns::PatternBase &pattern);

  /// Rank-0 output streams (silent on other ranks).
  std::ostream &log();
  std::ostream &err();

  /// Text of a deal.II exception without the backtrace.
  std::string exception_text(const std::exception &e);
} // namespace talus
