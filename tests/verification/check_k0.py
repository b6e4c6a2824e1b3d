"""K0 initial stresses (issue 5): an elastic column (fixed base, roller sides)
starts from sigma_v = -rho g (H - y), sigma_h = K0 sigma_v and must stay at
rest under gravity without damping: the largest probe velocity over 0.3 s must
be below 1 % of the peak velocity of the same column released stress-free;
sigma_xx / sigma_yy at the end within 1e-3 of K0 (the exact ratio at t = 0 is
checked to round-off by the unit test test_loads).
Usage: check_k0.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
vmax = {}
for k0 in (True, False):
    name = "k0" if k0 else "stress_free"
    text = tv.prm_set(base, "output/directory", name)
    text = tv.prm_set(text, "body 0/initial stress/K0 procedure", "true" if k0 else "false")
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    vmax[name] = max(max(abs(v) for v in s[c]) for c in ("probe0_vy", "probe1_vy"))
print(f"largest probe velocity: {vmax['k0']:.3e} m/s from K0 stresses, {vmax['stress_free']:.3e} m/s stress-free")
tv.check(vmax["k0"] < 0.01 * vmax["stress_free"],
         f"column from K0 stresses stays at rest ({vmax['k0']:.2e} < 1 % of {vmax['stress_free']:.2e} m/s)")
p = tv.read_csv(f"{work}/k0/particles_final.csv")
worst = max(abs(sx / sy - 0.5) for sx, sy in zip(p["stress_xx"], p["stress_yy"]) if sy < -1.0)
tv.check(worst < 1e-3, f"sigma_xx / sigma_yy stays within 1e-3 of K0 = 0.5 (worst deviation {worst:.2e})")
tv.finish()
