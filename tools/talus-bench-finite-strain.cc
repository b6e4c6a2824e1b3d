// talus-bench-finite-strain: ns per finite_strain_update() of the finite-strain
// models (with and without the consistent tangent; elastic and plastic steps).
// Micro-benchmark, not a test. Usage: talus-bench-finite-strain [--updates=N]
#include <talus/base/tool.h>
#include <talus/materials/hencky_mohr_coulomb.h>
#include <talus/materials/j2_plasticity.h>
#include <talus/materials/neo_hookean.h>
#include <talus/materials/nor_sand.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace talus::materials;
using T2 = dealii::Tensor<2, 3>;

namespace
{
  volatile double sink = 0;

  double
  ns_per_update(const Material &m, const T2 &dF, const std::vector<double> &h0, const bool tangent, const int n)
  {
    std::vector<double>  h1(h0.size());
    Stress               tau;
    dealii::Tensor<4, 3> D;
    const auto           t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i)
      {
        m.finite_strain_update(dF, dealii::ArrayView<const double>(h0.data(), h0.size()),
                               dealii::ArrayView<double>(h1.data(), h1.size()), tau, tangent ? &D : nullptr);
        sink += tau[0][0];
      }
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / n;
  }

  std::vector<double>
  hist(const Material &m, const Stress &s = Stress())
  {
    std::vector<double> h(m.n_history());
    m.initialize_history(s, dealii::ArrayView<double>(h.data(), h.size()));
    return h;
  }

  T2
  diag(const double a, const double b, const double c, const double g = 0)
  {
    T2 f;
    f[0][0] = a;
    f[1][1] = b;
    f[2][2] = c;
    f[0][1] = g;
    return f;
  }

  void
  row(const char *name, const Material &m, const T2 &dF, const std::vector<double> &h, const int n)
  {
    const double a = ns_per_update(m, dF, h, false, n);
    const double b = ns_per_update(m, dF, h, true, n);
    std::printf("| %-40s | %10.0f | %10.0f |\n", name, a, b);
  }

  int
  bench(const int n)
  {
    std::printf("| model, step                              | stress [ns] | +tangent [ns] |\n");
    std::printf("|---|---|---|\n");
    NeoHookean nh(1e7, 0.3);
    row("neo hookean (coupled)", nh, diag(1.01, 0.99, 1.0, 0.01), hist(nh), n);
    NeoHookean nhs(1e7, 0.3, NeoHookean::Energy::split);
    row("neo hookean (split)", nhs, diag(1.01, 0.99, 1.0, 0.01), hist(nhs), n);
    J2Plasticity j2(200e9, 0.3, 200e6, 20e9);
    row("j2 plasticity, elastic step", j2, diag(1.0002, 1.0, 1.0, 1e-4), hist(j2), n);
    row("j2 plasticity, plastic step", j2, diag(1.002, 1.0, 1.0, 3e-3), hist(j2), n);
    HenckyMohrCoulomb mc(20e6, 0.3, 10e3, 30, 10);
    const auto        hmc = hist(mc, -100e3 * dealii::unit_symmetric_tensor<3>());
    row("hencky mohr coulomb, elastic step", mc, diag(1.0005, 1.0, 0.9995, 2e-4), hmc, n);
    row("hencky mohr coulomb, plane return", mc, diag(1.004, 1.001, 0.99, 3e-3), hmc, n);
    row("hencky mohr coulomb, edge return", mc, diag(1.005, 1.005, 0.98), hmc, n);
    row("hencky mohr coulomb, apex return", mc, diag(1.03, 1.03, 1.03, 1e-3), hmc, n);
    NorSand::Parameters P;
    P.v0 = 1.63;
    P.p0 = 100e3;
    NorSand    ns(P);
    const auto hns = hist(ns);
    row("nor sand, elastic step", ns, diag(1.00001, 1.0, 1.0), hns, n);
    row("nor sand, plastic step (3x3 Newton)", ns, diag(0.999, 1.0005, 1.0005, 3e-4), hns, n);
    return sink == 12345.0;
  }
} // namespace

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name      = "talus-bench-finite-strain";
  tool.summary   = "Micro-benchmark: ns per finite_strain_update() of the finite-strain models, with and\n"
                   "without the consistent tangent, elastic and plastic steps. Reads no parameter file.";
  tool.reads_prm = false;
  tool.options   = {{"--updates=", "updates per timed row (default 200000, 1..10^9)"}};
  tool.check     = [](dealii::ParameterHandler &, const std::string &) {
    talus::tool_option_uint("--updates", 200000, 1, 1000000000);
  };
  tool.run = [](dealii::ParameterHandler &, const std::string &) {
    return bench(static_cast<int>(talus::tool_option_uint("--updates", 200000, 1, 1000000000)));
  };
  return talus::run_tool(argc, argv, tool);
}
