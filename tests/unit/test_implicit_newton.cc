// The grid-free pieces of the implicit step (formulations/implicit):
//  * Newmark in incremental-displacement form on a single-DoF oscillator:
//    the trapezoidal rule's period 2 atan(omega dt/2) and energy conservation,
//    the numerical damping of gamma > 1/2 against the spectral radius of the
//    scheme, the stability limit omega dt = 2 of central difference, Rayleigh
//    mass and stiffness damping against the exact decay of the envelope;
//  * the Newton driver on small nonlinear systems: quadratic order with the
//    exact tangent, linear order with a wrong one, line search against an
//    overshooting arctan residual, divergence, failures -> cut_back.
#include <talus/formulations/common/time_loop.h>
#include <talus/formulations/implicit/newmark.h>
#include <talus/formulations/implicit/newton.h>

#include <deal.II/lac/la_parallel_vector.h>

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <sstream>
#include <vector>

namespace
{
  using namespace talus;
  using namespace talus::implicit_mpm;

  constexpr double pi = 3.14159265358979323846;

  /// m u'' + c u' + k u = 0 with c = alpha_R m + beta_R k, advanced by the
  /// incremental form: the residual m a(du) + c v(du) + k (u + du) is linear in
  /// du, so one solve with the tangent m M_f + k K_f is exact.
  struct Oscillator
  {
    double  m = 2.0, k = 2.0 * 4 * pi * pi; // omega = 2 pi
    double  alpha_r = 0, beta_r = 0;
    double  u = 1.0, v = 0.0, a = 0.0;
    Newmark nm;

    Oscillator(const double gamma, const double beta, const double dt)
        : nm(gamma, beta, dt)
    {
      a = -k * u / m;
    }
    double
    omega() const
    {
      return std::sqrt(k / m);
    }
    double
    energy() const
    {
      return 0.5 * m * v * v + 0.5 * k * u * u;
    }
    void
    step()
    {
      const double c = alpha_r * m + beta_r * k;
      if (nm.implicit())
        {
          const auto   tf = nm.tangent_factors(alpha_r, beta_r);
          const double r0 = m * nm.acceleration(0.0, v, a) + c * nm.velocity(0.0, v, a) + k * u;
          const double du = -r0 / (tf.mass * m + tf.stiffness * k);
          const double an = nm.acceleration(du, v, a);
          v               = nm.velocity(du, v, a);
          a               = an;
          u += du;
        }
      else // central difference (c = 0 here)
        {
          u += nm.known_increment(v, a);
          const double an = -k * u / m;
          v               = nm.velocity_from_accelerations(v, a, an);
          a               = an;
        }
    }
  };

  TEST(ImplicitNewmark, ParametersAndCoefficients)
  {
    EXPECT_THROW(Newmark(0.4, 0.25), InputError);
    EXPECT_THROW(Newmark(1.1, 0.25), InputError);
    EXPECT_THROW(Newmark(0.5, -0.1), InputError);
    EXPECT_THROW(Newmark(0.5, 0.6), InputError);
    EXPECT_THROW(Newmark(0.5, 0.25, -1.0), InputError);
    EXPECT_TRUE(Newmark(0.5, 0.25).unconditionally_stable());
    EXPECT_TRUE(Newmark(0.6, 0.3025).unconditionally_stable());
    EXPECT_FALSE(Newmark(0.6, 0.25).unconditionally_stable());
    EXPECT_DOUBLE_EQ(Newmark(0.5, 0.0).critical_omega_dt(), 2.0);
    EXPECT_DOUBLE_EQ(Newmark(0.6, 0.25).critical_omega_dt(), 1.0 / std::sqrt(0.05));
    EXPECT_TRUE(std::isinf(Newmark(0.5, 0.25).critical_omega_dt()));

    const double dt = 0.01;
    Newmark      nm(0.5, 0.25, dt);
    EXPECT_DOUBLE_EQ(nm.mass_coefficient(), 4 / (dt * dt));
    EXPECT_DOUBLE_EQ(nm.damping_coefficient(), 2 / dt);
    EXPECT_DOUBLE_EQ(nm.tangent_factors(1.5, 0).mass, 4 / (dt * dt) + 1.5 * 2 / dt);
    EXPECT_DOUBLE_EQ(nm.tangent_factors(0, 0.1).stiffness, 1 + 0.1 * 2 / dt);
    // thesis predictor (note to Eq. 2.10-2.12): v = -v_n, a = -4 v_n/dt - a_n
    EXPECT_NEAR(nm.velocity(0.0, 3.0, 7.0), -3.0, 1e-12);
    EXPECT_NEAR(nm.acceleration(0.0, 3.0, 7.0), -4 * 3.0 / dt - 7.0, 1e-9);
    // Eq. 2.16
    EXPECT_DOUBLE_EQ(nm.point_velocity(1.0, 2.0, 4.0), 1.0 + dt / 2 * (2.0 + 4.0));

    // beta = 0 has no incremental form
    Newmark cd(0.5, 0.0, dt);
    EXPECT_FALSE(cd.implicit());
    EXPECT_THROW(cd.acceleration(0.0, 1.0, 1.0), InputError);
    EXPECT_THROW(cd.mass_coefficient(), InputError);
    EXPECT_DOUBLE_EQ(cd.known_increment(2.0, 3.0), dt * 2.0 + 0.5 * dt * dt * 3.0);
  }

