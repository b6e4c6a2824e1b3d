"""The shared boundary conditions and loads in talus-semi-implicit (issue 37;
docs/boundary-conditions.md, docs/semi-implicit.md 'Boundary conditions and loads').

Scene: parameter_files/verification/semi_implicit_boundary_loads.prm, a 1 m x 1 m
saturated elastic layer (E = 1 MPa, nu = 0.3: E_oed = 1.3462 MPa; n = 0.3,
k = 1e-2 m/s: c_v = k E_oed / (rho_w g) = 1.372 m^2/s), fixed base, roller sides,
no gravity.

Modes (one ctest each):
  displacement  'loads/velocity 0' pushes the top face (boundary id 3) down by
                d = 7.4286e-4 m over 1 s, then holds it; the face drains
                ('boundary conditions/drainage 0': boundary 3 drained). At 3 s
                (consolidated): the reaction of the condition (series column
                velocity_0_reaction_y) within 1 % of -E_oed (d / H) W = -1 kN/m,
                the mean sigma'_yy of the soil points within 1 % of -E_oed d / H,
                the top points moved by d (1 %) and the residual pore pressure
                below 1 % of E_oed d / H; the water crossed the moving drained
                face (its top row moved up while the soil's went down).
  traction      q = 1 kPa (ramp 1 s) on the top face to 3 s, the face drained:
                as 'loads/traction 0' on grid boundary id 3 (nodal forces) and on
                the body face y+ (point forces at the body surface); settlement
                H (1 - V / V0) within 1 % of q H / E_oed = 7.4286e-4 m in both,
                the mean sigma'_yy within 1 % of -q.
  pressure      the top face's pore pressure prescribed ('drainage 0': condition =
                pressure, -5 kPa ramped over 0.1 s), nothing else loading: at
                0.2 s every water point's pressure within 1 % of it, half of it at
                0.05 s (5 %), no effective stress (< 1 % of 5 kPa), no settlement.
  dry_face      the layer under dry cells (grid to 1.25 m), a sudden q = 1 kPa on
                the body face y+: impermeable by default (no drainage condition):
                at t = 0.05 s the mean pore pressure of the water points within
                5 % of the undrained -q and the settlement below 5 % of the
                drained one; with the surface drained ('drainage 0' on a region
                around it): mean pore pressure within 0.05 q of Terzaghi's
                average -(1 - U(T_v)) q (single drainage upwards) at 0.05 s, and
                the pressure of the top row of water points near 0 (< 0.2 q)
                where the impermeable run's is near -q (> 0.8 q).
  refuse        a traction on a grid boundary id in talus-explicit and
                talus-implicit (they carry tractions by material points): exit
                2 naming 'loads/traction 0/apply to', nothing written; the dry
                face sealed with linear shape functions (no pressure reference in
                a closed sealed box): exit 2 naming 'loads/traction 0'.
Usage: check_semi_boundary_loads.py MODE TOOLS_DIR PRM PRM_DIR WORKDIR
"""
import math
import os
import shutil
import sys

import talus_verify as tv

mode, tools, prm_path, prm_dir, work = sys.argv[1:6]
tool = os.path.join(tools, "talus-semi-implicit")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(prm_path).read()

E, nu, H, W, q = 1e6, 0.3, 1.0, 1.0, 1e3
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
d = 7.428571e-4
s_inf = q * H / E_oed
k, rho_w, g = 1e-2, 1000.0, 9.81
c_v = k * E_oed / (rho_w * g)


def run(name, text, expect_rc=0, tool_path=tool, **entries):
    t = tv.prm_set(text, "output/directory", os.path.join(work, name))
    for key, v in entries.items():
        t = tv.prm_set(t, key, v)
    return tv.run_tool(tool_path, t, os.path.join(work, "prm_" + name), name, expect_rc=expect_rc)


def series(name):
    return tv.read_csv(os.path.join(work, name, "series.csv"))


def at_time(s, col, t):
    ts = s["time"]
    for i in range(1, len(ts)):
        if ts[i] >= t - 1e-12:
            a = (t - ts[i - 1]) / (ts[i] - ts[i - 1]) if ts[i] > ts[i - 1] else 1.0
            return s[col][i - 1] + a * (s[col][i] - s[col][i - 1])
    return s[col][-1]


def final(name, which):
    return tv.read_csv(os.path.join(work, name, which + "_final.csv"))


def mean(xs):
    return sum(xs) / len(xs)


def U(Tv):
    """Terzaghi's average degree of consolidation (single drainage path H)."""
    s = 0.0
    for m in range(200):
        M = math.pi * (2 * m + 1) / 2
        s += 2 / M**2 * math.exp(-M * M * Tv)
    return 1 - s


no_velocity = {}

