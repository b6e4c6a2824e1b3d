#include <talus/base/errors.h>
#include <talus/base/tool.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace talus
{
  namespace
  {
    struct NullBuffer : public std::streambuf
    {
      int overflow(int c) override { return c; }
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
  } // namespace

  namespace
  {
    std::vector<std::string> given_options;
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
        std::string out;
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
  peek_entry(const std::string &                  prm_file,
             const std::string &                  subsection_path,
             const std::string &                  entry,
             const std::string &                  default_value,
             const dealii::Patterns::PatternBase &pattern)
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
      prm.parse_input(prm_file, "", /*skip_undefined=*/true);
    for (const auto &p : path)
      prm.enter_subsection(p);
    const std::string v = prm.get(entry);
    for (std::size_t i = 0; i < path.size(); ++i)
      prm.leave_subsection();
    return v;
  }

  int
  run_tool(int argc, char **argv, const ToolDescription &tool)
  {
    dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
    std::vector<std::string>                 args(argv + 1, argv + argc);

    const auto usage = [&](std::ostream &os) {
      os << "Usage: " << tool.name << " [--help] [--print-parameters] FILE.prm\n"
         << "       mpirun -np N " << tool.name << " FILE.prm\n\n"
         << tool.summary << "\n\n"
         << "  --help               this text\n"
         << "  --print-parameters   print a complete, documented default .prm and exit\n";
      for (const auto &[o, d] : tool.options)
        os << "  " << o << (o.back() == '=' ? "VALUE" : "") << std::string(o.size() + 5 < 21 ? 21 - o.size() - (o.back() == '=' ? 5 : 0) : 1, ' ') << d << "\n";
      os
         << "Exit status: 0 ok, 1 internal error, 2 bad input, 3 run went unstable.\n";
    };

    std::string prm_file;
    bool        print = false;
    for (const auto &a : args)
      {
        if (a == "--help" || a == "-h")
          {
            usage(log());
            return exit_ok;
          }
        else if (a == "--print-parameters")
          print = true;
        else if (!a.empty() && a[0] == '-' &&
                 std::any_of(tool.options.begin(), tool.options.end(), [&](const auto &o) {
                   return o.first.back() == '=' ? a.rfind(o.first, 0) == 0 : a == o.first;
                 }))
          given_options.push_back(a);
        else if (!a.empty() && a[0] == '-')
          {
            std::string allowed = "--help, --print-parameters";
            for (const auto &[o, d] : tool.options)
              allowed += ", " + o + (o.back() == '=' ? "VALUE" : "");
            err() << tool.name << ": error: unknown option '" << a << "' (allowed: " << allowed << ")\n";
            return exit_input_error;
          }
        else if (prm_file.empty())
          prm_file = a;
        else
          {
            err() << tool.name << ": error: more than one parameter file given ('"
                  << prm_file << "', '" << a << "')\n";
            return exit_input_error;
          }
      }

    try
      {
        if (print)
          {
            dealii::ParameterHandler prm;
            tool.declare(prm, "");
            prm.print_parameters(log(),
                                 dealii::ParameterHandler::OutputStyle::PRM);
            return exit_ok;
          }
        if (prm_file.empty())
          {
            err() << tool.name << ": error: no parameter file given\n\n";
            usage(err());
            return exit_input_error;
          }
        if (!std::filesystem::is_regular_file(prm_file))
          throw InputError("parameter file '" + prm_file + "' does not exist or is not a file");

        dealii::ParameterHandler prm;
        try
          {
            tool.declare(prm, prm_file);
            prm.parse_input(prm_file, "", /*skip_undefined=*/false, /*assert_mandatory=*/true);
          }
        catch (const dealii::ExceptionBase &e)
          {
            throw InputError("in '" + prm_file + "': " + exception_text(e));
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
    catch (const std::exception &e)
      {
        err() << tool.name << ": internal error: " << exception_text(e) << "\n";
        return exit_failure;
      }
  }
} // namespace talus
