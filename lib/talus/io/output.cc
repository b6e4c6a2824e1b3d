#include <talus/io/output.h>

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <stdexcept>

namespace talus::io
{
  AtomicFile::AtomicFile(const std::string &p)
      : path(p)
      , tmp(p + ".part")
      , out(tmp)
  {
    if (!out)
      throw std::runtime_error("cannot open '" + tmp + "' for writing");
  }

  AtomicFile::~AtomicFile()
  {
    if (!committed)
      {
        out.close();
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
      }
  }

  void
  AtomicFile::commit()
  {
    out.flush();
    const bool ok = static_cast<bool>(out);
    out.close();
    if (!ok)
      throw std::runtime_error("writing '" + tmp + "' failed (disk full?)");
    std::filesystem::rename(tmp, path);
    committed = true;
  }

  void
  write_pvd(const std::string &path, const std::vector<std::pair<double, std::string>> &records)
  {
    AtomicFile f(path);
    auto      &s = f.stream();
    s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n"
      << std::setprecision(12);
    for (const auto &[t, name] : records)
      s << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << name << "\"/>\n";
    s << "  </Collection>\n</VTKFile>\n";
    f.commit();
  }
} // namespace talus::io
