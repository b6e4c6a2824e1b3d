// Loads (issue 5): time functions; K0 initial stresses are exact at setup
// (sigma_h / sigma_v = K0 to round-off, sigma_v = -rho g depth); K0 = 1 - sin phi
// for Mohr-Coulomb; traction point forces sum to traction x area; mass scaling
// scales the critical time step by sqrt(beta). With a coupled 2-phase material
// (issue 12 item 2): K0 gives the effective stress of the buoyant weight and a
// hydrostatic pore pressure; 'traction face' and 'two phase/local damping' are
// the shared entries; mass scaling below 1 is refused.
#include <talus/base/errors.h>
#include <talus/formulations/explicit/explicit_solver.h>
#include <talus/formulations/explicit/load_control.h>
#include <talus/loads/time_function.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

using namespace talus;

TEST(Loads, TimeFunctions)
{
  using loads::TimeFunction;
  EXPECT_EQ(TimeFunction::parse("constant", "x").value(3.0), 1.0);
  const auto s = TimeFunction::parse("step 0.5", "x");
  EXPECT_EQ(s.value(0.49), 0.0);
  EXPECT_EQ(s.value(0.5), 1.0);
  const auto r = TimeFunction::parse("ramp 1 3", "x");
  EXPECT_EQ(r.value(0.5), 0.0);
  EXPECT_DOUBLE_EQ(r.value(2.0), 0.5);
  EXPECT_EQ(r.value(4.0), 1.0);
  EXPECT_EQ(r.settle_time(), 3.0);
  const auto t = TimeFunction::parse("table 0:0, 1:2, 3:-2", "x");
  EXPECT_DOUBLE_EQ(t.value(0.5), 1.0);
  EXPECT_DOUBLE_EQ(t.value(2.0), 0.0);
  EXPECT_DOUBLE_EQ(t.value(9.0), -2.0);
  const std::string csv = "talus_test_table.csv";
  {
    std::ofstream f(csv);
    f << "t,f\n0,1\n2,3\n";
  }
  EXPECT_DOUBLE_EQ(TimeFunction::parse("table file " + csv, "x").value(1.0), 2.0);
  EXPECT_THROW(TimeFunction::parse("ramp 2 1", "x"), InputError);
  EXPECT_THROW(TimeFunction::parse("sine 1", "x"), InputError);
  EXPECT_THROW(TimeFunction::parse("table 1:1, 0:2", "x"), InputError);
}

namespace
{
  const char *column_prm = R"(
set dimension = 2
subsection grid
  set upper corner = 0.1, 1.25
  set cells        = 2, 25
end
subsection boundary conditions
  set fixed  = 2
  set roller = 0, 1
end
subsection gravity
  set acceleration = 0, -9.81
end
subsection output
  set progress = false
end
set number of materials = 2
subsection material 0
  set model   = linear elastic
  set density = 2000
end
subsection material 1
  set model   = mohr coulomb
  set density = 1800
  subsection mohr coulomb
    set friction angle = 30
    set cohesion       = 0
  end
end
set number of bodies = 2
subsection body 0
  set material     = 0
  set upper corner = 0.05, 1
  set particles per direction = 3
  subsection initial stress
    set K0 procedure = true
    set K0           = 0.4
    set surcharge    = 1000
  end
end
subsection body 1
  set material     = 1
  set lower corner = 0.05, 0
  set upper corner = 0.1, 0.8
  subsection initial stress
    set K0 procedure = true
    set K0           = auto
  end
end
subsection loads
  set number of tractions = 1
  subsection traction 0
    set body     = 1
    set face     = y+
    set traction = 200, -1e4
  end
end
subsection mass scaling
  set factor = 16
end
)";

  template <typename F>
  void
  with_solver(const std::string &extra, F &&f)
  {
    const std::string name = "talus_test_loads.prm";
    if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        std::ofstream out(name);
        out << column_prm << extra;
      }
    MPI_Barrier(MPI_COMM_WORLD);
    dealii::ParameterHandler prm;
    explicit_mpm::declare_parameters(prm, name);
    prm.parse_input(name);
    const auto              p = explicit_mpm::parse_parameters<2>(prm);
    explicit_mpm::Solver<2> s(p, MPI_COMM_WORLD);
    s.setup();
    f(s);
  }
} // namespace

