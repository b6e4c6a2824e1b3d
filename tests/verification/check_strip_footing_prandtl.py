"""Rigid strip footing on undrained soil (seed 001 thesis §6.2, issue 13): the
stabilised mixed u-p formulation of talus-implicit with a plastic model (J2,
sigma_y = sqrt(3) c_u: Tresca in plane strain), displacement control
(parameter_files/implicit/strip_footing_prandtl.prm; the scene and the choices
not in the thesis are documented there and in docs/implicit.md).

The load: q = -prescribed_force_y / w of series.csv (the reaction of the footing's prescribed nodes,
half model), normalised by c_u = 100 Pa, w = x_e + h/2 the tributary width of the nodes x = 0 .. x_e
(x_e the last grid node within the footing; --width-b2: w = B/2, the earlier measure; the reaction is
linear in x_e with intercept h/2, docs/implicit.md); the settlement s = --du x step. Also reported: the
mean -sigma_yy of the top layer of points under the footing at the end (the thesis samples the stress
"at the edge"; not checked: the top layer of a half-filled cell carries about twice the stress).

Checks:
  * q / c_u within --tol (default 3 %) of 2 + pi at every step with s / B in
    the plateau window --window (default 0.02, 0.04); --no-window: reported only;
  * --peak=S: the largest q / c_u up to s = S B within --tol of 2 + pi;
  * --rise=S1,S2,...: q / c_u keeps rising at large settlement: the mean over
    the steps within 1 % of B of each S_k is larger than that of S_{k-1} and
    the first is above the plateau (thesis Fig. 6.8);
  * Newton: every step converged (the run reached the end) in at most
    --max-its iterations (default 12); the mean and the largest count reported;
  * --u-settlement=S (0 skips): the irreducible u formulation on the same scene
    to S: its mean stress oscillates, the u-p one does not: zigzag index
    (talus_verify.zigzag_index: RMS of the sign-changing neighbour differences of
    the point mean stress over its range, on the initial 2 x 2 lattice) of u above
    --zig-u, of u-p below --zig-up at the same settlement;
  * --ranks=N (0 skips): the u-p run of the first N steps on 1 and 2 ranks:
    q per step within 1e-8 relative (--ranks-klu: both with KLU, which repeats bitwise on 2
    ranks where MUMPS does not).
  * --points: the footing as a rigid plane on the material points ('rigid footing' of
    parameter_files/implicit/strip_footing_points.prm): q = footing_force / (B/2 + h/2) (the
    reaction is linear in the half width with intercept h/2 here too; --width-b2: / (B/2)),
    s = 2 m - footing_level; --edge, --smooth act on the plane.
Variants that must fail (docs/implicit.md): --yield=190.53 (sigma_y + 10 %) the
plateau check of the fast test (--tol=0.05); the u formulation the zigzag bound
of u-p (and u-p the bound of u).
Diagnostic variants (docs/implicit.md, "Rigid strip footing"): --edge=X (the footing's nodes x in
[0, X]), --alpha=A (stabilisation factor), --smooth (y only prescribed), --fine-ppd=N (N x N points
per cell in [0, 1] x [1, 2]), --negligible=F (implicit/negligible nodal mass).
Usage: check_strip_footing_prandtl.py TOOLS_DIR PRM WORKDIR [--h=H] [--ppd=N] [--du=D] [--settlement=S]
       [--window=A,B] [--no-window] [--peak=S] [--tol=T] [--rise=S1,...] [--max-its=N] [--u-settlement=S]
       [--zig-u=Z] [--zig-up=Z] [--ranks=N] [--ranks-klu] [--yield=Y] [--fixed-nodes] [--line-search] [--width-b2]
       [--edge=X] [--alpha=A] [--smooth] [--fine-ppd=N] [--negligible=F] [--points] [--set=entry=value ...]
(--set: any other .prm entry, e.g. --set=numerics/shape function=quadratic bspline)
"""
import math
import sys
import time

import talus_verify as tv


def option(name, default):
    return next((a.split("=", 1)[1] for a in sys.argv if a.startswith(f"--{name}=")), default)


