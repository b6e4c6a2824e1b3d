"""The rigid plate of talus-implicit (issue 37; docs/implicit.md "Rigid plate").

Cases (the last argument):
  layer         the shared scene parameter_files/verification/rigid_plate/layer_implicit.prm
                (layer.inc: 1 m x 1 m elastic layer, E = 1 MPa, nu = 0.3, fixed base, roller
                sides, a frictionless plate on the top face loaded by -1 kN/m): the plate's
                settlement q H / E_oed = 7.4286e-4 m within 1 %, on the default Q1 basis, on
                quadratic B-splines, with mixed u-p, with CG + AMG and in 3D (the layer as a
                1 m cube under a plate on z+); the reported force is the given one;
  displacement  the same layer with the plate driven by a displacement d = -1 mm instead: its
                reaction F = E_oed d / H x W = -1346.15 N within 1 %, frictionless and rough;
  dynamic       the layer under a step force (constant time function), dynamic (Newmark 1/2,
                1/4, 1 ms, 4 x 32 cells): the massless plate's settlement peaks at twice the
                static one at t = 2 H / c, c = sqrt(E_oed / rho) (the wave reflected at the
                fixed base), both within 5 % (the grid's and the trapezoidal rule's dispersion);
  footing       parameter_files/implicit/rigid_plate_footing.prm (a region plate on the top's
                half x <= 0.5 beside the roller wall x = 0, -1 kN/m, one load step): the top nodes of the plate, recovered
                from the points of the top cell row (one step: u_p is the bilinear interpolation
                of the nodal increments at the point's start, four points per cell give the four
                nodes), all move by the plate's displacement to round-off (1e-9 of it);
                frictionless their horizontal displacement is not zero (the layer spreads: the
                check of the rough plate can fail), rough it is zero to 1e-9 and the plate
                holds the layer back (a tangential reaction); the plate's force
                balance holds at convergence, not as a penalty: sum_p sigma_yy V_p = F (1 + s)
                (the discrete identity sum_i y_i r_i = sum_p V_p sigma_yy: only the plate's
                nodes carry a vertical reaction at a height other than 0) to 1e-8 of F; with
                the side x = 0 fixed instead of a roller the wall keeps the plate's corner
                node (u = 0) and the plate moves the other four as one;
  ranks         the footing (rough, 4 load steps) and the displacement-driven layer, both
                turned on their side so that the plate's nodes lie on both ranks, on 1 and
                2 ranks: point fields and the plate columns of series.csv agree to 1e-10
                relative (to the largest value of each field; the components of the
                displacement, velocity and stress to the largest component of the field).
Usage: check_implicit_rigid_plate.py TOOLS_DIR PRM_ROOT WORKDIR CASE
(PRM_ROOT: the parameter_files directory)
"""
import os
import re
import shutil
import sys

import talus_verify as tv

tools, prm_root, work, case = sys.argv[1:5]
tool = f"{tools}/talus-implicit"
shutil.rmtree(work, ignore_errors=True)
E, nu = 1e6, 0.3
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def inline_includes(path):
    """The .prm text with every `include FILE` line replaced by FILE's text (relative to
    the including file): the checks write the edited text elsewhere."""
    out = []
    for line in open(path).read().splitlines():
        m = re.match(r"\s*include\s+(\S+)\s*$", line)
        out.append(inline_includes(os.path.join(os.path.dirname(path), m.group(1))) if m else line)
    return "\n".join(out) + "\n"


def run(text, name, np=1, settings=()):
    text = tv.prm_set_args(text, list(settings))
    text = tv.prm_set(text, "output/directory", name)
    _, out, _ = tv.run_tool(tool, text, work, name, np=np)
    return out, tv.read_csv(f"{work}/{name}/series.csv"), tv.read_csv(f"{work}/{name}/particles_final.csv")


layer = inline_includes(f"{prm_root}/verification/rigid_plate/layer_implicit.prm")
footing = open(f"{prm_root}/implicit/rigid_plate_footing.prm").read()
displacement_layer = tv.prm_set_args(layer, ["boundary conditions/rigid plate 0/total force=",
                                             "boundary conditions/rigid plate 0/displacement=-1e-3"])