TEST(Loads, K0InitialStressesExact)
{
  with_solver("", [](explicit_mpm::Solver<2> &s) {
    using L                  = PropertyLayout<2>;
    double       worst_ratio = 0, worst_sv = 0;
    unsigned int n = 0;
    for (const auto &pt : s.points.handler)
      {
        const auto   P     = pt.get_properties();
        const int    b     = static_cast<int>(P[L::body]);
        const double K0    = b == 0 ? 0.4 : 1.0 - std::sin(M_PI / 6);
        const double top   = b == 0 ? 1.0 : 0.8;
        const double q     = b == 0 ? 1000.0 : 0.0;
        const double rho   = b == 0 ? 2000.0 : 1800.0;
        const double sv_ex = -(rho * 9.81 * (top - pt.get_location()[1]) + q);
        const double sxx = P[L::stress + 0], syy = P[L::stress + 1], szz = P[L::stress + 2], sxy = P[L::stress + 3];
        worst_ratio = std::max({worst_ratio, std::abs(sxx / syy - K0), std::abs(szz / syy - K0), std::abs(sxy)});
        worst_sv    = std::max(worst_sv, std::abs(syy - sv_ex) / std::abs(sv_ex));
        ++n;
      }
    EXPECT_GT(n, 0u);
    EXPECT_LT(worst_ratio, 1e-15);
    EXPECT_LT(worst_sv, 1e-12);
  });
}

TEST(Loads, TractionForcesSumToTractionTimesArea)
{
  with_solver("", [](explicit_mpm::Solver<2> &s) {
    using L = PropertyLayout<2>;
    ASSERT_TRUE(s.control);
    ASSERT_EQ(s.control->n_point_force_slots(), 1u);
    const unsigned off = s.control->point_force_offset();
    double         fx = 0, fy = 0;
    unsigned int   n = 0;
    for (const auto &pt : s.points.handler)
      {
        const auto P = pt.get_properties();
        if (P[off] != 0 || P[off + 1] != 0)
          {
            EXPECT_EQ(static_cast<int>(P[L::body]), 1);
            EXPECT_GT(pt.get_location()[1], 0.8 - 0.025);
            ++n;
          }
        fx += P[off];
        fy += P[off + 1];
      }
    fx = dealii::Utilities::MPI::sum(fx, MPI_COMM_WORLD);
    fy = dealii::Utilities::MPI::sum(fy, MPI_COMM_WORLD);
    EXPECT_EQ(dealii::Utilities::MPI::sum(n, MPI_COMM_WORLD), 2u); // one row of 2 points across 0.05 m
    EXPECT_NEAR(fx, 200 * 0.05, 1e-12);
    EXPECT_NEAR(fy, -1e4 * 0.05, 1e-9);
  });
}

TEST(Loads, MassScalingScalesCriticalTimeStep)
{
  double dt16 = 0, dt1 = 0;
  with_solver("", [&](explicit_mpm::Solver<2> &s) { dt16 = s.critical_time_step(); });
  with_solver("subsection mass scaling\n set factor = 1\nend\n",
              [&](explicit_mpm::Solver<2> &s) { dt1 = s.critical_time_step(); });
  EXPECT_NEAR(dt16 / dt1, 4.0, 1e-12);
}

// Issue 12 item 2: the loads with a coupled 2-phase material.
namespace
{
  const char *coupled_prm = R"(
set dimension = 2
subsection grid
  set upper corner = 0.05, 1.0
  set cells        = 2, 40
end
subsection boundary conditions
  set roller = 0, 1, 2
end
subsection gravity
  set acceleration = 0, -9.81
end
subsection output
  set progress = false
end
set number of materials = 1
subsection material 0
  set model   = linear elastic
  set density = 2650
  subsection pore liquid
    set drainage               = coupled
    set porosity               = 0.4
    set liquid density         = 1000
    set hydraulic conductivity = 1e-3
  end
end
set number of bodies = 1
subsection body 0
  set upper corner  = 0.05, 0.8
  set traction face = y+
  set traction      = 0, -2000
  subsection initial stress
    set K0 procedure = true
    set K0           = 0.6
    set surcharge    = 500
  end
end
)";

  template <typename F>
  void
  with_coupled(const std::string &extra, F &&f)
  {
    const std::string name = "talus_test_loads_coupled.prm";
    if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      {
        std::ofstream out(name);
        out << coupled_prm << extra;
      }
    MPI_Barrier(MPI_COMM_WORLD);
    dealii::ParameterHandler prm;
    explicit_mpm::declare_parameters(prm, name);
    prm.parse_input(name);
    const auto              p = explicit_mpm::parse_parameters<2>(prm);
    explicit_mpm::Solver<2> s(p, MPI_COMM_WORLD);
    s.setup();
    f(s);
  }
} // namespace

