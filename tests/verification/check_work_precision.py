"""The fast subset of the work-precision campaign (issue 42): every family of every scene of
tests/verification/work_precision.py (talus-explicit, talus-fem, talus-implicit,
talus-semi-implicit on the shared scene fragments parameter_files/work_precision/scenes/*.inc)
run by talus-convergence at the scene's two smallest resolutions (Scene.fast_values; the
column collapse, whose Richardson reference needs 3 runs of up to a minute each, is in the full
campaign only). Checks:
  * every run completes and the family's criterion holds on the two runs: the pairwise order
    within the stated range (bar: explicit [1.8, 2.6], implicit Newmark [1.8, 3.6]; cantilever
    [1.5, 2.3] for MPM damped to rest, UL-FEM and implicit static; Terzaghi explicit [0.8, 1.2])
    and/or every error below the stated bound (Terzaghi semi-implicit: 3e-3);
  * the work measures of each tool: talus-implicit reports Newton and linear iterations (> 0,
    linear >= Newton), talus-semi-implicit pressure CG iterations (> 0) and no Newton
    iterations, talus-explicit / talus-fem neither; every run reports its points and steps and
    a time-loop wall time no longer than the whole process;
  * the same scene gives the same problem to every tool: on the coarser resolution the families
    of a scene that share the cell size also share the number of points of the solid;
  * the `value` reference of talus-convergence refuses V = 0, a missing V and a missing quantity
    (exit 2, naming the entry, nothing written);
  * the `particles:<column>:front` quantity (the column collapse's run-out) on points of known
    spacing: the front of the contiguous body to 1e-12, a stray point left out;
  * the column collapse's fragment is one problem for both tools: at N = 12 the run-outs of
    talus-explicit and talus-implicit agree within 5 %.
Usage: check_work_precision.py TOOLS_DIR WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

import talus_verify as tv
import work_precision as wp

tools, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
tool = os.path.join(tools, "talus-convergence")

for sc in wp.SCENES:
    if not sc.fast_values:  # a scene of the full campaign only (make verify)
        continue
    points = {}
    for f in sc.families:
        text = open(os.path.join(wp.PRM_DIR, f.name + ".prm")).read()
        text = re.sub(r"(?m)^(\s*set base parameter file\s*=\s*)(\S+)\s*$",
                      lambda m: m.group(1) + os.path.join(wp.PRM_DIR, m.group(2)), text)
        text = tv.prm_set(text, "family/values", ", ".join(str(v) for v in sc.fast_values))
        text = tv.prm_set(text, "output/directory", f.name)
        text = tv.prm_set(text, "output/plots", "false")
        prm = os.path.join(work, f.name + ".prm")
        with open(prm, "w") as fh:
            fh.write(text)
        p = subprocess.run([tool, prm], cwd=work, capture_output=True, text=True, env=tv.child_env())
        print(p.stdout[-1500:])
        if p.returncode != 0:
            print(p.stderr[-1500:])
            tv.check(False, f"{sc.name}: {f.name}: talus-convergence exit {p.returncode}")
            continue
        r = tv.read_csv(os.path.join(work, f.name, f.name + ".csv"))
        order = tv.read_csv(os.path.join(work, f.name, f.name + "_summary.csv"))["observed_order"][0]
        errs = r["error"]
        tv.check(len(errs) == 2 and f.holds(order, errs),
                 f"{sc.name}: {f.name} at N = {sc.fast_values}: errors {', '.join(f'{e:.3e}' for e in errs)}, "
                 f"order {order:.3f}; criterion: {f.criterion()}")
        newton, linear = r["newton_iterations"], r["linear_iterations"]
        if f.tool == "talus-implicit":
            ok = all(n > 0 and l >= n for n, l in zip(newton, linear))
        elif f.tool == "talus-semi-implicit":
            ok = all(n == 0 and l > 0 for n, l in zip(newton, linear))
        else:
            ok = all(n == 0 and l == 0 for n, l in zip(newton, linear))
        tv.check(ok, f"{sc.name}: {f.name} ({f.tool}): Newton iterations {newton}, linear iterations {linear}")
        ok = all(n > 0 and s > 0 and 0 < w <= t for n, s, w, t in
                 zip(r["n_particles"], r["n_steps"], r["solver_wall_s"], r["run_time_s"]))
        tv.check(ok, f"{sc.name}: {f.name}: points {r['n_particles']}, steps {r['n_steps']}, loop "
                 f"{r['solver_wall_s']} s within the run time {r['run_time_s']} s")
        # the solid's points of the coarser run (the semi-implicit count holds soil + water)
        n = r["n_particles"][0] / (2 if f.tool == "talus-semi-implicit" else 1)
        points[f.name] = n
    tv.check(len(set(points.values())) == 1,
             f"{sc.name}: every family seeds the same solid from the shared fragment ({points})")
# particles:<column>:front (the column collapse's run-out): the front of the contiguous body,
# strays left out, on points of known spacing: 10 x 3 points at x = 0.05 .. 0.95 (volume 0.01,
# width 0.1) and one stray at x = 2: the front is 0.95 + 0.05 = 1 (to rounding), whatever the stray
import importlib.machinery  # noqa: E402
import importlib.util  # noqa: E402

loader = importlib.machinery.SourceFileLoader("talus_convergence", tool)
spec = importlib.util.spec_from_loader("talus_convergence", loader)
tc = importlib.util.module_from_spec(spec)
loader.exec_module(tc)
pts = {"pos_x": [0.05 + 0.1 * i for i in range(10) for _ in range(3)] + [2.0], "volume": [0.01] * 31}
f = tc._front(pts["pos_x"], pts)
tv.check(abs(f - 1.0) < 1e-12, f"particles:pos_x:front of a block 0..1 and a stray at 2: {f:.15g} = 1")
pts["pos_x"][-1] = 1.04  # a point in the next bin joins the body
f = tc._front(pts["pos_x"], pts)
tv.check(abs(f - 1.09) < 1e-12, f"particles:pos_x:front with a point at 1.04 joining the body: {f:.15g} = 1.09")

# the column collapse's shared fragment gives both tools the same problem: at N = 12 cells per
# column width their run-outs (particles:pos_x:front) agree within 5 %. Measured +2.6 %
# (explicit over implicit); with the rough base as 'fixed' instead of a prescribed zero velocity
# +8.8 % (talus-explicit's FLIP points slid on the base; docs/boundary-conditions.md).
fronts = {}
for name, dt in (("explicit", None), ("implicit", "0.0015")):
    text = open(os.path.join(wp.PRM_DIR, "scenes", f"column_collapse_{name}.prm")).read()
    text = text.replace("include column_collapse.inc",
                        "include " + os.path.join(wp.PRM_DIR, "scenes", "column_collapse.inc"))
    text = tv.prm_set(text, "grid/cells", "60, 20")
    text = tv.prm_set(text, "output/directory", f"collapse_{name}")
    text = tv.prm_set(text, "output/series interval", "0")
    if dt:
        text = tv.prm_set(text, "time/time step", dt)
    tv.run_tool(os.path.join(tools, f"talus-{name}"), text, work, f"collapse_{name}")
    d = tc._particles(os.path.join(work, f"collapse_{name}"))
    fronts[name] = tc._front(d["pos_x"], d)
ratio = fronts["explicit"] / fronts["implicit"] - 1
tv.check(abs(ratio) <= 0.05, f"column collapse at N = 12: run-out talus-explicit {fronts['explicit']:.4f} m, "
         f"talus-implicit {fronts['implicit']:.4f} m, {100 * ratio:+.1f} % (within 5 %)")

# the 'value' reference (the footing's common reference): bad input is refused before any run
# or output, naming the entry (exit 2)
base = open(os.path.join(wp.PRM_DIR, "footing_implicit.prm")).read()
base = re.sub(r"(?m)^(\s*set base parameter file\s*=\s*)(\S+)\s*$",
              lambda m: m.group(1) + os.path.join(wp.PRM_DIR, m.group(2)), base)
for what, entry, value, needle in [("V = 0", "reference/constants", "V=0", "reference/constants"),
                                   ("no V", "reference/constants", "W=1", "lacks V"),
                                   ("no quantity", "reference/quantity", "", "reference/quantity")]:
    out = os.path.join(work, "bad_" + what.replace(" ", "_"))
    text = tv.prm_set(tv.prm_set(base, entry, value), "output/directory", out)
    prm = out + ".prm"
    with open(prm, "w") as fh:
        fh.write(text)
    p = subprocess.run([tool, prm], cwd=work, capture_output=True, text=True, env=tv.child_env())
    tv.check(p.returncode == 2 and needle in p.stderr and not os.path.exists(out),
             f"value reference, {what}: exit {p.returncode} (2), the message names '{needle}', nothing written: "
             f"{p.stderr.strip()[:160]}")
tv.finish()
