#include <talus/base/errors.h>
#include <talus/base/mpi_session.h>
#include <talus/base/startup.h>
#include <talus/base/tool.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

namespace talus
{
  namespace
  {
    /// Parse a .prm file. deal.II opens the file of an `include FILE` line
    /// relative to the working directory; talus resolves it relative to the
    /// directory of the .prm given, so a shared scene fragment travels with
    /// the .prm files that include it (the parse runs in that directory).
    void
    parse_prm_file(dealii::ParameterHandler &prm, const std::string &prm_file, const bool skip_undefined,
                   const bool assert_mandatory)
    {
      bool has_include = false;
      {
        std::ifstream in(prm_file);
        std::string   line;
        while (!has_include && std::getline(in, line))
          {
            const auto b = line.find_first_not_of(" \t");
            has_include =
              b != std::string::npos && (line.compare(b, 8, "include ") == 0 || line.compare(b, 8, "INCLUDE ") == 0);
          }
      }
      if (!has_include)
        {
          prm.parse_input(prm_file, "", skip_undefined, assert_mandatory);
          return;
        }
      const std::filesystem::path file = std::filesystem::absolute(prm_file);
      const std::filesystem::path cwd  = std::filesystem::current_path();
      std::filesystem::current_path(file.parent_path());
      try
        {
          prm.parse_input(file.string(), "", skip_undefined, assert_mandatory);
        }
      catch (...)
        {
          std::filesystem::current_path(cwd);
          throw;
        }
      std::filesystem::current_path(cwd);
    }

    struct NullBuffer : public std::streambuf
    {
      int
      overflow(int c) override
      {
        return c;
      }
    };
    NullBuffer   null_buffer;
    std::ostream null_stream(&null_buffer);

    bool
    is_root()
    {
      int initialized = 0;
      MPI_Initialized(&initialized);
      if (!initialized)
        return true;
      return dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
    }

    std::string
    trim(const std::string &s)
    {
      const auto b = s.find_first_not_of(" \t\n\r");
      if (b == std::string::npos)
        return "";
      const auto e = s.find_last_not_of(" \t\n\r");
      return s.substr(b, e - b + 1);
    }

    /// deal.II's message for entries declared with has_to_be_set shows their
    /// mangled paths ("time.end_20time"); turn it into "'time/end time'".
    std::string
    readable_mandatory_message(const std::string &text)
    {
      const std::string a = "The following parameters ", b = " have not been set";
      const auto        i = text.find(a), j = text.find(b);
      if (text.find("has_to_be_set") == std::string::npos || i == std::string::npos || j == std::string::npos || j < i)
        return text;
      std::istringstream is(text.substr(i + a.size(), j - i - a.size()));
      std::string        token, list;
      while (is >> token)
        {
          while (!token.empty() && token.back() == ',')
            token.pop_back();
          std::string out;
          for (std::size_t k = 0; k < token.size(); ++k)
            if (token[k] == '_' && k + 2 < token.size() + 0 && std::isxdigit(token[k + 1]) &&
                std::isxdigit(token[k + 2]))
              {
                out += static_cast<char>(std::stoi(token.substr(k + 1, 2), nullptr, 16));
                k += 2;
              }
            else
              out += token[k] == '.' ? '/' : token[k];
          list += (list.empty() ? "'" : ", '") + out + "'";
        }
      return "entry " + list + " must be set (no usable default); see --print-parameters";
    }
  } // namespace

  namespace
  {
    std::vector<std::string> given_options;
    bool                     check_flag = false;
  } // namespace

  bool
  check_only()
  {
    return check_flag;
  }

  unsigned long
  tool_option_uint(const std::string &name, const unsigned long fallback, const unsigned long min,
                   const unsigned long max)
  {
    if (!tool_option_given(name))
      return fallback;
    const std::string v       = tool_option_value(name, "");
    const std::string allowed = "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    const bool        digits =
      !v.empty() && v.size() < 19 && std::all_of(v.begin(), v.end(), [](const char c) { return c >= '0' && c <= '9'; });
    if (!digits)
      throw InputError("option " + name + ": '" + v + "' is not " + allowed);
    const unsigned long n = std::stoul(v);
    if (n < min || n > max)
      throw InputError("option " + name + ": " + v + " is out of range (allowed: " + allowed + ")");
    return n;
  }

