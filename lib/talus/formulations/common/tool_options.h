// talus — the command line every formulation family's tool shares (besides
// run_tool's --help, --print-parameters and --check): one place, so that a
// family cannot promise an option in its parameter docs and not accept it.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace talus
{
  /// The options of talus-explicit, talus-fem, talus-implicit and
  /// talus-semi-implicit (read by parse_run_parameters).
  inline std::vector<std::pair<std::string, std::string>>
  formulation_tool_options()
  {
    return {{"--restart", "resume from the newest valid checkpoint (same as 'checkpoint/restart = true')"}};
  }
} // namespace talus
