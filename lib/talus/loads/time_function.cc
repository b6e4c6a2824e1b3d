#include <talus/base/errors.h>
#include <talus/loads/time_function.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace talus::loads
{
  namespace
  {
    const char *forms = "allowed: 'constant', 'step T', 'ramp T1', 'ramp T0 T1', 'table t0:f0, t1:f1, ...', "
                        "'table file NAME.csv'";

    double
    number(const std::string &s, const std::string &where, const std::string &text)
    {
      try
        {
          std::size_t  pos = 0;
          const double v   = std::stod(s, &pos);
          if (pos == s.size() && std::isfinite(v))
            return v;
        }
      catch (const std::exception &)
        {
        }
      throw InputError(where + ": '" + s + "' is not a number in '" + text + "' (" + forms + ")");
    }

    std::string
    trim(const std::string &s)
    {
      const auto a = s.find_first_not_of(" \t\r\n");
      if (a == std::string::npos)
        return "";
      const auto b = s.find_last_not_of(" \t\r\n");
      return s.substr(a, b - a + 1);
    }
  } // namespace

  TimeFunction
  TimeFunction::parse(const std::string &text_in, const std::string &where)
  {
    TimeFunction      f;
    const std::string text = trim(text_in);
    f.source               = text.empty() ? "constant" : text;
    std::istringstream is(text);
    std::string        word;
    is >> word;
    if (word.empty() || word == "constant")
      {
        std::string rest;
        require(!(is >> rest), where, "'constant' takes no argument (" + std::string(forms) + ")");
        f.kind = Kind::constant;
        return f;
      }
    std::vector<std::string> args;
    for (std::string a; is >> a;)
      args.push_back(a);
    if (word == "step")
      {
        require(args.size() == 1, where, "'step' needs one time T (" + std::string(forms) + ")");
        f.kind = Kind::step;
        f.t0   = number(args[0], where, text);
        return f;
      }
    if (word == "ramp")
      {
        require(args.size() == 1 || args.size() == 2, where, "'ramp' needs T1 or T0 T1 (" + std::string(forms) + ")");
        f.kind = Kind::ramp;
        f.t0   = args.size() == 2 ? number(args[0], where, text) : 0.0;
        f.t1   = number(args.back(), where, text);
        require(f.t1 > f.t0, where, "ramp end time must exceed its start time (got '" + text + "')");
        return f;
      }
    if (word == "table")
      {
        f.kind = Kind::table;
        std::vector<std::pair<std::string, std::string>> pairs;
        const std::string                                rest = trim(text.substr(5));
        if (rest.rfind("file", 0) == 0 && rest.find(':') == std::string::npos)
          {
            const std::string name = trim(rest.substr(4));
            std::ifstream     in(name);
            require(!name.empty() && in.good(), where, "cannot read table file '" + name + "'");
            std::string line;
            bool        first = true;
            while (std::getline(in, line))
              {
                line = trim(line.substr(0, line.find('#')));
                if (line.empty())
                  continue;
                std::replace(line.begin(), line.end(), ';', ',');
                const auto c = line.find(',');
                require(c != std::string::npos, where, "table file '" + name + "': line '" + line + "' is not 't,f'");
                const std::string a = trim(line.substr(0, c)), b = trim(line.substr(c + 1));
                if (first)
                  {
                    first = false;
                    try
                      {
                        (void)std::stod(a);
                      }
                    catch (const std::exception &)
                      {
                        continue; // header line
                      }
                  }
                pairs.emplace_back(a, b);
              }
          }
        else
          {
            std::stringstream ss(rest);
            std::string       item;
            while (std::getline(ss, item, ','))
              {
                item = trim(item);
                if (item.empty())
                  continue;
                const auto c = item.find(':');
                require(c != std::string::npos, where, "table entry '" + item + "' is not 't:f' (" + forms + ")");
                pairs.emplace_back(trim(item.substr(0, c)), trim(item.substr(c + 1)));
              }
          }
        for (const auto &[a, b] : pairs)
          {
            f.times.push_back(number(a, where, text));
            f.values.push_back(number(b, where, text));
          }
        require(!f.times.empty(), where, "a table needs at least one point t:f");
        for (std::size_t i = 1; i < f.times.size(); ++i)
          require(f.times[i] > f.times[i - 1], where, "table times must increase strictly (in '" + text + "')");
        return f;
      }
    throw InputError(where + ": unknown time function '" + text + "' (" + forms + ")");
  }

  double
  TimeFunction::value(const double t) const
  {
    switch (kind)
      {
        case Kind::constant:
          return 1.0;
        case Kind::step:
          return t >= t0 ? 1.0 : 0.0;
        case Kind::ramp:
          return t <= t0 ? 0.0 : (t >= t1 ? 1.0 : (t - t0) / (t1 - t0));
        case Kind::table:
          {
            if (t <= times.front())
              return values.front();
            if (t >= times.back())
              return values.back();
            const auto   it = std::upper_bound(times.begin(), times.end(), t);
            const auto   i  = static_cast<std::size_t>(it - times.begin());
            const double w  = (t - times[i - 1]) / (times[i] - times[i - 1]);
            return (1 - w) * values[i - 1] + w * values[i];
          }
      }
    return 1.0;
  }

  double
  TimeFunction::settle_time() const
  {
    switch (kind)
      {
        case Kind::constant:
          return 0.0;
        case Kind::step:
          return t0;
        case Kind::ramp:
          return t1;
        case Kind::table:
          return times.back();
      }
    return 0.0;
  }

  void
  declare_time_function(dealii::ParameterHandler &prm, const std::string &what, const std::string &time_base)
  {
    prm.declare_entry("time function", "constant", dealii::Patterns::Anything(),
                      "Factor f(t) of " + what + " (" + time_base +
                        "): constant | step T | ramp T1 | ramp T0 T1 | table t0:f0, t1:f1, ... | table file "
                        "NAME.csv (two columns t,f).");
  }

  TimeFunction
  parse_time_function(dealii::ParameterHandler &prm, const std::string &where)
  {
    return TimeFunction::parse(prm.get("time function"), where + "/time function");
  }
} // namespace talus::loads
