"""Checkpoint/restart of talus-semi-implicit (issue 14).

Scene: the self-weight consolidation column (soil and water point sets, free
water surface, FLIP with 1 % PIC) with a sudden surface load of 10 kPa, the
soil a Hencky Mohr-Coulomb that keeps b_e and the modified F-bar on: the state
a step reads from the previous one (both sets' velocities, the water's pore
pressure and its gradient, the soil's stress, b_e, volume and porosity) must
all come back. 200 steps of 3e-4 s, checkpoints every 0.015 s, two kept.

1. Reference: the uninterrupted run to t = 0.06 s.
2. The same scene run to t = 0.036 s (the loop writes no checkpoint at the last
   step, so its newest is the one of step 100 = N/2, t = 0.03 s), then again
   with end time 0.06 s and restart = true, from step 100: soil_final.csv,
   water_final.csv and series.csv byte for byte identical to the reference; soil.pvd and water.pvd without duplicate times;
   at most 2 checkpoints and no .part file left.
3. The same on 2 ranks (restart on as many ranks), against the uninterrupted
   2-rank run.
   A restart on another number of ranks (the 1-rank checkpoint continued on 2
   ranks): the points are redistributed, so round-off only: position,
   velocity, stress, volume and pore pressure within 1e-8 relative of the
   uninterrupted 1-rank run (points matched by their initial position).
4. The comparison can fail: a restart whose .prm changes the flip fraction
   (not part of the scene signature) must not be identical to the reference.
5. What stays invalid (exit 2, the cause named): restart = true without a
   checkpoint; a checkpoint of another scene (grid cells); of another
   dimension (a 3D run of the same column); of another tool (talus-implicit).
Usage: check_semi_restart.py TOOLS_DIR PRM IMPLICIT_PRM WORKDIR
(PRM: the consolidation column; IMPLICIT_PRM: any talus-implicit scene)
"""
import os
import re
import shutil
import sys

import talus_verify as tv

tools, prm_path, implicit_prm, work = sys.argv[1:5]
tool = f"{tools}/talus-semi-implicit"
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(prm_path).read()
for k, v in {"time/end time": "0.06", "time/time step": "3e-4", "output/vtu interval": "0.015",
             "output/series interval": "0", "output/final particles csv": "true", "output/progress": "false",
             "checkpoint/interval": "0.015", "checkpoint/keep": "2",
             "material 0/model": "hencky mohr coulomb",
             "material 0/hencky mohr coulomb/young modulus": "1e7",
             "material 0/hencky mohr coulomb/poisson ratio": "0.3",
             "material 0/hencky mohr coulomb/cohesion": "1e12",
             "material 0/hencky mohr coulomb/friction angle": "1",
             "material 0/hencky mohr coulomb/dilatancy angle": "0",
             "numerics/volumetric stabilisation": "modified f-bar",
             # the sudden 10 kPa on the soil's upper face (the shared traction), its
             # surface drained as the free surface around it
             "loads/number of tractions": "1", "loads/traction 0/traction": "0, -1e4",
             "boundary conditions/number of drainage conditions": "1",
             "boundary conditions/drainage 0/apply to": "region",
             "boundary conditions/drainage 0/region lower corner": "0, 0",
             "boundary conditions/drainage 0/region upper corner": "1e3, 1e3",
             # the AMG hierarchy kept between steps, rebuilt every 30 steps: the
             # restart step 100 is no multiple, so only the rebuild at the
             # checkpoint write keeps the runs alike
             "semi implicit/pressure preconditioner rebuild interval": "30",
             # tracked points (soil ids and water ids in the checkpoint): series.csv byte for byte
             "output/probes": "0.075, 0.99; 0.02, 0.1"}.items():
    base = tv.prm_set(base, k, v)


def run(name, np=1, expect_rc=0, text=None, tool_path=tool, **entries):
    t = tv.prm_set(text or base, "output/directory", os.path.join(work, name))
    for k, v in entries.items():
        t = tv.prm_set(t, k, v)
    return tv.run_tool(tool_path, t, os.path.join(work, "prm"), name, np=np, expect_rc=expect_rc)


def files(name):
    d = os.path.join(work, name)
    return [open(f"{d}/{f}").read() for f in ("soil_final.csv", "water_final.csv", "series.csv")]


for np in (1, 2):
    ref, part = f"ref_np{np}", f"restarted_np{np}"
    run(ref, np)
    run(part, np, **{"time/end time": "0.036"})
    _, out, _ = run(part, np, **{"checkpoint/restart": "true"})
    m = re.search(r"restarting from \S+ \(step (\d+)", out)
    tv.check(m is not None and int(m.group(1)) == 100, f"np={np}: the second run restarted at step 100 "
             f"({m.group(1) if m else 'no restart'})")
    a, b = files(ref), files(part)
    for k, what in enumerate(("soil_final.csv", "water_final.csv", "series.csv")):
        tv.check(a[k] == b[k], f"np={np}: {what} byte for byte identical to the uninterrupted run")
    d = os.path.join(work, part)
    for s in ("soil", "water"):
        times = [float(t) for t in re.findall(r'timestep="([^"]+)"', open(f"{d}/{s}.pvd").read())]
        tv.check(len(times) == len(set(times)) and times == sorted(times) and len(times) == 5,
                 f"np={np}: {s}.pvd without duplicates ({len(times)} records, 5 expected)")
    cps = os.listdir(f"{d}/checkpoints")
    tv.check(len([c for c in cps if c.endswith(".h5")]) <= 2 and not any(c.endswith(".part") for c in cps),
             f"np={np}: at most 2 checkpoints kept, no .part left ({sorted(cps)})")