  // The incremental forms reproduce the classical Newmark pair for any
  // (gamma, beta); the vector forms (deal.II vector) equal the scalar ones.
  TEST(ImplicitNewmark, IncrementalFormIsClassicalNewmark)
  {
    const double dt = 0.037;
    for (const auto &gb : std::vector<std::pair<double, double>>{{0.5, 0.25}, {0.6, 0.3025}, {0.9, 0.1}})
      {
        const Newmark nm(gb.first, gb.second, dt);
        const double  du = 0.31, v = -1.7, a = 4.2;
        const double  an = nm.acceleration(du, v, a), vn = nm.velocity(du, v, a);
        const double  g = gb.first, b = gb.second;
        EXPECT_NEAR(du, dt * v + dt * dt * ((0.5 - b) * a + b * an), 1e-13);
        EXPECT_NEAR(vn, v + dt * ((1 - g) * a + g * an), 1e-12);
        EXPECT_NEAR(vn, nm.velocity_from_accelerations(v, a, an), 1e-12);
        EXPECT_NEAR(du, nm.known_increment(v, a) + b * dt * dt * an, 1e-13);

        const unsigned int                                 n = 5;
        dealii::LinearAlgebra::distributed::Vector<double> dU(n), V(n), A(n), Vn(n), An(n), Vp(n), Ap(n);
        for (unsigned int i = 0; i < n; ++i)
          {
            dU[i] = 0.1 * i - 0.2;
            V[i]  = std::sin(i + 1.0);
            A[i]  = std::cos(3.0 * i);
          }
        nm.update(dU.locally_owned_size(), dU.begin(), V.begin(), A.begin(), Vn.begin(), An.begin());
        nm.predict(n, V, A, Vp, Ap);
        for (unsigned int i = 0; i < n; ++i)
          {
            EXPECT_NEAR(Vn[i], nm.velocity(double(dU[i]), double(V[i]), double(A[i])), 1e-12);
            EXPECT_NEAR(An[i], nm.acceleration(double(dU[i]), double(V[i]), double(A[i])), 1e-9);
            EXPECT_NEAR(Vp[i], nm.velocity(0.0, double(V[i]), double(A[i])), 1e-12);
            EXPECT_NEAR(Ap[i], nm.acceleration(0.0, double(V[i]), double(A[i])), 1e-9);
          }
        // in place: v, a overwritten by v^{n+1}, a^{n+1}
        auto Vi = V, Ai = A;
        nm.update(n, dU, Vi, Ai, Vi, Ai);
        for (unsigned int i = 0; i < n; ++i)
          {
            EXPECT_EQ(Vi[i], Vn[i]);
            EXPECT_EQ(Ai[i], An[i]);
          }
        std::vector<double> vp = {1.0, 2.0}, a_old = {3.0, -1.0}, a_new = {0.5, 0.25};
        nm.update_point_velocities(2, vp, a_old, a_new);
        EXPECT_NEAR(vp[0], 1.0 + dt * ((1 - g) * 3.0 + g * 0.5), 1e-15);
        EXPECT_NEAR(vp[1], 2.0 + dt * ((1 - g) * -1.0 + g * 0.25), 1e-15);
      }
  }

  // gamma = 1/2, beta = 1/4: per step the state (u, v) turns by
  // Omega dt = 2 atan(omega dt / 2) in the energy norm and keeps its length.
  TEST(ImplicitNewmark, TrapezoidalPeriodAndEnergy)
  {
    for (const double omega_dt : {0.05, 0.5, 10.0})
      {
        Oscillator   osc(0.5, 0.25, omega_dt / (2 * pi));
        const double w      = osc.omega();
        const double e0     = osc.energy();
        const auto   z      = [&] { return std::complex<double>(w * osc.u, osc.v); };
        double       turned = 0, max_drift = 0;
        const int    n = 1000;
        for (int i = 0; i < n; ++i)
          {
            const auto z0 = z();
            osc.step();
            turned -= std::arg(z() * std::conj(z0)); // z = w e^{-i omega t}: clockwise
            max_drift = std::max(max_drift, std::abs(osc.energy() - e0) / e0);
          }
        const double expected = 2 * std::atan(omega_dt / 2);
        const double period_h = 2 * pi * osc.nm.dt() * n / turned, period_closed = 2 * pi * osc.nm.dt() / expected;
        const double period_error = std::abs(period_h - period_closed) / period_closed;
        std::printf("  trapezoidal omega dt = %g: discrete period / closed form - 1 = %.2e "
                    "(elongation vs exact %.2e), max energy drift %.2e\n",
                    omega_dt, period_error, period_closed * w / (2 * pi) - 1, max_drift);
        EXPECT_LT(period_error, 1e-10);
        EXPECT_LT(max_drift, 1e-12);
      }
  }

