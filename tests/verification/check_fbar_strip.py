"""F-bar against volumetric locking in the explicit family (issue 38).

1. Analytic: the first flexural mode of a free elastic strip between rollers
   (parameter_files/verification/strip_bending_incompressible.prm: L = 4 m,
   H = 0.5 m, 6 cells across, nu = 0.49, plane strain). The rollers at x = 0, L
   (u_x = 0, no shear traction) make u_y ~ cos(k x), k = pi / L, an exact mode of
   2D elasticity: the antisymmetric Rayleigh-Lamb equation
     4 k^2 p q tanh(q H/2) = (k^2 + q^2)^2 tanh(p H/2),
     p^2 = k^2 - w^2 / c_L^2, q^2 = k^2 - w^2 / c_T^2,
   solved here by bisection (T = 36.82 s; Euler-Bernoulli would give 35.64 s).
   The MPM period: twice the spacing of the zero crossings of u_y at the end.
   Criteria: linear shape functions without stabilisation lock (period more
   than 5 % short); with f-bar, linear and quadratic B-splines are within 2 %;
   quadratic B-splines without it are reported (within 2 % as well: this
   mode does not lock them, docs/explicit.md "F-bar").
2. Locking of quadratic B-splines where it shows: the near-incompressible
   layer under a strip footing (footing_incompressible.prm, the strain
   smoothing test's case; no closed form): the settlement with f-bar must be
   >= 1.05 x the plain one at nu = 0.49 and >= 1.08 x at nu = 0.499.
3. The same footing (nu = 0.49, f-bar) over 0.1 s on 2 ranks equals the 1-rank run
   (relative 1e-8 of each column's largest value).
With a last argument `cell` or `nodal`, the device is numerics/strain smoothing = cell | nodal
instead of f-bar (with linear shape functions the Q1 cell-centre value, with quadratic B-splines
the cell average of the B-spline field's divergence; docs/explicit.md "Strain smoothing"): the
same runs and bounds.
Usage: check_fbar_strip.py TOOL PRM WORKDIR [f-bar|cell|nodal]
"""
import math
import os
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
DEVICE = sys.argv[4] if len(sys.argv) > 4 else "f-bar"
if DEVICE not in ("f-bar", "cell", "nodal"):
    tv.fail(f"unknown device '{DEVICE}' (allowed: f-bar, cell, nodal)")
base = open(prm_path).read()


def with_device(text, stab):
    """`stab` "none" or "f-bar" (the stabilised run): with DEVICE cell | nodal, the
    stabilised run is strain smoothing instead of f-bar."""
    if stab == "f-bar" and DEVICE != "f-bar":
        text = tv.prm_set(text, "numerics/volumetric stabilisation", "none")
        return tv.prm_set(text, "numerics/strain smoothing", DEVICE)
    return tv.prm_set(text, "numerics/volumetric stabilisation", stab)
L, H, G, rho, nu = 4.0, 0.5, 1.0, 1.0, 0.49


def rayleigh_lamb_period(nu):
    k, h = math.pi / L, H / 2
    cT = math.sqrt(G / rho)
    cL = cT * math.sqrt(2 * (1 - nu) / (1 - 2 * nu))

    def f(w):
        p = math.sqrt(k * k - w * w / cL**2)
        q = math.sqrt(k * k - w * w / cT**2)
        return 4 * k * k * p * q * math.tanh(q * h) - (k * k + q * q) ** 2 * math.tanh(p * h)

    # the flexural branch lies below the shear wave (w < c_T k): the first sign change
    # of f on a grid from w = 1e-3 c_T k (f ~ w^2 cancels below), then bisection
    ws = [cT * k * (1e-3 + (1 - 1e-3 - 1e-9) * i / 2000) for i in range(2001)]
    i = next(i for i in range(2000) if (f(ws[i]) > 0) != (f(ws[i + 1]) > 0))
    a, b = ws[i], ws[i + 1]
    fa = f(a)
    for _ in range(200):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return 2 * math.pi / (0.5 * (a + b))


T_exact = rayleigh_lamb_period(nu)
print(f"Rayleigh-Lamb period at nu = {nu}: {T_exact:.4f} s")