  void
  require_finite(const double x, const std::string &where)
  {
    if (!std::isfinite(x))
      throw InputError(where + ": the value must be a finite number (got " + std::to_string(x) + ")");
  }

  void
  require_input_file(const std::string &path, const std::string &where)
  {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (path.empty())
      throw InputError(where + ": no file given (the entry is empty)");
    if (!fs::exists(path, ec))
      throw InputError(where + ": file '" + path + "' does not exist");
    if (!fs::is_regular_file(path, ec))
      throw InputError(where + ": '" + path + "' is not a regular file");
    if (::access(path.c_str(), R_OK) != 0)
      throw InputError(where + ": file '" + path + "' is not readable");
  }

  void
  require_output_directory(const std::string &dir, const std::string &where)
  {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (dir.empty())
      throw InputError(where + ": must not be empty");
    fs::path p = fs::absolute(fs::path(dir), ec);
    if (ec)
      throw InputError(where + ": '" + dir + "' is not a valid path");
    // the nearest existing ancestor (or the directory itself) must be a
    // writable directory; nothing is created here
    while (!fs::exists(p, ec))
      {
        if (!p.has_parent_path() || p.parent_path() == p)
          throw InputError(where + ": '" + dir + "' cannot be created (no existing parent directory)");
        p = p.parent_path();
      }
    if (!fs::is_directory(p, ec))
      throw InputError(where + ": '" + dir + "' cannot be used: '" + p.string() + "' exists and is not a directory");
    if (::access(p.c_str(), W_OK | X_OK) != 0)
      throw InputError(where + ": '" + dir + "' cannot be written: directory '" + p.string() + "' is not writable");
    // access() says yes to root everywhere, also where nothing can be created
    // (/proc, read-only mounts): create and remove a probe directory there
    std::string probe = (p / ".talus-probe-XXXXXX").string();
    if (::mkdtemp(probe.data()) == nullptr)
      {
        const std::string why = std::strerror(errno);
        throw InputError(where + ": '" + dir + "' cannot be " + (p == fs::path(dir) ? "written" : "created") +
                         ": nothing can be created in '" + p.string() + "' (" + why + ")");
      }
    ::rmdir(probe.c_str());
  }

  void
  require_output_file(const std::string &file, const std::string &where)
  {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (file.empty())
      throw InputError(where + ": must not be empty");
    if (fs::is_directory(file, ec))
      throw InputError(where + ": '" + file + "' is a directory, not a file");
    const fs::path parent = fs::path(file).parent_path();
    require_output_directory(parent.empty() ? std::string(".") : parent.string(), where);
  }

  double
  available_memory_bytes()
  {
    double        avail = -1;
    std::ifstream f("/proc/meminfo");
    std::string   key;
    double        kb;
    std::string   unit;
    while (f >> key >> kb)
      {
        std::getline(f, unit);
        if (key == "MemAvailable:")
          avail = kb * 1024;
      }
    // a cgroup (v2) limit below the node's memory (containers, batch jobs)
    std::ifstream mx("/sys/fs/cgroup/memory.max"), cur("/sys/fs/cgroup/memory.current");
    double        limit = 0, used = 0;
    if (mx >> limit && cur >> used && limit > used)
      avail = avail < 0 ? limit - used : std::min(avail, limit - used);
    return avail;
  }

  const std::vector<std::string> &
  tool_options()
  {
    return given_options;
  }

  std::string
  tool_option_value(const std::string &name, const std::string &fallback)
  {
    for (const auto &o : given_options)
      if (o.rfind(name + "=", 0) == 0)
        return o.substr(name.size() + 1);
    return fallback;
  }

  bool
  tool_option_given(const std::string &name)
  {
    for (const auto &o : given_options)
      if (o == name || o.rfind(name + "=", 0) == 0)
        return true;
    return false;
  }

  std::ostream &
  log()
  {
    return is_root() ? std::cout : null_stream;
  }