tools, prm_path, work = [a for a in sys.argv if not a.startswith("--")][1:4]
h = float(option("h", 0.1))
ppd = int(option("ppd", 2))
du = float(option("du", 0.002))
s_end = float(option("settlement", 0.04))
window = [float(v) for v in option("window", "0.02,0.04").split(",")]
tol = float(option("tol", 0.03))
peak = float(option("peak", 0))  # check the largest q up to s = peak B (0 skips)
rise = [float(v) for v in option("rise", "").split(",") if v]
max_its = int(option("max-its", 12))
u_settlement = float(option("u-settlement", 0))
zig_u, zig_up = float(option("zig-u", 0.025)), float(option("zig-up", 0.012))
ranks = int(option("ranks", 0))
yield_stress = option("yield", None)
fixed_nodes = "--fixed-nodes" in sys.argv
# diagnostic variants (docs/implicit.md, "Rigid strip footing", why the coarse plateau is high)
edge = float(option("edge", 0.5))  # the footing's prescribed nodes: x in [0, edge]
alpha = option("alpha", None)  # implicit/stabilisation factor
smooth = "--smooth" in sys.argv  # y only prescribed (rough: x and y)
negligible = option("negligible", None)  # implicit/negligible nodal mass
fine_ppd = int(option("fine-ppd", 0))  # points per direction in [0, 1] x [1, 2] (0: ppd everywhere)
B, c_u, depth, width = 1.0, 100.0, 2.0, 3.0
prandtl = 2 + math.pi
# The width the reaction is spread over (docs/implicit.md, "Rigid strip footing"): the prescribed nodes
# x = 0, h, ..., x_e (x_e the last node within the footing) carry the tributary widths of nodal forces,
# [0, h/2], ..., [x_e - h/2, x_e + h/2]: x_e + h/2 (measured: the reaction is linear in x_e with
# intercept 0.053 m at h = 0.1 m). --width-b2 divides by B/2 instead (the earlier measure).
points = "--points" in sys.argv  # the rigid footing on the points (no prescribed nodes)
x_edge = edge if points else math.floor(edge / h + 1e-9) * h
loaded_width = B / 2 if "--width-b2" in sys.argv else x_edge + h / 2
tv.check(not (points and (fine_ppd or fixed_nodes)), "--points takes neither --fine-ppd nor --fixed-nodes")


def scene(settlement):
    text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
    text = tv.prm_set(text, "grid/upper corner", f"{width}, {depth + 2 * h}")
    text = tv.prm_set(text, "grid/cells", f"{round(width / h)}, {round((depth + 2 * h) / h)}")
    text = tv.prm_set(text, "body 0/particles per direction", str(ppd))
    # the row at or above the top layer of points (depth h / (2 n)) under the footing
    top = h / (2 * ppd)
    if points:
        text = tv.prm_set(text, "rigid footing/upper corner", f"{edge}")
        text = tv.prm_set(text, "rigid footing/velocity", f"{-du}")
        if smooth:
            text = tv.prm_set(text, "rigid footing/interface", "smooth")
    else:
        text = tv.prm_set(text, "loads/velocity 0/region lower corner", f"0, {depth - top}")
        text = tv.prm_set(text, "loads/velocity 0/region upper corner", f"{edge}, {depth + h - top}")
    if smooth and not points:
        text = tv.prm_set(text, "loads/velocity 0/components", "y")
        text = tv.prm_set(text, "loads/velocity 0/velocity", f"{-du}")
    if negligible:
        text = tv.prm_set(text, "implicit/negligible nodal mass", negligible)
    if alpha:
        text = tv.prm_set(text, "implicit/stabilisation factor", alpha)
    if fine_ppd:
        # the thesis's denser points near the footing: [0, 1] x [1, 2] with fine_ppd,
        # the rest (two boxes) with ppd; the top layer under the footing is then
        # h / (2 fine_ppd) deep
        top = h / (2 * fine_ppd)
        text = tv.prm_set(text, "loads/velocity 0/region lower corner", f"0, {depth - top}")
        text = tv.prm_set(text, "loads/velocity 0/region upper corner", f"{edge}, {depth + h - top}")
        text = tv.prm_set(text, "number of bodies", "3")
        text = tv.prm_set(text, "body 0/upper corner", f"1, {depth}")
        text = tv.prm_set(text, "body 0/lower corner", "0, 1")
        text = tv.prm_set(text, "body 0/particles per direction", str(fine_ppd))
        for b, (lo, hi) in ((1, ("1, 0", f"{width}, {depth}")), (2, ("0, 0", "1, 1"))):
            for key, val in (("name", f"soil{b}"), ("shape", "box"), ("lower corner", lo), ("upper corner", hi),
                             ("particles per direction", str(ppd))):
                text = tv.prm_set(text, f"body {b}/{key}", val)
    if not points:
        text = tv.prm_set(text, "loads/velocity 0/velocity", f"0, {-du}")
    text = tv.prm_set(text, "time/end time", str(round(settlement / du)))
    if yield_stress:
        text = tv.prm_set(text, "material 0/j2 plasticity/yield stress", yield_stress)
    if "--line-search" in sys.argv:  # h = 0.05 m needs it (docs/implicit.md)
        text = tv.prm_set(text, "newton/line search", "residual")
    if fixed_nodes:
        text = tv.prm_set(text, "implicit/velocity regions follow", "false")
    return tv.prm_set_args(text, [a[len("--set="):] for a in sys.argv if a.startswith("--set=")])


