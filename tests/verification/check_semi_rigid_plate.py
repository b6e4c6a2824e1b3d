"""The rigid plate of talus-semi-implicit (issue 37; docs/semi-implicit.md 'Rigid plate').

Scenes: the shared layer (parameter_files/verification/rigid_plate/
layer_semi_implicit.prm, including layer.inc: 1 m x 1 m saturated elastic
layer, E = 1 MPa, nu = 0.3, n = 0.3, k = 1e-2 m/s, fixed base, roller sides, a
frictionless plate on the top face draining the water (permeable)) and a
footing: a region plate on 0 <= x <= 0.5 m of the top of a 2 m x 1 m layer with
a free water surface beside it.

Modes (one ctest each):
  layer         the shared scene to the end of consolidation: plate settlement
                within 1 % of q H / E_oed = 7.4286e-4 m; the plate force equal to
                the given -1 kN x f(t) at every row (1e-9 relative: force control
                balances the plate at the end of each step); the plate nodes'
                displacement spread 0 (1e-15 m); the same with 'point sets =
                single' (1 %); the 3D column (3 x 3 x 8 cells, plate along z): 1 %
                and the 2D settlement to 1e-9 (the problem is 1D); and 1 vs 2 ranks over the first 0.4 s: every series
                column and every final point field within 1e-10 relative (per
                quantity, of its largest component).
  displacement  the layer driven by the displacement -7.4286e-4 m (ramp 1 s): the
                reaction at the end within 1 % of -E_oed (d / H) W = -1 kN.
  terzaghi      the layer under a sudden load: settlement / (q H / E_oed) within
                0.01 of Terzaghi's degree of consolidation U(T_v) at T_v = 0.1,
                0.2, 0.5 (single drainage through the plate, c_v = k E_oed /
                (rho_w g)).
  footing       frictionless and rough plates (force -500 N/m): the nodes' axis
                displacement spread 0 (1e-15 m) in both; the nodes' tangential
                displacement 0 for the rough plate (1e-15 m) and not 0 for the
                frictionless one (> 1e-5 m: the check can fail); the rough plate
                reports a tangential reaction (> 1 N/m), the frictionless one
                none; an impermeable footing reaches the force too; 1 vs 2 ranks
                of the rough impermeable footing within 1e-10.
  restart       checkpoint/restart of the layer: series.csv and both final point
                files byte for byte identical to the uninterrupted run, 1 and 2 ranks.
Usage: check_semi_rigid_plate.py MODE TOOL LAYER_PRM WORKDIR
"""
import math
import os
import re
import shutil
import sys

import talus_verify as tv

mode, tool, layer_prm, work = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
inc = os.path.join(os.path.dirname(os.path.abspath(layer_prm)), "layer.inc")
layer = open(layer_prm).read()

E, nu, H, W, q = 1e6, 0.3, 1.0, 1.0, 1e3
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
s_inf = q * H / E_oed  # 7.4286e-4 m
k, rho_w, g = 1e-2, 1000.0, 9.81
c_v = k * E_oed / (rho_w * g)


def run(name, text, np=1, expect_rc=0, **entries):
    t = tv.prm_set(text, "output/directory", os.path.join(work, name))
    for key, v in entries.items():
        t = tv.prm_set(t, key, v)
    d = os.path.join(work, "prm")
    os.makedirs(d, exist_ok=True)
    shutil.copy(inc, d)  # 'include layer.inc' is resolved next to the .prm
    return tv.run_tool(tool, t, d, name, np=np, expect_rc=expect_rc)


def series(name):
    return tv.read_csv(os.path.join(work, name, "series.csv"))


def at_time(s, col, t):
    """Column value at time t (linear interpolation between rows)."""
    ts = s["time"]
    for i in range(1, len(ts)):
        if ts[i] >= t:
            a = (t - ts[i - 1]) / (ts[i] - ts[i - 1])
            return s[col][i - 1] + a * (s[col][i] - s[col][i - 1])
    return s[col][-1]


def compare_ranks(a, b, what):
    worst, where = 0.0, ""
    sa, sb = series(a), series(b)
    for c in sa:
        if c in ("pressure_cg_iterations", "pressure_relative_residual"):
            continue
        if c.endswith(("_node_spread", "_node_slip")):  # round-off bounds in metres: absolute, 1e-12 m
            d = max(abs(x - y) for x, y in zip(sa[c], sb[c])) * 1e-10 / 1e-12
        else:
            d = tv.relative_differences(sa, sb, [c])[c]
        if d > worst:
            worst, where = d, "series " + c
    for s in ("soil", "water"):
        pa = tv.by_initial_position(tv.read_csv(os.path.join(work, a, f"{s}_final.csv")))
        pb = tv.by_initial_position(tv.read_csv(os.path.join(work, b, f"{s}_final.csv")))
        if len(pa["pos_x"]) != len(pb["pos_x"]):
            worst, where = 1.0, f"{s} point count"
            continue
        # per quantity, the scale of all its components (a 1D scene's x velocity is round-off);
        # the per-step scratch fields of the Poisson assembly are not compared
        cols = [c for c in pa if c not in ("material_id", "body_id") and not isinstance(pa[c][0], str)
                and not c.startswith(("poisson_", "plate_flux"))]

        def quantity(c):
            # the model's history variables share a scale too: the Neo-Hookean b_e of the
            # shared scene keeps its six components in history_0..5, the shear ones round-off
            if c.startswith("history_"):
                return "history"
            head, _, tail = c.rpartition("_")
            return head if tail in ("x", "y", "z", "xx", "yy", "zz", "xy", "xz", "yz") else c

        scale = {}
        for c in cols:
            scale[quantity(c)] = max(scale.get(quantity(c), 0.0), max(abs(v) for v in pa[c]))
        for c in cols:
            d = max(abs(x - y) for x, y in zip(pa[c], pb[c])) / (scale[quantity(c)] or 1.0)
            if d > worst:
                worst, where = d, f"{s} {c}"
    tv.check(worst < 1e-10, f"{what}: 1 vs 2 ranks within 1e-10 (largest {worst:.1e} in {where})")


