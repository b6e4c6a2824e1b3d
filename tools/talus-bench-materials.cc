// talus-bench-materials — micro-benchmark of the constitutive models: ns per
// stress update for every registered model with its default parameters.
//
//   talus-bench-materials [--points=N] [--steps=S]   (also "--points N")
//
// Each of N material points (own stress and history, initial stress -100 kPa
// isotropic) follows S strain increments d_eps_k = a (B1 + sin(0.3 k + phase) B2)
// with a non-coaxial pair B1, B2 (dt = 1e-3 s). Two scenarios:
//   elastic: a = 1e-9 (no yielding), loading: a = 1e-4 (soil models yield within
//   the first tens of steps with their defaults).
// Models with a finite-strain form are also timed through finite_strain_update
// with dF = I + a (B1 + sin(...) B2 + spin), without and with the consistent tangent.
// Prints a Markdown table (docs/materials.md).
#include <talus/base/errors.h>
#include <talus/base/tool.h>
#include <talus/materials/material.h>

#include <deal.II/base/parameter_handler.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

using namespace talus::materials;

namespace
{
  struct Path
  {
    Strain               B1, B2;
    dealii::Tensor<2, 3> Wp;
    Path()
    {
      B1[0][0] = -2.0, B1[1][1] = 1.0, B1[2][2] = 0.4, B1[0][1] = 0.7, B1[1][2] = -0.4, B1[0][2] = 0.3;
      B2[0][0] = 1.0, B2[1][1] = -1.5, B2[0][2] = 0.9, B2[1][2] = 0.5;
      Wp[0][1] = 0.3, Wp[1][0] = -0.3;
    }
  };

  double sink = 0; // defeats dead-code elimination

  double
  bench_small(const Material &m, const unsigned int N, const unsigned int S, const double a)
  {
    const Path          P;
    const unsigned int  nh = m.n_history();
    std::vector<Stress> sig(N);
    std::vector<double> h(std::max(1u, nh) * N);
    for (unsigned int i = 0; i < N; ++i)
      {
        sig[i] = Stress();
        for (unsigned int d = 0; d < 3; ++d)
          sig[i][d][d] = -100e3;
        m.initialize_history(sig[i], ArrayView<double>(h.data() + i * nh, nh));
      }
    Spin w;
    w[0][1] = 0.1 * a, w[1][0] = -0.1 * a;
    const auto t0 = std::chrono::steady_clock::now();
    for (unsigned int k = 0; k < S; ++k)
      for (unsigned int i = 0; i < N; ++i)
        {
          const Strain de = a * (P.B1 + std::sin(0.3 * k + 0.01 * i) * P.B2);
          m.update_stress(de, w, 1e-3, sig[i], ArrayView<double>(h.data() + i * nh, nh));
        }
    const auto t1 = std::chrono::steady_clock::now();
    for (const auto &s : sig)
      sink += s[0][0];
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / (double(N) * S);
  }

  double
  bench_finite(const Material &m, const unsigned int N, const unsigned int S, const double a, const bool tangent)
  {
    const Path          P;
    const unsigned int  nh = m.n_history();
    std::vector<double> h(std::max(1u, nh) * N), hn(std::max(1u, nh) * N);
    Stress              s0;
    for (unsigned int i = 0; i < N; ++i)
      m.initialize_history(s0, ArrayView<double>(h.data() + i * nh, nh));
    dealii::Tensor<4, 3> T;
    Stress               tau;
    const auto           t0 = std::chrono::steady_clock::now();
    for (unsigned int k = 0; k < S; ++k)
      {
        for (unsigned int i = 0; i < N; ++i)
          {
            dealii::Tensor<2, 3> dF = dealii::Tensor<2, 3>(a * (P.B1 + std::sin(0.3 * k + 0.01 * i) * P.B2)) + a * P.Wp;
            for (unsigned int d = 0; d < 3; ++d)
              dF[d][d] += 1.0;
            m.finite_strain_update(dF, ArrayView<const double>(h.data() + i * nh, nh),
                                   ArrayView<double>(hn.data() + i * nh, nh), tau, tangent ? &T : nullptr);
            sink += tau[0][0];
          }
        std::swap(h, hn);
      }
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / (double(N) * S);
  }

  std::string
  fmt(const double v)
  {
    if (v < 0)
      return "n/a";
    char b[32];
    std::snprintf(b, sizeof(b), "%.0f", v);
    return b;
  }
} // namespace

namespace
{
  int
  bench(const unsigned int N, const unsigned int S)
  {
    std::cout << "| model | small strain, elastic [ns] | small strain, loading [ns] | "
                 "finite strain [ns] | finite strain + tangent [ns] |\n"
                 "|---|---:|---:|---:|---:|\n";
    for (const auto &name : registered_models())
      {
        dealii::ParameterHandler prm;
        prm.enter_subsection("material");
        declare_material_parameters(prm);
        prm.set("model", name);
        std::unique_ptr<Material> m = create_material(prm, "material", 0);
        prm.leave_subsection();
        double e = -1, l = -1, f = -1, ft = -1;
        try
          {
            bench_small(*m, N, 5, 1e-9); // warm-up
            e = bench_small(*m, N, S, 1e-9);
            l = bench_small(*m, N, S, 1e-4);
          }
        catch (const std::exception &)
          {
          }
        if (m->has_finite_strain_form())
          {
            try
              {
                bench_finite(*m, N, 5, 1e-4, false);
                f  = bench_finite(*m, N, S, 1e-4, false);
                ft = bench_finite(*m, N, S, 1e-4, true);
              }
            catch (const std::exception &)
              {
              }
          }
        std::cout << "| " << name << " | " << fmt(e) << " | " << fmt(l) << " | " << fmt(f) << " | " << fmt(ft)
                  << " |\n";
      }
    if (sink == 12345.678)
      std::cout << sink;
    return 0;
  }
} // namespace

int
main(int argc, char **argv)
{
  talus::ToolDescription tool;
  tool.name      = "talus-bench-materials";
  tool.summary   = "Micro-benchmark of the constitutive models: ns per stress update of every registered model\n"
                   "with its default parameters (small strain elastic and loading, finite strain with and\n"
                   "without the consistent tangent). Prints a Markdown table. Reads no parameter file.";
  tool.reads_prm = false;
  tool.options   = {{"--points=", "material points per model (default 1000, 1..10^7)"},
                    {"--steps=", "strain increments per point (default 200, 1..10^7)"}};
  tool.check     = [](dealii::ParameterHandler &, const std::string &) {
    talus::tool_option_uint("--points", 1000, 1, 10000000);
    talus::tool_option_uint("--steps", 200, 1, 10000000);
  };
  tool.run = [](dealii::ParameterHandler &, const std::string &) {
    return bench(talus::tool_option_uint("--points", 1000, 1, 10000000),
                 talus::tool_option_uint("--steps", 200, 1, 10000000));
  };
  return talus::run_tool(argc, argv, tool);
}