  std::ostream &
  err()
  {
    return is_root() ? std::cerr : null_stream;
  }

  std::string
  exception_text(const std::exception &e)
  {
    if (const auto *d = dynamic_cast<const dealii::ExceptionBase *>(&e))
      {
        std::ostringstream os;
        d->print_info(os);
        std::string s = trim(os.str());
        // deal.II prefixes messages with "    " and sometimes "The violated
        // condition was:" blocks; keep the text compact.
        std::string        out;
        std::istringstream is(s);
        std::string        line;
        while (std::getline(is, line))
          {
            line = trim(line);
            if (!line.empty())
              out += (out.empty() ? "" : " ") + line;
          }
        return out.empty() ? std::string(d->get_exc_name()) : out;
      }
    return e.what();
  }

  std::string
  peek_entry(const std::string &prm_file, const std::string &subsection_path, const std::string &entry,
             const std::string &default_value, const dealii::Patterns::PatternBase &pattern)
  {
    dealii::ParameterHandler prm;
    std::vector<std::string> path;
    {
      std::istringstream is(subsection_path);
      std::string        part;
      while (std::getline(is, part, '/'))
        if (!part.empty())
          path.push_back(part);
    }
    for (const auto &p : path)
      prm.enter_subsection(p);
    prm.declare_entry(entry, default_value, pattern);
    for (std::size_t i = 0; i < path.size(); ++i)
      prm.leave_subsection();
    if (!prm_file.empty())
      parse_prm_file(prm, prm_file, /*skip_undefined=*/true, /*assert_mandatory=*/false);
    for (const auto &p : path)
      prm.enter_subsection(p);
    const std::string v = prm.get(entry);
    for (std::size_t i = 0; i < path.size(); ++i)
      prm.leave_subsection();
    return v;
  }


  namespace
  {
    double startup_seconds_main = -1;
    double startup_seconds_mpi  = -1;
  } // namespace