  // gamma > 1/2 damps: |lambda|^2 = 1 - Omega^2 (gamma - 1/2)/(1 + beta Omega^2)
  // per step (product of the complex pair of the characteristic polynomial).
  TEST(ImplicitNewmark, NumericalDampingMatchesSpectralRadius)
  {
    const double gamma = 0.6, beta = (gamma + 0.5) * (gamma + 0.5) / 4, omega_dt = 0.5;
    Oscillator   osc(gamma, beta, omega_dt / (2 * pi));
    const double e0 = osc.energy();
    const int    n  = 1000;
    for (int i = 0; i < n; ++i)
      osc.step();
    const double rate     = std::log(osc.energy() / e0) / n;
    const double expected = std::log(1 - omega_dt * omega_dt * (gamma - 0.5) / (1 + beta * omega_dt * omega_dt));
    std::printf("  gamma = 0.6: energy decay per step %.6e, spectral radius^2 %.6e\n", rate, expected);
    EXPECT_LT(osc.energy(), 1e-8 * e0);
    EXPECT_NEAR(rate / expected, 1.0, 1e-2);
  }

  // gamma = 1/2, beta = 0: stable below omega dt = 2, growth above.
  TEST(ImplicitNewmark, CentralDifferenceStabilityLimit)
  {
    for (const double omega_dt : {1.95, 2.05})
      {
        Oscillator   osc(0.5, 0.0, omega_dt / (2 * pi));
        const double e0    = osc.energy();
        double       e_max = e0;
        for (int i = 0; i < 200 && std::isfinite(e_max); ++i)
          {
            osc.step();
            e_max = std::max(e_max, osc.energy());
          }
        std::printf("  central difference omega dt = %g: max energy / initial over 200 steps %.3e\n", omega_dt,
                    e_max / e0);
        if (omega_dt < osc.nm.critical_omega_dt())
          EXPECT_LE(e_max, 1.0001 * e0);
        else
          EXPECT_GT(e_max, 1e10 * e0);
      }
  }

  // Peaks of u decay as exp(-zeta omega t): zeta omega = alpha_R / 2 (mass
  // damping), beta_R omega^2 / 2 (stiffness damping).
  TEST(ImplicitNewmark, RayleighDampingDecayRate)
  {
    for (const bool mass : {true, false})
      {
        Oscillator   osc(0.5, 0.25, 1.0 / 200); // omega = 2 pi: 200 steps per period
        const double w = osc.omega();
        if (mass)
          osc.alpha_r = 0.2;
        else
          osc.beta_r = 0.2 / (w * w);
        const double        expected = mass ? osc.alpha_r / 2 : osc.beta_r * w * w / 2; // both 0.1
        std::vector<double> t_peak, log_peak;
        double              u_mm = osc.u, u_m = osc.u;
        osc.step();
        u_m = osc.u;
        for (int i = 2; i <= 2000; ++i)
          {
            osc.step();
            if (u_m > u_mm && u_m >= osc.u) // parabola through three samples
              {
                const double d = u_mm - 2 * u_m + osc.u, s = 0.5 * (u_mm - osc.u) / d;
                t_peak.push_back((i - 1 + s) * osc.nm.dt());
                log_peak.push_back(std::log(u_m - 0.25 * (u_mm - osc.u) * s));
              }
            u_mm = u_m;
            u_m  = osc.u;
          }
        ASSERT_GE(t_peak.size(), 8u);
        // least-squares slope of log(peak) over time
        double st = 0, sl = 0, stt = 0, stl = 0;
        for (std::size_t i = 0; i < t_peak.size(); ++i)
          {
            st += t_peak[i];
            sl += log_peak[i];
            stt += t_peak[i] * t_peak[i];
            stl += t_peak[i] * log_peak[i];
          }
        const double np = t_peak.size(), slope = (np * stl - st * sl) / (np * stt - st * st);
        std::printf("  Rayleigh %s damping: decay rate %.6f, exact %.6f (relative error %.2e, %zu peaks)\n",
                    mass ? "mass" : "stiffness", -slope, expected, std::abs(-slope / expected - 1), t_peak.size());
        EXPECT_NEAR(-slope / expected, 1.0, 2e-3);
      }
  }

  // ---------------------------------------------------------------- Newton

