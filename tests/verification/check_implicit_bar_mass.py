"""Lumped against consistent mass (implicit/mass matrix) on the first axial mode of
an elastic bar, talus-implicit dynamic (issue 13 item 2).

The scene of bar_vibration.prm (L = 1 m, fixed at x = 0, free at x = L, nu = 0,
c = 10 m/s, exact period T = 4 L / c = 0.4 s) on coarse grids of n cells along the
bar (h = L / n, 2 x 2 points per cell), v0 = 1e-3 m/s (strain 1e-4), with a small
time step dt = 2e-3 s (w dt = 0.031: the trapezoidal rule stretches the period
by 8e-5) so that the grid's error dominates.

Prediction (FE dispersion of linear elements on a uniform mesh; the discrete
modes of the fixed-free bar are sin(k x_i) with k = pi / (2 L) exactly): with the
element mass rho h [[a, b], [b, a]] and the exact element stiffness (the strain
is constant in a cell, so the points integrate it exactly),
    w_h^2 = (c / h)^2 2 (1 - cos kh) / (2 a + 2 b cos kh).
Lumped: a = 1/2, b = 0 (w_h below w: period above T). Consistent mass integrated
by the points (p per direction at the sub-cell centres xi_q = (q + 1/2) / p, m_p =
rho h / p): a = sum (1 - xi_q)^2 / p, b = sum xi_q (1 - xi_q) / p; p = 2: a = 5/16,
b = 3/16 (the exact consistent 1/3, 1/6 has a smaller off-diagonal). Leading
terms (a + b = 1/2): w_h / w = 1 + (12 b - 1) (kh)^2 / 24; lumped -(kh)^2 / 24,
exact consistent +(kh)^2 / 24, point-consistent with p = 2: +1.25 (kh)^2 / 24. So
the consistent mass bounds the frequency from above, but with 2 points per cell
it is NOT the more accurate one: its error is 1.25 x the lumped one.
The measured period is predicted as T_h x w_h dt / (2 atan(w_h dt / 2)).

Checks (tolerances stated before the runs):
  * per grid and option: the measured period (mean spacing of the zero crossings
    of x_c - x_c(0) over 3 periods) within 1e-3 of the predicted one (the
    predicted lumped-consistent gap is 1.4 % at n = 4);
  * bounds: the period with the time stretch removed is above T (lumped) and
    below T (consistent) on every grid;
  * convergence: the error of each option falls by a factor >= 2^1.8 per halving of h;
  * Newton converged everywhere (the run reached its end time).
Usage: check_implicit_bar_mass.py TOOLS_DIR PRM WORKDIR DIM N1 [N2 ...]
  (DIM 2 or 3: 3 makes the bar a prism one cell thick in y and z, rollers on its sides)
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work, dim = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
ns = [int(n) for n in sys.argv[5:]]
E, rho, L, thick, dt, t_end, p = 100.0, 1.0, 1.0, 0.03125, 0.002, 1.2, 2
c = math.sqrt(E / rho)
T = 4 * L / c
k = math.pi / (2 * L)


def stretch(w):
    """Trapezoidal rule: the measured period over the period of the discrete system."""
    return w * dt / (2 * math.atan(w * dt / 2))


def predicted(mass, n):
    """Period of the semi-discrete first mode (before the time stretch)."""
    h = L / n
    if mass == "lumped":
        a, b = 0.5, 0.0
    else:
        xi = [(q + 0.5) / p for q in range(p)]
        a = sum((1 - x) ** 2 for x in xi) / p
        b = sum(x * (1 - x) for x in xi) / p
    w2 = (c / h) ** 2 * 2 * (1 - math.cos(k * h)) / (2 * a + 2 * b * math.cos(k * h))
    return 2 * math.pi / math.sqrt(w2)


def run(mass, n):
    h = L / n
    text = open(prm_path).read()
    tail = [", 0", ", 0"] if dim == 3 else [""]
    sets = {
        "dimension": str(dim),
        "output/directory": "out",
        "time/time step": str(dt),
        "time/end time": str(t_end),
        "implicit/mass matrix": mass,
        "grid/upper corner": f"{L + h}, {thick}" + (f", {thick}" if dim == 3 else ""),
        "grid/lower corner": "0, 0" + tail[0],
        "grid/cells": f"{n + 1}, 1" + (", 1" if dim == 3 else ""),
        "boundary conditions/roller": "2, 3, 4, 5" if dim == 3 else "2, 3",
        "gravity/acceleration": "0, 0" + tail[0],
        "body 0/lower corner": "0, 0" + tail[0],
        "body 0/upper corner": f"{L}, {thick}" + (f", {thick}" if dim == 3 else ""),
        "body 0/initial velocity function": "v0*sin(pi*x/(2*L)); 0" + ("; 0" if dim == 3 else ""),
        "body 0/function constants": "v0=0.001, L=1",
    }
    for key, v in sets.items():
        text = tv.prm_set(text, key, v)
    name = f"{mass}_n{n}_{dim}d"
    start = time.time()
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    wall = time.time() - start
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    t, x = s["time"], [v - s["centre_of_mass_x"][0] for v in s["centre_of_mass_x"]]
    up = tv.zero_crossings(t[1:], x[1:], +1)
    down = tv.zero_crossings(t[1:], x[1:], -1)
    periods = [b - a for a, b in zip(up, up[1:])] + [b - a for a, b in zip(down, down[1:])]
    tv.check(len(periods) >= 3, f"{name}: at least 3 periods between zero crossings ({len(periods)})")
    tv.check(abs(t[-1] - t_end) < 1e-9, f"{name}: the run reached its end time")
    steps = [i for i in range(len(t)) if s["step"][i] > 0]
    its = [s["newton_iterations"][i] for i in steps]
    return sum(periods) / len(periods), wall, sum(its) / len(its), max(its)


results = {}
for n in ns:
    for mass in ("lumped", "consistent"):
        Tm, wall, its_mean, its_max = run(mass, n)
        Th = predicted(mass, n)
        Tp = Th * stretch(2 * math.pi / Th)
        Ts = Tm / stretch(2 * math.pi / Tm)  # the time stretch removed: the grid's period
        results[(mass, n)] = Ts
        print(f"{mass:10s} n = {n:3d} (h = {L / n:.4f}): period {Tm:.6f} s, predicted {Tp:.6f} s "
              f"(rel. diff {(Tm - Tp) / Tp:+.2e}); without the time stretch {Ts:.6f} s, "
              f"error vs 4L/c {(Ts - T) / T:+.3e} (predicted {(Th - T) / T:+.3e}); Newton its/step "
              f"{its_mean:.2f} (max {its_max:.0f}); wall {wall:.1f} s")
        tv.check(abs(Tm - Tp) / Tp < 1e-3, f"{mass} n = {n}: period within 1e-3 of the FE prediction")
        if mass == "lumped":
            tv.check(Ts > T, f"lumped n = {n}: period above 4L/c (frequency below: lower bound)")
        else:
            tv.check(Ts < T, f"consistent n = {n}: period below 4L/c (frequency above: upper bound)")
for n in ns:
    el, ec = results[("lumped", n)] - T, results[("consistent", n)] - T
    print(f"n = {n}: |error consistent| / |error lumped| = {abs(ec) / abs(el):.3f} "
          f"(leading-order prediction for {p} points per cell: 1.25)")
for mass in ("lumped", "consistent"):
    for n1, n2 in zip(ns, ns[1:]):
        e1, e2 = abs(results[(mass, n1)] - T), abs(results[(mass, n2)] - T)
        order = math.log(e1 / e2) / math.log(n2 / n1)
        tv.check(order >= 1.8, f"{mass}: observed order {order:.2f} >= 1.8 between n = {n1} and {n2}")
tv.finish()
