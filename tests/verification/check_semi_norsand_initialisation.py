"""Seed 002 App. B.4 initialisation (issue 14 item 4) on a level saturated
Nor-Sand column (parameter_files/verification/semi_implicit_norsand_initialisation.prm:
gravity ramped over 0.2 s, elastic Nor-Sand, water points riding on the soil,
k = 1e-2 m/s during the stage).

Run A ends at the end of the stage (0.2 s), on the initialised state:
  - pore pressure at every water point within 2 % (of rho_w g H) of -rho_w g depth;
  - row means of the soil's sigma_yy within 2 % (of the base value) of the
    buoyant weight -(1 - n)(rho_s - rho_w) g depth;
  - every soil point: reference pressure (history 11) = its current Kirchhoff
    mean stress J tr(sigma) / 3 to 1e-6 (Eq. 111), image pressure (history 8) =
    OCR (1 - N)^((1 - N) / N) x reference pressure to 1e-10 (Eq. 113, N = 0.1:
    0.38742), accumulated deviatoric plastic strain (history 9) exactly 0
    (elastic stage);
  - every water point on a soil point (gap < 1e-12 m), and the log line of the
    end of the stage printed once.
Run B continues 0.03 s with plasticity: some point yields (history 9 > 1e-6),
the stage ended once (one log line), the water points have left the soil
points (gap > 1e-9 m). The specific volume is node-smoothed (Eqs. 96-97,
v = v0 Jbar): the mass-weighted sum of v / v0 equals that of the points' own
J = V / V0 to 1e-10 (the map-remap conserves it), while single points differ
from v0 J by more than 1e-6 (the smoothing acts). Run C, the same with
'nor sand specific volume = point': v = v0 J at every point to 1e-9.
Mutant: the same run A without the stage (initialisation time = 0) must fail
the Eq. 111 check (the reference stays p0 = 2 kPa).
Usage: check_semi_norsand_initialisation.py TOOL PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
g, rw, rs, n, H, ocr, N = 9.81, 1000.0, 2650.0, 0.4, 0.4, 1.0, 0.1
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
END_LINE = "initialisation (seed 002 App. B.4) ends"


def run(name, text):
    _, out, _ = tv.run_tool(tool, text, f"{work}/{name}", name)
    soil = tv.read_csv(f"{work}/{name}/out/soil_final.csv")
    water = tv.read_csv(f"{work}/{name}/out/water_final.csv")
    return out, soil, water


def gap(soil, water):
    a, b = tv.by_initial_position(soil), tv.by_initial_position(water)
    if len(a["pos_x"]) != len(b["pos_x"]):
        return float("inf")
    return max(math.hypot(xa - xb, ya - yb) for xa, ya, xb, yb in zip(a["pos_x"], a["pos_y"], b["pos_x"], b["pos_y"]))


def reference_error(soil):
    worst = 0.0
    for i in range(len(soil["pos_x"])):
        J = soil["history_6"][i]
        p = J * (soil["stress_xx"][i] + soil["stress_yy"][i] + soil["stress_zz"][i]) / 3
        worst = max(worst, abs(soil["history_11"][i] - p) / abs(p))
    return worst


# run A: the end of the stage
out, soil, water = run("stage", base)
depth = lambda t, i: H - (t["pos_y"][i] - t["displacement_y"][i])
e_p = max(abs(water["pore_pressure"][i] + rw * g * depth(water, i)) for i in range(len(water["pos_x"]))) / (rw * g * H)
rows = {}
for i in range(len(soil["pos_x"])):
    rows.setdefault(round(depth(soil, i), 9), []).append(soil["stress_yy"][i])
gamma_b = (1 - n) * (rs - rw) * g
e_s = max(abs(sum(v) / len(v) + gamma_b * d) for d, v in rows.items()) / (gamma_b * H)
e_ref = reference_error(soil)
factor = ocr * (1 - N) ** ((1 - N) / N)
e_pi = max(abs(soil["history_8"][i] - factor * soil["history_11"][i]) / abs(soil["history_11"][i])
           for i in range(len(soil["pos_x"])))
Ed = max(abs(v) for v in soil["history_9"])
p_ref = soil["history_11"]
print(f"end of the stage: pore pressure error {e_p:.2e} (of rho_w g H), effective stress error {e_s:.2e} "
      f"(of the buoyant base value), Eq. 111 {e_ref:.1e}, Eq. 113 {e_pi:.1e}, plastic strain {Ed:g}, "
      f"reference pressure {min(p_ref):.1f} ... {max(p_ref):.1f} Pa, gap {gap(soil, water):.1e} m")
tv.check(e_p < 0.02, f"pore pressure hydrostatic within 2 % ({e_p:.2e})")
tv.check(e_s < 0.02, f"effective stress = buoyant weight within 2 % ({e_s:.2e})")
tv.check(e_ref < 1e-6, f"reference pressure = current pressure at every point (Eq. 111, {e_ref:.1e})")
tv.check(e_pi < 1e-10, f"image pressure = {factor:.5f} OCR x reference pressure (Eq. 113, {e_pi:.1e})")
tv.check(Ed == 0.0, f"no plastic strain during the elastic stage ({Ed:g})")
tv.check(gap(soil, water) < 1e-12, f"water points on the soil points during the stage ({gap(soil, water):.1e} m)")
tv.check(out.count(END_LINE) == 1, f"the end of the stage is logged once ({out.count(END_LINE)})")

# run B: 0.03 s of plastic flow after the stage
out, soil, water = run("after", tv.prm_set(base, "time/end time", "0.23"))
Ed = max(abs(v) for v in soil["history_9"])
print(f"0.03 s after the stage: largest plastic deviatoric strain {Ed:.2e}, gap {gap(soil, water):.1e} m")
tv.check(Ed > 1e-6, f"plasticity is on after the stage (largest plastic strain {Ed:.2e})")
tv.check(out.count(END_LINE) == 1, f"the stage ends once in a longer run ({out.count(END_LINE)})")
tv.check(gap(soil, water) > 1e-9, f"the water points move on their own after the stage (gap {gap(soil, water):.1e} m)")
v0 = 1.55


def specific_volume_vs_J(soil):
    m = soil["mass"]
    ratio = [soil["history_7"][i] / v0 for i in range(len(m))]
    J = [soil["volume"][i] / soil["initial_volume"][i] for i in range(len(m))]
    sums = abs(sum(a * b for a, b in zip(m, ratio)) - sum(a * b for a, b in zip(m, J))) / sum(m)
    return sums, max(abs(a - b) for a, b in zip(ratio, J))


sums, local = specific_volume_vs_J(soil)
print(f"node-smoothed specific volume: mass-weighted sums of v / v0 and J differ by {sums:.1e}, points by up to {local:.1e}")
tv.check(sums < 1e-10, f"Eq. 97 map-remap conserves the mass-weighted J ({sums:.1e})")
tv.check(local > 1e-6, f"v / v0 is the smoothed J, not the point's J ({local:.1e})")
_, soil, _ = run("point_v", tv.prm_set(tv.prm_set(base, "time/end time", "0.23"),
                                        "semi implicit/nor sand specific volume", "point"))
_, local = specific_volume_vs_J(soil)
print(f"'point' specific volume: v / v0 vs J {local:.1e}")
tv.check(local < 1e-9, f"with 'point' v = v0 J at every point ({local:.1e})")

# mutant: no stage, the reference stays p0
_, soil, _ = run("no_stage", tv.prm_set(base, "initial state/initialisation time", "0"))
e_ref = reference_error(soil)
print(f"without the stage: Eq. 111 error {e_ref:.2e}")
tv.check(e_ref > 1e-3, f"without the stage the reference is not the current pressure ({e_ref:.2e}): the check can fail")
tv.finish()
