// talus — Newmark time integration of nodal fields in incremental-displacement
// form (Iaconeta 2019, Eqs. 2.10-2.12), for the implicit updated-Lagrangian
// family. The unknown of a step is the nodal displacement increment du (the
// grid is reset every step, so du is also the nodal displacement of the step);
// velocity and acceleration at t_{n+1} are functions of du and of the projected
// previous fields v^n, a^n:
//
//   a^{n+1} = du / (beta dt^2) - v^n / (beta dt) - (1/(2 beta) - 1) a^n
//   v^{n+1} = gamma/(beta dt) du - (gamma/beta - 1) v^n - dt (gamma/(2 beta) - 1) a^n
//
// which is the classical Newmark pair
//   du      = dt v^n + dt^2 ((1/2 - beta) a^n + beta a^{n+1})
//   v^{n+1} = v^n + dt ((1 - gamma) a^n + gamma a^{n+1})
// solved for a^{n+1}, v^{n+1}. The second line is also the material-point
// velocity update (Eq. 2.16 for gamma = 1/2).
//
// Header-only. Vector operations take any type with operator[] (raw pointers,
// std::vector, deal.II vectors); for a distributed vector pass the locally
// owned range, e.g. `vec.begin()` (a Number* over the owned entries of
// LinearAlgebra::distributed::Vector) and `vec.locally_owned_size()`.
// No explicit-family headers may be included here (talus_core tests use it).
#pragma once

#include <talus/base/errors.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>

namespace talus::implicit_mpm
{
  /// Newmark parameters and the coefficients derived from them and the step.
  ///
  /// Allowed: 1/2 <= gamma <= 1 and 0 <= beta <= 1/2.
  ///  * gamma < 1/2 adds negative numerical damping (growth): refused.
  ///  * 2 beta >= gamma >= 1/2: unconditionally stable (linear problems);
  ///    gamma = 1/2, beta = 1/4 (the thesis' choice, trapezoidal rule) has no
  ///    numerical damping and conserves the energy of a linear system;
  ///    gamma > 1/2 damps high frequencies (beta = (gamma + 1/2)^2/4 is the
  ///    usual pairing).
  ///  * beta < gamma/2: conditionally stable, omega dt < critical_omega_dt().
  ///  * beta = 0 is the explicit central-difference family: the increment is
  ///    known before the step (known_increment()) and the incremental forms
  ///    (acceleration(du, ...), velocity(du, ...), the tangent coefficients)
  ///    do not exist; calling them throws.
  class Newmark
  {
  public:
    explicit Newmark(const double gamma = 0.5, const double beta = 0.25, const double dt = 0)
    {
      set_parameters(gamma, beta);
      if (dt != 0)
        set_time_step(dt);
    }

    /// Throws InputError outside the allowed ranges (see the class comment).
    void
    set_parameters(const double gamma, const double beta)
    {
      std::ostringstream where;
      where << "Newmark (gamma = " << gamma << ", beta = " << beta << ")";
      require(std::isfinite(gamma) && gamma >= 0.5 && gamma <= 1.0, where.str(),
              "gamma must lie in [1/2, 1] (gamma < 1/2 makes the scheme unstable)");
      require(std::isfinite(beta) && beta >= 0.0 && beta <= 0.5, where.str(), "beta must lie in [0, 1/2]");
      gamma_ = gamma;
      beta_  = beta;
    }

    /// Call at the start of every step: a cut-back changes the step.
    void
    set_time_step(const double dt)
    {
      require(std::isfinite(dt) && dt > 0, "Newmark", "the time step must be positive and finite");
      dt_ = dt;
    }

    double
    gamma() const
    {
      return gamma_;
    }
    double
    beta() const
    {
      return beta_;
    }
    double
    dt() const
    {
      return dt_;
    }

    /// beta > 0: du is an unknown, solved for with the tangent.
    bool
    implicit() const
    {
      return beta_ > 0;
    }
    /// 2 beta >= gamma >= 1/2.
    bool
    unconditionally_stable() const
    {
      return 2 * beta_ >= gamma_;
    }
    /// Largest stable omega dt of an undamped linear oscillator:
    /// 1/sqrt(gamma/2 - beta) (2 for central difference); +inf when
    /// unconditionally stable.
    double
    critical_omega_dt() const
    {
      if (unconditionally_stable())
        return std::numeric_limits<double>::infinity();
      return 1.0 / std::sqrt(0.5 * gamma_ - beta_);
    }

    // ---- coefficients of the incremental form (beta > 0)
    /// d a^{n+1} / d du = 1/(beta dt^2): the factor of the mass in the tangent.
    double
    mass_coefficient() const
    {
      return 1.0 / (implicit_beta() * dt_ * dt_);
    }
    /// d v^{n+1} / d du = gamma/(beta dt): the factor of a damping matrix C
    /// in the tangent.
    double
    damping_coefficient() const
    {
      return gamma_ / (implicit_beta() * dt_);
    }

    /// Factors of the tangent K_eff = m M + k K for Rayleigh damping
    /// C = alpha_R M + beta_R K: the residual gets C v^{n+1}, so
    ///   m = 1/(beta dt^2) + alpha_R gamma/(beta dt),  k = 1 + beta_R gamma/(beta dt).
    /// (K: material + geometric stiffness; M: the mass matrix.)
    struct TangentFactors
    {
      double mass      = 0;
      double stiffness = 1;
    };
    TangentFactors
    tangent_factors(const double alpha_rayleigh = 0, const double beta_rayleigh = 0) const
    {
      return {mass_coefficient() + alpha_rayleigh * damping_coefficient(), 1.0 + beta_rayleigh * damping_coefficient()};
    }

