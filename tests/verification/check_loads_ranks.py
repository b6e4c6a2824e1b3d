"""Prescribed nodal velocities on 1 and 2 ranks (issue 12 item 2).

A rank that owns none of the prescribed nodes must take part in the same
collectives as the others: before, a prescribed base velocity made the ranks
reduce against different collectives (ExcMPI on one rank, a hang on the other).
Two scenes, each run on 1 and 2 ranks, no gravity, the base nodes (boundary 2)
pushed up at 1 mm/s (y), sides on rollers:
  * the 2-phase hydrostatic column (hydrostatic_2phase.prm, no damping, 0.1 s);
  * the 1-phase elastic column (elastic_column_gravity.prm, 0.05 s).
A third scene (issue 12: the loads with quadratic B-splines): the elastic
column 3 cells wide with B-spline shape functions, the whole body given v_y =
1 mm/s (`apply to = body`, the momentum change scattered through each point's
3 x 3 window) while the base nodes are left free: a rigid translation.
Check: all finish, and the positions, velocities (and pore pressures, liquid
velocities) agree to 1e-10 relative to the largest value of each field; in the
B-spline scene every point moved by v t (to 1e-9 m) and kept |stress| below
1e-6 x E v t / h (a translation strains nothing).
Usage: check_loads_ranks.py TOOL HYDROSTATIC_2PHASE_PRM ELASTIC_COLUMN_PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, two_phase_prm, column_prm, work = sys.argv[1:5]


def base_velocity(text, end):
    text = tv.prm_set(text, "gravity/acceleration", "0, 0")
    text = tv.prm_set(text, "boundary conditions/fixed", "")
    text = tv.prm_set(text, "boundary conditions/roller", "0, 1")
    text = tv.prm_set(text, "time/end time", end)
    text = tv.prm_set(text, "output/final particles csv", "true")
    text = tv.prm_set(text, "loads/number of velocity conditions", "1")
    text = tv.prm_set(text, "loads/velocity 0/apply to", "boundary")
    text = tv.prm_set(text, "loads/velocity 0/boundary id", "2")
    text = tv.prm_set(text, "loads/velocity 0/components", "y")
    return tv.prm_set(text, "loads/velocity 0/velocity", "0, 1e-3")


def body_velocity_bspline(text, end):
    for key, value in {"numerics/shape function": "quadratic bspline", "grid/cells": "3, 20",
                       "grid/upper corner": "0.1875, 1.25", "body 0/upper corner": "0.1875, 1",
                       "output/probes": "0.09375, 0.99"}.items():
        text = tv.prm_set(text, key, value)
    text = base_velocity(text, end)
    text = tv.prm_set(text, "loads/velocity 0/apply to", "body")
    return tv.prm_set(text, "loads/velocity 0/body", "0")


scenes = {
    "two_phase": (tv.prm_set(base_velocity(open(two_phase_prm).read(), "0.1"), "two phase/local damping", "0"),
                  ("pos_y", "v_y", "pore_pressure", "liquid_velocity_y")),
    "one_phase": (base_velocity(open(column_prm).read(), "0.05"), ("pos_y", "v_y", "stress_yy")),
    "one_phase_bspline_body": (body_velocity_bspline(open(column_prm).read(), "0.05"), ("pos_y", "v_y")),
}
for name, (text, fields) in scenes.items():
    for n in (1, 2):
        tv.run_tool(tool, tv.prm_set(text, "output/directory", f"{name}_np{n}"), work, f"{name}_np{n}", np=n)
    a = tv.read_csv(f"{work}/{name}_np1/particles_final.csv")
    b = tv.read_csv(f"{work}/{name}_np2/particles_final.csv")
    tv.check(len(a["id"]) == len(b["id"]) > 0, f"{name}: {len(a['id'])} / {len(b['id'])} points on 1 / 2 ranks")
    order_a = sorted(range(len(a["id"])), key=lambda i: a["id"][i])
    order_b = sorted(range(len(b["id"])), key=lambda i: b["id"][i])
    for k in fields:
        scale = max(abs(x) for x in a[k]) or 1.0
        d = max(abs(a[k][i] - b[k][j]) for i, j in zip(order_a, order_b)) / scale
        tv.check(d < 1e-10, f"{name}: {k} on 1 vs 2 ranks differs by {d:.2e} (relative to the largest value)")
    if name == "one_phase_bspline_body":
        v, t, E, h = 1e-3, 0.05, 1e6, 0.0625
        du = max(abs(u - v * t) for u in a["u_y"])
        sig = max(max(abs(x) for x in a[c]) for c in ("stress_xx", "stress_yy", "stress_xy"))
        tv.check(du < 1e-9, f"{name}: every point moved by v t = {v * t:.1e} m (largest deviation {du:.1e} m)")
        tv.check(sig < 1e-6 * E * v * t / h,
                 f"{name}: rigid translation, largest |stress| {sig:.2e} Pa < 1e-6 E v t / h = {1e-6 * E * v * t / h:.1e} Pa")
tv.finish()
