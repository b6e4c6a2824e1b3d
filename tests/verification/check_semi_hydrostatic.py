"""Hydrostatic saturated column, semi-implicit two-phase double-point MPM (issue 14).

The column (H = 1 m, n = 0.3, rho_s = 2650, rho_w = 1000, E = 10 MPa) starts in
the geostatic state and runs 0.3 s (2000 steps) at 0.44 of the soil skeleton's
critical step, for k = 1e-3 and k = 1e-7 m/s at the SAME time step (the step
does not depend on k). At the end, with d = H - y the depth of a point:
  water points: pore pressure p = -rho_w g d (tension positive)
  soil points:  vertical effective stress sigma'_yy = -(1-n)(rho_s - rho_w) g d
Each within 1 % of its value at the base (max |error| over all points / value
at d = H); the soil at rest (max soil point speed < 1e-4 m/s); no drift: the
water's kinetic energy at the end at most 1.1 x its value at half time and the
lowest pore pressure (series.csv) changing by less than 0.1 % of rho_w g H over
the second half. The explicit 2-phase
critical step of the same scene (talus-critical-dt, Eq. 4.129 of seed 000) is
printed beside the step used, with the ratio.
Usage: check_semi_hydrostatic.py TOOL PRM WORKDIR [CRITICAL_DT_TOOL EXPLICIT_PRM] [--end-time=T]
  --end-time=1.5: 10^4 steps (the 'no drift over 10^4 steps' of issue 14; make verify)
"""
import re
import sys

import talus_verify as tv

end_time = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--end-time=")), None)
args = [a for a in sys.argv if not a.startswith("--end-time=")]
tool, prm_path, work = args[1:4]
crit_tool = args[4] if len(args) > 5 else None
explicit_prm = args[5] if len(args) > 5 else None
g, H, n, rs, rw = 9.81, 1.0, 0.3, 2650.0, 1000.0
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
if end_time:
    base = tv.prm_set(base, "time/end time", end_time)
dts = {}
for k in ("1e-3", "1e-7"):
    text = tv.prm_set(base, "material 0/pore liquid/hydraulic conductivity", k)
    name = f"k{k}"
    _, out, _ = tv.run_tool(tool, text, f"{work}/{name}", name)
    m = re.search(r"time step ([0-9.eE+-]+) s", out)
    dts[k] = float(m.group(1)) if m else float("nan")
    w = tv.read_csv(f"{work}/{name}/out/water_final.csv")
    s = tv.read_csv(f"{work}/{name}/out/soil_final.csv")
    pw_ref, sv_ref = rw * g * H, (1 - n) * (rs - rw) * g * H
    ep = max(abs(p + rw * g * (H - y)) for p, y in zip(w["pore_pressure"], w["pos_y"])) / pw_ref
    es = max(abs(sy + (1 - n) * (rs - rw) * g * (H - y)) for sy, y in zip(s["stress_yy"], s["pos_y"])) / sv_ref
    v = max(max(abs(a), abs(b)) for a, b in zip(s["velocity_x"], s["velocity_y"]))
    vw = max(max(abs(a), abs(b)) for a, b in zip(w["velocity_x"], w["velocity_y"]))
    ser = tv.read_csv(f"{work}/{name}/out/series.csv")
    t, half = ser["time"], ser["time"][-1] / 2
    i_half = min(range(len(t)), key=lambda i: abs(t[i] - half))
    ekw_half, ekw_end = ser["kinetic_energy_water"][i_half], ser["kinetic_energy_water"][-1]
    drift = abs(ser["min_pore_pressure"][-1] - ser["min_pore_pressure"][i_half]) / pw_ref
    print(f"k = {k} m/s: dt = {dts[k]:.4e} s, {len(w['pos_y'])} water + {len(s['pos_y'])} soil points; "
          f"max |p + rho_w g d| / (rho_w g H) = {ep:.3e}, max |sigma'_yy - ref| / ((1-n)(rho_s-rho_w) g H) = {es:.3e}, "
          f"max soil speed {v:.2e} m/s, max water speed {vw:.2e} m/s, water kinetic energy {ekw_half:.3e} J at "
          f"t = {t[i_half]:.3f} s, {ekw_end:.3e} J at the end, base pressure drift {drift:.2e}")
    tv.check(ep < 0.01, f"k = {k}: pore pressure within 1 % of rho_w g d (error {ep:.2e})")
    tv.check(es < 0.01, f"k = {k}: vertical effective stress within 1 % of (1-n)(rho_s-rho_w) g d (error {es:.2e})")
    tv.check(v < 1e-4, f"k = {k}: soil at rest (max point speed {v:.2e} m/s < 1e-4)")
    tv.check(ekw_end <= 1.1 * ekw_half + 1e-12, f"k = {k}: water kinetic energy not growing ({ekw_half:.2e} -> {ekw_end:.2e} J)")
    tv.check(drift < 1e-3, f"k = {k}: base pore pressure drift over the second half {drift:.2e} < 1e-3 rho_w g H")
tv.check(dts["1e-3"] == dts["1e-7"], f"same time step for both k ({dts['1e-3']:.4e} s, {dts['1e-7']:.4e} s)")

if crit_tool and explicit_prm:
    for k in ("1e-3", "1e-7"):
        text = tv.prm_set(open(explicit_prm).read(), "material 0/pore liquid/hydraulic conductivity", k)
        text = tv.prm_set(text, "output/directory", "out")
        _, out, _ = tv.run_tool(crit_tool, text, f"{work}/explicit_k{k}", "critical")
        m = re.search(r"; critical time step (\S+) s", out)
        if m:
            dte = float(m.group(1))
            print(f"k = {k} m/s: explicit 2-phase critical step {dte:.3e} s; semi-implicit step "
                  f"{dts[k]:.3e} s = {dts[k] / dte:.1f} x larger")
        else:
            print(out)
            tv.check(False, "talus-critical-dt printed a critical time step")
tv.finish()
