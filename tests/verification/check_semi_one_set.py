"""The one-set single-point variant of talus-semi-implicit (issue 40 item 2):
`semi implicit/point sets = one set`, one point set whose points carry the soil
and its pore water (soil_final.csv holds pore_pressure, water_velocity,
water_mass; water_final.csv has no rows).

Modes:
  terzaghi TOOL PRM WORKDIR     the §5.1 Terzaghi column (semi_implicit_terzaghi.prm)
    at T_v = 0.1 with point sets = double, single and one set:
    - each: normalised L2 error of the pore pressure vs the series < 3 % (as
      check_semi_terzaghi.py);
    - one set vs double: the row means of the pore pressure (points binned
      by their current height in the grid's 0.025 m rows) within 1 % of q at
      every row, and the mean soil settlement of the top row within 1 %;
    - one set vs single (the same soil points, the water on them): every
      point's pore pressure within 1e-4 q, its soil displacement within 1e-4
      of the largest (the variants differ only in the water's porosity: the
      point's own or interpolated from the nodes); the one-set water set empty, the water mass of every
      point n0 rho_w V0 to 1e-12.
  hydrostatic TOOL PRM WORKDIR  the hydrostatic column (semi_implicit_hydrostatic.prm,
    k = 1e-3 m/s, 2000 steps) with one set and double: pore pressure within
    1 % of rho_w g d and sigma'_yy within 1 % of the buoyant weight at every
    point (the check of check_semi_hydrostatic.py), and the row means of the
    pore pressure of the two variants within 0.1 % of rho_w g H.
  ranks TOOL PRM WORKDIR        the consolidation column (semi_implicit_consolidation.prm)
    for 100 steps on 1 and 2 ranks with one set: every column of
    soil_final.csv (points matched by their initial position) within 1e-10
    of its scale (as check_semi_ranks.py; the step's scratch poisson_* printed).
  restart TOOL PRM WORKDIR      the same column, 200 steps vs 100 + checkpoint +
    restart + 100, on 1 and on 2 ranks, with one set: soil_final.csv and
    series.csv byte for byte identical.
Usage: check_semi_one_set.py MODE TOOL PRM WORKDIR
"""
import math
import os
import re
import shutil
import sys

import talus_verify as tv

mode, tool, prm_path, work = sys.argv[1:5]
base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
SETS = "semi implicit/point sets"


def run(name, text, np=1):
    tv.run_tool(tool, text, f"{work}/{name}", name, np=np)
    d = f"{work}/{name}/out"
    return tv.read_csv(f"{d}/soil_final.csv"), tv.read_csv(f"{d}/water_final.csv"), d


def row_means(ys, ps, h):
    """mean of ps per row of height h (by the point's current y)"""
    rows = {}
    for y, p in zip(ys, ps):
        rows.setdefault(int(math.floor(y / h)), []).append(p)
    return {k: sum(v) / len(v) for k, v in rows.items()}


def compare_rows(a, b, scale):
    common = sorted(set(a) & set(b))
    return max(abs(a[k] - b[k]) for k in common) / scale, len(common), len(set(a) ^ set(b))


def pore(soil, water, sets):
    """(heights, pore pressures) of the water of a run"""
    t = soil if sets == "one set" else water
    return t["pos_y"], t["pore_pressure"]


