"""talus-critical-dt on the 1D bar (partial issue 6):
  * the formula value equals L_min / c = h / sqrt(E/rho) (nu = 0) to 1e-12;
  * --probe brackets the measured limit to < 1 % and finds it at 1.7-1.8 x the
    formula (the momentum re-projection of seed 000 Eqs. 4.47-4.48 damps the highest
    grid mode; see docs/explicit.md), consistent with check_stability.py;
  * --csv writes the same numbers.
Usage: check_critical_dt.py TOOL PRM WORKDIR
"""
import os
import subprocess
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
csv = os.path.join(work, "critical_dt.csv")
p = subprocess.run([os.path.abspath(tool), "--probe", "--csv=" + csv, os.path.abspath(prm_path)],
                   capture_output=True, text=True, cwd=work)
print(p.stdout)
tv.check(p.returncode == 0, f"exit code {p.returncode}: {p.stderr.strip()[:200]}")
r = tv.read_csv(csv)
h, c = 1.0 / 32, (100.0 / 1.0) ** 0.5
tv.check(abs(r["dt_critical_formula"][0] - h / c) <= 1e-12 * h / c,
         f"formula dt_cr {r['dt_critical_formula'][0]:.9g} s = h/c {h / c:.9g} s")
lo, hi = r["probe_stable_factor"][0], r["probe_unstable_factor"][0]
tv.check(hi - lo < 0.01 * lo, f"probe brackets the limit to 1 %: stable {lo:.4f}, unstable {hi:.4f}")
tv.check(1.7 <= lo <= 1.8, f"measured limit {lo:.4f} x formula lies in [1.7, 1.8]")
q = subprocess.run([os.path.abspath(tool), "--help"], capture_output=True, text=True)
tv.check("--probe" in q.stdout and "--csv=" in q.stdout, "--help lists the tool's options")
tv.finish()
