"""Large-deformation 1D consolidation, the paper's §5.2 / Table 2 (seed 002,
issue 14): H = 1 m, E = 1 MPa, nu = 0, q = 200 kPa applied suddenly, k = 1e-3
m/s, n0 = 0.3, no body force (the drag's g = 9.81), run to T_v = 2 with
T_v = k t / (m_v rho_w g H^2), m_v = 1 / E.

The settlement is the column's shortening, S = H (1 - V / V0) with V the
soil points' total (mixture) volume (series.csv 'soil_volume'; exact for the
1D column between rollers). Ultimate settlements from the constitutive law,
the Cauchy stress -q in the consolidated column (lambda = the vertical stretch):
  finite strain, Hencky (tau = E ln lambda, sigma = tau / lambda):
      ln lambda + (q / E) lambda = 0, S = H (1 - lambda)            (0.15542 m)
  small-strain rate model (sigma = E ln lambda, integrated in the moving frame):
      S = H (1 - exp(-q / E))                                         (0.18127 m)
Check: |S(T_v = 2) - S_ultimate| / S_ultimate < TOL (the issue's 1 %) for each
model asked for. The settlement history (t, T_v, S, S / S_ultimate, and the
degree of consolidation of the single-drainage Xie & Leo form
U = 1 - sum 2 / M^2 exp(-M^2 T_v), M = (m - 1/2) pi) is written to
<WORKDIR>/<model>/settlement_history.csv.
The load acts on the body surface (`surface load acts at = body surface`, the
default); MODEL@top runs it at the top layer of points instead (the earlier
point-force load, which leaves the top half-row unloaded): that run must MISS
the tolerance by more than twice the surface run's error, which shows that the
check can fail and that the face integration is what meets it.
k and the end time are read from the .prm after the --set changes (the fast
ctest raises k to 1e-2 m/s: T_v = 2 at 1.962 s).
Usage: check_semi_large_consolidation.py TOOL PRM WORKDIR TOL MODEL[,MODEL] [--set=entry=value ...]
  MODEL: hencky (the .prm's hencky mohr coulomb) or small-strain (model = linear elastic),
         optionally with the suffix @top
"""
import math
import os
import re
import sys

import talus_verify as tv

sets = [a[len("--set="):].split("=", 1) for a in sys.argv if a.startswith("--set=")]
args = [a for a in sys.argv if not a.startswith("--set=")]
tool, prm_path, work, tol, models = args[1], args[2], args[3], float(args[4]), args[5].split(",")
q, H, E, rw, g = 2e5, 1.0, 1e6, 1000.0, 9.81
mv = 1 / E


def hencky_stretch():
    lam = 1.0
    for _ in range(50):  # Newton on ln(lam) + (q / E) lam = 0
        lam -= (math.log(lam) + q / E * lam) / (1 / lam + q / E)
    return lam


ultimate = {"hencky": H * (1 - hencky_stretch()), "small-strain": H * (1 - math.exp(-q / E))}


def degree_of_consolidation(Tv):
    return 1 - sum(2 / M ** 2 * math.exp(-M * M * Tv) for M in ((m - 0.5) * math.pi for m in range(1, 400)))


base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
for entry, value in sets:
    base = tv.prm_set(base, entry.strip(), value.strip())
k = float(re.search(r"set\s+hydraulic conductivity\s*=\s*([-+0-9.eE]+)", base).group(1))
errors = {}
for name in models:
    model, top = name.split("@")[0], name.endswith("@top")
    text = base if model == "hencky" else tv.prm_set(base, "material 0/model", "linear elastic")
    if top:
        text = tv.prm_set(text, "body 0/surface load acts at", "top points")
    d = os.path.join(work, name.replace("@", "_"))
    tv.run_tool(tool, text, d, model)
    ser = tv.read_csv(f"{d}/out/series.csv")
    V0 = ser["soil_volume"][0]
    S_ult = ultimate[model]
    rows = ["time,T_v,settlement,settlement_over_ultimate,U_xie_leo_single_drainage"]
    for t, V in zip(ser["time"], ser["soil_volume"]):
        Tv = k * t / (mv * rw * g * H * H)
        S = H * (1 - V / V0)
        rows.append(f"{t:.6g},{Tv:.6g},{S:.8g},{S / S_ult:.6g},{degree_of_consolidation(Tv) if Tv > 0 else 0.0:.6g}")
    with open(f"{d}/settlement_history.csv", "w") as f:
        f.write("\n".join(rows) + "\n")
    soil = tv.read_csv(f"{d}/out/soil_final.csv")
    S = H * (1 - sum(soil["volume"]) / sum(soil["initial_volume"]))
    Tv = k * ser["time"][-1] / (mv * rw * g * H * H)
    water = tv.read_csv(f"{d}/out/water_final.csv")
    p_excess = max(abs(p) for p in water["pore_pressure"]) / q
    for frac in (0.1, 0.25, 0.5, 1.0):  # a few points of the history
        i = min(range(len(ser["time"])), key=lambda j: abs(ser["time"][j] - frac * ser["time"][-1]))
        print(f"{model}: {rows[i + 1]}")
    e = (S - S_ult) / S_ult
    errors[name] = e
    print(f"{name}: T_v = {Tv:.4f}: settlement {S:.5f} m, ultimate {S_ult:.5f} m, relative error {e:+.3%}; "
          f"largest |p| / q {p_excess:.2e}")
    tv.check(abs(Tv - 2) < 1e-3, f"{name}: the run reached T_v = {Tv:.4f} (2 expected)")
    if top:
        surface = errors.get(model)
        tv.check(abs(e) > tol and (surface is None or abs(e) > 2 * abs(surface)),
                 f"{name}: the load at the top points misses: {e:+.2%} (beyond {tol:.0%}"
                 + (f" and twice the surface run's {surface:+.2%})" if surface is not None else ")"))
    else:
        tv.check(abs(e) < tol, f"{name}: settlement {S:.5f} m within {tol:.0%} of {S_ult:.5f} m ({e:+.2%})")
tv.finish()
