"""APIC on quadratic B-splines with the explicit features (issue 38 item 3).

talus-explicit with numerics/shape function = quadratic bspline and
numerics/velocity transfer = apic (docs/shape-functions.md, "APIC"), one case
per run of this script (4th argument):
  balance      the corner collapse of load_balance_collapse.prm (0.04 s,
               rebalanced at every check): 2 ranks agree with 1 rank to 1e-10
               relative (particles_final.csv, C_p included, rows matched by
               initial position, >= 5 rebalances), and a restart from a
               checkpoint between rebalances continues bitwise identically on 2
               ranks (particles_final.csv byte for byte);
  point_load   the point-load block (point_load/block_explicit.prm, local
               damping to rest): the base reaction plate_0_force equals the
               point load (100 N) within 1 % (the linear test's tolerance);
  friction     a block given v0 = 1 m/s along a horizontal friction floor (mu =
               0.3, gravity -9.81): while it slides the block's momentum falls
               at mu g M; the slope of momentum_x over 0.05 s <= t <= 0.25 s
               (least squares) within 1 % of -mu g M, the stopping distance
               within 1 % of v0^2 / (2 mu g), and the block at rest at the end
               (|momentum_x| < 1e-4 M v0);
  body_velocity  the elastic column 3 cells wide under gravity, the whole body
               given v_y = 1 mm/s (apply to = body, components y) with its base
               free: a rigid translation; every point moved by v t (1e-9 m),
               C_p = 0 (1e-12 1/s), |stress| < 1e-6 E v t / h; 1 vs 2 ranks to
               1e-10 (positions, velocities); and two bodies side by side
               without gravity, the left one driven, the right one free: the
               driven points' v_y and the y rows of C_p exactly the prescribed
               field (v, 0) while the free body is dragged (C_yx != 0 there);
  momentum     two elastic blocks, no gravity, no wall within reach, thrown at
               each other (v = +-1 m/s, one spinning at 2 rad/s) so that they
               collide and rebound on the shared grid: no external force acts,
               the total momentum (series momentum_x, momentum_y) stays at its
               initial value to 1e-12 relative to sum m |v| at every output, and
               the angular momentum with APIC's affine part, sum m (x x v_p +
               eps : (C_p D_p)^T) from particles_final.csv, after one step and
               at the end, to 1e-12 sum m |v| r (r the box's largest |x|).
Usage: check_apic_features.py TOOL PRM_DIR WORKDIR CASE
"""
import math
import os
import re
import sys

import talus_verify as tv

tool, prm_dir, work, case = sys.argv[1:5]
prm_dir = os.path.abspath(prm_dir)
os.makedirs(work, exist_ok=True)


def apic(text):
    text = tv.prm_set(text, "numerics/shape function", "quadratic bspline")
    return tv.prm_set(text, "numerics/velocity transfer", "apic")


def by_origin(t):
    """Rows of a particles_final.csv table in the order of their initial positions (pos - u)."""
    key = sorted(range(len(t["id"])), key=lambda i: (round(t["pos_y"][i] - t["u_y"][i], 7),
                                                     round(t["pos_x"][i] - t["u_x"][i], 7)))
    return {c: [t[c][i] for i in key] for c in t}


def ranks_agree(label, out1, out2, tol=1e-10, columns=None):
    a = by_origin(tv.read_csv(f"{out1}/particles_final.csv"))
    b = by_origin(tv.read_csv(f"{out2}/particles_final.csv"))
    tv.check(len(a["id"]) == len(b["id"]) > 0, f"{label}: {len(a['id'])} / {len(b['id'])} points on 1 / 2 ranks")
    tv.check(any(c.startswith("affine_velocity") for c in a), f"{label}: particles_final.csv holds C_p")
    cols = columns or [c for c in a if c != "id" and isinstance(a[c][0], float)]
    diff = tv.relative_differences(a, b, cols)
    worst = max(diff, key=diff.get)
    tv.check(diff[worst] <= tol, f"{label}: 1 rank vs 2 ranks agree to {tol:g} relative "
                                 f"(worst {diff[worst]:.2e}, {worst})")
    return a