if mode == "layer":
    for name, extra in (("double", {}), ("single", {"semi implicit/point sets": "single"})):
        run(name, layer, **extra)
        s = series(name)
        u = -s["plate_0_displacement"][-1]
        err = (u - s_inf) / s_inf
        tv.check(abs(err) < 0.01, f"{name} point sets: plate settlement {u:.5e} m vs q H / E_oed = {s_inf:.5e} m "
                 f"({100 * err:+.3f} %, tolerance 1 %)")
        ferr = max(abs(f - (-q * W * min(t, 1.0))) for t, f in zip(s["time"], s["plate_0_force"])) / (q * W)
        tv.check(ferr < 1e-9, f"{name}: plate force = -1 kN x f(t) at every row (largest difference {ferr:.1e} of 1 kN)")
        tv.check(s["plate_0_node_spread"][-1] < 1e-15,
                 f"{name}: the plate nodes moved as one (spread {s['plate_0_node_spread'][-1]:.1e} m)")
    # 3D: the same layer as a 0.375 x 0.375 x 1 m column (3 x 3 x 8 cells), rollers on the four
    # sides, fixed base, the plate on the top face (id 5) along z with q x 0.375^2
    text3 = layer.replace("include layer.inc", open(inc).read())
    for key, v in {"dimension": "3", "grid/lower corner": "0, 0, 0", "grid/upper corner": "0.375, 0.375, 1",
                   "grid/cells": "3, 3, 8", "boundary conditions/fixed": "4",
                   "boundary conditions/roller": "0, 1, 2, 3", "boundary conditions/rigid plate 0/boundary id": "5",
                   "boundary conditions/rigid plate 0/direction": "z",
                   "boundary conditions/rigid plate 0/total force": f"{-q * 0.375 ** 2}",
                   "gravity/acceleration": "0, 0, 0", "body 0/lower corner": "0, 0, 0",
                   "body 0/upper corner": "0.375, 0.375, 1"}.items():
        text3 = tv.prm_set(text3, key, v)
    run("three_d", text3)
    u3 = -series("three_d")["plate_0_displacement"][-1]
    u2 = -series("double")["plate_0_displacement"][-1]
    tv.check(abs(u3 - s_inf) / s_inf < 0.01 and abs(u3 - u2) / u2 < 1e-9,
             f"3D column: plate settlement {u3:.6e} m ({100 * (u3 - s_inf) / s_inf:+.3f} %; 2D {u2:.6e} m, "
             f"relative difference {abs(u3 - u2) / u2:.1e}, tolerances 1 % and 1e-9)")
    # 1 vs 2 ranks on the first 0.4 s (200 steps: through the ramp, mid-consolidation)
    run("short", layer, **{"time/end time": "0.4"})
    run("short_np2", layer, np=2, **{"time/end time": "0.4"})
    compare_ranks("short", "short_np2", "layer")

elif mode == "displacement":
    text = tv.prm_set(layer, "boundary conditions/rigid plate 0/total force", "")
    d_given = float(f"{-s_inf:.6e}")
    text = tv.prm_set(text, "boundary conditions/rigid plate 0/displacement", f"{d_given:.6e}")
    run("displacement", text)
    s = series("displacement")
    F = s["plate_0_force"][-1]
    F_ref = -E_oed * (s_inf / H) * W
    err = (F - F_ref) / abs(F_ref)
    tv.check(abs(err) < 0.01, f"displacement control: reaction {F:.3f} N/m vs -E_oed (d / H) W = {F_ref:.3f} N/m "
             f"({100 * err:+.3f} %, tolerance 1 %)")
    d = s["plate_0_displacement"][-1]
    tv.check(abs(d - d_given) < 1e-12 * abs(d_given) * 1500,
             f"displacement control: the plate at the history's {d_given:.6e} m ({d:.10e} m)")

