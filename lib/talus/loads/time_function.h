// talus — scalar time functions that scale loads and prescribed velocities:
// constant, step, ramp, and piecewise-linear tables (inline list or CSV file).
#pragma once

#include <string>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

namespace talus::loads
{
  /// f(t), dimensionless factor multiplying a load or a prescribed velocity.
  ///
  /// Text forms (the .prm entry 'time function'):
  ///   constant                 f = 1
  ///   step T                   f = 0 for t < T, 1 for t >= T
  ///   ramp T1                  f = t / T1 up to T1, then 1
  ///   ramp T0 T1               0 before T0, linear to 1 at T1, then 1
  ///   table t0:f0, t1:f1, ...  piecewise linear, constant outside the range
  ///   table file NAME          same from a CSV file with two columns t,f
  ///                            (a header line is skipped; '#' starts a comment)
  class TimeFunction
  {
  public:
    TimeFunction() = default;
    /// Parse; throws InputError naming `where` and the allowed forms.
    static TimeFunction parse(const std::string &text, const std::string &where);

    double value(const double t) const;
    /// Time after which f no longer changes (0 for constant).
    double settle_time() const;
    const std::string &
    text() const
    {
      return source;
    }

  private:
    enum class Kind
    {
      constant,
      step,
      ramp,
      table
    } kind                 = Kind::constant;
    double              t0 = 0, t1 = 0;
    std::vector<double> times, values;
    std::string         source = "constant";
  };

  /// Declare the entry 'time function' (default constant) in the current
  /// subsection: "Factor f(t) of <what> (<time base>): <the forms>". The one
  /// declaration of the entry for every load, velocity, plate and drainage.
  void declare_time_function(dealii::ParameterHandler &prm, const std::string &what, const std::string &time_base);
  /// Parse the current subsection's 'time function'; `where` names the
  /// subsection in errors (where + "/time function").
  TimeFunction parse_time_function(dealii::ParameterHandler &prm, const std::string &where);
} // namespace talus::loads
