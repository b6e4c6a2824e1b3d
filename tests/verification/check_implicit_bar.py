"""First axial mode of an elastic bar with talus-implicit, dynamic (issue 13):
Newmark gamma = 1/2, beta = 1/4 at 10 x the explicit critical step. The
centre of mass x_c(t) oscillates with the bar's first mode, x_c - x_c(0) ~ sin(w t).
Checks:
  * the step is >= 10 x the explicit critical step h / c;
  * the period from the zero crossings of x_c - x_c(0) (3 periods) is within
    0.5 % of the exact period 4 L / c stretched by the trapezoidal rule,
    T w dt / (2 atan(w dt / 2)) (the unit tests check that stretch exactly), and
    differs from the unstretched T by more than 1 % (what is measured is Newmark's);
  * no numerical damping: the RMS of x_c - x_c(0) over the last period is within
    2 % of that over the first;
  * Newton converged in every step.
With --rayleigh-beta=B (stiffness-proportional Rayleigh damping C = B K): instead of the
no-decay check, the RMS ratio last / first period equals, within 3 %, that of the single
mode u'' + B w^2 u' + w^2 u = 0 integrated by the same Newmark rule at the same dt (the
first mode's damping ratio is B w / 2), and is below 0.8 (the damping is seen).
Usage: check_implicit_bar.py TOOLS_DIR PRM WORKDIR [entry=value ...] [--rayleigh-beta=B]
"""
import math
import sys

import talus_verify as tv

rayleigh_beta = float(([a.split("=", 1)[1] for a in sys.argv if a.startswith("--rayleigh-beta=")] or ["0"])[0])
args = [a for a in sys.argv if not a.startswith("--rayleigh-beta=")]
tools, prm_path, work = args[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
text = tv.prm_set_args(text, args[4:])  # entry=value: e.g. the same bar in mixed u-p
if rayleigh_beta > 0:
    text = tv.prm_set(text, "damping/stiffness damping", str(rayleigh_beta))
_, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, work, "bar")
print(out.strip().splitlines()[-2])
E, rho, L, h, dt = 100.0, 1.0, 1.0, 1.25 / 40, 0.03125
c = math.sqrt(E / rho)
T = 4 * L / c
w = 2 * math.pi / T
T_newmark = T * w * dt / (2 * math.atan(w * dt / 2))
tv.check(dt / (h / c) >= 10 - 1e-9, f"time step {dt} = {dt / (h / c):.1f} x the explicit critical step {h / c:.3e} s")
s = tv.read_csv(f"{work}/out/series.csv")
t, x = s["time"], [v - s["centre_of_mass_x"][0] for v in s["centre_of_mass_x"]]
periods = tv.crossing_periods(t[1:], x[1:])
tv.check(len(periods) >= 3, f"at least 3 periods between zero crossings ({len(periods)})")
Tm = sum(periods) / len(periods)
print(f"period {Tm:.5f} s; exact {T:.5f} s, stretched by the trapezoidal rule {T_newmark:.5f} s "
      f"(w dt = {w * dt:.3f}); error vs stretched {abs(Tm - T_newmark) / T_newmark:.2e}")
tv.check(abs(Tm - T_newmark) / T_newmark < 5e-3, "period within 0.5 % of the trapezoidal-rule period")
tv.check(abs(Tm - T) / T > 1e-2, "period differs from the unstretched period by > 1 % (Newmark's stretch is seen)")
n = round(T_newmark / dt)


def rms(v):
    return math.sqrt(sum(y * y for y in v) / len(v))


first, last = rms(x[1:n + 1]), rms(x[-n:])
print(f"RMS of x_c over the first and last period: {first:.4e}, {last:.4e} (ratio {last / first:.4f})")
if rayleigh_beta > 0:
    # the single mode under the same Newmark rule (gamma 1/2, beta 1/4): u(0) = 0, v(0) = 1
    c, k, g_, b_ = rayleigh_beta * w * w, w * w, 0.5, 0.25
    u, v, a, us = 0.0, 1.0, -rayleigh_beta * w * w, [0.0]
    for _ in range(len(x) - 1):
        # (1 + c g dt + k b dt^2) a1 = -c (v + (1-g) dt a) - k (u + dt v + (1/2 - b) dt^2 a)
        a1 = (-c * (v + (1 - g_) * dt * a) - k * (u + dt * v + (0.5 - b_) * dt * dt * a)) / (1 + c * g_ * dt + k * b_ * dt * dt)
        u, v, a = u + dt * v + dt * dt * ((0.5 - b_) * a + b_ * a1), v + dt * ((1 - g_) * a + g_ * a1), a1
        us.append(u)
    ref = rms(us[-n:]) / rms(us[1:n + 1])
    print(f"Rayleigh beta = {rayleigh_beta}: first-mode damping ratio {rayleigh_beta * w / 2:.4f}; RMS ratio "
          f"{last / first:.4f}, single mode under the same Newmark rule {ref:.4f} ({last / first / ref - 1:+.2%})")
    tv.check(abs(last / first / ref - 1) < 0.03, "the decay matches the single mode's within 3 %")
    tv.check(last / first < 0.8, "the damping is seen (RMS ratio < 0.8)")
else:
    tv.check(abs(last / first - 1) < 0.02, "no amplitude decay (RMS ratio within 2 %)")
steps = [i for i in range(len(t)) if s["step"][i] > 0]
tv.check(abs(t[-1] - 1.2) < 1e-9, "the run reached its end time")
print(f"{len(steps)} steps, Newton iterations per step: max {max(s['newton_iterations'][i] for i in steps):.0f}")
tv.finish()
