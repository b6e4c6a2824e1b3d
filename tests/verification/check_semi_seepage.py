"""1D Darcy seepage through a fixed soil column under a constant head (issue 14).

Semi-implicit two-phase double-point MPM: a 0.2 m pond (a water body) on a
saturated 1 m column (n = 0.3) whose skeleton is held fixed ('rigid skeleton'),
drained base (p = 0, the water leaves), rollers on the sides, free water
surface at 1.2 m. Delta h = 1.2 m over L = 1 m, Darcy flux q = k Delta h / L
(k the hydraulic conductivity [m/s]; the drag is n^2 rho_w g / k with the
unit-weight constant g = 9.81). After the transient (its time scale is
k / (n g) ~ 3e-4 s) the flux n (v_w - v_s) (v_s = 0) averaged over the water
points in 0.3 < y < 0.7 must be within 2 % of q, and the same in the lower and
the upper half of that band (uniform flux). k = 1e-3 and 1e-4 m/s with
B-splines, k = 1e-3 with linear shape functions; 0.1 s each (667 steps; the
pond drops less than 0.5 mm, 0.25 % of its depth). Mass at the soil surface:
the pond's water (points above y = 1.05) must sink at the Darcy flux q, within
10 % (the point form phi div v* of the pressure equation let it sink at q / n).
Usage: check_semi_seepage.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
L, dh = 1.0, 1.2
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
for k, shape in (("1e-3", "quadratic bspline"), ("1e-4", "quadratic bspline"), ("1e-3", "linear")):
    text = tv.prm_set(base, "material 0/pore liquid/hydraulic conductivity", k)
    text = tv.prm_set(text, "numerics/shape function", shape)
    name = f"k{k}_" + shape.split()[-1]
    tv.run_tool(tool, text, f"{work}/{name}", name)
    w = tv.read_csv(f"{work}/{name}/out/water_final.csv")
    q_darcy = -float(k) * dh / L

    def flux(lo, hi):
        sel = [n * v for n, v, y in zip(w["porosity"], w["velocity_y"], w["pos_y"]) if lo < y < hi]
        return sum(sel) / len(sel)

    q, q_lo, q_hi = flux(0.3, 0.7), flux(0.3, 0.5), flux(0.5, 0.7)
    top = max(w["pos_y"])
    pond = [v for v, y in zip(w["velocity_y"], w["pos_y"]) if y > 1.05]
    v_pond = sum(pond) / len(pond)
    print(f"k = {k} m/s, {shape}: flux n v_w over 0.3 < y < 0.7 = {q:.5e} m/s, Darcy k dh / L = {q_darcy:.5e} m/s, "
          f"ratio {q / q_darcy:.4f} (0.3-0.5: {q_lo / q_darcy:.4f}, 0.5-0.7: {q_hi / q_darcy:.4f}); "
          f"highest water point at y = {top:.4f} m; pond velocity {v_pond:.4e} m/s = {v_pond / q_darcy:.3f} q")
    tv.check(abs(q / q_darcy - 1) < 0.02, f"k = {k}, {shape}: flux within 2 % of k dh / L ({q / q_darcy:.4f})")
    tv.check(abs(q_lo / q_darcy - 1) < 0.02 and abs(q_hi / q_darcy - 1) < 0.02,
             f"k = {k}, {shape}: the same flux in both halves of the band")
    tv.check(abs(v_pond / q_darcy - 1) < 0.1, f"k = {k}, {shape}: the pond sinks at the Darcy flux ({v_pond / q_darcy:.3f} q)")
tv.finish()
