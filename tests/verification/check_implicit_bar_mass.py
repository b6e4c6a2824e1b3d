"""Lumped against consistent mass (implicit/mass matrix) on the first axial mode of
an elastic bar, talus-implicit dynamic (issue 13 item 2).

Scene: the material of bar_vibration.prm (nu = 0, c = 10 m/s) as a FREE-FREE bar
of length 2 L = 2 m (no wall in x; rollers on the long sides), initial velocity
v0 cos(pi x / 2L), v0 = 1e-3 m/s (strain 1e-4): its first mode has the period of
the fixed-free bar of length L, T = 4 L / c = 0.4 s (the midpoint is a node). The
bar is free-free because a fixed grid wall perturbs MPM's step (the Newmark
acceleration of a fixed node, from its projected velocity, reaches the points of
the first cell: docs/implicit.md); here every node is free. n cells per L (h = L / n),
2 x 2 points per cell, dt = 2e-3 s (w dt = 0.031), 3 periods. Signal: the kinetic
energy, which oscillates with T / 2 (mean spacing of its zero crossings about
the run's mean; the point velocities' part the grid cannot represent adds a
constant and a term of period T, which cancels when up and down crossings are
averaged: 2e-7 in the model below).

Prediction (derived, not fitted). On a uniform grid the first discrete mode is
sin(k x_i), k = pi / 2L (cos about the free ends), and every operator of the step
acts on it as a number: the lumped-mass stiffness kappa = (c/h)^2 2 (1 - cos kh)
(exact: the strain is constant in a cell, the points integrate it exactly), and
the point mass matrix against the lumped one S = M_L^-1 M_p = 2 a + 2 b cos kh with
a = sum (1 - xi_q)^2 / p, b = sum xi_q (1 - xi_q) / p over the points xi_q = (q +
1/2) / p of a cell (p = 2: a = 5/16, b = 3/16). MPM's step re-projects v and a to
the nodes every step with the lumped mass (Eqs. 2.6-2.9): the nodal v, a seen by
Newmark are S times the ones of the interpolated point field, so the effective
frequency is
    lumped mass:      w^2 = kappa S     (FE lumped error x (1 + 9/4) at p = 2)
    consistent mass:  w^2 = kappa       (the mass S cancels the projection's S:
                                         exactly the FE lumped-mass frequency)
and the measured period is 2 pi / w x w dt / (2 atan(w dt / 2)) (trapezoidal rule).
Both are BELOW the exact frequency (periods above T): the FE upper bound of the
consistent mass does not survive MPM's lumped projection. Leading terms: lumped
-13/96 (kh)^2, consistent -4/96 (kh)^2, ratio 4/13 = 0.31.

Checks (tolerances before the runs: the neglected effects are the neo-Hookean
non-linearity at strain 1e-4 and the points' drift of 1e-3 h at most, each below
1e-5 on the period):
  * per grid and option: the measured period within 1e-4 of the prediction;
  * both periods above T; the consistent one the closer to T on every grid;
  * convergence: the error of each option falls by >= 2^1.8 per halving of h;
  * the run reached its end time.
The FE periods without the projection (the bounds of FE theory) are printed beside.

DIM = 2 also checks two things around the bar:
  * a lone point (one point in one cell, gravity, dynamic, dt = 0.01 s): with the
    consistent mass the tangent of its cell is singular (rank 5 of 8: the mass
    sees N u at the point, the stiffness its symmetric gradient); the system is
    compatible, the direct solve answers it (|b - A x| / |b| < 1e-6) and the
    point falls as with the lumped mass: as Newmark (1/2, 1/4) from rest with
    the points' initial acceleration 0 (the first step averages 0 and -g),
    within 1e-8 m (series.csv prints 8 significant digits);
  * the static cantilever (cantilever_self_weight.prm beside PRM, h = 0.25) with
    'mass matrix = consistent' writes particles_final.csv byte for byte as the
    lumped default (the option has no effect without inertia).
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
xi = [(q + 0.5) / p for q in range(p)]
a_, b_ = sum((1 - x) ** 2 for x in xi) / p, sum(x * (1 - x) for x in xi) / p


def stretch(w):
    """Trapezoidal rule: measured period / period of the semi-discrete system."""
    return w * dt / (2 * math.atan(w * dt / 2))


def frequencies(n):
    """(MPM lumped, MPM consistent, FE lumped, FE point-consistent) first-mode frequencies."""
    th = k * L / n
    kappa = (c * n / L) ** 2 * 2 * (1 - math.cos(th))
    S = 2 * a_ + 2 * b_ * math.cos(th)
    return math.sqrt(kappa * S), math.sqrt(kappa), math.sqrt(kappa), math.sqrt(kappa / S)


def run(mass, n):
    h = L / n
    z = ", 0" if dim == 3 else ""
    zt = f", {thick}" if dim == 3 else ""
    sets = {
        "dimension": str(dim),
        "output/directory": "out",
        "time/time step": str(dt),
        "time/end time": str(t_end),
        "implicit/mass matrix": mass,
        "grid/lower corner": "0, 0" + z,
        "grid/upper corner": f"{2 * L}, {thick}" + zt,
        "grid/cells": f"{2 * n}, 1" + (", 1" if dim == 3 else ""),
        "boundary conditions/fixed": "",
        "boundary conditions/roller": "2, 3, 4, 5" if dim == 3 else "2, 3",
        "gravity/acceleration": "0, 0" + z,
        "body 0/lower corner": "0, 0" + z,
        "body 0/upper corner": f"{2 * L}, {thick}" + zt,
        "body 0/initial velocity function": "v0*cos(pi*x/(2*L)); 0" + ("; 0" if dim == 3 else ""),
        "body 0/function constants": "v0=0.001, L=1",
    }
    text = open(prm_path).read()
    for key, v in sets.items():
        text = tv.prm_set(text, key, v)
    name = f"{mass}_n{n}_{dim}d"
    start = time.time()
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    wall = time.time() - start
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    t, e = s["time"], s["kinetic_energy"]
    mean = sum(e) / len(e)
    y = [v - mean for v in e]
    spacings = tv.crossing_periods(t[1:], y[1:])
    tv.check(len(spacings) >= 6, f"{name}: at least 6 half-periods of the kinetic energy ({len(spacings)})")
    tv.check(abs(t[-1] - t_end) < 1e-9, f"{name}: the run reached its end time")
    steps = [i for i in range(len(t)) if s["step"][i] > 0]
    its = [s["newton_iterations"][i] for i in steps]
    per_it = None
    for line in out.splitlines():  # the summary's assembly and solve times, for the cost per iteration
        if "assembly" in line and "solve" in line:
            per_it = line.strip()
    return 2 * sum(spacings) / len(spacings), wall, sum(its) / len(its), max(its), per_it


errors = {}
for n in ns:
    w_l, w_c, w_fe_l, w_fe_c = frequencies(n)
    for mass, w, w_fe in (("lumped", w_l, w_fe_l), ("consistent", w_c, w_fe_c)):
        Tm, wall, its_mean, its_max, timing = run(mass, n)
        Tp = 2 * math.pi / w * stretch(w)
        Ts = Tm / stretch(2 * math.pi / Tm)  # the time stretch removed
        errors[(mass, n)] = Ts - T
        print(f"{mass:10s} n = {n:3d} (h = {L / n:.4f}): period {Tm:.7f} s, predicted {Tp:.7f} s "
              f"(rel. diff {(Tm - Tp) / Tp:+.2e}); without the time stretch: error vs 4L/c {(Ts - T) / T:+.4e} "
              f"(FE without projection would give {(2 * math.pi / w_fe - T) / T:+.4e}); Newton its/step "
              f"{its_mean:.2f} (max {its_max:.0f}); wall {wall:.1f} s")
        if timing:
            print(f"    {timing}")
        tv.check(abs(Tm - Tp) / Tp < 1e-4, f"{mass} n = {n}: period within 1e-4 of the prediction")
        tv.check(Ts > T, f"{mass} n = {n}: period above 4L/c (frequency below the exact one)")
for n in ns:
    el, ec = errors[("lumped", n)], errors[("consistent", n)]
    print(f"n = {n}: |error consistent| / |error lumped| = {abs(ec) / abs(el):.3f} (leading order 4/13 = 0.308)")
    tv.check(abs(ec) < abs(el), f"n = {n}: the consistent mass is the more accurate")
for mass in ("lumped", "consistent"):
    for n1, n2 in zip(ns, ns[1:]):
        e1, e2 = abs(errors[(mass, n1)]), abs(errors[(mass, n2)])
        order = math.log(e1 / e2) / math.log(n2 / n1)
        tv.check(order >= 1.8, f"{mass}: observed order {order:.2f} >= 1.8 between n = {n1} and {n2}")
if dim == 2:
    import os
    lone = open(prm_path).read()
    for key, v in {"output/directory": "out", "time/time step": "0.01", "time/end time": "0.05",
                   "grid/lower corner": "0, 0", "grid/upper corner": "1, 1", "grid/cells": "4, 4",
                   "boundary conditions/fixed": "2", "boundary conditions/roller": "",
                   "gravity/acceleration": "0, -9.81", "material 0/density": "1000",
                   "material 0/neo hookean/young modulus": "1e6", "material 0/neo hookean/poisson ratio": "0.3",
                   "body 0/lower corner": "0.25, 0.5", "body 0/upper corner": "0.5, 0.75",
                   "body 0/particles per direction": "1", "body 0/initial velocity function": "0; 0"}.items():
        lone = tv.prm_set(lone, key, v)
    for mass in ("lumped", "consistent"):
        name = f"lone_point_{mass}"
        _, out, _ = tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(lone, "implicit/mass matrix", mass),
                                f"{work}/{name}", name)
        s = tv.read_csv(f"{work}/{name}/out/series.csv")
        # Newmark (1/2, 1/4) from rest with the points' initial acceleration 0: a = -g from the first step on
        ref, u, v, a = [0.625], 0.0, 0.0, 0.0
        for _ in range(len(s["time"]) - 1):
            u += 0.01 * v + 0.01 ** 2 / 4 * (a - 9.81)
            v += 0.01 / 2 * (a - 9.81)
            a = -9.81
            ref.append(0.625 + u)
        worst = max(abs(y - r) for y, r in zip(s["centre_of_mass_y"], ref))
        lin = [float(x) for x in __import__("re").findall(r"largest \|b - A x\|/\|b\| ([0-9.e+-]+)", out)]
        du = __import__("re").findall(r"\|du\| ([0-9.e+-]+)", out)
        print(f"lone point, {mass}: largest |y - y_Newmark| {worst:.2e} m; largest linear residual "
              f"{max(lin):.1e}; |du| per step {' '.join(du)}")
        tv.check(worst < 1e-8, f"lone point, {mass}: free fall as Newmark's within 1e-8 m ({worst:.1e})")
        tv.check(len(lin) == 5 and max(lin) < 1e-6, f"lone point, {mass}: every linear solve |b - A x| / |b| < 1e-6")
    cant = tv.prm_set(open(os.path.join(os.path.dirname(prm_path), "cantilever_self_weight.prm")).read(),
                      "output/final particles csv", "true")
    cant = tv.prm_set(cant, "output/directory", "out")
    csv = {}
    for mass in ("lumped", "consistent"):
        name = f"static_cantilever_{mass}"
        tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(cant, "implicit/mass matrix", mass), f"{work}/{name}", name)
        csv[mass] = open(f"{work}/{name}/out/particles_final.csv").read()
    tv.check(len(csv["lumped"]) > 0 and csv["lumped"] == csv["consistent"],
             "static cantilever: particles_final.csv identical with the lumped and the consistent mass")
tv.finish()