if mode == "terzaghi":
    q, H, rw, g, E, k, dt, n0 = 1e4, 1.0, 1000.0, 9.81, 1e7, 1e-3, 1e-4, 0.3
    cv = k * E / (rw * g)
    n_steps = round(0.1 * H * H / cv / dt)
    Tn = cv * n_steps * dt / (H * H)

    def analytic(zeta):
        return sum(2 * q / M * math.sin(M * zeta) * math.exp(-M * M * Tn)
                   for M in (math.pi * (2 * m + 1) / 2 for m in range(400)))

    runs = {}
    for sets in ("double", "single", "one set"):
        text = tv.prm_set(tv.prm_set(base, "time/end time", repr(n_steps * dt)), SETS, sets)
        runs[sets] = run(sets.replace(" ", "_"), text)
        ys, ps = pore(runs[sets][0], runs[sets][1], sets)
        num = sum((-p - analytic(min(max((H - y) / H, 0.0), 1.0))) ** 2 for p, y in zip(ps, ys))
        den = sum(analytic(min(max((H - y) / H, 0.0), 1.0)) ** 2 for y in ys)
        e = math.sqrt(num / den)
        print(f"{sets}: T_v = {Tn:.4f}, {len(ys)} pore pressure samples, normalised L2 error {e:.3e}")
        tv.check(e < 0.03, f"{sets}: normalised L2 error {e:.2e} < 0.03")
    s1, w1, _ = runs["one set"]
    tv.check(len(w1.get("pos_x", [])) == 0, f"one set: no water points ({len(w1.get('pos_x', []))})")
    ms = max(abs(m - n0 * rw * v) for m, v in zip(s1["water_mass"], s1["initial_volume"])) / (n0 * rw * max(
        s1["initial_volume"]))
    tv.check(ms < 1e-12, f"one set: every point's water mass n0 rho_w V0 ({ms:.1e})")
    # one set vs double: pore pressure rows, top-row settlement
    h = 0.025
    a = row_means(*pore(s1, w1, "one set"), h)
    sd, wd, _ = runs["double"]
    b = row_means(*pore(sd, wd, "double"), h)
    diff, n, odd = compare_rows(a, b, q)
    print(f"one set vs double: pore pressure row means, largest difference {diff:.3e} q over {n} rows "
          f"({odd} rows with points of one run only)")
    tv.check(diff < 0.01, f"one set vs double: pore pressure row means within 1 % of q ({diff:.2e})")

    def top_settlement(s):
        y0 = [y - u for y, u in zip(s["pos_y"], s["displacement_y"])]
        top = max(y0)
        us = [u for u, y in zip(s["displacement_y"], y0) if y > top - 1e-9]
        return -sum(us) / len(us)

    u1, ud = top_settlement(s1), top_settlement(sd)
    print(f"settlement of the top row: one set {u1:.6e} m, double {ud:.6e} m, single "
          f"{top_settlement(runs['single'][0]):.6e} m")
    tv.check(abs(u1 - ud) < 0.01 * abs(ud), f"one set vs double: top settlement within 1 % ({(u1 - ud) / ud:+.2e})")
    # one set vs single: point by point
    ss, ws, _ = runs["single"]
    A, B = tv.by_initial_position(s1), tv.by_initial_position(ss)
    W = tv.by_initial_position(ws)
    tv.check(len(A["pos_x"]) == len(B["pos_x"]) == len(W["pos_x"]), "one set vs single: same points")
    dp = max(abs(x - y) for x, y in zip(A["pore_pressure"], W["pore_pressure"])) / q
    umax = max(abs(u) for u in B["displacement_y"])
    du = max(abs(x - y) for x, y in zip(A["displacement_y"], B["displacement_y"])) / umax
    print(f"one set vs single: point pore pressure within {dp:.3e} q, soil displacement within {du:.3e} of the largest")
    tv.check(dp < 1e-4, f"one set vs single: every point's pore pressure within 1e-4 q ({dp:.2e})")
    tv.check(du < 1e-4, f"one set vs single: soil displacement within 1e-4 of the largest ({du:.2e})")
elif mode == "hydrostatic":
    g, H, n, rs, rw = 9.81, 1.0, 0.3, 2650.0, 1000.0
    pw_ref, sv_ref = rw * g * H, (1 - n) * (rs - rw) * g * H
    text = tv.prm_set(base, "material 0/pore liquid/hydraulic conductivity", "1e-3")
    rows = {}
    for sets in ("one set", "double"):
        s, w, _ = run(sets.replace(" ", "_"), tv.prm_set(text, SETS, sets))
        ys, ps = pore(s, w, sets)
        ep = max(abs(p + rw * g * (H - y)) for p, y in zip(ps, ys)) / pw_ref
        es = max(abs(sy + (1 - n) * (rs - rw) * g * (H - y)) for sy, y in zip(s["stress_yy"], s["pos_y"])) / sv_ref
        print(f"{sets}: max |p + rho_w g d| / (rho_w g H) = {ep:.3e}, "
              f"max |sigma'_yy - ref| / ((1-n)(rho_s-rho_w) g H) = {es:.3e}")
        tv.check(ep < 0.01, f"{sets}: pore pressure within 1 % of rho_w g d ({ep:.2e})")
        tv.check(es < 0.01, f"{sets}: vertical effective stress within 1 % ({es:.2e})")
        rows[sets] = row_means(ys, ps, 1.0 / 40)
    diff, nrow, odd = compare_rows(rows["one set"], rows["double"], pw_ref)
    print(f"one set vs double: pore pressure row means, largest difference {diff:.3e} rho_w g H over {nrow} rows")
    tv.check(diff < 1e-3, f"one set vs double: pore pressure row means within 0.1 % of rho_w g H ({diff:.2e})")
