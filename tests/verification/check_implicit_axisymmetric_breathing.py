"""Breathing mode of a thick cylinder, axisymmetric talus-implicit, dynamic (issue
13 item 6: the hoop terms and the ring mass in Newmark's inertia). The scene of
thick_cylinder_axisymmetric.prm (a = 1, b = 2 m, rollers on the y walls: plane
strain along the axis, E = 10 MPa, nu = 0.3, rho = 1000) with 'analysis =
dynamic' (Newmark 1/2, 1/4, no damping): the internal traction (1 kPa) acts from
t = 0 as a step load and the wall vibrates about its static state, mostly in its
fundamental radial mode. Exact period of that mode (linear, plane strain): the
smallest k with u'' + u'/r - u/r^2 + k^2 u = 0, sigma_rr = (lambda + 2 mu) u' +
lambda u / r = 0 at r = a and r = b (shooting in k, RK4), omega = k c_p, c_p =
sqrt((lambda + 2 mu) / rho): T = 0.085516 s (the next mode is 5 x faster). The
trapezoidal rule stretches it to 2 pi / Omega, Omega dt = 2 atan(omega dt / 2):
0.085670 s at dt = 0.002 s (43 steps per period).
Signal: centre_of_mass_x of series.csv (the ring-mass-weighted mean radius, which
the fundamental mode dominates), minus its mean over the run; period = the mean
spacing of its upward zero crossings over 0.35 s (4 crossings).
Checks per grid: the run reached the end, at most 3 Newton iterations per step,
>= 3 crossings, the period within TOL of the trapezoidal period, and closer to
it than to the exact one (the elongation, 1.8e-3, is resolved).
Usage: check_implicit_axisymmetric_breathing.py TOOLS_DIR PRM WORKDIR TOL N1 [N2 ...] [ENTRY=VALUE ...]
(N: cells per metre; ENTRY=VALUE: further .prm settings, e.g. implicit/mass matrix=consistent)
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
ns = [int(n) for n in sys.argv[5:] if "=" not in n]
settings = [kv.split("=", 1) for kv in sys.argv[5:] if "=" in kv]
E, nu, rho, a, b, dt, t_end = 1e7, 0.3, 1000.0, 1.0, 2.0, 0.002, 0.35
lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
M = lam + 2 * mu


def sigma_rr_at_b(k, n=2000):
    """Radial stress at b of the mode shape with sigma_rr(a) = 0, u(a) = 1."""
    u, up, r, h = 1.0, -lam / M / a, a, (b - a) / n

    def f(r, u, up):
        return up, -(up / r - u / (r * r) + k * k * u)

    for _ in range(n):
        k1 = f(r, u, up)
        k2 = f(r + h / 2, u + h / 2 * k1[0], up + h / 2 * k1[1])
        k3 = f(r + h / 2, u + h / 2 * k2[0], up + h / 2 * k2[1])
        k4 = f(r + h, u + h * k3[0], up + h * k3[1])
        u += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        up += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        r += h
    return M * up + lam * u / b


k_lo = 0.05
while sigma_rr_at_b(k_lo) * sigma_rr_at_b(k_lo + 0.05) > 0:
    k_lo += 0.05
k_hi = k_lo + 0.05
for _ in range(60):
    k_mid = 0.5 * (k_lo + k_hi)
    if sigma_rr_at_b(k_lo) * sigma_rr_at_b(k_mid) <= 0:
        k_hi = k_mid
    else:
        k_lo = k_mid
omega = k_lo * math.sqrt(M / rho)
T_exact = 2 * math.pi / omega
T_trap = 2 * math.pi * dt / (2 * math.atan(omega * dt / 2))
print(f"fundamental radial mode: k = {k_lo:.6f} 1/m, T = {T_exact:.6f} s; trapezoidal at dt = {dt}: {T_trap:.6f} s")

base = open(prm_path).read()
for entry, value in (("implicit/analysis", "dynamic"), ("time/time step", f"{dt}"), ("time/end time", f"{t_end}"),
                     ("output/directory", "out"), ("output/final particles csv", "false")):
    base = tv.prm_set(base, entry, value)
for entry, value in settings:
    base = tv.prm_set(base, entry, value)
for n in ns:
    name = f"n{n}"
    start = time.time()
    tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(base, "grid/cells", f"{round(2.5 * n)}, {round(0.5 * n)}"),
                f"{work}/{name}", name)
    wall = time.time() - start
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    t, x = s["time"], s["centre_of_mass_x"]
    tv.check(abs(t[-1] - t_end) < 1e-9, f"{name}: the run reached t = {t_end}")
    mean = sum(x) / len(x)
    y = [v - mean for v in x]
    up = [t[i] + (t[i + 1] - t[i]) * (-y[i]) / (y[i + 1] - y[i]) for i in range(len(t) - 1) if y[i] < 0 <= y[i + 1]]
    its = max(s["newton_iterations"])
    tv.check(len(up) >= 3, f"{name}: at least 3 upward crossings ({len(up)})")
    if len(up) < 2:
        continue
    T = (up[-1] - up[0]) / (len(up) - 1)
    err = abs(T - T_trap) / T_trap
    print(f"{n} cells/m: period {T:.6f} s, vs trapezoidal {err:.2e}, vs exact {(T - T_exact) / T_exact:+.2e}; "
          f"at most {its:.0f} Newton iterations per step; wall {wall:.1f} s")
    tv.check(err < tol, f"{name}: period within {tol} of the trapezoidal period ({err:.2e})")
    tv.check(abs(T - T_trap) < abs(T - T_exact), f"{name}: the period is closer to the trapezoidal one than to the "
             "exact one (the trapezoidal elongation is resolved)")
    tv.check(its <= 3, f"{name}: at most 3 Newton iterations per step ({its:.0f})")
tv.finish()
