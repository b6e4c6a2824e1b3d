"""Static cantilever under self-weight with talus-implicit (issue 13; seed 001 §4.5.1).
8 m x 1 m, plane strain, Neo-Hookean E = 90 MPa, nu = 0, rho = 1000, g = 9.81,
clamped at x = 0, 2 x 2 points per cell, gravity in one load step.

Tip deflection (decision, docs/implicit.md): the material points do not sit on
the free end, so delta = u_y extrapolated linearly to X = l from the mean u_y of
the two outermost columns of points (X = l - h/4, l - 3h/4): 1.5 u1 - 0.5 u2.
Checks, for the cell sizes given (each halving the previous):
  * the run reached t = 1 and Newton converges quadratically: the observed
    order of the last three increments |du_k| above round-off (series.csv
    'increment_order'; the residual norm of a slender beam hits its round-off
    floor first) of every step with >= 3 iterations is >= 1.8;
  * on the finest grid delta is within TOL of the thesis's non-linear reference
    -0.67433 m (linear Timoshenko -0.67806 m printed beside it);
  * observed order of convergence from three successive grids (Richardson,
    no reference needed): log2((d_h - d_h/2) / (d_h/2 - d_h/4)) >= 1.8.
Usage: check_implicit_cantilever.py TOOLS_DIR PRM WORKDIR TOL H1 [H2 ...] [--np N]
       [--set=entry=value ...] [--order=MIN] (MIN: the least observed order, default 1.8)
"""
import math
import sys

import talus_verify as tv

settings = [a[len("--set="):] for a in sys.argv[1:] if a.startswith("--set=")]
min_grid_order = float(([a[len("--order="):] for a in sys.argv[1:] if a.startswith("--order=")] or ["1.8"])[0])
args = [a for a in sys.argv[1:] if not a.startswith(("--set=", "--order="))]
np_ = 1
if "--np" in args:
    k = args.index("--np")
    np_ = int(args[k + 1])
    del args[k:k + 2]
tools, prm_path, work, tol = args[0], args[1], args[2], float(args[3])
hs = [float(h) for h in args[4:]]
l, ref_nonlinear, ref_linear = 8.0, -0.67433, -0.67806
base = tv.prm_set_args(open(prm_path).read(), settings)
deltas = []
print(f"{'h':>8} {'points':>7} {'delta [m]':>12} {'error vs -0.67433':>18} {'Newton its':>10} {'min order':>9}")
for h in hs:
    nx, ny = round(8.5 / h), round(2.5 / h)
    text = tv.prm_set(base, "grid/cells", f"{nx}, {ny}")
    text = tv.prm_set(text, "output/directory", "out")
    name = f"h{h:g}"
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", "cantilever", np=np_)
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    steps = [i for i in range(len(s["step"])) if s["step"][i] > 0]
    tv.check(len(steps) >= 1 and abs(s["time"][-1] - 1.0) < 1e-12, f"h = {h:g}: the run reached t = 1")
    orders = [s["increment_order"][i] for i in steps if s["newton_iterations"][i] >= 3]
    min_order = min(orders) if orders else float("nan")
    p = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    d, counts = tv.cantilever_tip(p, h, l)
    tv.check(counts[0] == counts[1] == round(2 / h), f"h = {h:g}: two columns of {round(2 / h)} points at the free end")
    deltas.append(d)
    its = sum(s["newton_iterations"][i] for i in steps)
    print(f"{h:8.4f} {len(p['pos_x']):7d} {d:12.6f} {abs(d - ref_nonlinear) / abs(ref_nonlinear):18.3e} {its:10.0f} "
          f"{min_order:9.2f}")
    if orders:
        tv.check(min_order >= 1.8, f"h = {h:g}: Newton converges quadratically (smallest observed order "
                                   f"{min_order:.2f} >= 1.8)")
err = abs(deltas[-1] - ref_nonlinear) / abs(ref_nonlinear)
print(f"finest h = {hs[-1]:g}: delta = {deltas[-1]:.6f} m; thesis non-linear {ref_nonlinear}, "
      f"linear Timoshenko {ref_linear}")
tv.check(err < tol, f"tip deflection within {tol:.1%} of the thesis's non-linear reference (error {err:.3e})")
for k in range(len(deltas) - 2):
    a, b = deltas[k] - deltas[k + 1], deltas[k + 1] - deltas[k + 2]
    order = math.log2(abs(a / b)) if b != 0 else float("inf")
    print(f"observed order from h = {hs[k]:g}, {hs[k + 1]:g}, {hs[k + 2]:g}: {order:.2f}")
    tv.check(order >= min_grid_order, f"observed order of the tip deflection >= {min_grid_order:g} (got {order:.2f})")
tv.finish()