def run(text, name, np=1):
    start = time.time()
    tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name, np=np)
    wall = time.time() - start
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    rows = [k for k, t in enumerate(s["time"]) if t > 0]
    if points:
        settle = [depth - s["footing_level"][k] for k in rows]
        q = [s["footing_force"][k] / loaded_width / c_u for k in rows]
    else:
        settle = [s["time"][k] * du for k in rows]
        q = [-s["prescribed_force_y"][k] / loaded_width / c_u for k in rows]
    its = [int(s["newton_iterations"][k]) for k in rows]
    order = [s["increment_order"][k] for k in rows]
    return settle, q, its, order, wall


def zigzag(name):
    p = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    X = [x - u for x, u in zip(p["pos_x"], p["u_x"])]
    Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
    mean = [(a + b + c) / 3 for a, b, c in zip(p["stress_xx"], p["stress_yy"], p["stress_zz"])]
    return tv.zigzag_index(X, Y, mean, h)


def sampled_load(name):
    """The thesis's measure (§8.1 item 4: the stress field sampled at the footing): the mean -sigma_yy
    of the top layer of points (by initial position) under the footing, 0 <= X <= B/2, over c_u."""
    p = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    X = [x - u for x, u in zip(p["pos_x"], p["u_x"])]
    Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
    layer = h / (fine_ppd or ppd)  # the top layer's points lie within half of this below the surface
    under = [-syy for x, y, syy in zip(X, Y, p["stress_yy"]) if x < B / 2 and y > depth - layer]
    return sum(under) / len(under) / c_u, len(under)


up = scene(s_end)
settle, q, its, order, wall = run(up, "up")
q_sampled, n_sampled = sampled_load("up")
if points:
    print(f"the load: q = footing_force / {loaded_width:.4g} m (rigid footing on the points, half width {edge:.4g} m)")
else:
    print(f"the load: q = -prescribed_force_y / {loaded_width:.4g} m (last footing node x = {x_edge:.4g} m)")
print(f"u-p, h = {h} m, {ppd} x {ppd} points per cell, {du} m per step, {len(q)} steps to s = {settle[-1]:.4g} m: "
      f"{wall:.1f} s")
print("  s/B      q/c_u    vs 2+pi   Newton its  order(|du|)")
marks = sorted(set([0.005, 0.01, 0.02, 0.03, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0] + window))
for m in marks:
    k = min(range(len(settle)), key=lambda i: abs(settle[i] - m * B))
    if abs(settle[k] - m * B) < 0.5 * du + 1e-12:
        print(f"  {settle[k] / B:7.4f}  {q[k]:7.4f}  {q[k] / prandtl - 1:+7.2%}   {its[k]:3d}        {order[k]:.2f}")

print(f"at s = {settle[-1]:.4g} m: reaction q/c_u {q[-1]:.4f} ({q[-1] / prandtl - 1:+.2%}), sampled (mean -sigma_yy of "
      f"the {n_sampled} top-layer points under the footing) {q_sampled:.4f} ({q_sampled / prandtl - 1:+.2%})")
tv.check(abs(settle[-1] - s_end) < 1e-9 * max(1, s_end), f"the run reached s = {s_end} m ({len(q)} steps)")
if "--no-window" in sys.argv:
    window = [0, s_end / B]  # reported, not checked
