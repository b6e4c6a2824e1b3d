// talus — Open MPI singleton start-up without the shared session directory.
//
// A process not launched by mpirun (a "singleton") makes Open MPI 4.1 fork an
// orted daemon, and both create their session directory below
// <TMPDIR>/ompi.<host>.<uid>: one directory shared by every Open MPI job of the
// user on the node, removed by whichever job ends while it is empty. A job that
// starts while another ends can lose it between its mkdir (EEXIST) and the stat
// that follows (ENOENT): "orte_session_dir failed", "Local abort before
// MPI_INIT completed" (docs/reliability.md, measured there). So a singleton
// gets a fresh private session base and no daemon (talus never spawns); the
// directory is removed again after MPI_Finalize (and by a later start if the
// process was killed). Processes started by mpirun
// (or another process manager) keep what their launcher set.
#pragma once

#include <mpi.h>

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace talus
{
  /// Construct before MPI_Init, destroy after MPI_Finalize (run_tool() and the
  /// unit-test main do). Header-only so that tests linking only the materials
  /// library can use it too.
  /// True if a process manager (mpirun, srun, ...) started this process; false
  /// for a singleton (a tool started directly).
  inline bool
  launched_by_process_manager()
  {
    for (const char *v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "OMPI_MCA_orte_hnp_uri", "PMI_RANK"})
      if (std::getenv(v))
        return true;
    return false;
  }

  /// Open MPI settings of a singleton's start-up (docs/scaling.md, "Start-up"):
  /// a singleton is one process on one node, so the ob1 messaging layer with the
  /// self and shared-memory transports is all it can use; without them Open MPI
  /// probes its network libraries (PSM/PSM2, OFI, UCX) first, 0.2-0.3 s on the
  /// build machine. Each is set only if the user has not set it.
  inline void
  set_singleton_mca_defaults()
  {
#ifdef OPEN_MPI
    if (launched_by_process_manager() || std::getenv("TALUS_KEEP_MPI_DEFAULTS"))
      return;
    ::setenv("OMPI_MCA_pml", "ob1", 0);
    ::setenv("OMPI_MCA_btl", "self,vader", 0);
#endif
  }

  struct PrivateMpiSessionBase
  {
    std::string dir; ///< the private base; empty: nothing was changed

    PrivateMpiSessionBase()
    {
#ifdef OPEN_MPI
      if (launched_by_process_manager())
        return; // launched by mpirun or another process manager
      set_singleton_mca_defaults();
      if (std::getenv("TALUS_SHARED_MPI_SESSION")) // opt out (diagnosis of the shared case)
        return;
      const char       *env_base = std::getenv("TMPDIR");
      const std::string base     = env_base && *env_base ? env_base : "/tmp";
      remove_stale(base);
      const std::string templ = base + "/talus-mpi-" + std::to_string(::getpid()) + "-XXXXXX";
      std::vector<char> buf(templ.begin(), templ.end());
      buf.push_back('\0');
      if (::mkdtemp(buf.data()) == nullptr)
        return; // Open MPI then reports the unusable temporary directory itself
      dir = buf.data();
      // an MPI_Init that aborts leaves through exit(), past every destructor
      static std::string at_exit_dir;
      at_exit_dir = dir;
      std::atexit([]() {
        std::error_code ec;
        std::filesystem::remove_all(at_exit_dir, ec);
      });
      ::setenv("OMPI_MCA_orte_tmpdir_base", dir.c_str(), 1);
      if (!std::getenv("OMPI_MCA_ess_singleton_isolated"))
        ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 1);
#endif
    }

    ~PrivateMpiSessionBase()
    {
      if (!dir.empty())
        {
          std::error_code ec;
          std::filesystem::remove_all(dir, ec);
        }
    }

    /// Directories of killed tools (SIGKILL skips the destructor): talus-mpi-<pid>-*
    /// whose process no longer exists.
    static void
    remove_stale(const std::string &base)
    {
      std::error_code ec;
      for (const auto &e : std::filesystem::directory_iterator(base, ec))
        {
          const std::string n = e.path().filename().string();
          if (n.rfind("talus-mpi-", 0) != 0)
            continue;
          const auto dash = n.find('-', 10);
          if (dash == std::string::npos)
            continue;
          const long pid = std::strtol(n.substr(10, dash - 10).c_str(), nullptr, 10);
          if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
            std::filesystem::remove_all(e.path(), ec);
        }
    }

    PrivateMpiSessionBase(const PrivateMpiSessionBase &)            = delete;
    PrivateMpiSessionBase &operator=(const PrivateMpiSessionBase &) = delete;
  };
} // namespace talus