  /// Two hardening springs in series, f(e) = e + e^3, wall - 1 - 2, force F
  /// at DoF 2. The tangent can be scaled to make it wrong.
  struct Springs
  {
    double              F = 2.0, tangent_scale = 1.0;
    std::vector<double> u = {0, 0}, r = {0, 0}, du = {0, 0};
    double              K[2][2]    = {{0, 0}, {0, 0}};
    unsigned int        assemblies = 0, tangents = 0;

    static double
    f(const double e)
    {
      return e + e * e * e;
    }
    static double
    df(const double e)
    {
      return 1 + 3 * e * e;
    }

    NewtonProblem
    problem()
    {
      NewtonProblem p;
      p.assemble = [this](const bool with_tangent) {
        ++assemblies;
        const double e1 = u[0], e2 = u[1] - u[0];
        r = {f(e1) - f(e2), f(e2) - F};
        if (with_tangent)
          {
            ++tangents;
            const double a = tangent_scale * df(e1), b = tangent_scale * df(e2);
            K[0][0] = a + b;
            K[0][1] = K[1][0] = -b;
            K[1][1]           = b;
          }
        return std::hypot(r[0], r[1]);
      };
      p.solve = [this] {
        const double det = K[0][0] * K[1][1] - K[0][1] * K[1][0];
        du[0]            = (-r[0] * K[1][1] + r[1] * K[0][1]) / det;
        du[1]            = (-K[0][0] * r[1] + K[1][0] * r[0]) / det;
        return std::hypot(du[0], du[1]);
      };
      p.apply = [this](const double alpha) {
        u[0] += alpha * du[0];
        u[1] += alpha * du[1];
      };
      p.step_increment_norm = [this] { return std::hypot(u[0], u[1]); };
      return p;
    }
  };

  void
  print(const char *name, const NewtonResult &r)
  {
    std::printf("  %s: %s, %u iterations, order %.3f; |r|:", name, r.message.c_str(), r.iterations, r.observed_order);
    for (const auto &h : r.history)
      std::printf(" %.2e", h.residual);
    std::printf("\n");
  }

  TEST(ImplicitNewton, SettingsValidation)
  {
    NewtonSettings s;
    EXPECT_NO_THROW(s.validate());
    EXPECT_EQ(s.max_iterations, 20u);
    EXPECT_EQ(s.residual_relative, 1e-4);
    EXPECT_EQ(s.residual_absolute, 1e-9);
    EXPECT_EQ(s.increment_relative, 1e-4);
    EXPECT_EQ(s.increment_absolute, 1e-9);
    EXPECT_EQ(s.criterion, NewtonCriterion::residual);
    for (const auto c : {NewtonCriterion::residual, NewtonCriterion::increment, NewtonCriterion::residual_and_increment,
                         NewtonCriterion::residual_or_increment})
      EXPECT_EQ(parse_newton_criterion(to_string(c)), c);
    EXPECT_THROW(parse_newton_criterion("residual_and_increment"), InputError);
    s.max_iterations = 0;
    EXPECT_THROW(NewtonSolver{s}, InputError);
    s                   = NewtonSettings();
    s.divergence_factor = 0.5;
    EXPECT_THROW(NewtonSolver{s}, InputError);
    s        = NewtonSettings();
    s.armijo = 1.0;
    EXPECT_THROW(NewtonSolver{s}, InputError);
  }

  TEST(ImplicitNewton, ExactTangentIsQuadraticWrongTangentLinear)
  {
    Springs    exact;
    const auto re = NewtonSolver().solve(exact.problem());
    print("exact tangent", re);
    ASSERT_TRUE(re.converged);
    EXPECT_EQ(re.outcome(), StepOutcome::done);
    EXPECT_LE(re.iterations, 6u);
    EXPECT_GE(re.observed_order, 1.8);
    EXPECT_LE(re.history.back().residual, 1e-4 * re.history.front().residual);
    EXPECT_EQ(re.history.size(), re.iterations + 1);

    Springs wrong;
    wrong.tangent_scale = 1.3;
    const auto rw       = NewtonSolver().solve(wrong.problem());
    print("tangent x 1.3", rw);
    ASSERT_TRUE(rw.converged);
    EXPECT_GT(rw.iterations, re.iterations + 2);
    EXPECT_NEAR(rw.observed_order, 1.0, 0.2);
    // asymptotic contraction of a tangent scaled by s: 1 - 1/s
    const auto &h = rw.history;
    EXPECT_NEAR(h.back().residual / h[h.size() - 2].residual, 1 - 1 / 1.3, 0.02);
    // both reach the same solution
    EXPECT_NEAR(exact.u[1], wrong.u[1], 1e-3);
    EXPECT_NEAR(Springs::f(exact.u[1] - exact.u[0]), exact.F, 1e-3);
  }