# another number of ranks: the 1-rank checkpoint of step 100 continued on 2 ranks


def by_initial_position(path):
    return tv.by_initial_position(tv.read_csv(path))


shutil.copytree(os.path.join(work, "restarted_np1", "checkpoints"), os.path.join(work, "cross", "checkpoints"))
for c in os.listdir(os.path.join(work, "cross", "checkpoints")):
    if not c.startswith("checkpoint-0000000100"):
        os.remove(os.path.join(work, "cross", "checkpoints", c))
_, out, _ = run("cross", 2, **{"checkpoint/restart": "true", "checkpoint/interval": "0"})
tv.check("restarting from" in out, "1-rank checkpoint on 2 ranks: restarted")
for s in ("soil", "water"):
    a = by_initial_position(os.path.join(work, "ref_np1", f"{s}_final.csv"))
    b = by_initial_position(os.path.join(work, "cross", f"{s}_final.csv"))
    cols = ["pos_y", "velocity_y", "stress_yy", "volume"] + (["pore_pressure"] if s == "water" else [])
    d = tv.relative_differences(a, b, cols) if len(a["pos_x"]) == len(b["pos_x"]) else {"point count": 1.0}
    worst = max(d, key=d.get)
    tv.check(d[worst] < 1e-8, f"1-rank checkpoint on 2 ranks, {s}: within 1e-8 of the 1-rank run "
             f"(largest {d[worst]:.1e} in '{worst}')")

# the comparison sees a changed continuation
shutil.copytree(os.path.join(work, "restarted_np1", "checkpoints"), os.path.join(work, "mutant", "checkpoints"))
run("mutant", **{"checkpoint/restart": "true", "checkpoint/interval": "0",
                 "semi implicit/flip fraction": "0.98"})
tv.check(files("mutant")[1] != files("ref_np1")[1], "a restart with flip fraction 0.98 differs from the reference "
         "(the byte comparison can fail)")

# what stays invalid
_, out, err = run("none", expect_rc=2, **{"checkpoint/restart": "true"})
tv.check("checkpoint/restart" in out + err, "restart = true without a checkpoint: exit 2 naming checkpoint/restart")
shutil.copytree(os.path.join(work, "ref_np1", "checkpoints"), os.path.join(work, "other", "checkpoints"))
_, out, err = run("other", expect_rc=2, **{"checkpoint/restart": "true", "grid/cells": "3, 26"})
tv.check("another scene" in out + err, "a checkpoint of another grid: exit 2, 'written for another scene'")

# another dimension: the same column in 3D, one checkpoint after two steps
text3 = base
for k, v in {"dimension": "3", "grid/lower corner": "0, 0, 0", "grid/upper corner": "0.15, 0.15, 1.2",
             "grid/cells": "3, 3, 24", "boundary conditions/roller": "0, 1, 2, 3, 4",
             "gravity/acceleration": "0, 0, -9.81", "body 0/lower corner": "0, 0, 0",
             "body 0/upper corner": "0.15, 0.15, 1", "time/end time": "6e-4",
             "checkpoint/interval": "3e-4",
             # the traction on the upper face (z+ in 3D) and the drained region in 3D
             "loads/traction 0/face": "z+", "loads/traction 0/traction": "0, 0, -1e4",
             "boundary conditions/drainage 0/region lower corner": "0, 0, 0",
             "boundary conditions/drainage 0/region upper corner": "1e3, 1e3, 1e3",
             "output/probes": "0.075, 0.075, 0.99"}.items():
    text3 = tv.prm_set(text3, k, v)
run("three_d", text=text3)
shutil.copytree(os.path.join(work, "three_d", "checkpoints"), os.path.join(work, "dim", "checkpoints"))
_, out, err = run("dim", expect_rc=2, **{"checkpoint/restart": "true"})
tv.check("written by a 3D run" in out + err, "a checkpoint of a 3D run: exit 2, 'written by a 3D run'")

# another tool: a talus-implicit checkpoint is skipped (named in the log), none is left
imp = tv.prm_set(open(implicit_prm).read(), "output/directory", os.path.join(work, "implicit"))
for k, v in {"time/end time": "1", "checkpoint/interval": "0.5", "output/progress": "false"}.items():
    imp = tv.prm_set(imp, k, v)
rc, _, _ = tv.run_tool(f"{tools}/talus-implicit", imp, os.path.join(work, "prm"), "implicit", expect_rc=None)
cps = os.path.join(work, "implicit", "checkpoints")
tv.check(rc == 0 and os.path.isdir(cps) and os.listdir(cps), f"talus-implicit wrote a checkpoint (exit {rc})")
shutil.copytree(cps, os.path.join(work, "foreign", "checkpoints"))
_, out, err = run("foreign", expect_rc=2, **{"checkpoint/restart": "true"})
tv.check("not a talus-semi-implicit-checkpoint" in out + err and "no valid checkpoint" in out + err,
         "a talus-implicit checkpoint: exit 2, 'not a talus-semi-implicit-checkpoint', 'no valid checkpoint'")
tv.finish()