if mode == "displacement":
    sig = -E_oed * d / H
    velocity = tv.prm_set_args(base, ["loads/number of velocity conditions=1", "loads/velocity 0/apply to=boundary",
                                      "loads/velocity 0/boundary id=3", "loads/velocity 0/components=y",
                                      f"loads/velocity 0/velocity=0, {-d}",
                                      "loads/velocity 0/time function=table 0:1, 1:1, 1.000001:0"])
    for name, entries in (("drained_top", {}),):
        run(name, velocity, **entries)
        s, soil, water = series(name), final(name, "soil"), final(name, "water")
        R = s["velocity_0_reaction_y"][-1]
        tv.check(abs(R / (sig * W) - 1) < 0.01,
                 f"{name}: reaction {R:.6g} N/m vs -E_oed (d / H) W = {sig * W:.6g} ({100 * (R / (sig * W) - 1):+.3f} %)")
        syy = mean(soil["stress_yy"])
        tv.check(abs(syy / sig - 1) < 0.01, f"{name}: mean sigma'_yy {syy:.6g} Pa vs {sig:.6g} ({100 * (syy / sig - 1):+.3f} %)")
        Y0 = [y - u for y, u in zip(soil["pos_y"], soil["displacement_y"])]
        top = max(Y0)
        uy = mean([u for y0, u in zip(Y0, soil["displacement_y"]) if y0 > top - 1e-9])
        # the top points sit h / 4 below the face: in a uniform strain d (H - h/4) / H
        expect = -d * (H - 0.125 / 4) / H
        tv.check(abs(uy / expect - 1) < 0.01, f"{name}: top points moved {uy:.6g} m vs {expect:.6g} m")
        pmax = max(abs(p) for p in water["pore_pressure"])
        tv.check(pmax < 0.01 * abs(sig), f"{name}: residual pore pressure {pmax:.3g} Pa < 1 % of {abs(sig):.4g} Pa")
    # the water leaves through the drained face: its top row rose while the soil's went down
    water = final("drained_top", "water")
    Y0 = [y - u for y, u in zip(water["pos_y"], water["displacement_y"])]
    uw = mean([u for y0, u in zip(Y0, water["displacement_y"]) if y0 > max(Y0) - 1e-9])
    tv.check(uw > 0, f"the water crossed the moving drained face: its top row moved {uw:.4g} m (up)")

elif mode == "traction":
    trac = dict(no_velocity)
    trac.update({"loads/number of tractions": "1", "loads/traction 0/traction": "0, -1e3",
                 "loads/traction 0/time function": "ramp 1"})
    for name, target in (("boundary", {"loads/traction 0/apply to": "boundary", "loads/traction 0/boundary id": "3"}),
                         ("body_face", {"loads/traction 0/apply to": "body face", "loads/traction 0/face": "y+"})):
        entries = dict(trac)
        entries.update(target)
        run(name, base, **entries)
        s, soil = series(name), final(name, "soil")
        S = H * (1 - s["soil_volume"][-1] / s["soil_volume"][0])
        tv.check(abs(S / s_inf - 1) < 0.01, f"traction on the {name.replace('_', ' ')}: settlement {S:.6e} m vs "
                 f"q H / E_oed = {s_inf:.6e} m ({100 * (S / s_inf - 1):+.3f} %)")
        syy = mean(soil["stress_yy"])
        tv.check(abs(syy / -q - 1) < 0.01, f"{name}: mean sigma'_yy {syy:.6g} Pa vs {-q:.6g} ({100 * (syy / -q - 1):+.3f} %)")

elif mode == "pressure":
    # the top face's pore pressure prescribed: -5 kPa (a 5 kPa water pressure, tension
    # positive) ramped over 0.1 s; with incompressible grains and water and nothing else
    # loading the layer, the pressure is the same everywhere at once and the skeleton
    # carries nothing: no effective stress, no settlement
    P0 = -5e3
    run("pressure", base, **{"boundary conditions/drainage 0/condition": "pressure",
                             "boundary conditions/drainage 0/pressure": str(P0),
                             "boundary conditions/drainage 0/time function": "ramp 0.1",
                             "time/end time": "0.2", "output/series interval": "0.01"})
    s, soil, water = series("pressure"), final("pressure", "soil"), final("pressure", "water")
    worst = max(abs(p / P0 - 1) for p in water["pore_pressure"])
    tv.check(worst < 0.01, f"prescribed pore pressure {P0:g} Pa on the top face: every water point within "
             f"{100 * worst:.3g} % of it (1 %)")
    half = at_time(s, "min_pore_pressure", 0.05)
    tv.check(abs(half / (0.5 * P0) - 1) < 0.05, f"at 0.05 s (f = 0.5) the pore pressure {half:.5g} Pa follows the time "
             f"function ({0.5 * P0:g} Pa, 5 %)")
    smax = max(abs(x) for x in soil["stress_yy"])
    tv.check(smax < 0.01 * abs(P0), f"the skeleton carries nothing: largest |sigma'_yy| {smax:.3g} Pa (< 1 % of {abs(P0):g})")
    S = H * (1 - s["soil_volume"][-1] / s["soil_volume"][0])
    tv.check(abs(S) < 1e-3 * abs(P0) * H / E_oed, f"no settlement: {S:.3g} m")

