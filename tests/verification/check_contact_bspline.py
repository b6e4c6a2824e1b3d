"""Contact between bodies (seed 000 §6.2) with quadratic B-splines — issue 38.

The scenes of check_contact.py (block_sliding_contact.prm, disks_collision.prm) with
numerics/shape function = quadratic bspline. One part per ctest (the last argument):

slide    Block on a stiff base under gravity tilted by theta = 30 deg (grid aligned with
         the slope). The acceleration fitted to the block centre's displacement
         (least squares u = 1/2 a t^2 over t >= 0.1 s) within 1 % of
         g (sin theta - mu cos theta) for mu = 0.3 and mu = 0; theta = 10 deg, mu = 0.3
         (tan theta < mu): at rest, max |u| < 1 % of the frictionless displacement.
disks    Sulsky disks, frictionless contact: momentum conserved to round-off
         (|p| <= 1e-12 sum m|v|), energy within 2 % of its initial value before contact
         (t <= 0.5 s), as check_disks.py: the kinetic energy dips below half its initial
         value (collision) and ends above half (separation); kinetic + strain energy at
         most 5 % above the initial (linear shape functions: +10 %, docs/explicit.md);
         the overlap of the two disks' points along the line of centres (t = 1, 1.25, ...,
         2 s) below half a cell (a regression bound: B-spline contact lets the surfaces
         overlap by about a quarter cell, docs/explicit.md).
ranks    The disks and the sliding block (mu = 0.3) on 1 and 2 ranks: particles_final.csv
         within 1e-10 relative.
restart  The disks with checkpoints every 0.5 s, stopped at 1.2 s (in the collision) and
         restarted: particles_final.csv and series.csv byte for byte those of the
         uninterrupted run, on 1 rank and on 2 ranks.
A last argument, a '+'-separated option set, switches more on in every run, with the same checks
and bounds: `f-bar` (numerics/volumetric stabilisation = f-bar: each body maps and remaps its own
dJ, docs/explicit.md "F-bar with contact"), `apic` (numerics/velocity transfer = apic: each body's
v_p, C_p from its own corrected v^L_b, "APIC with contact"), `cell` or `nodal` (numerics/strain
smoothing: each body's cell values from its own velocities, "Strain smoothing with contact").
Usage: check_contact_bspline.py TOOL SLIDING_PRM DISKS_PRM WORKDIR slide|disks|ranks|restart [OPTIONS]
       OPTIONS: f-bar, apic, cell, nodal joined by '+' (f-bar excludes cell and nodal)
"""
import math
import os
import shutil
import sys

import talus_verify as tv

tool, sliding_prm, disks_prm, work, part = sys.argv[1:6]
OPTIONS = sys.argv[6].split("+") if len(sys.argv) > 6 else []
if any(o not in ("f-bar", "apic", "cell", "nodal") for o in OPTIONS):
    tv.fail(f"unknown option set '{sys.argv[6]}' (allowed: f-bar, apic, cell, nodal joined by '+')")
SMOOTHING = "cell" if "cell" in OPTIONS else "nodal" if "nodal" in OPTIONS else "none"


def with_options(text):
    text = tv.prm_set(text, "numerics/shape function", BSPLINE)
    text = tv.prm_set(text, "numerics/volumetric stabilisation", "f-bar" if "f-bar" in OPTIONS else "none")
    text = tv.prm_set(text, "numerics/strain smoothing", SMOOTHING)
    return tv.prm_set(text, "numerics/velocity transfer", "apic" if "apic" in OPTIONS else "flip")

shutil.rmtree(work, ignore_errors=True)  # no checkpoint of an earlier run may be restarted from
os.makedirs(work)
g = 9.81
BSPLINE = "quadratic bspline"