if case == "balance":
    base = apic(open(os.path.join(prm_dir, "verification", "load_balance_collapse.prm")).read())
    base = tv.prm_set(base, "time/end time", "0.04")
    base = tv.prm_set(base, "load balancing/imbalance threshold", "1.0")
    tv.run_tool(tool, tv.prm_set(base, "output/directory", "np1"), work, "np1")
    _, log2, _ = tv.run_tool(tool, tv.prm_set(base, "output/directory", "np2"), work, "np2", np=2)
    n = int(re.search(r"rebalances (\d+)", log2).group(1))
    tv.check(n >= 5, f"rebalances during the 2-rank run: {n} >= 5")
    a = ranks_agree("balance", f"{work}/np1", f"{work}/np2")
    cmax = max(max(abs(x) for x in a[c]) for c in a if c.startswith("affine_velocity"))
    tv.check(cmax > 0, f"the collapse has a non-zero C_p (largest |C_p| {cmax:.3e} 1/s)")
    tv.check_restart_across_rebalances(tool, base, work, "balance", interval=0.02, min_step=100, min_rebalances=2)

elif case == "point_load":
    scene = os.path.join(prm_dir, "verification", "point_load")
    inc = os.path.join(work, "block.inc")
    if not os.path.exists(inc):
        os.symlink(os.path.join(scene, "block.inc"), inc)
    text = apic(open(os.path.join(scene, "block_explicit.prm")).read())
    out = os.path.abspath(os.path.join(work, "out"))
    tv.run_tool(tool, tv.prm_set(text, "output/directory", out), work, "block")
    s = tv.read_csv(f"{out}/series.csv")
    f, t = s["plate_0_force"][-1], s["time"][-1]
    err = abs(f - 100.0) / 100.0
    print(f"t = {t:g} s, base reaction {f:.8e} N vs point load 100 N: relative error {err:.3e}")
    tv.check(t < 29.9, f"the run ended by convergence (t = {t:g} s < end time 30 s)")
    tv.check(err < 0.01, f"the base reaction equals the point load within 1 % ({err:.3e})")

elif case == "friction":
    mu, g, v0, rho = 0.3, 9.81, 1.0, 2000.0
    text = apic(open(os.path.join(prm_dir, "verification", "block_friction.prm")).read())
    text = tv.prm_set(text, "gravity/acceleration", f"0, {-g}")
    text = tv.prm_set(text, "boundary conditions/friction coefficient", str(mu))
    text = tv.prm_set(text, "body 0/initial velocity", f"{v0}, 0")
    text = tv.prm_set(text, "time/end time", "0.45")
    text = tv.prm_set(text, "output/directory", "out")
    tv.run_tool(tool, text, work, "block")
    s = tv.read_csv(f"{work}/out/series.csv")
    M = rho * 0.2 * 0.1
    rows = [(t, p) for t, p in zip(s["time"], s["momentum_x"]) if 0.05 <= t <= 0.25]
    n = len(rows)
    tm, pm = sum(r[0] for r in rows) / n, sum(r[1] for r in rows) / n
    slope = sum((t - tm) * (p - pm) for t, p in rows) / sum((t - tm) ** 2 for t, _ in rows)
    exact = -mu * g * M
    err = abs(slope - exact) / abs(exact)
    print(f"sliding: dP/dt = {slope:.6e} N vs -mu g M = {exact:.6e} N over {n} rows (relative error {err:.3e}); "
          f"momentum at {s['time'][-1]:g} s: {s['momentum_x'][-1]:.3e} kg m/s")
    tv.check(abs(s["momentum_x"][0] - M * v0) < 1e-9 * M * v0,
             f"initial momentum M v0 = {M * v0:g} kg m/s ({s['momentum_x'][0]:.12g})")
    tv.check(err < 0.01, f"the friction wall decelerates the block at mu g within 1 % ({err:.3e})")
    tv.check(abs(s["momentum_x"][-1]) < 1e-4 * M * v0,
             f"at rest after t_stop = v0 / (mu g) = {v0 / (mu * g):.4f} s (|P| = {abs(s['momentum_x'][-1]):.2e} "
             f"< 1e-4 M v0: the stuck block's elastic ringing decays)")
    d, da = s["probe0_ux"][-1], v0 * v0 / (2 * mu * g)
    tv.check(abs(d - da) < 0.01 * da, f"stopping distance {d:.6f} m vs v0^2 / (2 mu g) = {da:.6f} m "
                                      f"(relative error {abs(d - da) / da:.2e} < 1e-2)")