  // Tighter tolerances, other criteria.
  TEST(ImplicitNewton, Criteria)
  {
    NewtonSettings s;
    s.residual_relative = 1e-12;
    s.residual_absolute = 0;
    Springs    tight;
    const auto rt = NewtonSolver(s).solve(tight.problem());
    print("exact tangent, rel 1e-12", rt);
    ASSERT_TRUE(rt.converged);
    EXPECT_GE(rt.observed_order, 1.8); // the exact zero at the end is skipped
    EXPECT_TRUE(std::isnan(observed_order({1.0, 0.1})));
    EXPECT_NEAR(observed_order({1e-1, 1e-2, 1e-4, 0.0}), 2.0, 1e-12);
    EXPECT_NEAR(observed_order({1.0, 1e-1, 1e-2}), 1.0, 1e-12);

    // increment criterion: relative to |Du| of the step
    s           = NewtonSettings();
    s.criterion = NewtonCriterion::increment;
    Springs    inc;
    const auto ri = NewtonSolver(s).solve(inc.problem());
    ASSERT_TRUE(ri.converged);
    EXPECT_LE(ri.history.back().increment, 1e-4 * ri.history.back().step_increment);
    EXPECT_GT(ri.history[ri.iterations - 1].increment, 1e-4 * ri.history[ri.iterations - 1].step_increment);

    // without step_increment_norm the first increment is the reference; with
    // it, its value is (a huge |Du| passes the test at once)
    s.criterion = NewtonCriterion::increment;
    Springs       first, huge;
    NewtonProblem pf = first.problem(), ph = huge.problem();
    pf.step_increment_norm = nullptr;
    ph.step_increment_norm = [] { return 1e8; };
    const auto rf = NewtonSolver(s).solve(pf), rh = NewtonSolver(s).solve(ph);
    ASSERT_TRUE(rf.converged && rh.converged);
    EXPECT_LE(rf.history.back().increment, 1e-4 * rf.history[1].increment);
    EXPECT_TRUE(std::isnan(rf.history.back().step_increment));
    EXPECT_EQ(rh.iterations, 1u);

    // "and" needs at least as many iterations as either test alone
    s.criterion = NewtonCriterion::residual_and_increment;
    Springs    both;
    const auto rb = NewtonSolver(s).solve(both.problem());
    s.criterion   = NewtonCriterion::residual;
    Springs    res;
    const auto rr = NewtonSolver(s).solve(res.problem());
    s.criterion   = NewtonCriterion::residual_or_increment;
    Springs    either;
    const auto ro = NewtonSolver(s).solve(either.problem());
    std::printf("  iterations: residual %u, increment %u, and %u, or %u\n", rr.iterations, ri.iterations, rb.iterations,
                ro.iterations);
    ASSERT_TRUE(rb.converged && rr.converged && ro.converged);
    EXPECT_EQ(rb.iterations, std::max(rr.iterations, ri.iterations));
    EXPECT_EQ(ro.iterations, std::min(rr.iterations, ri.iterations));

    // a linear problem: one solve under the residual test
    Springs linear;
    linear.tangent_scale = 1.0;
    NewtonProblem p      = linear.problem();
    p.assemble           = [&](const bool) {
      linear.r       = {2 * linear.u[0] - linear.u[1], linear.u[1] - linear.u[0] - 1.0};
      linear.K[0][0] = 2;
      linear.K[0][1] = linear.K[1][0] = -1;
      linear.K[1][1]                  = 1;
      return std::hypot(linear.r[0], linear.r[1]);
    };
    const auto rl = NewtonSolver().solve(p);
    EXPECT_TRUE(rl.converged);
    EXPECT_EQ(rl.iterations, 1u);
    EXPECT_TRUE(std::isnan(rl.observed_order)); // two residuals only

    // a step that starts in equilibrium needs no solve
    Springs rest;
    rest.F        = 0;
    const auto r0 = NewtonSolver().solve(rest.problem());
    EXPECT_TRUE(r0.converged);
    EXPECT_EQ(r0.iterations, 0u);
    EXPECT_EQ(r0.outcome(), StepOutcome::done);

    // residual_reference: relative to a force scale when r_0 is tiny (a
    // wrong tangent makes the iterations countable)
    s                   = NewtonSettings();
    s.residual_absolute = 0;
    Springs tiny, tiny_ref;
    tiny.F = tiny_ref.F = 1e-6;
    tiny.tangent_scale = tiny_ref.tangent_scale = 1.3;
    NewtonProblem pt                            = tiny_ref.problem();
    pt.residual_reference                       = [] { return 1.0; };
    const auto rref                             = NewtonSolver(s).solve(pt);
    const auto rno                              = NewtonSolver(s).solve(tiny.problem());
    std::printf("  r_0 = 1e-6: %u iterations relative to r_0, %u relative to a reference 1\n", rno.iterations,
                rref.iterations);
    EXPECT_TRUE(rref.converged && rno.converged);
    EXPECT_EQ(rref.iterations, 1u);
    EXPECT_GE(rno.iterations, 5u);
  }

