// talus — error types. Tools catch these at main() level, print one clear
// message and exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace talus
{
  /// Bad input: a .prm entry, a file, an inconsistent setting. The message names
  /// the file / subsection / entry and the allowed values.
  class InputError : public std::runtime_error
  {
  public:
    explicit InputError(const std::string &what)
        : std::runtime_error(what)
    {
    }
  };

  /// A run went unstable (non-finite state, unbounded energy growth).
  class InstabilityError : public std::runtime_error
  {
  public:
    explicit InstabilityError(const std::string &what)
        : std::runtime_error(what)
    {
    }
  };

  /// The run met a condition the .prm says must stop it (e.g. material points
  /// leaving the grid with 'lost particles = stop'). Exit code 3 like instability.
  class RunStopped : public std::runtime_error
  {
  public:
    explicit RunStopped(const std::string &what)
        : std::runtime_error(what)
    {
    }
  };

  /// Throw InputError with `where: message` when cond is false.
  inline void
  require(const bool cond, const std::string &where, const std::string &message)
  {
    if (!cond)
      throw InputError(where + ": " + message);
  }
} // namespace talus