in_window = [(s, v) for s, v in zip(settle, q) if window[0] * B - 1e-12 <= s <= window[1] * B + 1e-12]
worst = max(in_window, key=lambda sv: abs(sv[1] / prandtl - 1))
mean_w = sum(v for _, v in in_window) / len(in_window)
print(f"plateau s/B in [{window[0]}, {window[1]}]: {len(in_window)} steps, q/c_u {min(v for _, v in in_window):.4f} .. "
      f"{max(v for _, v in in_window):.4f}, mean {mean_w:.4f} ({mean_w / prandtl - 1:+.2%} from 2 + pi = {prandtl:.4f})")
if "--no-window" not in sys.argv:
    tv.check(abs(worst[1] / prandtl - 1) < tol,
             f"q/c_u within {tol:.0%} of 2 + pi over the plateau (worst {worst[1]:.4f} at s/B = {worst[0] / B:.4f}, "
             f"{worst[1] / prandtl - 1:+.2%})")
print(f"Newton iterations per step: mean {sum(its) / len(its):.2f}, largest {max(its)}; increment order: median "
      f"{sorted(o for o in order if o == o)[len(order) // 2] if any(o == o for o in order) else float('nan'):.2f}")
tv.check(max(its) <= max_its, f"Newton converged in at most {max_its} iterations per step (largest {max(its)})")

if peak > 0:
    # the collapse load of the displacement control: the largest q up to s = peak B
    upto = [(s, v) for s, v in zip(settle, q) if s <= peak * B + 1e-12]
    s_max, q_max = max(upto, key=lambda sv: sv[1])
    print(f"peak q/c_u for s/B <= {peak}: {q_max:.4f} at s/B = {s_max / B:.4f} ({q_max / prandtl - 1:+.2%}); "
          f"with B/2: {q_max * loaded_width / (B / 2):.4f} ({q_max * loaded_width / (B / 2) / prandtl - 1:+.2%})")
    tv.check(abs(q_max / prandtl - 1) < tol, f"peak q/c_u within {tol:.0%} of 2 + pi ({q_max / prandtl - 1:+.2%})")

if rise:
    means = []
    for r in rise:
        near = [v for s, v in zip(settle, q) if abs(s - r * B) <= 0.01 * B + 1e-12]
        means.append(sum(near) / len(near))
    print("large settlement: " + ", ".join(f"s/B = {r}: q/c_u {m:.4f}" for r, m in zip(rise, means)))
    tv.check(means[0] > mean_w and all(b > a for a, b in zip(means, means[1:])),
             f"q/c_u keeps rising at large settlement (plateau {mean_w:.4f}, then "
             + ", ".join(f"{m:.4f}" for m in means) + ")")

if u_settlement > 0:
    n_u = round(u_settlement / du)
    short = tv.prm_set(up, "time/end time", str(n_u))
    if n_u != len(q):  # else the u-p run above ends there
        run(short, "up_short")
    su, qu, itsu, _, wall_u = run(tv.prm_set(short, "implicit/formulation", "irreducible"), "u")
    z_u, z_up = zigzag("u"), zigzag("up_short" if n_u != len(q) else "up")
    print(f"s = {u_settlement} m: zigzag index of the mean stress: u {z_u:.3e}, u-p {z_up:.3e} (ratio {z_u / z_up:.1f}); "
          f"q/c_u u {qu[-1]:.4f}, u-p {q[n_u - 1]:.4f}; u run {wall_u:.1f} s, Newton its mean "
          f"{sum(itsu) / len(itsu):.2f}, largest {max(itsu)}")
    tv.check(z_up < zig_up, f"u-p: no pressure oscillation (zigzag {z_up:.3e} < {zig_up})")
    tv.check(z_u > zig_u, f"u: the pressure oscillates (zigzag {z_u:.3e} > {zig_u})")

if ranks > 0:
    short = tv.prm_set(up, "time/end time", str(ranks))
    if "--ranks-klu" in sys.argv:  # MUMPS on 2 ranks does not repeat bitwise (docs/dealii-9.4-notes.md)
        short = tv.prm_set(short, "linear solver/direct package", "klu")
    _, q1, its1, _, _ = run(short, "ranks_1")
    _, q2, its2, _, _ = run(short, "ranks_2", np=2)
    d = max(abs(a - b) / abs(a) for a, b in zip(q1, q2))
    print(f"1 vs 2 ranks, {ranks} steps: largest relative difference of q {d:.2e}; Newton its {its1} vs {its2}")
    tv.check(len(q1) == len(q2) and d < 1e-8, f"1 vs 2 ranks: q per step within 1e-8 ({d:.2e})")
tv.finish()
