"""Rigid plate in talus-explicit (issue 37; docs/explicit.md, Rigid plate).

Usage: check_rigid_plate_explicit.py TOOL PRM WORKDIR CASE
PRM is parameter_files/verification/rigid_plate/layer_explicit.prm (it includes
the shared layer.inc, inlined here so that the runs can live in WORKDIR).
CASE:
  layer, layer_bspline, layer_fem
      the shared layer (1 m x 1 m, E = 1 MPa, nu = 0.3, fixed base, roller
      sides) under a frictionless plate loaded by -1 kN/m, to quasi-static
      rest: plate settlement vs q H / E_oed = 7.4286e-4 m within 1 %; with
      Q1, quadratic B-splines, numerics/integration = fem. With Q1 also the
      separate-pass step (a zero body traction selects it): within 1e-8 of the
      fused step.
  displacement
      the same layer with the plate driven by a displacement of -1 mm:
      reaction vs E_oed (d / H) W = 1346.2 N within 1 %, and the plate at -1 mm.
  frictionless
      a layer one cell tall (4 cells wide, fixed base, roller sides) of a soft
      (E = 1 MPa) and a stiff (E = 4 MPa) half under a force-loaded
      frictionless plate. With Q1 and the base at rest, a point's vertical
      velocity is its xi_y times the x-interpolated velocity of the top nodes,
      so points of one initial height settle alike exactly when the plate
      nodes move as one: their u_y agree to 1e-10 (relative). The same layer
      under a uniform traction instead of the plate must show a spread > 5 %
      (the check can fail). A frictionless plate has no tangential column.
      Zero horizontal reaction: the layer (1 m x 1 m) between a roller base and
      the frictionless plate, x held at x = 0 only, is in uniaxial stress in
      the plane (plane strain): settlement (1 - nu^2) q H / E and
      u_x = nu (1 + nu) q X / E at every point, within 1 %.
  rough
      the one-cell layer (uniform, free sides, fixed base) under a rough plate:
      every node of the cell holds u_x = 0, so every point has |u_x| <= 1e-12
      of the settlement; with a frictionless plate the top expands sideways
      (|u_x| > 1 % of the settlement), so the check can fail.
  two_phase
      Terzaghi's column (terzaghi_consolidation.prm, one cell wide) loaded by a
      plate with a step force q = 10 kPa instead of the traction: permeable
      plate, T_v = 0.5: settlement U(T_v) q H / E_c within 1 %, pore pressures
      within 3 % (L2, of q) of Terzaghi's series; impermeable plate (and base):
      undrained, settlement q H / (E_c + K_L / n) and mean pore pressure
      (K_L / n) / (E_c + K_L / n) q within 1 %.
  ranks
      the layer to t = 0.5 s (mid-ramp: every field still moves; near rest the
      velocities are round-off themselves) on 1 and 2 ranks: every series.csv
      column and every final point field within 1e-10, relative to the largest
      value of its group (a vector's components, the energies, a plate's
      forces); the same for a displacement-driven rough plate with free sides,
      and for a rough permeable plate on Terzaghi's column to t = 0.05 s.
  restart
      the layer stopped at t = 0.6 s (checkpoints every 0.2 s) and restarted
      to 1.2 s: series.csv and particles_final.csv byte for byte equal to the
      uninterrupted run, on 1 rank and on 2 ranks; Terzaghi's column under a
      permeable plate stopped at 0.03 s and restarted to 0.06 s, on 1 rank.
"""
import math
import os
import shutil
import sys

import talus_verify as tv

tool, prm_path, work, case = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
text = open(prm_path).read()
inc = open(os.path.join(os.path.dirname(prm_path), "layer.inc")).read()
base = text.replace("include layer.inc", inc)
base = tv.prm_set(base, "output/progress", "false")

E, nu, q, H, W = 1e6, 0.3, 1e3, 1.0, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def run(name, t, np=1):
    t = tv.prm_set(t, "output/directory", name)
    rc, out, err = tv.run_tool(tool, t, work, name, np=np)
    return tv.read_csv(os.path.join(work, name, "series.csv")), out


