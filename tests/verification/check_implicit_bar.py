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
Usage: check_implicit_bar.py TOOLS_DIR PRM WORKDIR [entry=value ...]
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
text = tv.prm_set_args(text, sys.argv[4:])  # entry=value: e.g. the same bar in mixed u-p
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
tv.check(abs(last / first - 1) < 0.02, "no amplitude decay (RMS ratio within 2 %)")
steps = [i for i in range(len(t)) if s["step"][i] > 0]
tv.check(abs(t[-1] - 1.2) < 1e-9, "the run reached its end time")
print(f"{len(steps)} steps, Newton iterations per step: max {max(s['newton_iterations'][i] for i in steps):.0f}")
tv.finish()
