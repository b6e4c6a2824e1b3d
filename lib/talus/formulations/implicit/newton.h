// talus — a Newton-Raphson driver for the implicit family that knows nothing
// about the linear algebra: the formulation hands it callables that assemble,
// solve and update its own (distributed) vectors. The driver owns only the
// control: convergence test, backtracking line search, divergence detection,
// the per-iteration history and the observed order of convergence. A Newton
// that does not converge is a result (StepOutcome::cut_back), never a crash.
//
// Header-only (the implicit family has no library yet; the unit test links
// talus_core only). No explicit-family headers may be included here.
#pragma once

#include <talus/base/errors.h>
#include <talus/formulations/common/formulation.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace talus::implicit_mpm
{
  /// Thrown by a callable for a failure the step can recover from by a
  /// smaller step: linear solver not converged (catch SolverControl::
  /// NoConvergence and rethrow as this), inverted point (det F <= 0),
  /// constitutive return that failed. The driver reports it as not converged
  /// (status callable_failed); every other exception propagates.
  class NewtonFailure : public std::runtime_error
  {
  public:
    explicit NewtonFailure(const std::string &what)
        : std::runtime_error(what)
    {
    }
  };

  /// Which tests must pass for convergence.
  enum class NewtonCriterion
  {
    residual,               ///< residual test only (default, as Kratos MPM's residual_criterion)
    increment,              ///< increment test only
    residual_and_increment, ///< both
    residual_or_increment   ///< either
  };

  /// .prm spelling: "residual", "increment", "residual and increment",
  /// "residual or increment".
  inline std::string
  to_string(const NewtonCriterion c)
  {
    switch (c)
      {
        case NewtonCriterion::residual:
          return "residual";
        case NewtonCriterion::increment:
          return "increment";
        case NewtonCriterion::residual_and_increment:
          return "residual and increment";
        case NewtonCriterion::residual_or_increment:
          return "residual or increment";
      }
    return "unknown";
  }

  /// Inverse of to_string(NewtonCriterion); InputError names the allowed values.
  inline NewtonCriterion
  parse_newton_criterion(const std::string &s)
  {
    for (const auto c : {NewtonCriterion::residual, NewtonCriterion::increment, NewtonCriterion::residual_and_increment,
                         NewtonCriterion::residual_or_increment})
      if (s == to_string(c))
        return c;
    throw InputError("Newton convergence criterion '" + s +
                     "': allowed are residual | increment | residual and increment | residual or increment");
  }

  /// The line search of the driver ('newton/line search').
  enum class LineSearch
  {
    none,
    residual, ///< backtracking on the residual norm (Armijo)
    energy    ///< regula falsi on the directional derivative du . r(alpha)
  };

  /// Settings of the driver. Defaults: the Kratos MPM inputs quoted in the
  /// seed001 notes §1.9 (the thesis gives none).
  struct NewtonSettings
  {
    unsigned int max_iterations = 20; ///< linear solves per step

    /// Residual test at iterate k: r_k <= max(residual_relative * r_ref,
    /// residual_absolute), r_ref = max(r_0, reference) where r_0 is the
    /// residual norm at the predictor (before the first solve of the step)
    /// and `reference` the optional NewtonProblem::residual_reference().
    double residual_relative = 1e-4;
    double residual_absolute = 1e-9;
    /// Increment test at iteration k: |alpha_k du_k| <= max(increment_relative
    /// * |Du|, increment_absolute), Du the accumulated displacement increment
    /// of the step after iteration k (NewtonProblem::step_increment_norm; when
    /// absent, the norm of the first increment of the step stands in for it).
    double          increment_relative = 1e-4;
    double          increment_absolute = 1e-9;
    NewtonCriterion criterion          = NewtonCriterion::residual;

    /// Line search along the Newton increment du (docs/implicit.md, "Newton
    /// driver"):
    ///  - residual: backtracking on the residual norm: accept the step length
    ///    alpha (1, 1/2, 1/4, ...) once r(alpha) <= (1 - armijo * alpha) r_prev,
    ///    at most line_search_max_halvings halvings; when none passes, the
    ///    smallest step is kept (the divergence tests then judge);
    ///  - energy: the directional derivative of the energy s(alpha) = du .
    ///    r(u + alpha du) (NewtonProblem::slope); the full step is kept unless it
    ///    overshoots the energy's minimum along du (s(1) > 0 and |s(1)| >
    ///    energy_tolerance |s(0)|); then regula falsi on s in (0, 1), at most
    ///    line_search_max_halvings trials, alpha >= 1/10 of the bracket. The
    ///    residual norm may grow on the way to a solution of a geometrically
    ///    non-linear problem; the energy does not.
    LineSearch   line_search              = LineSearch::none;
    unsigned int line_search_max_halvings = 6;
    double       armijo                   = 1e-4;
    double       energy_tolerance         = 0.5;

    /// Divergence: r_k > divergence_factor * r_{k-w} or |du_k| >
    /// divergence_factor * |du_{k-w}| with w = divergence_window. 0 disables.
    /// Non-finite norms always stop the iteration.
    double       divergence_factor = 1e3;
    unsigned int divergence_window = 3;

    /// Throws InputError naming the entry.
    void
    validate() const
    {
      const std::string w = "Newton settings";
      require(max_iterations >= 1, w, "max iterations must be at least 1");
      require(residual_relative >= 0 && residual_absolute >= 0 && increment_relative >= 0 && increment_absolute >= 0, w,
              "tolerances must be non-negative");
      require(residual_relative > 0 || residual_absolute > 0 || criterion == NewtonCriterion::increment, w,
              "the residual test has no positive tolerance");
      require(increment_relative > 0 || increment_absolute > 0 || criterion == NewtonCriterion::residual, w,
              "the increment test has no positive tolerance");
      require(armijo >= 0 && armijo < 1, w, "the Armijo constant must lie in [0, 1)");
      require(energy_tolerance > 0 && energy_tolerance < 1, w, "the energy tolerance must lie in (0, 1)");
      require(divergence_factor == 0 || divergence_factor > 1, w, "the divergence factor must be 0 (off) or > 1");
      require(divergence_window >= 1, w, "the divergence window must be at least 1");
    }
  };

  /// What the formulation supplies. Call order per iteration: solve(),
  /// apply(alpha) (possibly several times with line search), assemble().
  struct NewtonProblem
  {
    /// Assemble the residual (and, if `with_tangent`, the tangent) at the
    /// current iterate; return the residual norm. Called once before the first
    /// solve (at the predictor). Line-search trials ask for no tangent; if such
    /// a trial is accepted and the iteration goes on, the driver calls again
    /// with the tangent at the same iterate.
    std::function<double(bool with_tangent)> assemble;
    /// Solve tangent * du = -residual; keep du; return |du|.
    std::function<double()> solve;
    /// Add alpha * du to the iterate (and update everything that depends on
    /// it: v, a by Newmark, grid positions). The line search steps back with a
    /// negative alpha (1 -> 1/2: apply(-1/2)).
    std::function<void(double alpha)> apply;
    /// Optional: |Du|, the accumulated increment of the step at the iterate.
    std::function<double()> step_increment_norm;
    /// du . r at the current iterate, du the last solve's increment and r the
    /// residual of the last assembly (a global sum): the derivative of the
    /// energy along du. Required by LineSearch::energy.
    std::function<double()> slope;
    /// Optional: a force scale of the step (e.g. |f_ext| + |f_inertia|) so that
    /// a step starting in equilibrium to round-off is not judged relative to
    /// its round-off residual. Called once, after the first assembly.
    std::function<double()> residual_reference;
  };

  enum class NewtonStatus
  {
    converged,
    max_iterations,     ///< not converged within max_iterations
    non_finite,         ///< a residual or increment norm was NaN or inf
    residual_diverged,  ///< residual grew by divergence_factor over the window
    increment_diverged, ///< increment grew by divergence_factor over the window
    callable_failed     ///< a callable threw NewtonFailure
  };

  inline const char *
  to_string(const NewtonStatus s)
  {
    switch (s)
      {
        case NewtonStatus::converged:
          return "converged";
        case NewtonStatus::max_iterations:
          return "max iterations reached";
        case NewtonStatus::non_finite:
          return "non-finite norm";
        case NewtonStatus::residual_diverged:
          return "residual diverged";
        case NewtonStatus::increment_diverged:
          return "increment diverged";
        case NewtonStatus::callable_failed:
          return "callable failed";
      }
    return "unknown";
  }

  /// One row of the history. Row 0 is the predictor (increment 0, alpha 0).
  struct NewtonIteration
  {
    double       residual       = 0; ///< r_k at the accepted iterate
    double       increment      = 0; ///< |alpha_k du_k|
    double       step_increment = 0; ///< |Du| after iteration k (NaN if not supplied)
    double       alpha          = 0; ///< accepted step length
    unsigned int halvings       = 0; ///< line-search halvings in this iteration
  };

  struct NewtonResult
  {
    bool                         converged = false;
    NewtonStatus                 status    = NewtonStatus::max_iterations;
    std::string                  message;        ///< why it stopped, with numbers
    unsigned int                 iterations = 0; ///< linear solves done
    std::vector<NewtonIteration> history;
    /// Order p from the last three positive residuals of the history (see
    /// observed_order()); NaN with fewer than three.
    double observed_order = std::numeric_limits<double>::quiet_NaN();

    /// The TimeLoop contract: not converged -> retry with half the step.
    StepOutcome
    outcome() const
    {
      return converged ? StepOutcome::done : StepOutcome::cut_back;
    }
  };

  /// Order estimate p from the last three positive entries of a sequence of
  /// residual norms (r_{k+1} ~ C r_k^p): p = log(r_k/r_{k-1}) / log(r_{k-1}/r_{k-2}).
  /// An exact zero (a linear problem solved exactly) has no order and is
  /// skipped; a residual at round-off level lowers the estimate. NaN with fewer
  /// than three positive entries.
  inline double
  observed_order(const std::vector<double> &r)
  {
    std::vector<double> pos;
    for (const double x : r)
      if (x > 0 && std::isfinite(x))
        pos.push_back(x);
    if (pos.size() < 3)
      return std::numeric_limits<double>::quiet_NaN();
    const double r0 = pos[pos.size() - 3], r1 = pos[pos.size() - 2], r2 = pos[pos.size() - 1];
    if (r0 == r1)
      return std::numeric_limits<double>::quiet_NaN();
    return std::log(r2 / r1) / std::log(r1 / r0);
  }

  class NewtonSolver
  {
  public:
    explicit NewtonSolver(const NewtonSettings &s = NewtonSettings())
        : settings_(s)
    {
      settings_.validate();
    }

    const NewtonSettings &
    settings() const
    {
      return settings_;
    }

    /// Iterate from the caller's current iterate (the predictor).
    NewtonResult
    solve(const NewtonProblem &p) const
    {
      require(bool(p.assemble) && bool(p.solve) && bool(p.apply), "Newton", "assemble, solve and apply are required");
      require(settings_.line_search != LineSearch::energy || bool(p.slope), "Newton",
              "the energy line search needs the slope du . r");
      NewtonResult res;
      try
        {
          iterate(p, res);
        }
      catch (const NewtonFailure &e)
        {
          finish(res, NewtonStatus::callable_failed, std::string("callable failed: ") + e.what());
        }
      std::vector<double> r;
      for (const auto &h : res.history)
        r.push_back(h.residual);
      res.observed_order = observed_order(r);
      return res;
    }

  private:
    static void
    finish(NewtonResult &res, const NewtonStatus s, const std::string &message)
    {
      res.status    = s;
      res.converged = (s == NewtonStatus::converged);
      res.message   = message;
    }

    void
    iterate(const NewtonProblem &p, NewtonResult &res) const
    {
      const NewtonSettings &s  = settings_;
      const double          r0 = p.assemble(true);
      res.history.push_back({r0, 0, 0, 0, 0});
      if (!std::isfinite(r0))
        return finish(res, NewtonStatus::non_finite, "non-finite residual at the predictor");
      if (r0 <= s.residual_absolute)
        {
          std::ostringstream m;
          m << "converged at the predictor: |r_0| = " << r0 << " <= " << s.residual_absolute;
          return finish(res, NewtonStatus::converged, m.str());
        }
      double r_ref = r0;
      if (p.residual_reference)
        r_ref = std::max(r_ref, p.residual_reference());
      const double nan = std::numeric_limits<double>::quiet_NaN();

      double r_prev = r0, first_increment = 0;
      bool   have_tangent = true;
      for (unsigned int k = 1; k <= s.max_iterations; ++k)
        {
          if (!have_tangent)
            {
              p.assemble(true); // same iterate: only the tangent is new
              have_tangent = true;
            }
          const double du = p.solve();
          res.iterations  = k;
          if (!std::isfinite(du))
            {
              res.history.push_back({nan, du, nan, 0, 0});
              std::ostringstream m;
              m << "non-finite increment norm at iteration " << k << " (failed solve or singular tangent)";
              return finish(res, NewtonStatus::non_finite, m.str());
            }

          // full step, then backtrack on the residual norm
          double       alpha    = 1;
          unsigned int halvings = 0;
          // with line search, a trial the callables reject (e.g. an inverted
          // point at the full step) counts as an infinite residual: halve
          const auto trial = [&](const bool with_tangent) {
            if (s.line_search == LineSearch::none)
              return p.assemble(with_tangent);
            try
              {
                return p.assemble(with_tangent);
              }
            catch (const NewtonFailure &)
              {
                return std::numeric_limits<double>::infinity();
              }
          };
          const double s0 = s.line_search == LineSearch::energy ? p.slope() : 0.0;
          p.apply(1.0);
          double r = trial(true);
          if (s.line_search == LineSearch::residual)
            while (!(r <= (1 - s.armijo * alpha) * r_prev) && halvings < s.line_search_max_halvings)
              {
                p.apply(-0.5 * alpha);
                alpha *= 0.5;
                ++halvings;
                r            = trial(false);
                have_tangent = false;
              }
          if (s.line_search == LineSearch::energy && s0 < 0)
            {
              // a rejected trial (infinite residual) counts as an overshoot
              const auto slope = [&]() {
                return std::isfinite(r) ? p.slope() : std::numeric_limits<double>::infinity();
              };
              double s_hi = slope(), a_lo = 0, s_lo = s0, a_hi = 1;
              while (s_hi > 0 && std::abs(s_hi) > s.energy_tolerance * std::abs(s0) &&
                     halvings < s.line_search_max_halvings)
                {
                  double a = std::isfinite(s_hi) ? a_lo - s_lo * (a_hi - a_lo) / (s_hi - s_lo) : 0.5 * (a_lo + a_hi);
                  const double margin = 0.1 * (a_hi - a_lo);
                  a                   = std::min(std::max(a, a_lo + margin), a_hi - margin);
                  p.apply(a - alpha);
                  alpha = a;
                  ++halvings;
                  r                  = trial(false);
                  have_tangent       = false;
                  const double s_now = slope();
                  if (std::abs(s_now) <= s.energy_tolerance * std::abs(s0))
                    break;
                  if (s_now > 0)
                    a_hi = a, s_hi = s_now;
                  else
                    a_lo = a, s_lo = s_now;
                }
            }

          const double inc  = alpha * du;
          const double step = p.step_increment_norm ? p.step_increment_norm() : nan;
          res.history.push_back({r, inc, step, alpha, halvings});
          if (k == 1)
            first_increment = inc;

          if (!std::isfinite(r) || (p.step_increment_norm && !std::isfinite(step)))
            {
              std::ostringstream m;
              m << "non-finite " << (std::isfinite(r) ? "step increment" : "residual") << " norm at iteration " << k;
              return finish(res, NewtonStatus::non_finite, m.str());
            }

          const double inc_ref = p.step_increment_norm ? step : first_increment;
          const bool   res_ok  = r <= std::max(s.residual_relative * r_ref, s.residual_absolute);
          const bool   inc_ok  = inc <= std::max(s.increment_relative * inc_ref, s.increment_absolute);
          bool         ok      = false;
          switch (s.criterion)
            {
              case NewtonCriterion::residual:
                ok = res_ok;
                break;
              case NewtonCriterion::increment:
                ok = inc_ok;
                break;
              case NewtonCriterion::residual_and_increment:
                ok = res_ok && inc_ok;
                break;
              case NewtonCriterion::residual_or_increment:
                ok = res_ok || inc_ok;
                break;
            }
          if (ok)
            {
              std::ostringstream m;
              m << "converged in " << k << " iterations: |r|/|r_ref| = " << r / r_ref << ", |du| = " << inc;
              return finish(res, NewtonStatus::converged, m.str());
            }

          if (s.divergence_factor > 0 && k >= s.divergence_window)
            {
              const auto &old = res.history[k - s.divergence_window];
              if (r > s.divergence_factor * old.residual)
                {
                  std::ostringstream m;
                  m << "residual diverged: |r_" << k << "| = " << r << " > " << s.divergence_factor << " |r_"
                    << k - s.divergence_window << "| = " << old.residual;
                  return finish(res, NewtonStatus::residual_diverged, m.str());
                }
              // the predictor row has no increment: compare increments from row 1
              if (k > s.divergence_window && inc > s.divergence_factor * old.increment)
                {
                  std::ostringstream m;
                  m << "increment diverged: |du_" << k << "| = " << inc << " > " << s.divergence_factor << " |du_"
                    << k - s.divergence_window << "| = " << old.increment;
                  return finish(res, NewtonStatus::increment_diverged, m.str());
                }
            }
          r_prev = r;
        }
      std::ostringstream m;
      m << "not converged in " << s.max_iterations << " iterations: |r|/|r_ref| = " << r_prev / r_ref
        << ", last |du| = " << res.history.back().increment;
      finish(res, NewtonStatus::max_iterations, m.str());
    }

    NewtonSettings settings_;
  };
} // namespace talus::implicit_mpm
