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
                the body face y+. Sealed by default (no drainage condition): nothing
                drains (base and sides impermeable, the face sealed) and grains and
                water are incompressible, so at t = 0.05 s the pore pressure carries
                the whole load: mean pore pressure and the top water row's within 2 %
                of the undrained -q (tension positive), settlement below 1 % of the
                drained run's, the top water row within 0.01 h of the top soil row and
                no water point above it (no water leaves through the face). With the
                surface drained ('drainage 0' on a region around it): mean pore
                pressure within 0.05 q of Terzaghi's average -(1 - U(T_v)) q (single
                drainage upwards), the top row's pressure near 0 (< 0.2 q) and the
                water risen above the soil's top row (> 0.002 h).
  refuse        a traction on a grid boundary id in talus-explicit and
                talus-implicit (they carry tractions by material points): exit
                2 naming 'loads/traction 0/apply to', nothing written; a sealed
                closed box (the layer filling the grid, its top face impermeable
                under a boundary traction: no free surface, no pressure reference):
                exit 2 naming 'loads/traction 0'.
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
    h = 0.125  # the grid's cell

    def rows(points):
        """(initial y of each point row, its mean current y, its mean pore pressure)"""
        by = {}
        for y, u, p in zip(points["pos_y"], points["displacement_y"],
                           points.get("pore_pressure", [0.0] * len(points["pos_y"]))):
            by.setdefault(round(y - u, 6), []).append((y, p))
        return [(y0, mean([a for a, _ in v]), mean([b for _, b in v])) for y0, v in sorted(by.items())]

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
            wr, sr = rows(water), rows(soil)
            S = H * (1 - s["soil_volume"][-1] / s["soil_volume"][0])
            rise = max(water["pos_y"]) - sr[-1][1]  # the water's highest point above the soil's top row
            res[name] = (mean(p), wr[-1][2], S, wr[-1][1] - sr[-1][1], rise)
            print(f"{name}: mean pore pressure {mean(p):.5g} Pa, top row {wr[-1][2]:.5g} Pa, settlement {S:.4e} m, "
                  f"top water row - top soil row {wr[-1][1] - sr[-1][1]:+.3e} m, highest water point above the "
                  f"soil's top row {rise:+.3e} m")
        # impermeable (sealed, the default): the undrained answer. Grains and water are
        # incompressible and nothing drains (base and sides impermeable, the face sealed),
        # so the skeleton cannot compress: no settlement, no effective stress, and the pore
        # pressure carries the whole load, p = -q everywhere (tension positive), also at
        # the face (the pore pressure's surface term, docs/semi-implicit.md 'A sealed
        # surface'); no water leaves through the face
        pm, pt, S, gap, rise = res["impermeable"]
        tv.check(abs(pm / -q - 1) < 0.02, f"sealed loaded face: mean pore pressure {pm:.6g} Pa vs the undrained -q = "
                 f"{-q:g} Pa ({100 * (pm / -q - 1):+.3f} %, 2 %)")
        tv.check(abs(pt / -q - 1) < 0.02, f"sealed loaded face: top water row {pt:.6g} Pa vs -q ({100 * (pt / -q - 1):+.3f} %, 2 %)")
        tv.check(abs(S) < 0.01 * res["drained"][2], f"sealed loaded face: settlement {S:.3e} m (< 1 % of the drained "
                 f"run's {res['drained'][2]:.3e} m)")
        tv.check(abs(gap) < 0.01 * h and rise < 0.01 * h,
                 f"sealed loaded face: the water stays in the soil: top water row - top soil row {gap:+.3e} m, highest "
                 f"water point {rise:+.3e} m above the soil's top row (both within 0.01 h = {0.01 * h:g} m)")
        pm, pt, S, gap, rise = res["drained"]
        ref = -(1 - U(c_v * t_check / H**2)) * q
        tv.check(abs(pm - ref) < 0.05 * q, f"drained loaded face: mean pore pressure {pm:.5g} Pa vs Terzaghi "
                 f"-(1 - U) q = {ref:.5g} Pa (T_v = {c_v * t_check:.4f})")
        tv.check(abs(pt) < 0.2 * q, f"drained loaded face: top row pore pressure {pt:.5g} Pa (< 0.2 q in size)")
        tv.check(gap > 0.002 * h, f"drained loaded face: the water left through it (top water row {gap:+.3e} m above "
                 f"the top soil row, > 0.002 h)")
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
        # a sealed closed box: the layer fills the grid (no free surface, so no sealed
        # surface either), a traction on its top face (boundary id 3) made impermeable
        rc, out, err = run("sealed_box", base, expect_rc=None, **{
            "boundary conditions/drainage 0/condition": "impermeable", "time/end time": "0.01",
            "loads/number of tractions": "1", "loads/traction 0/apply to": "boundary",
            "loads/traction 0/boundary id": "3", "loads/traction 0/traction": "0, -1e3"})
        tv.check(rc == 2 and "loads/traction 0" in out + err and "no pressure reference" in out + err,
                 f"sealed closed box: exit {rc}, the traction named")
else:
    tv.fail("unknown mode " + mode)
tv.finish()