def sliding_text(theta_deg, mu, name):
    th = math.radians(theta_deg)
    text = open(sliding_prm).read()
    text = with_options(text)
    text = tv.prm_set(text, "gravity/acceleration", f"{g * math.sin(th)!r}, {-g * math.cos(th)!r}")
    text = tv.prm_set(text, "contact/pairs", f"0, 1, {mu}, 0")
    text = tv.prm_set(text, "output/vtu interval", "0")
    return tv.prm_set(text, "output/directory", name)


def disks_text(name, end=None):
    text = open(disks_prm).read()
    text = with_options(text)
    text = tv.prm_set(text, "contact/pairs", "0, 1, 0, 0")
    text = tv.prm_set(text, "output/vtu interval", "0")
    text = tv.prm_set(text, "output/series interval", "0.01")
    if end is not None:
        text = tv.prm_set(text, "time/end time", str(end))
    return tv.prm_set(text, "output/directory", name)


def along_centres(csv):
    """(position along the line of centres, velocity along it) of the points of each disk."""
    a = tv.read_csv(csv)
    lower, upper = [], []
    for i in range(len(a["id"])):
        x0 = a["pos_x"][i] - a["u_x"][i] + a["pos_y"][i] - a["u_y"][i]
        s = (a["pos_x"][i] + a["pos_y"][i]) / math.sqrt(2)
        (lower if x0 < 1 else upper).append((s, (a["v_x"][i] + a["v_y"][i]) / math.sqrt(2)))
    return lower, upper


def by_initial_position(t):
    """The table reordered by the points' initial positions x - u (rounded to 1e-9)."""
    key = sorted(range(len(t["id"])), key=lambda i: (round(t["pos_y"][i] - t["u_y"][i], 9),
                                                     round(t["pos_x"][i] - t["u_x"][i], 9)))
    return {c: [v[i] for i in key] for c, v in t.items()}


