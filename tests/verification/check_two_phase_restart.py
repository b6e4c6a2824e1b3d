"""Checkpoint/restart of the 2-phase step (issue 38): a 2-phase scene (ctest: the hydrostatic column
on quadratic B-splines) run to 0.02 s with
checkpoints every 0.004 s, stopped at 0.011 s and restarted from its 0.008 s checkpoint, on 1 and on
2 ranks: particles_final.csv byte for byte identical to the uninterrupted run on as many ranks
(the state of the step is on the points: porosity, pore pressure, liquid velocity; the node map of
the pore-pressure relaxation is rebuilt from them at each step).
Usage: check_two_phase_restart.py TOOL PRM WORKDIR [entry=value ...]
  entry=value: .prm settings (e.g. numerics/shape function=quadratic bspline).
"""
import os
import shutil
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
tz = tv.prm_set_args(open(prm_path).read(), sys.argv[4:])
for k, v in [("time/end time", "0.02"), ("output/final particles csv", "true"), ("output/progress", "false"),
             ("checkpoint/interval", "0.004")]:
    tz = tv.prm_set(tz, k, v)


def final(name):
    return open(os.path.join(work, name, "particles_final.csv")).read()


for n in (1, 2):
    tv.run_tool(tool, tv.prm_set(tz, "output/directory", f"ref{n}"), work, f"ref{n}", np=n)
    part = tv.prm_set(tz, "output/directory", f"part{n}")
    tv.run_tool(tool, tv.prm_set(part, "time/end time", "0.011"), work, f"part{n}", np=n)
    os.remove(os.path.join(work, f"part{n}", "particles_final.csv"))
    tv.run_tool(tool, tv.prm_set(part, "checkpoint/restart", "true"), work, f"restart{n}", np=n)
    a, b = final(f"part{n}"), final(f"ref{n}")
    tv.check(a == b and len(a) > 0,
             f"{n} rank(s): restart byte for byte identical to the uninterrupted run ({a.count(chr(10))} lines)")
tv.finish()
