"""Reuse of the pressure solve's ML AMG hierarchy between steps (issue 14).

Scene: the bench slope (parameter_files/bench/semi_implicit_slope.prm: a
saturated Mohr-Coulomb slope that starts to fail under sudden gravity) at 2 x 2
points per cell, STEPS steps: the points cross cells, so the pressure DoF set
changes every few steps (a new hierarchy each time) and in between the matrix
changes with the points.

1. Reuse (the default `pressure preconditioner rebuild interval` = 100): the
   summary's AMG set-ups are at most (pressure DoF set rebuilds) + (multiples
   of the interval among the steps) + (rebuilds after slow solves) + 1, and the series' last
   `pressure_amg_setups` says the same; far fewer than the solves. No
   fallback (CG never failed with a kept hierarchy).
2. Interval 1 (a new hierarchy every step, the behaviour before the reuse):
   one set-up per solve.
3. Both runs end within the solver tolerance of each other: every point's
   displacement, velocity, stress and pore pressure within BOUND (per
   quantity relative to its largest magnitude over all points and components). The check can fail: the same scene at a pressure
   solver tolerance of 1e-6 (both runs at interval 1, so only the tolerance
   differs) must differ from the 1e-10 run by more than BOUND.
4. 1 vs 2 ranks with the reuse: the 2-rank run (its own partition, its own
   hierarchies, the same rebuild steps) within BOUND of the 1-rank interval-1
   run, with the same number of set-ups as the 1-rank reuse run.
5. The mean CG iterations with a kept hierarchy stay small (<= 4 x those of
   the interval-1 run + 2): a stale hierarchy costs iterations, not accuracy.
Usage: check_semi_amg_reuse.py TOOL PRM WORKDIR   (PRM: the bench slope)
"""
import os
import re
import shutil
import sys

import talus_verify as tv

STEPS = 200
BOUND = 1e-8

tool, prm_path, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(prm_path).read()
for k, v in {"time/end time": str(STEPS * 5e-4), "time/time step": "5e-4", "output/vtu interval": "0",
             "output/series interval": "0", "output/final particles csv": "true", "output/progress": "false",
             "body 0/particles per direction": "2"}.items():
    base = tv.prm_set(base, k, v)


def run(name, np=1, **entries):
    t = tv.prm_set(base, "output/directory", os.path.join(work, name))
    for k, v in entries.items():
        t = tv.prm_set(t, k.replace("__", "/").replace("_", " "), v)
    _, out, _ = tv.run_tool(tool, t, os.path.join(work, "prm"), name, np=np)
    m = re.search(r"done: (\d+) steps.*mean ([0-9.e+-]+) CG iterations; AMG set-ups (\d+) \(interval (\d+), "
                  r"fallbacks (\d+), after slow solves (\d+)\), pressure DoF set rebuilds (\d+)", out)
    if not m:
        sys.stdout.write(out)
        tv.fail(f"{name}: no summary line with the AMG set-ups")
    steps, iters, setups, interval, fallbacks, slow, rebuilds = (float(m.group(2)) if i == 2 else int(m.group(i))
                                                                 for i in range(1, 8))
    series = tv.read_csv(os.path.join(work, name, "series.csv"))
    d = os.path.join(work, name)
    points = [tv.by_initial_position(tv.read_csv(os.path.join(d, f))) for f in ("soil_final.csv", "water_final.csv")]
    print(f"{name}: {steps} steps, interval {interval}, AMG set-ups {setups}, pressure DoF set rebuilds {rebuilds}, "
          f"mean CG iterations {iters:.2f}, fallbacks {fallbacks}, rebuilds after slow solves {slow}")
    return dict(steps=steps, iters=iters, setups=setups, fallbacks=fallbacks, rebuilds=rebuilds, slow=slow,
                series_setups=int(series["pressure_amg_setups"][-1]), points=points)


QUANTITIES = {"displacement": ["displacement_x", "displacement_y"], "velocity": ["velocity_x", "velocity_y"],
              "stress": ["stress_xx", "stress_yy", "stress_xy"], "pore pressure": ["pore_pressure"]}


def max_difference(a, b):
    """Largest difference between two runs' points, per quantity relative to its largest magnitude."""
    worst = {}
    for ta, tb in zip(a["points"], b["points"]):
        if len(ta["pos_x"]) != len(tb["pos_x"]):
            return float("inf"), "point count"
        for q, cols in QUANTITIES.items():
            cols = [c for c in cols if c in ta]
            if not cols:
                continue
            scale = max(abs(v) for c in cols for v in ta[c]) or 1.0
            d = max(abs(x - y) for c in cols for x, y in zip(ta[c], tb[c])) / scale
            worst[q] = max(worst.get(q, 0.0), d)
    q = max(worst, key=worst.get)
    return worst[q], q


reuse = run("reuse")
every = run("every_step", semi_implicit__pressure_preconditioner_rebuild_interval="1")
reuse2 = run("reuse_np2", np=2)
loose = run("every_step_tolerance_1e-6", semi_implicit__pressure_preconditioner_rebuild_interval="1",
            semi_implicit__pressure_solver_tolerance="1e-6")

multiples = (reuse["steps"] - 1) // 100 + 1  # steps 0, 100, ... (the step number before the step)
tv.check(reuse["setups"] <= reuse["rebuilds"] + multiples + reuse["slow"] + 1,
         f"reuse: AMG set-ups {reuse['setups']} <= DoF set rebuilds {reuse['rebuilds']} + {multiples} + "
         f"slow solves {reuse['slow']} + 1")
tv.check(reuse["setups"] < reuse["steps"] / 4, f"reuse: AMG set-ups {reuse['setups']} < steps / 4")
tv.check(reuse["series_setups"] == reuse["setups"],
         f"reuse: series pressure_amg_setups {reuse['series_setups']} = summary {reuse['setups']}")
tv.check(reuse["fallbacks"] == 0, "reuse: no fallback rebuild")
tv.check(every["setups"] == every["steps"], f"interval 1: AMG set-ups {every['setups']} = steps {every['steps']}")
d, q = max_difference(every, reuse)
tv.check(d <= BOUND, f"reuse vs every step: largest relative difference {d:.3g} ({q}) <= {BOUND:g}")
d_loose, q = max_difference(every, loose)
tv.check(d_loose > BOUND,
         f"the comparison can fail: tolerance 1e-6 vs 1e-10 differ by {d_loose:.3g} ({q}) > {BOUND:g}")
d2, q = max_difference(every, reuse2)
tv.check(d2 <= BOUND, f"2 ranks with reuse vs 1 rank every step: largest relative difference {d2:.3g} ({q}) <= {BOUND:g}")
tv.check(reuse2["setups"] == reuse["setups"],
         f"2 ranks: AMG set-ups {reuse2['setups']} = 1 rank's {reuse['setups']} (the rebuild decision is global)")
tv.check(reuse["iters"] <= 4 * every["iters"] + 2,
         f"mean CG iterations with reuse {reuse['iters']:.2f} <= 4 x {every['iters']:.2f} + 2")
tv.finish()