elif mode == "terzaghi":
    text = tv.prm_set(layer, "boundary conditions/rigid plate 0/time function", "constant")
    text = tv.prm_set(text, "time/end time", f"{0.52 / c_v:.4f}")
    text = tv.prm_set(text, "output/series interval", "0")
    run("terzaghi", text)
    s = series("terzaghi")

    def U(T):
        return 1 - sum(8 / ((2 * m + 1) ** 2 * math.pi ** 2) * math.exp(-((2 * m + 1) ** 2) * math.pi ** 2 * T / 4)
                       for m in range(200))

    for T in (0.1, 0.2, 0.5):
        u = -at_time(s, "plate_0_displacement", T / c_v) / s_inf
        tv.check(abs(u - U(T)) < 0.01, f"sudden load, T_v = {T}: settlement / s_inf = {u:.4f} vs U = {U(T):.4f} "
                 f"(difference {u - U(T):+.4f}, tolerance 0.01)")

elif mode == "footing":
    foot = layer.replace("include layer.inc", open(inc).read())
    for key, v in {"grid/upper corner": "2, 1.125", "grid/cells": "16, 9", "body 0/upper corner": "2, 1",
                   "boundary conditions/rigid plate 0/apply to": "region",
                   "boundary conditions/rigid plate 0/region lower corner": "-0.01, 0.99",
                   "boundary conditions/rigid plate 0/region upper corner": "0.51, 1.01",
                   "boundary conditions/rigid plate 0/total force": "-500",
                   "boundary conditions/rigid plate 0/time function": "ramp 0.5",
                   "time/end time": "1"}.items():
        foot = tv.prm_set(foot, key, v)
    runs = {"frictionless": {}, "rough": {"boundary conditions/rigid plate 0/surface": "rough"},
            "rough_impermeable": {"boundary conditions/rigid plate 0/surface": "rough",
                                  "boundary conditions/rigid plate 0/drainage": "impermeable"}}
    for name, extra in runs.items():
        _, out, _ = run(name, foot, **extra)
        tv.check(re.search(r"rigid plate 0: region, 5 nodes", out) is not None, f"{name}: log names the plate, 5 nodes")
        s = series(name)
        ferr = max(abs(f - (-500 * min(t / 0.5, 1.0))) for t, f in zip(s["time"], s["plate_0_force"])) / 500
        tv.check(ferr < 1e-9, f"{name}: plate force = -500 N/m x f(t) at every row ({ferr:.1e})")
        tv.check(s["plate_0_node_spread"][-1] < 1e-15,
                 f"{name}: the plate nodes' vertical displacement uniform (spread {s['plate_0_node_spread'][-1]:.1e} m)")
        slip = s["plate_0_node_slip"][-1]
        if name == "frictionless":
            tv.check(slip > 1e-5, f"frictionless: the plate nodes slide horizontally ({slip:.2e} m > 1e-5 m)")
            tv.check("plate_0_tangential_force" not in s, "frictionless: no tangential reaction column")
        else:
            tv.check(slip < 1e-15, f"{name}: the plate nodes' horizontal displacement 0 ({slip:.1e} m)")
            T = max(abs(x) for x in s["plate_0_tangential_force"])
            tv.check(T > 1, f"{name}: a tangential reaction is reported ({T:.2f} N/m)")
    short = dict(runs["rough_impermeable"], **{"time/end time": "0.3"})
    run("rough_impermeable_short", foot, **short)
    run("rough_impermeable_np2", foot, np=2, **short)
    compare_ranks("rough_impermeable_short", "rough_impermeable_np2", "rough impermeable footing (0.3 s)")

elif mode == "restart":
    text = layer
    for key, v in {"time/end time": "0.4", "output/series interval": "0", "checkpoint/interval": "0.1",
                   "checkpoint/keep": "2"}.items():
        text = tv.prm_set(text, key, v)
    for np in (1, 2):
        ref, part = f"ref_np{np}", f"restarted_np{np}"
        run(ref, text, np)
        run(part, text, np, **{"time/end time": "0.25"})
        _, out, _ = run(part, text, np, **{"checkpoint/restart": "true"})
        m = re.search(r"restarting from \S+ \(step (\d+)", out)
        tv.check(m is not None and int(m.group(1)) == 100,
                 f"np={np}: restarted at step 100 ({m.group(1) if m else 'no restart'})")
        for f in ("series.csv", "soil_final.csv", "water_final.csv"):
            a = open(os.path.join(work, ref, f)).read()
            b = open(os.path.join(work, part, f)).read()
            tv.check(a == b, f"np={np}: {f} byte for byte identical to the uninterrupted run")
    # the comparison can fail: a restart with another plate force differs
    shutil.copytree(os.path.join(work, "restarted_np1", "checkpoints"), os.path.join(work, "mutant", "checkpoints"))
    run("mutant", text, **{"checkpoint/restart": "true", "checkpoint/interval": "0",
                           "boundary conditions/rigid plate 0/total force": "-1001"})
    tv.check(open(os.path.join(work, "mutant", "series.csv")).read()
             != open(os.path.join(work, "ref_np1", "series.csv")).read(),
             "a restart with a force of -1001 N differs (the comparison can fail)")
else:
    tv.fail(f"unknown mode '{mode}'")
tv.finish()
