#!/usr/bin/env python3
"""Short runs of every talus tool (for the sanitizer build, `make sanitize`).

Each tool in TOOLS_DIR runs its tiny cases below (scenes of a few dozen material
points, a few steps); a tool without a case here is an error, so that a new
tool gets one. The run fails on a non-zero exit (other than an expected one), a
timeout, or any AddressSanitizer / UndefinedBehaviorSanitizer report.

Usage: sanitize_smoke.py TOOLS_DIR PRM_DIR WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "verification"))
import talus_verify as tv  # noqa: E402

tools_dir, prm_dir, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)


def tiny(prm, extra):
    """A shipped .prm cut down to a few steps (entries set through prm_set)."""
    text = open(os.path.join(prm_dir, prm)).read()
    for k, v in extra.items():
        text = tv.prm_set(text, k, v)
    return text


short = {"time/maximum steps": "12", "output/directory": "out", "output/progress": "false",
         "output/final particles csv": "true", "output/write grid": "true"}
explicit_cases = [
    ("bar_2d", tiny("verification/bar_vibration.prm", short), 0),
    ("disks_2d", tiny("verification/disks_collision.prm", short), 0),
    ("column_3d", tiny("verification/elastic_column_gravity_3d.prm", dict(short, **{"grid/cells": "2, 2, 4"}))
     if os.path.exists(os.path.join(prm_dir, "verification/elastic_column_gravity_3d.prm")) else None, 0),
    ("lost_stop", tiny("verification/block_leaving_grid.prm",
                       {"output/directory": "out", "stability/lost particles": "stop"}), 3),
    ("demo_mc", tiny("demo/column_collapse_2d.prm", dict(short, **{"time/maximum steps": "5"})), 0),
    ("bad_input", tiny("verification/bar_vibration.prm", {"body 0/material": "4"}), 2),
]
cases = {
    "talus-explicit": [(n, t, rc, []) for n, t, rc in explicit_cases if t],
    "talus-critical-dt": [("bar", tiny("verification/bar_vibration.prm", short), 0,
                           ["--probe", "--probe-steps=20", "--csv=dt.csv"])],
    "talus-element": [(os.path.splitext(f)[0],
                       tiny("element/" + f, {"test/number of increments": "50", "output/plots": "false"}),
                       2 if "broken" in f else 0, [])
                      for f in sorted(os.listdir(os.path.join(prm_dir, "element")))],
    "talus-fem": [
        ("oedometer_fem", tiny("verification/oedometer_gravity.prm", dict(short, **{"output/results file": "r.h5"})),
         0, []),
        ("oedometer_ulfem", tiny("verification/oedometer_gravity.prm",
                                 dict(short, **{"output/results file": "r.h5", "numerics/integration": "ul-fem"})),
         0, []),
        ("bad_input", tiny("verification/oedometer_gravity.prm", {"numerics/strain smoothing": "cell"}), 2, []),
    ],
    # runs after talus-fem (see the order below) and compares its results
    "talus-compare": [
        ("fem_vs_ulfem", None, 0,
         [os.path.join(work, "talus-fem", "oedometer_fem", "out", "r.h5"),
          os.path.join(work, "talus-fem", "oedometer_ulfem", "out", "r.h5"),
          "--quantities=probes,energies,grid:displacement,grid:stress,particles:displacement", "--tolerance=1e9"]),
        ("missing_file", None, 2, ["none.h5", os.path.join(work, "talus-fem", "oedometer_fem", "out", "r.h5")]),
    ],
    "talus-convergence": [
        ("check", open(os.path.join(prm_dir, "convergence", "bar_displacement.prm")).read().replace(
            "../verification/", os.path.join(os.path.abspath(prm_dir), "verification") + "/"), 0, ["--check"]),
        ("bad_input", "set mode = fast\n", 2, [])],
    # a box grid with a box body, and the gmsh column (meshed through the gmsh API)
    "talus-mesh": [
        ("box", "set dimension = 2\nsubsection grid\n  set cells = 4, 4\nend\n"
                "subsection body 0\n  set upper corner = 0.5, 0.5\nend\n"
                "subsection output\n  set grid file = g.msh\n  set particle file = p.h5\nend\n", 0, []),
        ("gmsh_column", open(os.path.join(prm_dir, "mesh", "elastic_column_2d.prm")).read().replace(
            "meshes/", os.path.join(os.path.abspath(prm_dir), "..", "meshes") + "/"), 0, []),
        ("bad_input", "set dimension = 2\nsubsection grid\n  set cells = 0, 4\nend\n"
                      "subsection output\n  set grid file = g.msh\n  set particle file = p.h5\nend\n", 2, []),
    ],
    "talus-bench-materials": [("bench", None, 0, ["--points=8", "--steps=4"])],
    "talus-bench-finite-strain": [("bench", None, 0, ["--updates=50"])],
}
env = dict(os.environ)
env.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1", "OMP_NUM_THREADS": "1",
            "UBSAN_OPTIONS": env.get("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1")})
report = re.compile(r"AddressSanitizer|LeakSanitizer|runtime error:|UndefinedBehaviorSanitizer")
tools = sorted(t for t in os.listdir(tools_dir) if t.startswith("talus-") and os.access(os.path.join(tools_dir, t), os.X_OK))
tools.sort(key=lambda t: t == "talus-compare")  # last: it reads the results of talus-fem
for t in tools:
    if t not in cases:
        tv.check(False, f"{t}: no sanitizer smoke case; add one to tests/reliability/sanitize_smoke.py")
        continue
    for name, text, want, args in cases[t]:
        d = os.path.join(work, t, name)
        os.makedirs(d)
        cmd = [os.path.join(os.path.abspath(tools_dir), t)] + args
        if text is not None:
            with open(os.path.join(d, "case.prm"), "w") as f:
                f.write(text)
            cmd.append("case.prm")
        try:
            p = subprocess.run(cmd, cwd=d, capture_output=True, text=True, env=env, timeout=1200)
            rc, out = p.returncode, p.stdout + p.stderr
        except subprocess.TimeoutExpired:
            rc, out = None, "TIMEOUT"
        bad = report.search(out)
        ok = rc == want and not bad
        tv.check(ok, f"{t} {name}: exit {rc} (want {want})" + (": sanitizer report" if bad else ""))
        if not ok:
            sys.stdout.write(out[-6000:] + "\n")
tv.finish()
