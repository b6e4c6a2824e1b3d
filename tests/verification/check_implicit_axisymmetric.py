"""Thick-walled cylinder under internal pressure, axisymmetric talus-implicit
(issue 13 item 6; seed 001 App. C) against the linear Lame solution.
a = 1, b = 2, E = 10 MPa, nu = 0.3, p = 1 kPa (p / E = 1e-4, so the finite-strain
model differs from the linear answer by O(1e-4)), rollers on the y walls (plane
strain along the axis):
  u_r(r) = (1 + nu) / E a^2 p / (b^2 - a^2) ((1 - 2 nu) r + b^2 / r)
  sigma_tt(r) = A (1 + b^2 / r^2), sigma_rr(r) = A (1 - b^2 / r^2), A = a^2 p / (b^2 - a^2)
Per grid (cell size h, 2 x 2 points per cell, each point compared at its initial
radius R = x - u_x):
  * u_r(a), u_r(b): the mean u_x of the two point columns nearest the surface
    (R = a + h/4, a + 3h/4), extrapolated linearly to the surface
    (1.5 u1 - 0.5 u2, as for the cantilever's tip), error relative to u_r(a);
  * the largest error of u_x over all points, relative to u_r(a);
  * the hoop stress (stress_zz), largest error relative to sigma_tt(a), over the
    points outside the loaded cell (R > a + h) and, separately, in it: the
    traction acts on the first layer of points, not on the surface (seed 000
    Eq. 5.3), so the cell at r = a carries only part of it (sigma_rr there is
    about -3/4 p, as in the plane block of check_implicit_traction.py): an O(1)
    error confined to that cell, and an O(h) perturbation beyond it;
  * the radial stress outside the loaded cell, relative to p (printed);
  * Newton iterations per load step (the problem is nearly linear).
Checks: on the finest grid u_r(a), u_r(b) and u_x at every point within TOL_U,
the hoop stress outside the loaded cell within TOL_S, in the loaded cell within
0.1 (measured 0.067 on every grid: the traction artifact, not a hoop term);
Newton <= 3 iterations per step on every grid; the errors of u_r(a) and of the
hoop stress outside the loaded cell fall with h at an observed order >= ORDER
over the last two grids.
Usage: check_implicit_axisymmetric.py TOOLS_DIR PRM WORKDIR TOL_U TOL_S ORDER H1 H2 [H3 ...]
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work = sys.argv[1], sys.argv[2], sys.argv[3]
tol_u, tol_s, min_order = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
hs = [float(h) for h in sys.argv[7:]]
a, b, p, E, nu = 1.0, 2.0, 1000.0, 1e7, 0.3
u_exact, hoop_exact, radial_exact = tv.lame_cylinder(a, b, p, E, nu)


base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
rows = []
print(f"{'h':>8} {'points':>6} {'u_r(a) err':>10} {'u_r(b) err':>10} {'max u err':>10} {'hoop out':>9} "
      f"{'hoop cell':>9} {'rad out':>9} {'Newton':>8} {'wall [s]':>8}")
for h in hs:
    text = tv.prm_set(base, "grid/cells", f"{round(2.5 / h)}, {round(0.5 / h)}")
    name = f"h{h:g}"
    start = time.time()
    tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    wall = time.time() - start
    t = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    n = len(t["id"])
    R = [t["pos_x"][i] - t["u_x"][i] for i in range(n)]
    ua = u_exact(a)

    def column_mean(r0):
        sel = [t["u_x"][i] for i in range(n) if abs(R[i] - r0) < 1e-9]
        tv.check(len(sel) > 0, f"{name}: a point column at R = {r0}")
        return sum(sel) / len(sel)

    u_a = 1.5 * column_mean(a + h / 4) - 0.5 * column_mean(a + 3 * h / 4)
    u_b = 1.5 * column_mean(b - h / 4) - 0.5 * column_mean(b - 3 * h / 4)
    err_ua, err_ub = abs(u_a - ua) / ua, abs(u_b - u_exact(b)) / ua
    err_u = max(abs(t["u_x"][i] - u_exact(R[i])) for i in range(n)) / ua
    sa = hoop_exact(a)
    outside = [i for i in range(n) if R[i] > a + h]
    loaded = [i for i in range(n) if R[i] < a + h]
    err_h = max(abs(t["stress_zz"][i] - hoop_exact(R[i])) for i in outside) / sa
    err_hc = max(abs(t["stress_zz"][i] - hoop_exact(R[i])) for i in loaded) / sa
    err_r = max(abs(t["stress_xx"][i] - radial_exact(R[i])) for i in outside) / p
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    its = [int(k) for k, st in zip(s["newton_iterations"], s["step"]) if st > 0]
    tv.check(abs(s["time"][-1] - 1.0) < 1e-9, f"{name}: the run reached t = 1")
    rows.append((h, err_ua, err_ub, err_u, err_h, err_hc, its))
    print(f"{h:8.5f} {n:6d} {err_ua:10.2e} {err_ub:10.2e} {err_u:10.2e} {err_h:9.2e} {err_hc:9.2e} {err_r:9.2e} "
          f"{str(its):>8} {wall:8.2f}")
    print(f"         u_r(a) = {u_a:.6e} m (exact {ua:.6e}), u_r(b) = {u_b:.6e} m (exact {u_exact(b):.6e})")

h, err_ua, err_ub, err_u, err_h, err_hc, its = rows[-1]
tv.check(err_ua < tol_u, f"finest grid: u_r(a) within {tol_u} of u_r(a) ({err_ua:.2e})")
tv.check(err_ub < tol_u, f"finest grid: u_r(b) within {tol_u} of u_r(a) ({err_ub:.2e})")
tv.check(err_u < tol_u, f"finest grid: u_x at every point within {tol_u} of u_r(a) ({err_u:.2e})")
tv.check(err_h < tol_s, f"finest grid: hoop stress outside the loaded cell within {tol_s} of sigma_tt(a) ({err_h:.2e})")
for r in rows:
    tv.check(r[5] < 0.1, f"h = {r[0]:g}: hoop stress in the loaded cell within 0.1 of sigma_tt(a) ({r[5]:.2e})")
    tv.check(max(r[6]) <= 3, f"h = {r[0]:g}: at most 3 Newton iterations per load step ({r[6]})")
if len(rows) >= 2:
    r1, r2 = rows[-2], rows[-1]
    q_u = math.log(r1[1] / r2[1]) / math.log(r1[0] / r2[0])
    q_h = math.log(r1[4] / r2[4]) / math.log(r1[0] / r2[0])
    print(f"observed order over the last two grids: u_r(a) {q_u:.2f}, hoop stress outside the loaded cell {q_h:.2f}")
    tv.check(q_u >= min_order, f"u_r(a) error falls with h at order >= {min_order} ({q_u:.2f})")
    tv.check(q_h >= min_order, f"hoop stress error falls with h at order >= {min_order} ({q_h:.2f})")
tv.finish()
