"""A water body on a soil body: a 0.2 m pond on a saturated 1 m column (issue 14).

Semi-implicit two-phase double-point MPM, quadratic B-splines. The pond is a
'water' body (free water, porosity 1) on a saturated column (n = 0.3, rho_s =
2650, E = 10 MPa), rollers on the sides and the closed base, started in the
geostatic state with the water level at 1.2 m, run 0.3 s (2000 steps) for
k = 1e-3 and 1e-7 m/s at the same step. With d = 1.2 - y the depth below the
free water surface:
  water points (pond and pores): pore pressure p = -rho_w g d (tension positive)
  soil points: sigma'_yy = -(1-n)(rho_s - rho_w) g (1 - y)
each within 1 % of its value at the base (max |error| over all points); the
run ends without instability (before the fix: det(dF) < 0 within 5 steps),
every point kept, the soil at rest (< 1e-4 m/s).
Usage: check_semi_pond.py TOOL PRM WORKDIR [--linear]
  --linear: the same with linear shape functions
"""
import sys

import talus_verify as tv

linear = "--linear" in sys.argv
tool, prm_path, work = [a for a in sys.argv if not a.startswith("--")][1:4]
g, Hw, Hs, n, rs, rw = 9.81, 1.2, 1.0, 0.3, 2650.0, 1000.0
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
if linear:
    base = tv.prm_set(base, "numerics/shape function", "linear")
for k in ("1e-3", "1e-7"):
    text = tv.prm_set(base, "material 0/pore liquid/hydraulic conductivity", k)
    name = f"k{k}"
    _, out, err = tv.run_tool(tool, text, f"{work}/{name}", name)
    w = tv.read_csv(f"{work}/{name}/out/water_final.csv")
    s = tv.read_csv(f"{work}/{name}/out/soil_final.csv")
    pw_ref, sv_ref = rw * g * Hw, (1 - n) * (rs - rw) * g * Hs
    ep = max(abs(p + rw * g * max(0.0, Hw - y)) for p, y in zip(w["pore_pressure"], w["pos_y"])) / pw_ref
    es = max(abs(sy + (1 - n) * (rs - rw) * g * (Hs - y)) for sy, y in zip(s["stress_yy"], s["pos_y"])) / sv_ref
    vs = max(max(abs(a), abs(b)) for a, b in zip(s["velocity_x"], s["velocity_y"]))
    vw = max(max(abs(a), abs(b)) for a, b in zip(w["velocity_x"], w["velocity_y"]))
    print(f"k = {k} m/s: {len(w['pos_y'])} water + {len(s['pos_y'])} soil points; max |p + rho_w g d| / (rho_w g 1.2) = "
          f"{ep:.3e}, max |sigma'_yy - ref| / ((1-n)(rho_s-rho_w) g H) = {es:.3e}, max soil speed {vs:.2e} m/s, "
          f"max water speed {vw:.2e} m/s")
    tv.check(len(w["pos_y"]) == 576 and len(s["pos_y"]) == 480, f"k = {k}: every point kept")
    tv.check(ep < 0.01, f"k = {k}: pore pressure within 1 % of rho_w g d (error {ep:.2e})")
    tv.check(es < 0.01, f"k = {k}: vertical effective stress within 1 % (error {es:.2e})")
    tv.check(vs < 1e-4, f"k = {k}: soil at rest (max point speed {vs:.2e} m/s < 1e-4)")
tv.finish()