elif mode in ("dry_face", "refuse"):
    # (drainage 0 stays on boundary id 3, now the grid's top at 1.25 m, which no water reaches)
    dry = tv.prm_set_args(base, ["grid/upper corner=1, 1.25", "grid/cells=8, 10", "time/end time=0.05",
                                 "output/series interval=0.01",
                                 "loads/number of tractions=1", "loads/traction 0/traction=0, -1e3"])
    if mode == "dry_face":
        t_check = 0.05
        res = {}
        for name, entries in (("impermeable", {}),
                              ("drained", {"boundary conditions/drainage 0/apply to": "region",
                                           "boundary conditions/drainage 0/region lower corner": "0, 0.9",
                                           "boundary conditions/drainage 0/region upper corner": "1, 1.25"})):
            run(name, dry, **entries)
            s, soil, water = series(name), final(name, "soil"), final(name, "water")
            p = water["pore_pressure"]
            Y0 = [y - u for y, u in zip(water["pos_y"], water["displacement_y"])]
            top = max(Y0)
            p_top = mean([pp for pp, y0 in zip(p, Y0) if y0 > top - 1e-9])
            S = H * (1 - s["soil_volume"][-1] / s["soil_volume"][0])
            res[name] = (mean(p), p_top, S)
            print(f"{name}: mean pore pressure {mean(p):.5g} Pa, top row {p_top:.5g} Pa, settlement {S:.4e} m")
        # impermeable: the pressure builds under the load (the face is not the
        # free surface's p = 0); its size is not the undrained -q yet (the
        # gradient-form pressure force lacks the face term, docs/semi-implicit.md
        # 'Boundary conditions and loads'), so only the contrast is checked
        pm, pt, S = res["impermeable"]
        tv.check(abs(pt) > 0.8 * q, f"impermeable loaded face: top row pore pressure {pt:.5g} Pa (> 0.8 q in size)")
        tv.check(abs(pm) > abs(res["drained"][0]) and abs(pt) > 5 * abs(res["drained"][1]),
                 f"impermeable loaded face: pressure builds, mean {pm:.5g} / top row {pt:.5g} Pa against "
                 f"{res['drained'][0]:.5g} / {res['drained'][1]:.5g} Pa drained")
        pm, pt, S = res["drained"]
        ref = -(1 - U(c_v * t_check / H**2)) * q
        tv.check(abs(pm - ref) < 0.05 * q, f"drained loaded face: mean pore pressure {pm:.5g} Pa vs Terzaghi "
                 f"-(1 - U) q = {ref:.5g} Pa (T_v = {c_v * t_check:.4f})")
        tv.check(abs(pt) < 0.2 * q, f"drained loaded face: top row pore pressure {pt:.5g} Pa (< 0.2 q in size)")
    else:
        # talus-explicit and talus-implicit carry tractions by material points
        layer_dir = os.path.join(prm_dir, "verification", "rigid_plate")
        for fam, prm in (("explicit", "layer_explicit.prm"), ("implicit", "layer_implicit.prm")):
            text = open(os.path.join(layer_dir, prm)).read()
            text = tv.prm_set_args(text, ["loads/number of tractions=1",
                                          "loads/traction 0/apply to=boundary", "loads/traction 0/boundary id=3",
                                          "loads/traction 0/traction=0, -1e3"])
            text = tv.prm_set(text, "output/directory", "out")
            wd = os.path.join(work, fam)
            os.makedirs(wd, exist_ok=True)
            shutil.copy(os.path.join(layer_dir, "layer.inc"), wd)
            rc, out, err = tv.run_tool(os.path.join(tools, "talus-" + fam), text, wd, "case", expect_rc=None)
            tv.check(rc == 2 and "loads/traction 0/apply to" in out + err and "cannot honour" in out + err
                     and not os.path.exists(os.path.join(wd, "out")),
                     f"talus-{fam}: a traction on a boundary id: exit {rc}, refused naming the entry, nothing written")
        # a sealed closed box (linear shape functions: no dry node touches the water)
        rc, out, err = run("sealed_linear", dry, expect_rc=None, **{"numerics/shape function": "linear"})
        tv.check(rc == 2 and "loads/traction 0" in out + err and "no pressure reference" in out + err,
                 f"sealed closed box: exit {rc}, the traction named")
else:
    tv.fail("unknown mode " + mode)
tv.finish()