def period(shape, stab):
    name = f"strip_{shape.split()[-1]}_{stab}"
    text = with_device(tv.prm_set(base, "numerics/shape function", shape), stab)
    text = tv.prm_set(text, "output/directory", name)
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    z = tv.zero_crossings(s["time"], s["probe0_uy"])
    tv.check(len(z) >= 2, f"{shape}, {stab}: at least 2 zero crossings of u_y (got {len(z)})")
    if len(z) < 2:
        return float("nan")
    T = 2 * (z[-1] - z[0]) / (len(z) - 1)
    e = T / T_exact - 1
    print(f"  {shape}, {DEVICE if stab != 'none' else 'none'}: T = {T:.4f} s, error {e:+.2%}")
    return e


e = {(sh, st): period(sh, st) for sh in ("linear", "quadratic bspline") for st in ("none", "f-bar")}
tv.check(e["linear", "none"] < -0.05, f"linear, none: locked, period error {e['linear', 'none']:+.2%} < -5 %")
for sh in ("linear", "quadratic bspline"):
    tv.check(abs(e[sh, "f-bar"]) < 0.02, f"{sh}, {DEVICE}: |period error| {abs(e[sh, 'f-bar']):.2%} < 2 %")
tv.check(abs(e["quadratic bspline", "none"]) < 0.02,
         f"quadratic bspline, none: |period error| {abs(e['quadratic bspline', 'none']):.2%} < 2 % (no locking here)")

# 2. the footing: quadratic B-splines lock under a constrained, non-smooth load
footing = open(os.path.join(os.path.dirname(prm_path), "footing_incompressible.prm")).read()


def footing_text(nu, stab):
    text = tv.prm_set(footing, "material 0/linear elastic/young modulus", repr(2 * 1e6 * (1 + nu)))
    text = tv.prm_set(text, "material 0/linear elastic/poisson ratio", str(nu))
    text = tv.prm_set(text, "numerics/shape function", "quadratic bspline")
    return with_device(text, stab)


def settlement(nu, stab):
    name = f"footing_{nu}_{stab}"
    tv.run_tool(tool, tv.prm_set(footing_text(nu, stab), "output/directory", name), work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    sel = [u for t, u in zip(s["time"], s["probe0_uy"]) if t >= 0.25 * s["time"][-1]]
    return -sum(sel) / len(sel)


for nu_f, bound in ((0.49, 1.05), (0.499, 1.08)):
    plain, fbar = settlement(nu_f, "none"), settlement(nu_f, "f-bar")
    print(f"  footing, quadratic bspline, nu = {nu_f}: settlement {plain:.4e} m plain, {fbar:.4e} m {DEVICE}")
    tv.check(fbar / plain >= bound, f"nu = {nu_f}: {DEVICE} / plain settlement {fbar / plain:.3f} >= {bound}")

# 3. the node map-remap across ranks: the first 0.1 s of the nu = 0.49 f-bar footing on 2 ranks
# (points of a cell near the partition reach ghost nodes) equals the 1-rank run
name = "footing_0.49_f-bar_np2"
text = tv.prm_set(tv.prm_set(footing_text(0.49, "f-bar"), "time/end time", "0.1"), "output/directory", name)
tv.run_tool(tool, text, work, name, np=2)
one, two = tv.read_csv(f"{work}/footing_0.49_f-bar/series.csv"), tv.read_csv(f"{work}/{name}/series.csv")
worst = 0.0
n = len(two["time"]) - 1  # the last row of the short run ends on a shortened step at t = 0.1
for col in ("kinetic_energy", "strain_energy", "probe0_uy", "probe0_stress_yy"):
    scale = max(abs(x) for x in one[col][:n])
    worst = max(worst, max(abs(a - b) for a, b in zip(one[col][:n], two[col][:n])) / scale)
tv.check(worst < 1e-8 and one["time"][:n] == two["time"][:n],
         f"1 vs 2 ranks over 0.1 s ({n} rows): largest relative difference {worst:.1e} < 1e-8")
tv.finish()