  double
  thread_cpu_seconds()
  {
    timespec t{};
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) != 0)
      return 0.0;
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }

  double
  seconds_since_process_start()
  {
    std::ifstream in("/proc/self/stat");
    std::string   stat;
    std::getline(in, stat);
    const auto paren = stat.rfind(')'); // the command name may contain spaces
    if (paren == std::string::npos)
      return -1;
    std::istringstream fields(stat.substr(paren + 2));
    std::string        f;
    // fields after the name start at 3 (state); starttime is field 22
    for (int i = 3; i < 22 && (fields >> f); ++i)
      ;
    unsigned long long start_ticks = 0;
    if (!(fields >> start_ticks))
      return -1;
    timespec now{};
    if (::clock_gettime(CLOCK_BOOTTIME, &now) != 0)
      return -1;
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec) - double(start_ticks) / double(::sysconf(_SC_CLK_TCK));
  }

  double
  startup_seconds_until_main()
  {
    return startup_seconds_main;
  }

  double
  startup_seconds_until_mpi()
  {
    return startup_seconds_mpi;
  }

  int
  run_tool(int argc, char **argv, const ToolDescription &tool)
  {
    startup_seconds_main = seconds_since_process_start();
    std::vector<std::string> args(argv + 1, argv + argc);
    given_options.clear();
    check_flag = false;

    // --help, --print-parameters and --check of a singleton are serial by
    // nature: no MPI start (0.1-0.3 s, docs/scaling.md "Start-up"). Every MPI
    // use on their path is guarded (MPI_Initialized; deal.II's Utilities::MPI
    // functions answer rank 0 of 1 without MPI). Under mpirun every rank
    // starts MPI as before, so the ranks agree and one of them prints.
    const bool serial_mode = std::any_of(args.begin(), args.end(), [&](const std::string &a) {
      return a == "--help" || a == "-h" || (a == "--print-parameters" && tool.reads_prm) || a == "--check";
    });
    // session_base destroyed after `mpi`: the directory is removed after MPI_Finalize
    std::optional<PrivateMpiSessionBase>                    session_base;
    std::optional<dealii::Utilities::MPI::MPI_InitFinalize> mpi;
    if (!(serial_mode && !launched_by_process_manager()) || std::getenv("TALUS_ALWAYS_START_MPI"))
      {
        session_base.emplace();
        mpi.emplace(argc, argv, 1);
      }
    startup_seconds_mpi = seconds_since_process_start();

    const std::string file_arg = tool.reads_prm ? (tool.prm_optional ? " [FILE.prm]" : " FILE.prm") : "";
    const auto        usage    = [&](std::ostream &os) {
      os << "Usage: " << tool.name << " [--help]" << (tool.reads_prm ? " [--print-parameters]" : "") << " [--check]";
      for (const auto &[o, d] : tool.options)
        os << " [" << o << (o.back() == '=' ? "VALUE" : "") << "]";
      os << file_arg << "\n";
      if (tool.reads_prm)
        os << "       mpirun -np N " << tool.name << file_arg << "\n";
      os << "\n"
         << tool.summary << "\n\n"
         << "  --help               this text\n";
      if (tool.reads_prm)
        os << "  --print-parameters   print a complete, documented default .prm and exit\n"
           << "  --check              parse and validate FILE.prm completely (entries, ranges, consistency,\n"
           << "                       input files, output location), run nothing, write nothing; exit 0 if valid\n";
      else
        os << "  --check              validate the command line, run nothing; exit 0 if valid\n";
      for (const auto &[o, d] : tool.options)
        {
          const std::string shown = o + (o.back() == '=' ? "VALUE" : "");
          os << "  " << shown << std::string(shown.size() < 21 ? 21 - shown.size() : 1, ' ') << d << "\n";
        }
      os << "Exit status: 0 ok, 1 internal error, 2 bad input, 3 run went unstable or was stopped.\n";
    };
    const auto allowed_options = [&]() {
      std::string allowed = tool.reads_prm ? "--help, --print-parameters, --check" : "--help, --check";
      for (const auto &[o, d] : tool.options)
        allowed += ", " + o + (o.back() == '=' ? "VALUE" : "");
      return allowed;
    };

    std::string prm_file;
    bool        print = false;
    for (std::size_t i = 0; i < args.size(); ++i)
      {
        const std::string &a = args[i];
        if (a == "--help" || a == "-h")
          {
            usage(log());
            return exit_ok;
          }
        else if (a == "--print-parameters" && tool.reads_prm)
          print = true;
        else if (a == "--check")
          check_flag = true;
        else if (!a.empty() && a[0] == '-' && std::any_of(tool.options.begin(), tool.options.end(), [&](const auto &o) {
                   return o.first.back() == '=' ? a.rfind(o.first, 0) == 0 : a == o.first;
                 }))
          given_options.push_back(a);
        else if (!a.empty() && a[0] == '-' && std::any_of(tool.options.begin(), tool.options.end(), [&](const auto &o) {
                   return o.first.back() == '=' && a + "=" == o.first;
                 }))
          {
            // "--name VALUE"
            if (i + 1 == args.size())
              {
                err() << tool.name << ": error: option " << a << " needs a value (" << a << "=VALUE)\n";
                return exit_input_error;
              }
            given_options.push_back(a + "=" + args[++i]);
          }
        else if (!a.empty() && a[0] == '-' && a != "-")
          {
            err() << tool.name << ": error: unknown option '" << a << "' (allowed: " << allowed_options() << ")\n";
            return exit_input_error;
          }
        else if (!tool.reads_prm)
          {
            err() << tool.name << ": error: unexpected argument '" << a << "' (this tool reads no parameter file; "
                  << "allowed: " << allowed_options() << ")\n";
            return exit_input_error;
          }
        else if (prm_file.empty())
          prm_file = a;
        else
          {
            err() << tool.name << ": error: more than one parameter file given ('" << prm_file << "', '" << a << "')\n";
            return exit_input_error;
          }
      }

    try
      {
        dealii::ParameterHandler prm;
        if (tool.reads_prm)
          {
            if (print)
              {
                tool.declare(prm, "");
                prm.print_parameters(log(), dealii::ParameterHandler::OutputStyle::PRM);
                return exit_ok;
              }
            if (prm_file.empty() && tool.prm_optional)
              tool.declare(prm, "");
            else if (prm_file.empty())
              {
                err() << tool.name << ": error: no parameter file given\n\n";
                usage(err());
                return exit_input_error;
              }
            std::error_code ec;
            if (!prm_file.empty())
              {
                if (!std::filesystem::exists(prm_file, ec))
                  throw InputError("parameter file '" + prm_file + "' does not exist");
                if (!std::filesystem::is_regular_file(prm_file, ec))
                  throw InputError("parameter file '" + prm_file + "' is not a regular file");
                try
                  {
                    tool.declare(prm, prm_file);
                    parse_prm_file(prm, prm_file, /*skip_undefined=*/false, /*assert_mandatory=*/true);
                  }
                catch (const dealii::ExceptionBase &e)
                  {
                    throw InputError("in '" + prm_file + "': " + readable_mandatory_message(exception_text(e)));
                  }
              }
          }
        try
          {
            if (tool.check)
              tool.check(prm, prm_file);
          }
        catch (const InputError &e)
          {
            throw InputError((prm_file.empty() ? "" : "in '" + prm_file + "': ") + e.what());
          }
        catch (const dealii::ExceptionBase &e)
          {
            // a value the patterns let through but the tool cannot use
            throw InputError((prm_file.empty() ? "" : "in '" + prm_file + "': ") + exception_text(e));
          }
        if (check_flag)
          {
            log() << tool.name << ": " << (prm_file.empty() ? "command line" : "'" + prm_file + "'")
                  << " is valid (--check: nothing was run or written)\n";
            return exit_ok;
          }
        return tool.run(prm, prm_file);
      }
    catch (const InputError &e)
      {
        err() << tool.name << ": error: " << e.what() << "\n";
        return exit_input_error;
      }
    catch (const InstabilityError &e)
      {
        err() << tool.name << ": UNSTABLE: " << e.what() << "\n";
        return exit_unstable;
      }
    catch (const RunStopped &e)
      {
        err() << tool.name << ": stopped: " << e.what() << "\n";
        return exit_unstable;
      }
    catch (const std::bad_alloc &)
      {
        err() << tool.name << ": error: out of memory (is the grid or the number of material points far larger "
              << "than intended?)\n";
        return exit_failure;
      }
    catch (const std::exception &e)
      {
        err() << tool.name << ": internal error: " << exception_text(e) << "\n";
        return exit_failure;
      }
    catch (...)
      {
        err() << tool.name << ": internal error: unknown exception\n";
        return exit_failure;
      }
  }
} // namespace talus