TEST(Loads, K0CoupledEffectiveStressAndHydrostaticPorePressure)
{
  with_coupled("", [](explicit_mpm::Solver<2> &s) {
    using L = PropertyLayout<2>;
    ASSERT_TRUE(s.two_phase && s.two_phase->coupled);
    const double n = 0.4, g = 9.81, top = 0.8, q = 500;
    double       worst_sv = 0, worst_p = 0, worst_k0 = 0;
    for (const auto &pt : s.points.handler)
      {
        const auto   P     = pt.get_properties();
        const double depth = top - pt.get_location()[1];
        const double sv    = -((1 - n) * (2650 - 1000) * g * depth + q); // buoyant weight
        worst_sv           = std::max(worst_sv, std::abs(P[L::stress + 1] - sv) / std::abs(sv));
        worst_p  = std::max(worst_p, std::abs(P[s.two_phase->pore_pressure] - 1000 * g * depth) / (1000 * g * top));
        worst_k0 = std::max(worst_k0, std::abs(P[L::stress + 0] / P[L::stress + 1] - 0.6));
        EXPECT_NEAR(P[L::mass], (1 - n) * 2650 * P[L::volume], 1e-12); // solid mass
      }
    EXPECT_LT(worst_sv, 1e-12);
    EXPECT_LT(worst_p, 1e-12);
    EXPECT_LT(worst_k0, 1e-14);
  });
}

TEST(Loads, CoupledAliasesBecomeSharedEntries)
{
  // 'traction face' is a constant global loads/traction on the body face,
  // 'two phase/local damping' the top-level damping/local damping
  with_coupled("subsection two phase\n set local damping = 0.3\nend\n", [](explicit_mpm::Solver<2> &s) {
    ASSERT_TRUE(s.control);
    const auto &st = s.prm.loads.stages.at(0);
    ASSERT_EQ(st.tractions.size(), 1u);
    EXPECT_EQ(st.n_global_tractions, 1u);
    EXPECT_EQ(st.tractions[0].target, loads::Traction<2>::Target::body_face);
    EXPECT_EQ(st.tractions[0].axis, 1u);
    EXPECT_EQ(st.tractions[0].side, 1);
    EXPECT_EQ(st.tractions[0].traction[1], -2000.0);
    EXPECT_EQ(st.damping, 0.3);
    EXPECT_EQ(s.control->local_damping(), 0.3);
    // the point forces of the face sum to traction x width
    double fy = 0;
    for (const auto &pt : s.points.handler)
      fy += pt.get_properties()[s.control->point_force_offset() + 1];
    EXPECT_NEAR(dealii::Utilities::MPI::sum(fy, MPI_COMM_WORLD), -2000 * 0.05, 1e-9);
  });
}

TEST(Loads, CoupledMassScalingBelowOneRefused)
{
  EXPECT_THROW(with_coupled("subsection mass scaling\n set factor = 0.5\nend\n", [](explicit_mpm::Solver<2> &) {}),
               InputError);
  // >= 1 runs, and the critical step scales by sqrt(beta) (conservative for Eq. 4.129)
  double dt1 = 0, dt4 = 0;
  with_coupled("", [&](explicit_mpm::Solver<2> &s) { dt1 = s.critical_time_step(); });
  with_coupled("subsection mass scaling\n set factor = 4\nend\n",
               [&](explicit_mpm::Solver<2> &s) { dt4 = s.critical_time_step(); });
  EXPECT_NEAR(dt4 / dt1, 2.0, 1e-12);
}