def top_nodes(p, h=0.125, top=1.0):
    """Nodal (u_x, u_y) of the top grid nodes from the points of the top cell row after
    one step: per cell the bilinear interpolant through its 2 x 2 points, extrapolated
    to the cell's upper corners. {x: (u_x, u_y)} (x rounded), each node from every cell
    it belongs to (both must agree)."""
    cells = {}
    for i in range(len(p["id"])):
        X, Y = p["pos_x"][i] - p["u_x"][i], p["pos_y"][i] - p["u_y"][i]
        if Y < top - h:
            continue
        c = int(X // h)
        xi, eta = round((X - c * h) / h, 6), round((Y - (top - h)) / h, 6)
        cells.setdefault(c, {})[(xi, eta)] = (p["u_x"][i], p["u_y"][i])
    nodes = {}
    for c, pts in cells.items():
        assert sorted(pts) == [(0.25, 0.25), (0.25, 0.75), (0.75, 0.25), (0.75, 0.75)], pts
        for comp in (0, 1):
            # to eta = 1 along each column of points, then to xi = 0 and 1
            up = {xi: 1.5 * pts[(xi, 0.75)][comp] - 0.5 * pts[(xi, 0.25)][comp] for xi in (0.25, 0.75)}
            for xn, val in ((c * h, 1.5 * up[0.25] - 0.5 * up[0.75]), ((c + 1) * h, 1.5 * up[0.75] - 0.5 * up[0.25])):
                nodes.setdefault(round(xn, 6), [[], []])[comp].append(val)
    return nodes


def by_origin(t):
    """Point rows in the order of their initial positions (pos - u): ids follow the
    seeding order of the ranks' cells."""
    key = [(round(t["pos_y"][i] - t["u_y"][i], 9), round(t["pos_x"][i] - t["u_x"][i], 9)) for i in range(len(t["id"]))]
    order = sorted(range(len(key)), key=lambda i: key[i])
    return {c: [t[c][i] for i in order] for c in t}


if case == "layer":
    s_exact = 1e3 * 1.0 / E_oed
    box3d = ["dimension=3", "grid/lower corner=0, 0, 0", "grid/upper corner=1, 1, 1", "grid/cells=4, 4, 4",
             "boundary conditions/fixed=4", "boundary conditions/roller=0, 1, 2, 3",
             "boundary conditions/rigid plate 0/boundary id=5", "boundary conditions/rigid plate 0/direction=z",
             "gravity/acceleration=0, 0, 0", "body 0/lower corner=0, 0, 0", "body 0/upper corner=1, 1, 1"]
    for label, nodes, settings in (
            ("Q1", 9, []), ("quadratic B-splines", 9, ["numerics/shape function=quadratic bspline"]),
            ("mixed u-p", 9, ["implicit/formulation=mixed up", "material 0/neo hookean/volumetric energy=split"]),
            ("CG + AMG", 9, ["linear solver/method=cg amg"]), ("3D (4 x 4 x 4 cells, plate on z+)", 25, box3d)):
        name = label.split()[0].replace("-", "")
        out, ser, _ = run(layer, name, settings=settings)
        tv.check("rigid plate 0 (" in out and f"): {nodes} grid node(s)" in out,
                 f"{label}: the log names the plate and its {nodes} nodes")
        s = -ser["plate_0_displacement"][-1]
        err = abs(s - s_exact) / s_exact
        print(f"{label}: settlement {s:.6e} m, analytic {s_exact:.6e} m, error {100 * err:.3f} %")
        tv.check(err < 0.01, f"{label}: the plate's settlement within 1 % of q H / E_oed ({100 * err:.3f} %)")
        tv.check(abs(ser["plate_0_force"][-1] + 1e3) < 1e-9, f"{label}: plate_0_force = -1000 N at t = 1 s")

elif case == "displacement":
    F_exact = -E_oed * 1e-3 / 1.0 * 1.0
    for surface in ("frictionless", "rough"):
        text = tv.prm_set(displacement_layer, "boundary conditions/rigid plate 0/surface", surface)
        out, ser, _ = run(text, surface)
        F = ser["plate_0_force"][-1]
        err = abs(F - F_exact) / abs(F_exact)
        d = ser["plate_0_displacement"][-1]
        print(f"{surface}: reaction {F:.6e} N, analytic {F_exact:.6e} N, error {100 * err:.3f} %; displacement {d}")
        tv.check(abs(d + 1e-3) < 1e-15, f"{surface}: plate_0_displacement = -1 mm at t = 1 s")
        tv.check(err < 0.01, f"{surface}: the reaction within 1 % of E_oed d / H W ({100 * err:.3f} %)")
        if surface == "rough":
            tv.check("plate_0_tangential_force" in ser, "rough: series.csv has plate_0_tangential_force")
            T = ser["plate_0_tangential_force"][-1]
            print(f"rough: tangential reaction {T:.3e} N (oedometric: none)")
            tv.check(T < 1e-6 * abs(F), f"rough, oedometric: no tangential reaction ({T:.2e} N)")

elif case == "dynamic":
    # a step force on the layer (4 x 32 cells, dynamic, Newmark 1/2, 1/4, dt = 1 ms): the
    # compression wave from the massless plate reflects at the fixed base; the plate's
    # settlement peaks at twice the static one at t = 2 H / c (c = sqrt(E_oed / rho))
    s_static = 1e3 * 1.0 / E_oed
    c = (E_oed / 2000.0) ** 0.5
    text = tv.prm_set_args(layer, ["implicit/analysis=dynamic", "boundary conditions/rigid plate 0/time function=constant",
                                   "time/end time=0.12", "time/time step=0.001", "output/series interval=0",
                                   "grid/cells=4, 32"])
    out, ser, _ = run(text, "step")
    d, t = ser["plate_0_displacement"], ser["time"]
    i = min(range(len(d)), key=lambda k: d[k])
    peak, t_peak = -d[i] / (2 * s_static), t[i] / (2 * 1.0 / c)
    print(f"dynamic step load: peak settlement {-d[i]:.6e} m = {peak:.4f} x 2 s_static at t = {t[i]:.4f} s = "
          f"{t_peak:.4f} x 2 H / c")
    tv.check(abs(peak - 1) < 0.05, f"dynamic: the peak settlement within 5 % of twice the static one ({peak:.4f})")
    tv.check(abs(t_peak - 1) < 0.05, f"dynamic: at t = 2 H / c within 5 % ({t_peak:.4f})")

elif case == "footing":
    F = -1e3
    res = {}
    for surface in ("frictionless", "rough"):
        text = tv.prm_set(footing, "boundary conditions/rigid plate 0/surface", surface)
        out, ser, p = run(text, surface)
        s = ser["plate_0_displacement"][-1]
        nodes = top_nodes(p)
        plate = {x: v for x, v in nodes.items() if -1e-9 <= x <= 0.5 + 1e-9}
        tv.check(len(plate) == 5, f"{surface}: 5 plate nodes recovered from the points ({sorted(plate)})")
        uy = [v for x in plate for v in plate[x][1]]
        ux = [v for x in plate for v in plate[x][0]]
        spread = max(abs(v - s) for v in uy) / abs(s)
        print(f"{surface}: plate displacement {s:.9e} m; its nodes' u_y deviate from it by at most "
              f"{spread:.2e} of it; largest |u_x| at its nodes {max(abs(v) for v in ux):.3e} m")
        tv.check(spread < 1e-9, f"{surface}: every plate node moves down by the plate's displacement "
                                f"(largest deviation {spread:.2e} of it)")
        outside = [v for x, val in nodes.items() if not -1e-9 <= x <= 0.5 + 1e-9 for v in val[1]]
        tv.check(max(abs(v - s) for v in outside) > 1e-2 * abs(s),
                 f"{surface}: the free surface beside the plate does not follow it (a flexible top)")
        sv = sum(syy * V for syy, V in zip(p["stress_yy"], p["volume"]))
        bal = abs(sv - F * (1 + s)) / abs(F)
        print(f"{surface}: sum sigma_yy V = {sv:.12e} N, F (1 + s) = {F * (1 + s):.12e} N, difference {bal:.2e} of F")
        tv.check(bal < 1e-8, f"{surface}: the plate's force balance at convergence (sum sigma_yy V_p = F (1 + s), "
                             f"difference {bal:.2e} of F)")
        res[surface] = (max(abs(v) for v in ux), abs(s))
        if surface == "rough":
            T = ser["plate_0_tangential_force"][-1]
            print(f"rough: tangential reaction {T:.4e} N")
            tv.check(T > 1e-3 * abs(F), f"rough: the plate holds the layer back (tangential reaction {T:.3e} N)")
    # walls win: with the side x = 0 fixed (not a roller) the plate's corner node (0, 1)
    # keeps both components held; the other four move as one
    text = tv.prm_set_args(footing, ["boundary conditions/fixed=0, 2", "boundary conditions/roller=1"])
    out, ser, p = run(text, "fixed_side")
    s = ser["plate_0_displacement"][-1]
    nodes = top_nodes(p)
    corner = max(abs(v) for v in nodes[0.0][0] + nodes[0.0][1])
    spread = max(abs(v - s) for x in nodes if 0.1 < x <= 0.5 + 1e-9 for v in nodes[x][1]) / abs(s)
    print(f"fixed side: the log says '{[l.strip() for l in out.splitlines() if 'rigid plate 0' in l][0]}'; "
          f"corner node |u| {corner:.2e} m, the other plate nodes' u_y within {spread:.2e} of s = {s:.6e} m")
    tv.check("5 grid node(s) (1 held along y by a wall, they stay)" in out,
             "fixed side: the log counts 5 plate nodes, 1 held along y")
    tv.check(corner < 1e-9 * abs(s) and spread < 1e-9,
             "fixed side: the wall keeps the corner node (u = 0), the plate moves the other four as one")
    ux_f, s_f = res["frictionless"]
    ux_r, s_r = res["rough"]
    tv.check(ux_f > 1e-2 * s_f, f"frictionless: the plate's nodes move sideways (|u_x| up to {ux_f / s_f:.3f} s)")
    tv.check(ux_r < 1e-9 * s_r, f"rough: the plate's nodes do not move sideways (|u_x| <= {ux_r / s_r:.2e} s)")

elif case == "ranks":
    # turned on their side (plates on the x+ face, pushing along -x): the 2 ranks own the
    # lower and the upper half of the grid (p4est's Morton order), so each plate's nodes
    # lie on both ranks
    side = ["boundary conditions/fixed=0", "boundary conditions/roller=2, 3",
            "boundary conditions/rigid plate 0/direction=x"]
    scenes = {"footing_rough": tv.prm_set_args(footing, side + [
                  "boundary conditions/rigid plate 0/surface=rough", "time/time step=0.25",
                  "boundary conditions/rigid plate 0/region lower corner=1, 0.375",
                  "boundary conditions/rigid plate 0/region upper corner=1, 0.875"]),
              "layer_displacement": tv.prm_set_args(displacement_layer, side + [
                  "boundary conditions/rigid plate 0/boundary id=1"])}
    for name, text in scenes.items():
        r = {n: run(text, f"{name}_np{n}", np=n) for n in (1, 2)}
        a, b = (by_origin(r[n][2]) for n in (1, 2))
        # per field, relative to its largest value; the components of a vector or tensor
        # field relative to the field's largest component (u_x of the oedometric layer
        # is round-off: relative to itself it would compare noise)
        diff = {}
        for c in [c for c in a if c != "id"]:
            group = [g for g in a if g.split("_")[0] == c.split("_")[0]] if c[:2] in ("u_", "v_") or \
                c.startswith("stress_") else [c]
            scale = max(abs(v) for g in group for v in a[g]) or 1.0
            diff[c] = max(abs(x - y) for x, y in zip(a[c], b[c])) / scale
        sa, sb = r[1][1], r[2][1]
        plate_cols = [c for c in sa if c.startswith("plate_")]
        diff.update(tv.relative_differences(sa, sb, plate_cols))
        worst = max(diff, key=diff.get)
        print(f"{name}: largest relative differences: " +
              ", ".join(f"{k} {d:.1e}" for k, d in sorted(diff.items(), key=lambda x: -x[1])[:4]))
        tv.check(diff[worst] < 1e-10, f"{name}: 1 vs 2 ranks agree to {diff[worst]:.2e} ({worst}) < 1e-10")
        tv.check(sa["newton_iterations"] == sb["newton_iterations"], f"{name}: the same Newton iterations per step")
else:
    tv.fail(f"unknown case '{case}'")
tv.finish()
