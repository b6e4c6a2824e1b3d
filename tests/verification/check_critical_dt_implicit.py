"""talus-critical-dt on implicit scenes (issue 13 item 7).
Checks, on the implicit bar (dynamic, Newmark 1/2, 1/4) and the cantilever (static):
  * the tool recognises the talus-implicit .prm, says the step is not CFL-limited
    and writes cfl_limited = 0;
  * the explicit critical step it prints equals L_min / c (c = sqrt(E/rho), nu = 0)
    to 1e-12, and the ratio of the implicit step to it is h / (L_min / c);
  * with beta = 0.2 < gamma / 2 (conditionally stable Newmark) it reports the limit
    h <= Omega_crit / omega_max with Omega_crit = 1 / sqrt(gamma/2 - beta) and
    omega_max = 2 c / L_min (the finite-element bound), flags the scene's step as above
    it, and warns that MPM lowers it (measured, docs/implicit.md: the bar diverges from
    about 0.7 x that bound with beta = 0.2);
  * --probe (an explicit-scheme option) is refused with exit 2 for an implicit scene.
Usage: check_critical_dt_implicit.py TOOLS_DIR IMPLICIT_PRM_DIR WORKDIR
"""
import math
import os
import subprocess
import sys

import talus_verify as tv

tools, prm_dir, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
tool = os.path.abspath(f"{tools}/talus-critical-dt")


def report(name, text, *options):
    prm = os.path.join(work, name + ".prm")
    with open(prm, "w") as f:
        f.write(text)
    csv = os.path.join(work, name + ".csv")
    p = subprocess.run([tool, *options, "--csv=" + csv, prm], capture_output=True, text=True, cwd=work,
                       env=tv.child_env())
    print(p.stdout)
    return p, csv


bar = open(os.path.join(prm_dir, "bar_vibration.prm")).read()
E, rho, L_min, h = 100.0, 1.0, 1.25 / 40, 0.03125
dt_cr = L_min / math.sqrt(E / rho)
p, csv = report("bar", bar)
tv.check(p.returncode == 0, f"bar: exit code {p.returncode}: {p.stderr.strip()[:300]}")
r = tv.read_csv(csv)
tv.check(abs(r["dt_critical_explicit"][0] - dt_cr) <= 1e-12 * dt_cr,
         f"bar: explicit dt_cr {r['dt_critical_explicit'][0]:.9g} s = L_min / c {dt_cr:.9g} s")
tv.check(abs(r["ratio_to_explicit"][0] - h / dt_cr) <= 1e-9 * h / dt_cr,
         f"bar: ratio {r['ratio_to_explicit'][0]:.6g} = h / dt_cr {h / dt_cr:.6g}")
tv.check(r["cfl_limited"][0] == 0 and "not CFL-limited" in p.stdout, "bar: Newmark 1/2, 1/4 is not CFL-limited")

cant = open(os.path.join(prm_dir, "cantilever_self_weight.prm")).read()
p, csv = report("cantilever", cant)
tv.check(p.returncode == 0, f"cantilever: exit code {p.returncode}: {p.stderr.strip()[:300]}")
tv.check("static analysis" in p.stdout and tv.read_csv(csv)["cfl_limited"][0] == 0,
         "cantilever: a static analysis has no step limit")

gamma, beta = 0.5, 0.2
limit = 0.5 / math.sqrt(gamma / 2 - beta) * dt_cr
bar_b = tv.prm_set(bar, "implicit/newmark beta", str(beta))
p, csv = report("bar_beta02", bar_b)
r = tv.read_csv(csv)
tv.check(p.returncode == 0 and r["cfl_limited"][0] == 1, "beta = 0.2: conditionally stable, cfl_limited = 1")
tv.check(abs(r["dt_newmark_limit"][0] - limit) <= 1e-9 * limit,
         f"beta = 0.2: Newmark limit {r['dt_newmark_limit'][0]:.6g} s = Omega_crit / omega_max {limit:.6g} s")
tv.check("ABOVE the finite-element Newmark bound" in p.stdout, "beta = 0.2: the scene's step (10 x dt_cr) is flagged above the bound")
tv.check("not a safe bound for MPM" in p.stdout, "beta = 0.2: the warning that MPM lowers the bound is printed")

p, _ = report("probe", bar, "--probe")
tv.check(p.returncode == 2 and "--probe" in p.stderr, "--probe refused for an implicit scene (exit 2)")
tv.finish()