  /// r(x) = atan(x): the full Newton step overshoots for |x0| > 1.39 and the
  /// iterates run away; backtracking keeps them.
  struct Arctan
  {
    double x = 2.0, dx = 0, r = 0, drdx = 1;
    /// x at each solve; where the tangent in use was assembled
    std::vector<double> x_at_solve;
    double              x_tangent      = 0;
    unsigned int        stale_tangents = 0;
    NewtonProblem
    problem()
    {
      NewtonProblem p;
      p.assemble = [this](const bool with_tangent) {
        r = std::atan(x);
        if (with_tangent)
          {
            drdx      = 1 / (1 + x * x);
            x_tangent = x;
          }
        return std::abs(r);
      };
      p.solve = [this] {
        stale_tangents += (x_tangent != x);
        x_at_solve.push_back(x);
        dx = -r / drdx;
        return std::abs(dx);
      };
      p.apply = [this](const double alpha) { x += alpha * dx; };
      p.slope = [this] { return dx * r; }; // d/dalpha of E = x atan x - ln(1 + x^2) / 2
      return p;
    }
  };

  TEST(ImplicitNewton, LineSearchRescuesOvershoot)
  {
    Arctan     plain;
    const auto rp = NewtonSolver().solve(plain.problem());
    print("arctan, no line search", rp);
    EXPECT_FALSE(rp.converged);
    EXPECT_EQ(rp.outcome(), StepOutcome::cut_back);
    // the residual stays below pi/2; the iterates run away: |du_4| > 1e3 |du_1|
    EXPECT_EQ(rp.status, NewtonStatus::increment_diverged) << to_string(rp.status);
    EXPECT_NE(rp.message.find("increment diverged"), std::string::npos);
    EXPECT_EQ(rp.iterations, 4u); // stopped by divergence detection, not by the limit

    NewtonSettings s;
    s.line_search       = LineSearch::residual;
    s.residual_relative = 1e-10;
    Arctan     ls;
    const auto rl = NewtonSolver(s).solve(ls.problem());
    print("arctan, line search", rl);
    ASSERT_TRUE(rl.converged);
    EXPECT_LT(std::abs(ls.x), 1e-9);
    EXPECT_GT(rl.history[1].halvings, 0u);
    EXPECT_LT(rl.history[1].alpha, 1.0);
    EXPECT_EQ(rl.history.back().alpha, 1.0); // full steps near the root
    EXPECT_GE(rl.observed_order, 1.8);       // atan has r'' = 0 at the root: even cubic
    // every solve used the tangent of its own iterate (re-assembled after a
    // halved trial), and the history's increment is the step actually taken
    EXPECT_EQ(ls.stale_tangents, 0u);
    ls.x_at_solve.push_back(ls.x);
    ASSERT_EQ(ls.x_at_solve.size(), rl.iterations + 1);
    for (unsigned int k = 1; k <= rl.iterations; ++k)
      EXPECT_NEAR(std::abs(ls.x_at_solve[k] - ls.x_at_solve[k - 1]), rl.history[k].increment,
                  1e-14 * (1 + rl.history[k].increment));
  }

  TEST(ImplicitNewton, EnergyLineSearchRescuesOvershoot)
  {
    // the energy E(x) = x atan x - ln(1 + x^2) / 2 is convex with its minimum at
    // the root: the full step from x = 2 overshoots its minimum along dx
    NewtonSettings s;
    s.line_search       = LineSearch::energy;
    s.residual_relative = 1e-10;
    Arctan     ls;
    const auto rl = NewtonSolver(s).solve(ls.problem());
    print("arctan, energy line search", rl);
    ASSERT_TRUE(rl.converged);
    EXPECT_LT(std::abs(ls.x), 1e-9);
    EXPECT_GT(rl.history[1].halvings, 0u);
    EXPECT_LT(rl.history[1].alpha, 1.0);
    EXPECT_GT(rl.history[1].alpha, 0.0);
    EXPECT_EQ(rl.history.back().alpha, 1.0); // full steps near the root
    EXPECT_GE(rl.observed_order, 1.8);
    EXPECT_EQ(ls.stale_tangents, 0u);
    // without the slope the energy search is refused
    NewtonProblem p = ls.problem();
    p.slope         = nullptr;
    EXPECT_THROW(NewtonSolver(s).solve(p), std::exception);
  }

