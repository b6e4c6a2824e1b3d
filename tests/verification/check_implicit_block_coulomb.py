"""A block on a Coulomb contact floor of grid nodes (talus-implicit, contact method = nodes,
'contact friction = mu'), gravity tilted by theta, released from rest.

Reference: a rigid block sliding with Coulomb friction accelerates along the floor at
a = g (sin theta - mu cos theta) (mu < tan theta). Measured: the least-squares fit
x_c = x_0 + v_0 t + a t^2 / 2 of the centre of mass (series.csv, every step).
Checks, in 2D and in 3D (the same block extruded, gravity in the x-y plane):
  * a within 1 % of g (sin theta - mu cos theta), the run reached its end time;
  * the mutant: the same floor frictionless (contact friction = 0) gives g sin theta
    within 1 %, so the friction check can fail.
Usage: check_implicit_block_coulomb.py TOOLS_DIR PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
base = tv.prm_set(base, "output/directory", "out")


def fit_a(ts, xs):
    """Second derivative of the least-squares quadratic through (ts, xs)."""
    S = [[sum(t ** (i + j) for t in ts) for j in range(3)] for i in range(3)]
    A = [S[i][:] + [sum(x * t ** i for t, x in zip(ts, xs))] for i in range(3)]
    for i in range(3):
        p = A[i][i]
        A[i] = [v / p for v in A[i]]
        for k in range(3):
            if k != i:
                f = A[k][i]
                A[k] = [vk - f * vi for vk, vi in zip(A[k], A[i])]
    return 2 * A[2][3]


def run(text, name):
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    end = float(tv.prm_get(text, "time/end time"))
    tv.check(abs(s["time"][-1] - end) < 1e-9, f"{name}: the run reached its end time")
    for line in out.splitlines():
        if "contact friction (" in line or "contact walls:" in line:
            print(f"{name}: {line.strip()}")
    return fit_a(s["time"], s["centre_of_mass_x"])


g, theta = 9.81, math.radians(30)
mu = 0.2
a_mu = g * (math.sin(theta) - mu * math.cos(theta))
a_0 = g * math.sin(theta)
three = base
for k, v in {"dimension": "3", "grid/lower corner": "0, 0, 0", "grid/upper corner": "0.6, 0.2, 0.1",
             "grid/cells": "30, 10, 5", "gravity/acceleration": "4.905, -8.495709211, 0",
             "body 0/lower corner": "0.1, 0, 0.02", "body 0/upper corner": "0.3, 0.1, 0.08"}.items():
    three = tv.prm_set(three, k, v)
for dim, text in (("2d", base), ("3d", three)):
    text = tv.prm_set(text, "boundary conditions/contact friction", str(mu))
    a = run(text, f"coulomb_{dim}")
    print(f"{dim}: mu = {mu}: fitted a = {a:.6f} m/s^2, g (sin - mu cos) = {a_mu:.6f} ({a / a_mu - 1:+.4%})")
    tv.check(abs(a / a_mu - 1) < 0.01, f"{dim}: a within 1 % of g (sin - mu cos) ({a / a_mu - 1:+.4%})")
a = run(tv.prm_set(base, "boundary conditions/contact friction", "0"), "frictionless_2d")
print(f"2d: frictionless: fitted a = {a:.6f} m/s^2, g sin = {a_0:.6f} ({a / a_0 - 1:+.4%})")
tv.check(abs(a / a_0 - 1) < 0.01, f"frictionless: a within 1 % of g sin theta ({a / a_0 - 1:+.4%})")
tv.check(abs(a / a_mu - 1) > 0.01, "frictionless: the friction check fails on it (it can fail)")
tv.finish()