def converged(name, s, end):
    t_end = s["time"][-1]
    tv.check(1.0 <= t_end < end - 1e-9 and s["force_ratio"][-1] < 1e-6 and s["energy_ratio"][-1] < 1e-8,
             f"{name}: stage ended by convergence after the ramp at t = {t_end:.3f} s, step {int(s['step'][-1])} "
             f"(force ratio {s['force_ratio'][-1]:.2e}, energy ratio {s['energy_ratio'][-1]:.2e})")


def one_cell_layer(t, soft_stiff, sides, plate=True):
    """The layer of the frictionless/rough cases: 1 m x 0.25 m, 4 x 1 cells."""
    t = tv.prm_set(t, "grid/upper corner", "1, 0.25")
    t = tv.prm_set(t, "grid/cells", "4, 1")
    t = tv.prm_set(t, "boundary conditions/roller", sides)
    t = tv.prm_set(t, "body 0/upper corner", "0.5, 0.25" if soft_stiff else "1, 0.25")
    t = tv.prm_set(t, "output/final particles csv", "true")
    if soft_stiff:
        t = tv.prm_set(t, "number of materials", "2")
        t = tv.prm_set(t, "number of bodies", "2")
        for key, value in {"model": "linear elastic", "density": "2000", "linear elastic/young modulus": "4e6",
                           "linear elastic/poisson ratio": "0.3"}.items():
            t = tv.prm_set(t, "material 1/" + key, value)
        for key, value in {"name": "stiff", "shape": "box", "lower corner": "0.5, 0", "upper corner": "1, 0.25",
                           "particles per direction": "2", "material": "1"}.items():
            t = tv.prm_set(t, "body 1/" + key, value)
    if not plate:  # the plate's subsection out, the same force as a traction on the top faces
        lines, out, depth = t.splitlines(), [], 0
        for line in lines:
            s = line.split("#", 1)[0].strip()
            if depth == 0 and s == "subsection rigid plate 0":
                depth = 1
                continue
            if depth > 0:
                depth += s.startswith("subsection ") - (s == "end")
                continue
            out.append(line)
        t = tv.prm_set("\n".join(out) + "\n", "boundary conditions/number of rigid plates", "0")
        n = 2 if soft_stiff else 1
        t = tv.prm_set(t, "loads/number of tractions", str(n))
        for b in range(n):
            for key, value in {"apply to": "body face", "body": str(b), "face": "y+", "traction": "0, -1e3",
                               "time function": "ramp 1"}.items():
                t = tv.prm_set(t, f"loads/traction {b}/{key}", value)
    return t


def group(col):
    """The group of a column whose largest value scales its differences."""
    if col.startswith("plate_") and col.endswith("force"):
        return col[: col.index("_", 6)] + "_force"
    if col.endswith("energy") or col == "external_work":
        return "energy"
    if col.startswith("stress_"):
        return "stress"
    if col[-2:] in ("_x", "_y", "_z"):
        return col[:-2]
    return col


# Terzaghi's column (terzaghi_consolidation.prm, one cell wide as its fast check):
# the top traction replaced by a region plate on the nodes at y = 1 m, a step force
Et, KL, n0, qt = 1e7, 2.2e9, 0.3, 1e4


def terzaghi_plate(drainage):
    t = open(os.path.join(os.path.dirname(prm_path), "..", "terzaghi_consolidation.prm")).read()
    for key, value in [("grid/upper corner", "0.025, 1.025"), ("grid/cells", "1, 41"),
                       ("body 0/upper corner", "0.025, 1"), ("body 0/traction face", "none"),
                       ("output/progress", "false"),
                       ("boundary conditions/number of rigid plates", "1"),
                       ("boundary conditions/rigid plate 0/apply to", "region"),
                       ("boundary conditions/rigid plate 0/region lower corner", "0, 1"),
                       ("boundary conditions/rigid plate 0/region upper corner", "0.025, 1"),
                       ("boundary conditions/rigid plate 0/total force", str(-qt * 0.025)),
                       ("boundary conditions/rigid plate 0/drainage", drainage)]:
        t = tv.prm_set(t, key, value)
    return t


def points(name):
    return tv.read_csv(os.path.join(work, name, "particles_final.csv"))


