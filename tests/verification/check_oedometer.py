"""Oedometer, quasi-static with local damping and a traction load (issue 5).

An elastic column loaded on its top face by a traction ramp (material points
of the top layer carry it, seed 000 §5.2) with local damping 0.7 (§6.3); the
stage ends by the force/energy ratio criterion (§6.4). Checks:
  * the run ended by convergence (before the end time, ratios below tolerance);
  * settlement of two points (top y = 0.99375, middle y = 0.49375) within 1 %
    of u(y) = q y / E_oed, E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu));
  * with mass scaling beta = 100 (§6.5): the same settlement (within 1 %) in
    fewer steps; the step counts are printed.
With a 4th argument `bspline` (issue 12): the same with quadratic B-spline
shape functions on a column 3 cells wide (B-splines need 3 cells per direction);
the traction point forces then reach the nodes of each point's 3 x 3 window.
With `bspline_apic` (issue 38): the same B-spline column with the affine
particle-in-cell transfer (numerics/velocity transfer = apic): the traction
point forces enter the nodal force, hence v^L, from which the points' v_p and
C_p are read back.
Usage: check_oedometer.py TOOL PRM WORKDIR [bspline | bspline_apic]
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
if len(sys.argv) > 4 and sys.argv[4] in ("bspline", "bspline_apic"):
    for key, value in {"numerics/shape function": "quadratic bspline", "grid/cells": "3, 50",
                       "grid/upper corner": "0.075, 1.25", "body 0/upper corner": "0.075, 1",
                       "output/probes": "0.0375, 1.0; 0.0375, 0.5"}.items():
        base = tv.prm_set(base, key, value)
    if sys.argv[4] == "bspline_apic":
        base = tv.prm_set(base, "numerics/velocity transfer", "apic")
E, nu, q = 1e6, 0.3, 1e3
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
points = [("probe0_uy", 0.99375), ("probe1_uy", 0.49375)]
steps = {}
for beta in (1, 100):
    name = f"beta{beta}"
    text = tv.prm_set(base, "output/directory", name)
    text = tv.prm_set(text, "mass scaling/factor", str(beta))
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    t_end, n = s["time"][-1], int(s["step"][-1])
    steps[beta] = n
    F, Er = s["force_ratio"][-1], s["energy_ratio"][-1]
    tv.check(t_end < 59.9 and F < 1e-5 and Er < 1e-7,
             f"beta = {beta}: stage ended by convergence at t = {t_end:.4f} s, step {n} "
             f"(force ratio {F:.2e} < 1e-5, energy ratio {Er:.2e} < 1e-7)")
    tv.check(t_end >= 5.0, f"beta = {beta}: not before the load ramp ended (t = {t_end:.4f} s >= 5 s)")
    for col, y in points:
        u = s[col][-1]
        ua = -q * y / E_oed
        err = abs(u - ua) / abs(ua)
        tv.check(err < 0.01, f"beta = {beta}: settlement at y = {y}: {u:.6e} m vs q y / E_oed = {ua:.6e} m "
                             f"(error {err:.2e} < 1e-2)")
print(f"steps to convergence: {steps[1]} without mass scaling, {steps[100]} with beta = 100")
tv.check(steps[100] < steps[1], f"mass scaling reaches the same state in fewer steps ({steps[100]} < {steps[1]})")
tv.finish()
