// talus — the memory bandwidth of one core, for the roofline of the explicit step
// (docs/scaling.md, "Roofline of the explicit step"; issue 41 item 1).
//
// The four kernels of McCalpin's STREAM (copy, scale, add, triad), written here,
// on arrays far larger than the caches, one thread (the bench runs one rank per
// core). Each kernel is timed `repeats` times; the best time gives the bandwidth
// as STREAM counts it (bytes the kernel names: 16 per element for copy/scale,
// 24 for add/triad; the write-allocate read of the target line is not counted,
// so a kernel that writes moves one third to one half more than it reports).
//
// Built and run by scripts/bench.sh: c++ -O2 scripts/stream_bandwidth.cc.
// Prints one line per kernel and a last line "stream: triad GB/s".
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int
main(int argc, char **argv)
{
  const std::size_t   n       = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : (std::size_t(1) << 24);
  const int           repeats = argc > 2 ? std::atoi(argv[2]) : 10;
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 0.0);
  const double        s = 3.0;
  double              best[4];
  std::fill(best, best + 4, 1e30);
  using Clock = std::chrono::steady_clock;
  for (int r = 0; r < repeats; ++r)
    {
      auto t0 = Clock::now();
      for (std::size_t i = 0; i < n; ++i)
        c[i] = a[i];
      auto t1 = Clock::now();
      for (std::size_t i = 0; i < n; ++i)
        b[i] = s * c[i];
      auto t2 = Clock::now();
      for (std::size_t i = 0; i < n; ++i)
        c[i] = a[i] + b[i];
      auto t3 = Clock::now();
      for (std::size_t i = 0; i < n; ++i)
        a[i] = b[i] + s * c[i];
      auto                                t4   = Clock::now();
      const std::chrono::duration<double> d[4] = {t1 - t0, t2 - t1, t3 - t2, t4 - t3};
      for (int k = 0; k < 4; ++k)
        best[k] = std::min(best[k], d[k].count());
    }
  // a checksum, so that the loops are not removed
  double sum = 0;
  for (std::size_t i = 0; i < n; i += 4096)
    sum += a[i] + b[i] + c[i];
  const char  *name[4]  = {"copy", "scale", "add", "triad"};
  const double bytes[4] = {16.0 * n, 16.0 * n, 24.0 * n, 24.0 * n};
  for (int k = 0; k < 4; ++k)
    std::printf("  %-6s %8.2f GB/s (best of %d, %zu doubles per array)\n", name[k], bytes[k] / best[k] / 1e9, repeats,
                n);
  std::printf("stream: triad %.2f GB/s (checksum %g)\n", bytes[3] / best[3] / 1e9, sum);
  return 0;
}
