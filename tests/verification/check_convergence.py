"""talus-convergence (issue 6):
  * the 1D elastic bar (fixed-free, small amplitude, the points never leave their cells)
    at 8/16/32/64 cells: observed order of the displacement error >= 1.8;
  * the translating free-free bar (points cross up to ~40 cells) at 16/32/64/128 cells,
    Courant number 0.5: the scheme analysis (docs/stability-analysis.md, "Cell crossing")
    predicts that the frozen-coefficient step stays stable (limit >= sqrt(2) h/c for any
    shift of the points) but that the moving points make the step parametrically unstable
    (growth rate ~ 1/h over a fixed time): the fitted order must fall below 1.0 and the
    finest run must not beat the 32-cell run;
    at Courant number 0.1 the 128-cell error must be below the 32-cell error at 0.5
    (the crossing error depends on dt);
  * the cause, predicted by the Floquet analysis of the translating state (talus-critical-dt
    --crossing-velocity): perturbations grow by a factor mu > 1 per step (1.0355 at dt c/h =
    0.5, V/c = 0.2, 2 points per cell), a rate ln(mu)/dt ~ 1/h; the growth rate measured
    on the 256-cell run must be within 10 % of it;
  * CSV and plots are written; --check passes; bad input exits 2 before any output.
Usage: check_convergence.py CONVERGENCE_TOOL PRM_DIR WORKDIR
"""
import os
import subprocess
import sys

import talus_verify as tv

tool, prm_dir, work = sys.argv[1:4]
tool = os.path.abspath(tool)
os.makedirs(work, exist_ok=True)


def convergence(prm_text, name):
    prm = os.path.join(work, name + ".prm")
    with open(prm, "w") as f:
        f.write(prm_text)
    p = subprocess.run([tool, prm], capture_output=True, text=True, cwd=work)
    print(p.stdout)
    if p.returncode != 0:
        print(p.stderr)
        tv.fail(f"{name}: exit code {p.returncode}")
    return p


def base(name):
    text = open(os.path.join(prm_dir, "convergence", name + ".prm")).read()
    return text.replace("../verification/", os.path.join(os.path.abspath(prm_dir), "verification") + "/")


# 1. no cell crossing
t = tv.prm_set(base("bar_displacement"), "output/directory", "bar")
convergence(t, "bar")
s = tv.read_csv(os.path.join(work, "bar", "bar_displacement_summary.csv"))
r = tv.read_csv(os.path.join(work, "bar", "bar_displacement.csv"))
order = s["observed_order"][0]
print("bar errors:", ", ".join(f"{e:.3e}" for e in r["error"]))
tv.check(len(r["error"]) == 4, "4 runs in the CSV")
tv.check(order >= 1.8, f"bar displacement: observed order {order:.3f} >= 1.8")
for f in ("bar_displacement_error.png", "bar_displacement_work.png"):
    path = os.path.join(work, "bar", f)
    tv.check(os.path.isfile(path) and open(path, "rb").read(4) == b"\x89PNG", f"plot {f} written")

# 2. cell crossing
t = tv.prm_set(base("translating_bar"), "output/directory", "crossing")
t = tv.prm_set(t, "family/values", "16, 32, 64, 128")
convergence(t, "crossing")
s = tv.read_csv(os.path.join(work, "crossing", "translating_bar_summary.csv"))
r = tv.read_csv(os.path.join(work, "crossing", "translating_bar.csv"))
e = dict(zip(r["value"], r["error"]))
order_x = s["observed_order"][0]
print("crossing errors:", ", ".join(f"{x:.3e}" for x in r["error"]))
tv.check(order_x < 1.0, f"cell crossing: fitted order {order_x:.3f} < 1.0 (second order lost)")
tv.check(e[128] >= e[32], f"cell crossing: 128-cell error {e[128]:.3e} not below the 32-cell error {e[32]:.3e}")
t = tv.prm_set(t, "output/directory", "crossing_c01")
t = tv.prm_set(t, "family/values", "64, 128")
t = tv.prm_set(t, "family/substitution 5", "time/courant number = 0.1")
convergence(t, "crossing_c01")
r = tv.read_csv(os.path.join(work, "crossing_c01", "translating_bar.csv"))
e01 = dict(zip(r["value"], r["error"]))
tv.check(e01[128] < e[32], f"cell crossing at Courant 0.1: 128-cell error {e01[128]:.3e} < {e[32]:.3e} (32 cells, 0.5)")

# 2b. the growth of the crossing instability: measured on the 256-cell run (strain energy
# ~ amplitude^2 once the growing mode dominates) against the Floquet analysis of
# talus-critical-dt --crossing-velocity (growth per step of the translating state)
tools = os.path.dirname(tool)
text = open(os.path.join(prm_dir, "verification", "translating_bar.prm")).read()
for k, v in (("grid/cells", "512, 1"), ("grid/upper corner", "2, 0.00390625"),
             ("body 0/upper corner", "1.5, 0.00390625"), ("output/directory", "growth")):
    text = tv.prm_set(text, k, v)
tv.run_tool(os.path.join(tools, "talus-explicit"), text, work, "growth")
growth_csv = os.path.join(work, "growth_dt.csv")
p = subprocess.run([os.path.join(tools, "talus-critical-dt"), "--crossing-velocity=2", "--csv=" + growth_csv,
                    os.path.join(work, "growth.prm")], capture_output=True, text=True, cwd=work)
print(p.stdout)
tv.check(p.returncode == 0, f"talus-critical-dt --crossing-velocity: exit {p.returncode} {p.stderr[:200]}")
predicted = tv.read_csv(growth_csv)["crossing_growth_rate"][0]
s = tv.read_csv(os.path.join(work, "growth", "series.csv"))
rate, n_fit = tv.parasitic_growth_rate(s)
tv.check(n_fit > 50, f"the growing mode dominates the strain energy (linear regime) over {n_fit} steps (> 50)")
tv.check(abs(rate / predicted - 1) <= 0.10,
         f"crossing growth rate: measured {rate:.1f} 1/s, predicted {predicted:.1f} 1/s (within 10 %)")

# 3. --check and bad input
good = os.path.join(work, "bar.prm")
p = subprocess.run([tool, "--check", good], capture_output=True, text=True, cwd=work)
tv.check(p.returncode == 0, f"--check of a good file: exit {p.returncode}")
bad_cases = {
    "unknown entry": (tv.prm_set(open(good).read(), "family/colour", "red"), "colour"),
    "bad parameter": (tv.prm_set(open(good).read(), "family/parameter", "mesh size"), "cell size | particles"),
    "bad expression": (tv.prm_set(open(good).read(), "family/substitution 1", "grid/cells = {import(N)}, 1"), "substitution 1"),
    "missing constant": (tv.prm_set(open(good).read(), "reference/constants", "L=1, E=100"), "rho"),
    "solver refuses": (tv.prm_set(open(good).read(), "family/substitution 1", "grid/cells = {-N}, 1"), "--check"),
}
for what, (text, token) in bad_cases.items():
    d = os.path.join(work, "bad_" + what.replace(" ", "_"))
    os.makedirs(d, exist_ok=True)
    prm = os.path.join(d, "in.prm")
    with open(prm, "w") as f:
        f.write(text.replace("set directory = bar", f"set directory = {d}/out"))
    p = subprocess.run([tool, prm], capture_output=True, text=True, cwd=d)
    msg = p.stderr.strip()
    tv.check(p.returncode == 2 and token in msg and not os.path.exists(os.path.join(d, "out")),
             f"{what}: exit {p.returncode}, message names it, no output: {msg[:160]}")
tv.finish()