elif case == "body_velocity":
    text = apic(open(os.path.join(prm_dir, "verification", "elastic_column_gravity.prm")).read())
    for key, value in {"grid/cells": "3, 20", "grid/upper corner": "0.1875, 1.25",
                       "body 0/upper corner": "0.1875, 1", "output/probes": "0.09375, 0.99",
                       "boundary conditions/fixed": "", "boundary conditions/roller": "0, 1",
                       "time/end time": "0.05", "output/final particles csv": "true",
                       "loads/number of velocity conditions": "1", "loads/velocity 0/apply to": "body",
                       "loads/velocity 0/body": "0", "loads/velocity 0/components": "y",
                       "loads/velocity 0/velocity": "0, 1e-3"}.items():
        text = tv.prm_set(text, key, value)
    for n in (1, 2):
        tv.run_tool(tool, tv.prm_set(text, "output/directory", f"np{n}"), work, f"np{n}", np=n)
    # positions and velocities (C_p and the stresses are round-off here: checked against 0 below)
    a = ranks_agree("body_velocity", f"{work}/np1", f"{work}/np2", columns=["pos_x", "pos_y", "u_y", "v_y"])
    v, t, E, h = 1e-3, 0.05, 1e6, 0.0625
    du = max(abs(u - v * t) for u in a["u_y"])
    dx = max(abs(u) for u in a["u_x"])
    cmax = max(max(abs(x) for x in a[c]) for c in a if c.startswith("affine_velocity"))
    sig = max(max(abs(x) for x in a[c]) for c in ("stress_xx", "stress_yy", "stress_xy"))
    tv.check(du < 1e-9 and dx < 1e-9, f"every point moved by v t = {v * t:.1e} m along y (largest deviation "
                                      f"{du:.1e} m, sideways {dx:.1e} m)")
    tv.check(cmax < 1e-12, f"C_p = 0 for the rigid translation (largest |C_p| {cmax:.1e} 1/s)")
    tv.check(sig < 1e-6 * E * v * t / h,
             f"rigid translation, largest |stress| {sig:.2e} Pa < 1e-6 E v t / h = {1e-6 * E * v * t / h:.1e} Pa")
    # two bodies side by side, no gravity: the left one driven up (components y), the right one
    # free and dragged along through the shared nodes (no contact pair): the driven points' v_y
    # is the prescribed value and their C_p rows of y are 0 although the grid's velocity field
    # varies across the interface (its x row is the APIC one)
    two = tv.prm_set(text, "gravity/acceleration", "0, 0")
    two = tv.prm_set(two, "body 0/upper corner", "0.09375, 1")
    two = tv.prm_set(two, "number of bodies", "2") + tv.box_body(1, "free", "0.09375, 0", "0.1875, 1")
    two = tv.prm_set(two, "output/directory", "two")
    tv.run_tool(tool, two, work, "two")
    b = tv.read_csv(f"{work}/two/particles_final.csv")
    left = [i for i in range(len(b["id"])) if b["pos_x"][i] - b["u_x"][i] < 0.09375]
    right = [i for i in range(len(b["id"])) if i not in set(left)]
    dv = max(abs(b["v_y"][i] - v) for i in left)
    cy = max(max(abs(b["affine_velocity_yx"][i]), abs(b["affine_velocity_yy"][i])) for i in left)
    cyr = max(abs(b["affine_velocity_yx"][i]) for i in right)
    vr = sum(b["v_y"][i] for i in right) / len(right)
    tv.check(len(left) == len(right) > 0, f"two bodies: {len(left)} driven and {len(right)} free points")
    tv.check(dv == 0.0, f"two bodies: the driven points' v_y is the prescribed value (largest deviation {dv:.1e})")
    tv.check(cy == 0.0, f"two bodies: the driven points' C_p rows of y are 0 (largest {cy:.1e} 1/s)")
    tv.check(cyr > 1e-6 and 0 < vr < v,
             f"two bodies: the free body is dragged (mean v_y {vr:.3e} m/s in (0, {v:g}), largest |C_yx| {cyr:.2e} "
             f"1/s > 1e-6: the grid field varies across the interface)")