elif mode == "ranks":
    text = tv.prm_set(base, "time/end time", "0.03")
    text = tv.prm_set(tv.prm_set(text, "time/time step", "3e-4"), SETS, "one set")
    t = {np: tv.by_initial_position(run(f"np{np}", text, np)[0]) for np in (1, 2)}
    a, b = t[1], t[2]
    tv.check(len(a["pos_x"]) == len(b["pos_x"]), f"same number of points ({len(a['pos_x'])}, {len(b['pos_x'])})")
    def stem(c):  # a vector's or the stress's components share the scale of the largest
        for suffix in ("_xx", "_yy", "_zz", "_xy", "_xz", "_yz", "_x", "_y", "_z"):
            if c.endswith(suffix):
                return c[: -len(suffix)]
        return None

    # the step's scratch (the points' Poisson coefficient and flux phi v*, set
    # anew every step and read by nothing after it) printed, not checked
    scratch = [c for c in a if c.startswith("poisson_")]
    d = {}
    for c in a:
        scale = max(abs(v) for v in a[c])
        if stem(c):
            scale = max([scale] + [max(abs(v) for v in a[o]) for o in a if stem(o) == stem(c)])
        d[c] = max(abs(x - y) for x, y in zip(a[c], b[c])) / (scale or 1.0)
    print("scratch: " + ", ".join(f"{c} {d.pop(c):.1e}" for c in scratch))
    worst = max(d, key=d.get)
    print(f"one set, 1 vs 2 ranks: largest relative difference {d[worst]:.2e} in '{worst}' "
          f"(pore_pressure {d['pore_pressure']:.2e}, water_velocity_y {d['water_velocity_y']:.2e})")
    tv.check(d[worst] < 1e-10, f"one set: 1 and 2 ranks agree to 1e-10 (largest {d[worst]:.2e} in '{worst}')")
elif mode == "restart":
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    text = base
    for k, v in {"time/end time": "0.06", "time/time step": "3e-4", "output/vtu interval": "0",
                 "output/series interval": "0", "output/final particles csv": "true", "output/progress": "false",
                 "checkpoint/interval": "0.015", "checkpoint/keep": "2",
                 "semi implicit/pressure preconditioner rebuild interval": "30",
                 "output/probes": "0.075, 0.99; 0.02, 0.1", SETS: "one set"}.items():
        text = tv.prm_set(text, k, v)

    def files(name):
        d = f"{work}/{name}/out"
        return [open(f"{d}/{f}").read() for f in ("soil_final.csv", "series.csv")]

    for np in (1, 2):
        ref, part = f"ref_np{np}", f"restarted_np{np}"
        run(ref, text, np)
        run(part, tv.prm_set(text, "time/end time", "0.036"), np)
        _, out, _ = tv.run_tool(tool, tv.prm_set(text, "checkpoint/restart", "true"), f"{work}/{part}", part, np=np)
        m = re.search(r"restarting from \S+ \(step (\d+)", out)
        tv.check(m is not None and int(m.group(1)) == 100,
                 f"np={np}: restarted at step 100 ({m.group(1) if m else 'no restart'})")
        a, b = files(ref), files(part)
        tv.check(a[0] == b[0], f"np={np}: soil_final.csv (soil and pore water) byte for byte identical")
        tv.check(a[1] == b[1], f"np={np}: series.csv byte for byte identical (with the probes' pore pressure)")
        tv.check("probe0_pore_pressure" in a[1].splitlines()[0], f"np={np}: the probes' pore pressure in series.csv")
else:
    tv.fail(f"unknown mode {mode}")
tv.finish()
