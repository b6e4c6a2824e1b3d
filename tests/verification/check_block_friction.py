"""Block on a frictional plane (issue 5): frictional contact with the grid floor.

Gravity is tilted by theta relative to the floor (boundary 2, Coulomb friction
mu, seed 000 §6.2 specialised to a rigid fixed boundary).
  * theta = 30 deg, mu = 0.3 (tan theta > mu): the block-centre displacement
    along the floor within 2 % of 1/2 g (sin theta - mu cos theta) t^2 at every
    output time t >= 0.05 s;
  * theta = 15 deg, mu = 0.4 (tan theta < mu): at rest, |displacement| < 1e-4 m
    over 0.5 s (frictionless it would slide 0.32 m);
  * while sliding, the block centre rises less than 5e-4 m (it must stay on the
    floor; before the friction nodes tested whether the material had lifted off,
    velocity noise was rectified into a 3.8 mm rise).
With a 4th argument `bspline` (issue 12): the same with quadratic B-spline
shape functions (the friction nodes act on the wall nodes' sums, whichever
kernel made them).
With `bspline_apic` (issue 38): the same with the affine particle-in-cell
transfer (the friction nodes set a and v^L before the APIC G2P).
Usage: check_block_friction.py TOOL PRM WORKDIR [bspline | bspline_apic]
"""
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
if len(sys.argv) > 4 and sys.argv[4] in ("bspline", "bspline_apic"):
    base = tv.prm_set(base, "numerics/shape function", "quadratic bspline")
    if sys.argv[4] == "bspline_apic":
        base = tv.prm_set(base, "numerics/velocity transfer", "apic")
g = 9.81
for theta, mu in ((30.0, 0.3), (15.0, 0.4)):
    th = math.radians(theta)
    name = f"theta{int(theta)}_mu{mu}"
    text = tv.prm_set(base, "output/directory", name)
    text = tv.prm_set(text, "gravity/acceleration", f"{g * math.sin(th):.12g}, {-g * math.cos(th):.12g}")
    text = tv.prm_set(text, "boundary conditions/friction coefficient", str(mu))
    tv.run_tool(tool, text, work, name)
    s = tv.read_csv(f"{work}/{name}/series.csv")
    t, ux, uy = s["time"], s["probe0_ux"], s["probe0_uy"]
    if math.tan(th) > mu:
        a = 0.5 * g * (math.sin(th) - mu * math.cos(th))
        worst, at = 0.0, 0.0
        for ti, x in zip(t, ux):
            if ti >= 0.05:
                e = abs(x - a * ti * ti) / (a * ti * ti)
                if e > worst:
                    worst, at = e, ti
        print(f"theta = {theta}, mu = {mu}: d({t[-1]:.3f} s) = {ux[-1]:.6f} m, analytic {a * t[-1] ** 2:.6f} m; "
              f"largest relative error {worst:.2e} at t = {at:.3f} s; vertical drift {uy[-1]:.2e} m")
        tv.check(worst < 0.02, f"sliding: displacement within 2 % of 1/2 g (sin - mu cos) t^2 (worst {worst:.2e})")
        lift = max(uy)
        tv.check(lift < 5e-4, f"sliding: the block stays on the floor, largest rise {lift:.2e} m < 5e-4 m "
                              f"(2 % of a cell; the contact without the lift test drifted up 3.8e-3 m)")
    else:
        d = max(math.hypot(x, y) for x, y in zip(ux, uy))
        print(f"theta = {theta}, mu = {mu}: largest displacement {d:.3e} m")
        tv.check(d < 1e-4, f"sticking: block at rest, largest displacement {d:.2e} m < 1e-4 m")
tv.finish()