elif case == "momentum":
    text = apic(open(os.path.join(prm_dir, "verification", "block_friction.prm")).read())
    for key, value in {"grid/lower corner": "0, 0", "grid/upper corner": "1, 0.5", "grid/cells": "40, 20",
                       "boundary conditions/friction": "", "gravity/acceleration": "0, 0",
                       "time/end time": "0.2", "output/directory": "out",
                       "body 0/lower corner": "0.2, 0.15", "body 0/upper corner": "0.4, 0.3",
                       "body 0/initial velocity function": "1 - 2 * (y - 0.225); 2 * (x - 0.3)"}.items():
        text = tv.prm_set(text, key, value)
    text = tv.prm_set(text, "number of bodies", "2") + tv.box_body(1, "other", "0.6, 0.2", "0.8, 0.35", "-1, 0")
    tv.run_tool(tool, text, work, "blocks")
    s = tv.read_csv(f"{work}/out/series.csv")
    rho = 2000.0
    scale = rho * (0.2 * 0.15 * 1.0 + 0.2 * 0.15 * 1.0)  # sum m |v| >= this (|v| >= 1 everywhere)
    for c in ("momentum_x", "momentum_y"):
        d = max(abs(p - s[c][0]) for p in s[c])
        tv.check(d < 1e-12 * scale, f"{c}: largest change {d:.2e} kg m/s < 1e-12 sum m |v| "
                                    f"({1e-12 * scale:.1e}) over {len(s[c])} outputs")
    # angular momentum about the origin (2D: z), APIC's: sum m (x v_y - y v_x + (h^2 / 4)(C_yx - C_xy));
    # every point has m = rho (h / 2)^2 (2 x 2 points in full cells) and stays in the splines' interior
    # (D_p = h^2 / 4 I); after one step and at the end (the start has C_p = 0 by seeding)
    h = 0.025
    m = rho * (h / 2) ** 2

    def angular(t):
        return sum(m * (x * vy - y * vx + h * h / 4 * (cyx - cxy)) for x, y, vx, vy, cyx, cxy in
                   zip(t["pos_x"], t["pos_y"], t["v_x"], t["v_y"], t["affine_velocity_yx"],
                       t["affine_velocity_xy"]))

    one = tv.prm_set(text, "time/end time", "1e-9")
    one = tv.prm_set(tv.prm_set(one, "output/directory", "one"), "output/final particles csv", "true")
    tv.run_tool(tool, one, work, "one")
    tv.run_tool(tool, tv.prm_set(text, "output/final particles csv", "true"), work, "blocks_csv")
    L1 = angular(tv.read_csv(f"{work}/one/particles_final.csv"))
    L2 = angular(tv.read_csv(f"{work}/out/particles_final.csv"))
    r = 0.5 * math.hypot(1.0, 0.5)  # the largest |x| in the box
    tv.check(abs(L2 - L1) < 1e-12 * scale * r,
             f"angular momentum after one step {L1:.12e}, at {s['time'][-1]:g} s {L2:.12e} kg m^2/s: change "
             f"{abs(L2 - L1):.2e} < 1e-12 sum m |v| r ({1e-12 * scale * r:.1e})")
    ke = s["kinetic_energy"]
    tv.check(min(ke) < 0.9 * ke[0], f"the blocks collided (kinetic energy {ke[0]:.4g} J -> min {min(ke):.4g} J)")
else:
    tv.fail(f"unknown case '{case}'")
tv.finish()