if case in ("layer", "layer_bspline", "layer_fem"):
    t = base
    if case == "layer_bspline":
        t = tv.prm_set(t, "numerics/shape function", "quadratic bspline")
    if case == "layer_fem":
        t = tv.prm_set(t, "numerics/integration", "fem")
    s, out = run(case, t)
    tv.check("rigid plate 0 (boundary id 3): 9 grid node(s)" in out and "force control" in out,
             "the log names the plate, its 9 nodes and its control")
    converged(case, s, 30)
    u, ua = s["plate_0_displacement"][-1], -q * H / E_oed
    err = abs(u - ua) / abs(ua)
    tv.check(err < 0.01, f"{case}: plate settlement {u:.6e} m vs -q H / E_oed = {ua:.6e} m (error {err:.2e} < 1e-2)")
    tv.check(abs(s["plate_0_force"][-1] + q * W) < 1e-9, f"plate_0_force = the given force {s['plate_0_force'][-1]}")
    if case == "layer":
        # a body traction (zero, on a roller side) sends the run through the separate-pass
        # step of explicit_two_phase.cc (the plate's balance in nodal_forces_two_phase)
        t2 = tv.prm_set(tv.prm_set(t, "body 0/traction face", "x+"), "body 0/traction", "0, 0")
        s2, _ = run("separate_passes", t2)
        u2 = s2["plate_0_displacement"][-1]
        d = abs(u2 - u) / abs(u)
        tv.check(d < 1e-8, f"separate-pass step (body traction): settlement {u2:.10e} m, {d:.1e} from the fused "
                           "step (< 1e-8)")
elif case == "displacement":
    t = tv.prm_set(base, "boundary conditions/rigid plate 0/total force", "")
    t = tv.prm_set(t, "boundary conditions/rigid plate 0/displacement", "-1e-3")
    s, out = run(case, t)
    tv.check("displacement control" in out, "the log says displacement control")
    converged(case, s, 30)
    F, Fa = s["plate_0_force"][-1], -E_oed * 1e-3 / H * W
    err = abs(F - Fa) / abs(Fa)
    tv.check(err < 0.01, f"reaction {F:.6e} N vs -E_oed (d / H) W = {Fa:.6e} N (error {err:.2e} < 1e-2)")
    d = s["plate_0_displacement"][-1]
    tv.check(abs(d + 1e-3) < 1e-12, f"plate displacement {d:.12e} m = -1e-3 m")
elif case == "frictionless":
    spreads = {}
    for name, plate in (("plate", True), ("traction", False)):
        t = one_cell_layer(base, True, "0, 1", plate)
        s, _ = run(name, t)
        p = points(name)
        y0 = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
        top = max(y0)
        uy = [u for u, y in zip(p["u_y"], y0) if abs(y - top) < 1e-9]
        spreads[name] = (max(uy) - min(uy)) / abs(sum(uy) / len(uy))
        print(f"{name}: {len(uy)} points at y0 = {top}: u_y from {min(uy):.10e} to {max(uy):.10e}, "
              f"spread {spreads[name]:.2e} of the mean")
        if plate:
            tv.check("plate_0_tangential_force" not in s, "a frictionless plate has no tangential reaction column")
            tv.check(abs(s["plate_0_force"][-1] + q * W) < 1e-9, "plate_0_force = the given force")
    # zero horizontal reaction: the layer between a frictionless base (roller) and the
    # frictionless plate, free right side, x held at x = 0 only, is in uniaxial stress
    # in the plane (plane strain: sigma_zz = nu sigma_yy): settlement (1 - nu^2) q H / E,
    # u_x = nu (1 + nu) q X / E (a plate that held u_x would give 0)
    t = tv.prm_set(tv.prm_set(base, "boundary conditions/fixed", ""), "boundary conditions/roller", "0, 2")
    t = tv.prm_set(t, "output/final particles csv", "true")
    s, _ = run("uniaxial", t)
    u, ua = s["plate_0_displacement"][-1], -(1 - nu * nu) * q * H / E
    err = abs(u - ua) / abs(ua)
    tv.check(err < 0.01, f"uniaxial stress: plate settlement {u:.6e} m vs -(1 - nu^2) q H / E = {ua:.6e} m "
                         f"(error {err:.2e} < 1e-2)")
    p = points("uniaxial")
    c = nu * (1 + nu) * q / E
    ex = max(abs(ux - c * (x - ux)) for x, ux in zip(p["pos_x"], p["u_x"])) / (c * W)
    tv.check(ex < 0.01, f"uniaxial stress: u_x = nu (1 + nu) q X / E at every point within {ex:.2e} of its value "
                        "at X = W (< 1e-2): the frictionless plate exerts no horizontal force")
    tv.check(spreads["plate"] < 1e-10,
             f"frictionless plate: the points of the top row settle alike (spread {spreads['plate']:.2e} < 1e-10): "
             "the plate nodes move as one")
    tv.check(spreads["traction"] > 0.05,
             f"the same layer under a uniform traction settles unevenly (spread {spreads['traction']:.2e} > 5e-2)")
