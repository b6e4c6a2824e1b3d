"""Checkpoint/restart of talus-implicit (issue 13).

Scene: the implicit granular column collapse a = 1.2 (Hencky Mohr-Coulomb with
history variables, plastic flow, Rayleigh damping, points changing cells every
step) on a coarse grid, checkpoints every 0.04 s, two kept.

1. Reference: the uninterrupted run to t = 0.2 s.
2. The same scene run to t = 0.13 s, then run again with end time 0.2 s and
   restart = true: particles_final.csv and series.csv byte for byte identical to
   the reference, the PVD series without duplicate times, at most `keep`
   checkpoints, no .part file left.
3. The same on 2 ranks (restart on as many ranks): byte for byte identical to the
   uninterrupted 2-rank run.
4. restart = true without a checkpoint, and a checkpoint of another scene: input
   errors (exit 2) naming the cause.
Usage: check_implicit_restart.py TOOLS_DIR PRM WORKDIR [ENTRY=VALUE ...]
(ENTRY=VALUE: further .prm settings, e.g. implicit/geometry=axisymmetric)
"""
import os
import re
import shutil
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
tool = f"{tools}/talus-implicit"
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(prm_path).read()
for k, v in {"grid/cells": "60, 20", "time/end time": "0.2", "output/vtu interval": "0.05",
             "output/series interval": "0", "output/final particles csv": "true", "output/progress": "false",
             "checkpoint/interval": "0.04", "checkpoint/keep": "2",
             # the top corner point moves far: a restart must track the saved ids, not
             # the points nearest by then (probe columns of series.csv byte for byte)
             "output/probes": "0.09, 0.108; 0.02, 0.02"}.items():
    base = tv.prm_set(base, k, v)
base = tv.prm_set_args(base, sys.argv[4:])


def run(name, np=1, expect_rc=0, **entries):
    t = tv.prm_set(base, "output/directory", os.path.join(work, name))
    for k, v in entries.items():
        t = tv.prm_set(t, k, v)
    return tv.run_tool(tool, t, os.path.join(work, "prm"), name, np=np, expect_rc=expect_rc)


def files(name):
    d = os.path.join(work, name)
    return open(f"{d}/particles_final.csv").read(), open(f"{d}/series.csv").read()


for np in (1, 2):
    ref, part = f"ref_np{np}", f"restarted_np{np}"
    _, out, _ = run(ref, np)
    if "implicit/geometry=axisymmetric" in sys.argv[4:]:
        tv.check("axisymmetric: points carry their rings" in out, f"np={np}: the run is axisymmetric")
    run(part, np, **{"time/end time": "0.13"})
    _, out, _ = run(part, np, **{"checkpoint/restart": "true"})
    tv.check("restarting from" in out, f"np={np}: the second run restarted from a checkpoint")
    a, b = files(ref), files(part)
    tv.check(a[0] == b[0], f"np={np}: particles_final.csv byte for byte identical to the uninterrupted run")
    tv.check(a[1] == b[1], f"np={np}: series.csv byte for byte identical to the uninterrupted run")
    d = os.path.join(work, part)
    times = [float(t) for t in re.findall(r'timestep="([^"]+)"', open(f"{d}/particles.pvd").read())]
    tv.check(len(times) == len(set(times)) and times == sorted(times) and len(times) >= 5,
             f"np={np}: PVD series without duplicates ({len(times)} records)")
    cps = os.listdir(f"{d}/checkpoints")
    tv.check(len([c for c in cps if c.endswith(".h5")]) <= 2 and not any(c.endswith(".part") for c in cps),
             f"np={np}: at most 2 checkpoints kept, no .part left ({sorted(cps)})")

_, _, err = run("none", expect_rc=2, **{"checkpoint/restart": "true"})
tv.check("checkpoint" in err, "restart = true without a checkpoint: exit 2 naming checkpoint/restart")
shutil.copytree(os.path.join(work, "ref_np1", "checkpoints"), os.path.join(work, "other", "checkpoints"))
_, _, err = run("other", expect_rc=2, **{"checkpoint/restart": "true", "grid/cells": "62, 20"})
tv.check("another scene" in err, "a checkpoint of another grid: exit 2, 'written for another scene'")
tv.finish()
