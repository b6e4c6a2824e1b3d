"""Hydrostatic columns (issue 5): 1-phase liquid and 2-phase coupled soil.

Released stress-free under gravity, the column settles (viscosity for the
liquid, local damping for the 2-phase soil) to the hydrostatic state. With Y the
initial height of a material point (Lagrangian: the mass above it never changes)
and H = 1 m the initial height of the column:
  liquid:  pressure p = -tr(sigma)/3 = rho g (H - Y)
  2-phase: pore pressure p = rho_L g (H - Y), vertical effective stress
           sigma'_yy = -(rho_sat - rho_L) g (H - Y), rho_sat = (1-n) rho_S + n rho_L
Every point must be within 2 % of the value at the base (max |error| / (rho g H)),
and the column must be at rest (final kinetic energy < 1e-3 of its peak).
Usage: check_hydrostatic.py TOOL PRM WORKDIR liquid|two-phase [model] [entry=value ...]
  entry=value: .prm settings applied first (e.g. numerics/shape function=quadratic bspline);
  model (liquid only): newtonian (default) | bingham | frictional fluid; the
  frictional fluid carries a deviatoric stress at rest, so for it the vertical
  stress -sigma_yy = rho g (H - Y) is checked instead of the pressure.
"""
import sys

import talus_verify as tv

tool, prm_path, work, mode = sys.argv[1:5]
rest = [a for a in sys.argv[5:] if "=" not in a]
model = rest[0] if rest else "newtonian"
text = tv.prm_set_args(open(prm_path).read(), [a for a in sys.argv[5:] if "=" in a])
text = tv.prm_set(text, "output/directory", "out")
g, H = 9.81, 1.0
if mode == "liquid" and model != "newtonian":
    text = tv.prm_set(text, "material 0/model", model)
    for m in ("bingham", "frictional fluid"):
        text = tv.prm_set(text, f"material 0/{m}/bulk modulus", "1e6")
        text = tv.prm_set(text, f"material 0/{m}/dynamic viscosity", "5000")
        text = tv.prm_set(text, f"material 0/{m}/maximum viscosity", "5000")
        text = tv.prm_set(text, f"material 0/{m}/young modulus", "1e5")
        text = tv.prm_set(text, f"material 0/{m}/poisson ratio", "0.3")
    text = tv.prm_set(text, "material 0/bingham/yield stress", "1")
    text = tv.prm_set(text, "material 0/frictional fluid/friction angle", "20")
tv.run_tool(tool, text, work, "hydrostatic")
p = tv.read_csv(f"{work}/out/particles_final.csv")
s = tv.read_csv(f"{work}/out/series.csv")
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
ke = s["kinetic_energy"]
tv.check(ke[-1] < 1e-3 * max(ke), f"at rest: final kinetic energy {ke[-1]:.3e} J < 1e-3 x peak {max(ke):.3e} J")

if mode == "liquid":
    rho = 1000.0
    if model == "frictional fluid":
        val = [-syy for syy in p["stress_yy"]]
        what = "vertical stress -sigma_yy"
    else:
        val = [-(a + b + c) / 3 for a, b, c in zip(p["stress_xx"], p["stress_yy"], p["stress_zz"])]
        what = "pressure"
    ref = [rho * g * (H - y) for y in Y]
    err = max(abs(a - b) for a, b in zip(val, ref)) / (rho * g * H)
    print(f"{model}: {len(val)} points, max |{what} - rho g (H - Y)| / (rho g H) = {err:.3e}")
    tv.check(err < 0.02, f"{what} within 2 % of rho g h at every point (error {err:.2e})")
    if "free_surface" in p:
        top = max(Y)
        flagged = [y for y, f in zip(Y, p["free_surface"]) if f > 0.5]
        tv.check(len(flagged) > 0 and min(flagged) > top - 0.05,
                 f"free surface detected at the top only: {len(flagged)} points, lowest Y "
                 f"{min(flagged) if flagged else float('nan'):.4f} m (top row Y {top:.4f} m)")
        tv.check("free_surface_points" in s and s["free_surface_points"][-1] == len(flagged),
                 "series.csv counts the free-surface points")
else:
    n, rhoS, rhoL = 0.3, 2650.0, 1000.0
    rho_sat = (1 - n) * rhoS + n * rhoL
    pw = p["pore_pressure"]
    ref_p = [rhoL * g * (H - y) for y in Y]
    err_p = max(abs(a - b) for a, b in zip(pw, ref_p)) / (rhoL * g * H)
    ref_s = [-(rho_sat - rhoL) * g * (H - y) for y in Y]
    err_s = max(abs(a - b) for a, b in zip(p["stress_yy"], ref_s)) / ((rho_sat - rhoL) * g * H)
    print(f"2-phase: {len(pw)} points, pore pressure error {err_p:.3e}, effective stress error {err_s:.3e} "
          f"(max |error| / value at the base)")
    tv.check(err_p < 0.02, f"pore pressure within 2 % of rho_L g h (error {err_p:.2e})")
    tv.check(err_s < 0.02, f"vertical effective stress within 2 % of (rho_sat - rho_L) g h (error {err_s:.2e})")
tv.finish()
