// talus — output helpers: atomic files (written under a temporary name and
// renamed when complete, so a killed run never leaves a truncated result) and
// the ParaView PVD series record.
#pragma once

#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace talus::io
{
  /// A file written to "<path>.part" and renamed to <path> by commit(). If the
  /// object is destroyed without commit() (an exception), the temporary file is
  /// removed.
  class AtomicFile
  {
  public:
    explicit AtomicFile(const std::string &path);
    ~AtomicFile();
    AtomicFile(const AtomicFile &)            = delete;
    AtomicFile &operator=(const AtomicFile &) = delete;

    std::ofstream &
    stream()
    {
      return out;
    }
    /// Flush, close and rename into place. Throws std::runtime_error on I/O failure.
    void commit();

  private:
    std::string   path, tmp;
    std::ofstream out;
    bool          committed = false;
  };

  /// Write a PVD record (time, file name) atomically.
  void write_pvd(const std::string &path, const std::vector<std::pair<double, std::string>> &records);
} // namespace talus::io