elif case == "rough":
    ux = {}
    for surface in ("rough", "frictionless"):
        t = one_cell_layer(base, False, "", True)
        t = tv.prm_set(t, "boundary conditions/rigid plate 0/surface", surface)
        s, _ = run(surface, t)
        p = points(surface)
        uy = max(abs(u) for u in p["u_y"])
        ux[surface] = max(abs(u) for u in p["u_x"]) / uy
        print(f"{surface}: max |u_x| / max |u_y| = {ux[surface]:.3e}, plate settlement "
              f"{s['plate_0_displacement'][-1]:.6e} m"
              + (f", tangential reaction {s['plate_0_tangential_force'][-1]:.3e} N" if surface == "rough" else ""))
        if surface == "rough":
            tv.check("plate_0_tangential_force" in s, "a rough plate reports plate_0_tangential_force")
    tv.check(ux["rough"] <= 1e-12, f"rough plate: no horizontal displacement (max |u_x| / |u_y| = {ux['rough']:.2e})")
    tv.check(ux["frictionless"] > 0.01,
             f"frictionless plate: the top expands sideways (max |u_x| / |u_y| = {ux['frictionless']:.2e} > 1e-2)")
elif case == "two_phase":
    # Terzaghi's column under the plate (coupled 2-phase single point)
    t = terzaghi_plate("permeable")
    s, out = run("permeable", t)
    Tv = 0.5
    U = 1 - sum(8 / (m * m * math.pi ** 2) * math.exp(-m * m * math.pi ** 2 * Tv / 4) for m in range(1, 400, 2))
    u, ua = s["plate_0_displacement"][-1], -U * qt * H / Et
    err = abs(u - ua) / abs(ua)
    tv.check(err < 0.01, f"permeable plate, T_v = 0.5: settlement {u:.6e} m vs Terzaghi U q H / E_c = {ua:.6e} m "
                         f"(U = {U:.4f}; error {err:.2e} < 1e-2)")
    p = points("permeable")
    z = [H - (y - uy) for y, uy in zip(p["pos_y"], p["u_y"])]
    ref = [sum(4 / (m * math.pi) * math.sin(m * math.pi * zz / (2 * H)) * math.exp(-m * m * math.pi ** 2 * Tv / 4)
               for m in range(1, 400, 2)) for zz in z]
    l2 = math.sqrt(sum((x / qt - r) ** 2 for x, r in zip(p["pore_pressure"], ref)) / len(ref))
    tv.check(l2 < 0.03, f"permeable plate: pore pressures vs Terzaghi's series, L2 error {l2:.2e} q < 3e-2 "
                        "(the water drains through the plate)")
    mean_perm = sum(p["pore_pressure"]) / len(ref) / qt
    s, out = run("impermeable", terzaghi_plate("impermeable"))
    u, ua = s["plate_0_displacement"][-1], -qt * H / (Et + KL / n0)
    err = abs(u - ua) / abs(ua)
    tv.check(err < 0.01, f"impermeable plate (and base): undrained settlement {u:.6e} m vs q H / (E_c + K_L / n) = "
                         f"{ua:.6e} m (error {err:.2e} < 1e-2)")
    p = points("impermeable")
    mean, ma = sum(p["pore_pressure"]) / len(ref) / qt, (KL / n0) / (Et + KL / n0)
    tv.check(abs(mean - ma) < 0.01, f"impermeable plate: mean pore pressure {mean:.5f} q vs (K_L / n) / (E_c + K_L / n) "
                                    f"= {ma:.5f} q (within 1e-2; the permeable plate left {mean_perm:.3f} q)")
