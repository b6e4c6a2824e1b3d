"""Stability of the explicit scheme on the elastic bar — issue 2 verification.

* dt = 0.9 x critical (seed 000 Eq. 4.120) runs to the end, exit 0, bounded energy;
* dt = 1.5 x critical without 'force time step' is refused before the run (exit 2);
* dt = 2.0 x critical forced is detected as unstable: exit 3, a message naming the
  step, and no NaN in any output file.
Note: the momentum re-projection of seed 000 §4.3.7 (Eqs. 4.47-4.48) damps the
highest grid mode (by 4x per step for the checkerboard mode with 2 points per cell),
so the measured limit of this scheme on the bar is sqrt(3) x the Eq. 4.120 value
for 2 points per direction (docs/stability-analysis.md): a forced 1.5 x run is stable.
Usage: check_stability.py TOOL PRM WORKDIR
"""
import glob
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
n = 32
h = 1.0 / n
dt_cr = h / math.sqrt(100.0 / 1.0)
base = tv.prm_set(base, "grid/cells", f"{int(1.25 * n)}, 1")
base = tv.prm_set(base, "grid/upper corner", f"1.25, {h}")
base = tv.prm_set(base, "body 0/upper corner", f"1, {h}")
base = tv.prm_set(base, "time/end time", "2.0")

t = tv.prm_set(tv.prm_set(base, "time/time step", f"{0.9 * dt_cr}"), "output/directory", "stable")
tv.run_tool(tool, t, work, "stable", expect_rc=0)
s = tv.read_csv(f"{work}/stable/series.csv")
e = [k + w for k, w in zip(s["kinetic_energy"], s["strain_energy"])]
tv.check(max(e) < 1.05 * e[0], f"0.9 x critical: energy stays bounded (max/initial = {max(e) / e[0]:.4f})")

t = tv.prm_set(tv.prm_set(base, "time/time step", f"{1.5 * dt_cr}"), "output/directory", "refused")
rc, out, err = tv.run_tool(tool, t, work, "refused", expect_rc=2)
tv.check("exceeds the critical time step" in err, "1.5 x critical refused with a clear message: " + err.strip())

t = tv.prm_set(tv.prm_set(base, "time/time step", f"{2.0 * dt_cr}"), "output/directory", "unstable")
t = tv.prm_set(t, "time/force time step", "true")
t = tv.prm_set(t, "output/vtu interval", "0.01")
rc, out, err = tv.run_tool(tool, t, work, "unstable", expect_rc=3)
tv.check("UNSTABLE" in err and "step" in err, "2.0 x critical forced: detected as unstable: " + err.strip()[:200])
# text outputs must hold no NaN/inf; binary VTUs are only written after the
# stability check of their step, so the PVD may only list steps before the stop
bad = []
texts = glob.glob(f"{work}/unstable/*.csv") + glob.glob(f"{work}/unstable/*.pvd")
for f in texts:
    txt = open(f).read().lower()
    if "nan" in txt or "inf" in txt:
        bad.append(f)
tv.check(texts and not bad, f"no NaN/inf in the text outputs ({len(texts)} files) {bad}")
import re
m = re.search(r"step (\d+) \(t = ([0-9.e+-]+) s", err)
t_stop = float(m.group(2))
pvd = open(f"{work}/unstable/particles.pvd").read()
times = [float(x) for x in re.findall(r'timestep="([^"]+)"', pvd)]
tv.check(max(times) < t_stop, f"VTU outputs end before the unstable step (last {max(times):.4g} s < {t_stop:.4g} s)")
rows = tv.read_csv(f"{work}/unstable/series.csv")
tv.check(max(rows["time"]) < t_stop, "series.csv ends before the unstable step")
tv.finish()