  TEST(ImplicitNewton, FailuresMapToCutBack)
  {
    // iteration limit
    NewtonSettings s;
    s.max_iterations = 3;
    Springs wrong;
    wrong.tangent_scale = 1.3;
    const auto rm       = NewtonSolver(s).solve(wrong.problem());
    EXPECT_FALSE(rm.converged);
    EXPECT_EQ(rm.status, NewtonStatus::max_iterations);
    EXPECT_EQ(rm.iterations, 3u);
    EXPECT_EQ(rm.history.size(), 4u);
    EXPECT_EQ(rm.outcome(), StepOutcome::cut_back);
    for (const auto &h : rm.history)
      EXPECT_TRUE(std::isfinite(h.residual));

    // residual growth by the factor over the window
    Springs grow;
    grow.K[0][0] = grow.K[1][1] = 1; // the assembly below sets no tangent
    NewtonProblem p             = grow.problem();
    p.assemble                  = [&](const bool) { return std::pow(10.0, 2.0 * grow.assemblies++); };
    const auto rg               = NewtonSolver().solve(p);
    EXPECT_EQ(rg.status, NewtonStatus::residual_diverged) << rg.message;
    EXPECT_EQ(rg.iterations, 3u); // 1e6 > 1e3 * 1e0 at k = 3
    EXPECT_EQ(rg.outcome(), StepOutcome::cut_back);

    // NaN from the assembly
    Springs nan;
    nan.K[0][0] = nan.K[1][1] = 1;
    p                         = nan.problem();
    p.assemble                = [&](const bool) { return nan.assemblies++ ? std::nan("") : 1.0; };
    const auto rn             = NewtonSolver().solve(p);
    EXPECT_EQ(rn.status, NewtonStatus::non_finite);
    EXPECT_EQ(rn.iterations, 1u);
    EXPECT_EQ(rn.outcome(), StepOutcome::cut_back);
    p.assemble     = [](const bool) { return std::nan(""); }; // already at the predictor
    const auto rn0 = NewtonSolver().solve(p);
    EXPECT_EQ(rn0.status, NewtonStatus::non_finite);
    EXPECT_EQ(rn0.iterations, 0u);
    EXPECT_EQ(rn0.outcome(), StepOutcome::cut_back);

    // a solve that returns NaN leaves the iterate alone
    Springs      nan_solve;
    unsigned int applied = 0;
    p                    = nan_solve.problem();
    p.solve              = [] { return std::nan(""); };
    p.apply              = [&](const double) { ++applied; };
    const auto rs        = NewtonSolver().solve(p);
    EXPECT_EQ(rs.status, NewtonStatus::non_finite);
    EXPECT_NE(rs.message.find("increment"), std::string::npos);
    EXPECT_EQ(applied, 0u);
    EXPECT_EQ(rs.outcome(), StepOutcome::cut_back);

    // a linear solver that gives up
    Springs fail;
    p             = fail.problem();
    p.solve       = []() -> double { throw NewtonFailure("linear solver: no convergence in 1000 iterations"); };
    const auto rf = NewtonSolver().solve(p);
    EXPECT_EQ(rf.status, NewtonStatus::callable_failed);
    EXPECT_NE(rf.message.find("no convergence"), std::string::npos);
    EXPECT_EQ(rf.outcome(), StepOutcome::cut_back);

    // with line search, a rejected full step (e.g. inverted point) is halved
    Springs inverted;
    p               = inverted.problem();
    const auto base = p.assemble;
    p.assemble      = [&](const bool t) {
      if (inverted.u[1] > 3.0) // pretend det F <= 0 beyond this (the full first step reaches 4)
        throw NewtonFailure("det F <= 0");
      return base(t);
    };
    s             = NewtonSettings();
    s.line_search = LineSearch::residual;
    const auto ri = NewtonSolver(s).solve(p);
    print("rejected full step, line search", ri);
    EXPECT_TRUE(ri.converged) << ri.message;
    EXPECT_GT(ri.history[1].halvings, 0u);

    // other exceptions are bugs: they propagate
    Springs bug;
    p       = bug.problem();
    p.solve = []() -> double { throw std::logic_error("bug"); };
    EXPECT_THROW(NewtonSolver().solve(p), std::logic_error);
  }