elif case == "ranks":
    fixed = tv.prm_set(tv.prm_set(base, "convergence/enabled", "false"), "time/end time", "0.5")
    fixed = tv.prm_set(fixed, "output/final particles csv", "true")
    rough = tv.prm_set(fixed, "boundary conditions/rigid plate 0/total force", "")
    rough = tv.prm_set(rough, "boundary conditions/rigid plate 0/displacement", "-1e-3")
    rough = tv.prm_set(rough, "boundary conditions/rigid plate 0/surface", "rough")
    rough = tv.prm_set(rough, "boundary conditions/roller", "")
    two = tv.prm_set(terzaghi_plate("permeable"), "time/end time", "0.05")
    two = tv.prm_set(two, "boundary conditions/rigid plate 0/surface", "rough")
    for label, t in (("force", fixed), ("rough_displacement", rough), ("two_phase", two)):
        worst = {}
        for np in (1, 2):
            run(f"{label}_np{np}", t, np)
        for what, reader in (("series", lambda n: tv.read_csv(os.path.join(work, n, "series.csv"))),
                             ("points", lambda n: points(n))):
            a, b = reader(f"{label}_np1"), reader(f"{label}_np2")
            if what == "points":
                order_a = sorted(range(len(a["id"])), key=lambda i: a["id"][i])
                order_b = sorted(range(len(b["id"])), key=lambda i: b["id"][i])
                a = {k: [v[i] for i in order_a] for k, v in a.items()}
                b = {k: [v[i] for i in order_b] for k, v in b.items()}
            tv.check(list(a) == list(b) and all(len(a[k]) == len(b[k]) for k in a), f"{label}: same {what} shape")
            # scale: the largest value of the column's group (the components of one
            # vector or tensor, the energies, a plate's forces): a column that is
            # zero up to round-off (u_x of the oedometer) is judged against its group
            groups = {}
            for k in a:
                groups.setdefault(group(k), []).extend(abs(v) for v in a[k])
            for k in a:
                if len(a[k]) != len(b[k]):
                    continue
                scale = max(1e-300, max(groups[group(k)]))
                worst[(what, k)] = max(abs(u - v) for u, v in zip(a[k], b[k])) / scale
        (w, col), d = max(worst.items(), key=lambda kv: kv[1])
        plate_cols = [c for c in ("plate_0_displacement", "plate_0_force", "plate_0_tangential_force")
                      if ("series", c) in worst]
        print(f"{label}: plate columns " + ", ".join(f"{c} {worst[('series', c)]:.2e}" for c in plate_cols))
        tv.check(d <= 1e-10, f"{label}: 1 vs 2 ranks, max relative difference {d:.2e} ({w} {col}) <= 1e-10")
elif case == "restart":
    t = tv.prm_set(tv.prm_set(base, "convergence/enabled", "false"), "time/end time", "1.2")
    t = tv.prm_set(t, "output/final particles csv", "true")
    t = tv.prm_set(t, "checkpoint/interval", "0.2")
    # and Terzaghi's column under a permeable plate (coupled 2-phase), stopped at 0.03 s of 0.06 s
    two = tv.prm_set(tv.prm_set(terzaghi_plate("permeable"), "time/end time", "0.06"), "checkpoint/interval", "0.01")
    for np, label, t, t_stop in ((1, "", t, "0.6"), (2, "", t, "0.6"), (1, "two_phase_", two, "0.03")):
        ref, part = f"{label}reference_np{np}", f"{label}part_np{np}"
        run(ref, t, np)
        tp = tv.prm_set(t, "output/directory", part)
        tv.run_tool(tool, tv.prm_set(tp, "time/end time", t_stop), work, part + "_early", np=np)
        os.remove(os.path.join(work, part, "particles_final.csv"))
        rc, out, err = tv.run_tool(tool, tv.prm_set(tp, "checkpoint/restart", "true"), work, part, np=np)
        tv.check("restarting from" in out, f"{np} rank(s): the run restarted from a checkpoint")
        for f in ("series.csv", "particles_final.csv"):
            a = open(os.path.join(work, ref, f)).read()
            b = open(os.path.join(work, part, f)).read()
            tv.check(a == b, f"{label}{np} rank(s): {f} after the restart at t = {t_stop} s byte for byte equal to "
                             f"the uninterrupted run ({len(a.splitlines())} lines)")
        s = tv.read_csv(os.path.join(work, part, "series.csv"))
        print(f"{np} rank(s): plate displacement at t = {s['time'][-1]}: {s['plate_0_displacement'][-1]:.10e} m")
else:
    tv.fail(f"unknown case {case}")
tv.finish()