    // ---- scalar relations (one DoF); T may be double or a deal.II Tensor<1,dim>
    /// Eq. 2.12: a^{n+1}(du).
    template <typename T>
    T
    acceleration(const T &du, const T &v_n, const T &a_n) const
    {
      const double b = implicit_beta();
      return du * (1.0 / (b * dt_ * dt_)) - v_n * (1.0 / (b * dt_)) - a_n * (0.5 / b - 1.0);
    }
    /// Eq. 2.11: v^{n+1}(du).
    template <typename T>
    T
    velocity(const T &du, const T &v_n, const T &a_n) const
    {
      const double b = implicit_beta();
      return du * (gamma_ / (b * dt_)) - v_n * (gamma_ / b - 1.0) - a_n * (dt_ * (0.5 * gamma_ / b - 1.0));
    }
    /// The part of du known at t_n: dt v^n + dt^2 (1/2 - beta) a^n (the whole
    /// increment when beta = 0).
    template <typename T>
    T
    known_increment(const T &v_n, const T &a_n) const
    {
      return v_n * dt_ + a_n * (dt_ * dt_ * (0.5 - beta_));
    }
    /// v^{n+1} = v^n + dt ((1 - gamma) a^n + gamma a^{n+1}): valid for every
    /// beta, and the material-point update of Eq. 2.16 (gamma = 1/2:
    /// v_p^{n+1} = v_p^n + dt/2 (a_p^n + a_p^{n+1})).
    template <typename T>
    T
    velocity_from_accelerations(const T &v_n, const T &a_n, const T &a_np1) const
    {
      return v_n + (a_n * (1.0 - gamma_) + a_np1 * gamma_) * dt_;
    }
    /// Same as velocity_from_accelerations, named for the point update.
    template <typename T>
    T
    point_velocity(const T &v_p, const T &a_p_n, const T &a_p_np1) const
    {
      return velocity_from_accelerations(v_p, a_p_n, a_p_np1);
    }

    // ---- vector forms on entries [0, n)
    /// v_new[i], a_new[i] from du[i], v_n[i], a_n[i] (Eqs. 2.11-2.12). With du
    /// = 0 this is the predictor of Eq. 2.10. Each entry is read before it is
    /// written, so v_new may be v_n and a_new may be a_n (in-place update).
    template <typename Du, typename Vn, typename An, typename Vout, typename Aout>
    void
    update(const std::size_t n, const Du &du, const Vn &v_n, const An &a_n, Vout &&v_new, Aout &&a_new) const
    {
      const double b  = implicit_beta();
      const double ca = 1.0 / (b * dt_ * dt_), cav = 1.0 / (b * dt_), caa = 0.5 / b - 1.0;
      const double cv = gamma_ / (b * dt_), cvv = gamma_ / b - 1.0, cva = dt_ * (0.5 * gamma_ / b - 1.0);
      for (std::size_t i = 0; i < n; ++i)
        {
          const double d = du[i], v = v_n[i], a = a_n[i];
          v_new[i] = cv * d - cvv * v - cva * a;
          a_new[i] = ca * d - cav * v - caa * a;
        }
    }
    /// The predictor (Eq. 2.10-2.12 with du = 0): v_pred, a_pred.
    template <typename Vn, typename An, typename Vout, typename Aout>
    void
    predict(const std::size_t n, const Vn &v_n, const An &a_n, Vout &&v_pred, Aout &&a_pred) const
    {
      const double b   = implicit_beta();
      const double cav = 1.0 / (b * dt_), caa = 0.5 / b - 1.0;
      const double cvv = gamma_ / b - 1.0, cva = dt_ * (0.5 * gamma_ / b - 1.0);
      for (std::size_t i = 0; i < n; ++i)
        {
          const double v = v_n[i], a = a_n[i];
          v_pred[i] = -cvv * v - cva * a;
          a_pred[i] = -cav * v - caa * a;
        }
    }
    /// v_p[i] <- v_p[i] + dt ((1 - gamma) a_old[i] + gamma a_new[i]) in place
    /// (point velocities, Eq. 2.16 and its general-gamma form).
    template <typename V, typename Ao, typename An>
    void
    update_point_velocities(const std::size_t n, V &&v_p, const Ao &a_old, const An &a_new) const
    {
      const double c0 = dt_ * (1.0 - gamma_), c1 = dt_ * gamma_;
      for (std::size_t i = 0; i < n; ++i)
        v_p[i] = v_p[i] + c0 * a_old[i] + c1 * a_new[i];
    }

  private:
    double
    implicit_beta() const
    {
      if (!(beta_ > 0))
        throw InputError("Newmark: beta = 0 (central difference) has no incremental-displacement form; "
                         "use known_increment() and velocity_from_accelerations()");
      if (!(dt_ > 0))
        throw InputError("Newmark: the time step is not set");
      return beta_;
    }

    double gamma_ = 0.5, beta_ = 0.25, dt_ = 0;
  };
} // namespace talus::implicit_mpm