  // Newmark + Newton on a hardening (Duffing) oscillator m u'' + k u + c u^3 = 0:
  // every step converges in a few iterations and the trapezoidal rule keeps
  // the energy to O(dt^2) (exactly only for linear systems).
  TEST(ImplicitNewton, NewmarkDuffingOscillator)
  {
    const double  m = 1.0, k = 4 * pi * pi, c = 400.0, dt = 0.005;
    Newmark       nm(0.5, 0.25, dt);
    double        u = 1.0, v = 0.0, a = -(k * u + c * u * u * u) / m;
    const auto    energy = [&] { return 0.5 * m * v * v + 0.5 * k * u * u + 0.25 * c * u * u * u * u; };
    const double  e0     = energy();
    double        du = 0, ddu = 0, r = 0, kt = 1, max_drift = 0;
    unsigned int  max_it = 0, total_it = 0;
    NewtonProblem p;
    p.assemble = [&](const bool) {
      const double x = u + du;
      r              = m * nm.acceleration(du, v, a) + k * x + c * x * x * x;
      kt             = m * nm.mass_coefficient() + k + 3 * c * x * x;
      return std::abs(r);
    };
    p.solve = [&] {
      ddu = -r / kt;
      return std::abs(ddu);
    };
    p.apply               = [&](const double alpha) { du += alpha * ddu; };
    p.step_increment_norm = [&] { return std::abs(du); };
    NewtonSettings s;
    s.residual_relative = 1e-8;
    s.residual_absolute = 1e-12;
    const NewtonSolver newton(s);
    for (int n = 0; n < 1000; ++n)
      {
        du            = 0;
        const auto rs = newton.solve(p);
        ASSERT_TRUE(rs.converged) << "step " << n << ": " << rs.message;
        max_it = std::max(max_it, rs.iterations);
        total_it += rs.iterations;
        const double an = nm.acceleration(du, v, a);
        v               = nm.velocity(du, v, a);
        a               = an;
        u += du;
        max_drift = std::max(max_drift, std::abs(energy() - e0) / e0);
      }
    std::printf("  Duffing: max %u, mean %.2f Newton iterations per step, max energy drift %.2e\n", max_it,
                total_it / 1000.0, max_drift);
    EXPECT_LE(max_it, 3u);
    EXPECT_LT(max_drift, 1e-2);
    EXPECT_GT(max_drift, 1e-6); // nonlinear: not conserved to round-off
  }

  /// A stand-in implicit formulation for the cut-back contract: the state x
  /// follows x' = 1; each step solves atan(s (z - x - h)) = 0 by Newton from
  /// the predictor z = x, which converges only when s h < 1.39. The committed
  /// state x changes only after convergence (as point history will).
  struct ArctanStep : Formulation
  {
    double       x = 0, s = 10;
    unsigned int newton_failures = 0;
    std::string  last_message;

    std::string
    tool_name() const override
    {
      return "talus-test";
    }
    void
    describe(std::ostream &) const override
    {
    }
    double
    begin_stage(const unsigned int, const bool, const bool) override
    {
      return 1e9;
    }
    StepOutcome
    advance_by(const double h) override
    {
      double        z = x, dz = 0, r = 0, drdz = 1;
      NewtonProblem p;
      p.assemble = [&](const bool) {
        r    = std::atan(s * (z - x - h));
        drdz = s / (1 + s * s * (z - x - h) * (z - x - h));
        return std::abs(r);
      };
      p.solve = [&] {
        dz = -r / drdz;
        return std::abs(dz);
      };
      p.apply = [&](const double alpha) { z += alpha * dz; };
      NewtonSettings ns;
      ns.residual_relative = 1e-12;
      const auto res       = NewtonSolver(ns).solve(p);
      if (res.converged)
        x = z;
      else
        {
          ++newton_failures;
          last_message = res.message;
        }
      return res.outcome();
    }
    void
    check_stability() const override
    {
      if (!std::isfinite(x))
        throw InstabilityError("x is not finite");
    }
    std::vector<std::string>
    series_columns() const override
    {
      return {"x"};
    }
    std::vector<double>
    series_values(const bool) override
    {
      return {x};
    }
    void
    write_vtu(const unsigned int) override
    {
    }
    std::string
    write_checkpoint() override
    {
      return "";
    }
    void
    summary(const LoopTimings &) override
    {
    }
  };

  TEST(ImplicitNewton, FailedNewtonCutsBackInTheTimeLoop)
  {
    ArctanStep f;
    f.dt = 0.5; // s h: 5 and 2.5 fail, 1.25 converges
    LoopSettings ls;
    ls.progress = false;
    TimeLoop(f, ls, MPI_COMM_SELF).advance_steps(4);
    std::printf("  cut-backs: t = %g after 4 steps, %u cut-backs; a failure: %s\n", f.time, f.cut_backs,
                f.last_message.c_str());
    EXPECT_NEAR(f.time, 4 * 0.125, 1e-15);
    EXPECT_EQ(f.cut_backs, 8u);
    EXPECT_EQ(f.newton_failures, 8u);
    EXPECT_NEAR(f.x, f.time, 1e-12); // failed attempts left no trace
    EXPECT_FALSE(f.last_message.empty());

    // a step that never converges: the loop's cut-back limit ends the run
    ArctanStep never;
    never.dt = 0.5;
    never.s  = 1e6; // needs h < 1.4e-6: more than 6 halvings
    EXPECT_THROW(TimeLoop(never, ls, MPI_COMM_SELF).advance_steps(1), InstabilityError);
    EXPECT_EQ(never.x, 0.0);
    EXPECT_EQ(never.newton_failures, ls.max_cut_backs + 1);
  }
} // namespace