namespace talus
{
  std::vector<double>
  parse_doubles(const std::string &text, const std::string &where)
  {
    std::vector<double> r;
    for (const auto &s : dealii::Utilities::split_string_list(text, ','))
      {
        try
          {
            std::size_t  pos = 0;
            const double v   = std::stod(s, &pos);
            if (pos != s.size() || !std::isfinite(v))
              throw std::invalid_argument(s);
            r.push_back(v);
          }
        catch (const std::exception &)
          {
            throw InputError(where + ": '" + s + "' is not a finite number (in '" + text + "')");
          }
      }
    return r;
  }

  std::string
  zeros_text(const unsigned int dim, const std::string &last)
  {
    std::string s;
    for (unsigned int d = 0; d + 1 < dim; ++d)
      s += "0, ";
    return s + last;
  }

  template <int dim>
  dealii::Point<dim>
  parse_point(const std::string &text, const std::string &where)
  {
    const auto v = parse_doubles(text, where);
    require(v.size() == dim, where,
            "needs exactly " + std::to_string(dim) + " comma-separated numbers for dimension " + std::to_string(dim) +
              " (got '" + text + "')");
    dealii::Point<dim> p;
    for (unsigned int d = 0; d < dim; ++d)
      p[d] = v[d];
    return p;
  }

  template dealii::Point<1> parse_point<1>(const std::string &, const std::string &);
  template dealii::Point<2> parse_point<2>(const std::string &, const std::string &);
  template dealii::Point<3> parse_point<3>(const std::string &, const std::string &);
} // namespace talus