if part == "slide":
    for theta, mu in [(30, 0.3), (30, 0.0)]:
        name = f"slide_{theta}_{mu}"
        tv.run_tool(tool, sliding_text(theta, mu, name), work, name)
        s = tv.read_csv(f"{work}/{name}/series.csv")
        pts = [(t, u) for t, u in zip(s["time"], s["probe0_ux"]) if t >= 0.1]
        a_fit = 2 * sum(u * t * t for t, u in pts) / sum(t ** 4 for t, _ in pts)
        a = g * (math.sin(math.radians(theta)) - mu * math.cos(math.radians(theta)))
        err = abs(a_fit - a) / a
        tv.check(err < 0.01, f"theta {theta} deg, mu {mu}: fitted acceleration {a_fit:.4f} m/s^2 within 1 % of "
                             f"g (sin - mu cos) = {a:.4f} (error {err:.2e}; {len(pts)} samples, t >= 0.1 s)")
    name = "stick_10_0.3"
    tv.run_tool(tool, sliding_text(10, 0.3, name), work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    umax = max(abs(u) for u in s["probe0_ux"])
    free = 0.5 * g * math.sin(math.radians(10)) * s["time"][-1] ** 2
    tv.check(umax < 0.01 * free, f"theta 10 deg, mu 0.3: at rest (max |u| {umax:.2e} m, frictionless {free:.3f} m)")

elif part == "disks":
    tv.run_tool(tool, disks_text("disks"), work, "disks")
    s = tv.read_csv(f"{work}/disks/series.csv")
    t, ke, se = s["time"], s["kinetic_energy"], s["strain_energy"]
    e = [k + w for k, w in zip(ke, se)]
    pre = max(abs(x - e[0]) / e[0] for x, tt in zip(e, t) if tt <= 0.5)
    tv.check(pre < 0.02, f"energy before contact within 2 % (max deviation {pre:.2e})")
    scale = 2 * 1000 * math.pi * 0.2 ** 2 * 0.1 * math.sqrt(2)
    pmax = max(math.hypot(px, py) for px, py in zip(s["momentum_x"], s["momentum_y"]))
    tv.check(pmax <= 1e-12 * scale, f"momentum conserved to round-off (max |p| = {pmax:.2e}, scale {scale:.2e})")
    kmin = min(ke)
    tv.check(kmin < 0.5 * ke[0], f"collision: kinetic energy dips to {kmin / ke[0]:.3f} of initial "
                                 f"at t = {t[ke.index(kmin)]:.2f} s")
    tv.check(ke[-1] > 0.5 * ke[0], f"separation: final kinetic energy {ke[-1] / ke[0]:.3f} of initial")
    tv.check(max(e) <= 1.05 * e[0], f"kinetic + strain energy: initial {e[0]:.4f} J, max {max(e):.4f} J "
                                    f"(+{max(e) / e[0] - 1:.1%}), final {e[-1]:.4f} J; max <= +5 %")
    gaps = []
    for T in [1.0, 1.25, 1.5, 1.75, 2.0]:
        name = f"disks_{T}"
        tv.run_tool(tool, tv.prm_set(disks_text(name, T), "output/final particles csv", "true"), work, name)
        lower, upper = along_centres(f"{work}/{name}/particles_final.csv")
        gaps.append(min(x for x, _ in upper) - max(x for x, _ in lower))
        print(f"  t = {T}: gap along the line of centres {gaps[-1]:.4f} m")
    # with linear shape functions the points keep half a cell apart (+0.0125 m); with B-splines
    # the surface points also follow nodes that are no contact nodes (one body's share < 10 %)
    # and overlap by about a quarter cell (measured -0.0064 m at t = 1.5 s, docs/explicit.md):
    # a regression bound, not a property of the method
    tv.check(min(gaps) > -0.0125, f"overlap of the disks' points along the line of centres below half a cell: "
                                  f"smallest gap {min(gaps):.4f} m (> -0.0125 m)")

elif part == "ranks":
    for name, text in [("disks", disks_text("disks")), ("slide", sliding_text(30, 0.3, "slide"))]:
        text = tv.prm_set(text, "output/final particles csv", "true")
        for n in (1, 2):
            tv.run_tool(tool, tv.prm_set(text, "output/directory", f"{name}_np{n}"), work, f"{name}_np{n}", np=n)
        # the point ids of a scene with several bodies depend on the partition: compare by
        # initial position
        a = by_initial_position(tv.read_csv(f"{work}/{name}_np1/particles_final.csv"))
        b = by_initial_position(tv.read_csv(f"{work}/{name}_np2/particles_final.csv"))
        worst = max(tv.relative_differences(a, b, [c for c in a if c != "id"]).values())
        tv.check(len(a["id"]) == len(b["id"]) and worst <= 1e-10,
                 f"{name}: 1 and 2 ranks agree to 1e-10 relative (worst {worst:.2e}, {len(a['id'])} points)")

elif part == "restart":
    base = tv.prm_set(disks_text("x"), "checkpoint/interval", "0.5")
    for n in (1, 2):
        ref, cut = f"ref_np{n}", f"cut_np{n}"
        tv.run_tool(tool, tv.prm_set(base, "output/directory", ref), work, ref, np=n)
        text = tv.prm_set(base, "output/directory", cut)
        tv.run_tool(tool, tv.prm_set(text, "time/end time", "1.2"), work, cut, np=n)
        os.remove(f"{work}/{cut}/particles_final.csv")
        tv.run_tool(tool, tv.prm_set(text, "checkpoint/restart", "true"), work, cut + "_restart", np=n)
        same = open(f"{work}/{cut}/particles_final.csv").read() == open(f"{work}/{ref}/particles_final.csv").read()
        series = open(f"{work}/{cut}/series.csv").read() == open(f"{work}/{ref}/series.csv").read()
        tv.check(same and series, f"{n} rank(s): stopped at 1.2 s, restarted from its newest checkpoint: "
                                  f"particles_final.csv and series.csv bitwise identical ({same}, {series})")
else:
    tv.fail(f"unknown part '{part}'")
tv.finish()
