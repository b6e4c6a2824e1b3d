"""Self-weight of a laterally confined solid cylinder, axisymmetric talus-implicit
(issue 13 item 6: the body force with the ring measure, points next to the axis).
The scene of thick_cylinder_axisymmetric.prm changed to a solid cylinder of
radius 1 m and height H = 1 m that touches the axis (x = 0: radial roller added
automatically), a roller on the outer wall x = 1 and on the floor, gravity
9.81 m/s^2 along -y, no traction (its value set to 0). Exact (linear, p/E ~ 1e-3):
u_r = 0, sigma_zz = -rho g (H - z), sigma_rr = sigma_tt = nu / (1 - nu) sigma_zz,
u_z = -rho g / E_oed (H z - z^2 / 2). If the mass and the volume of the points did
not carry the same ring weight 2 pi r, the stress would be wrong by O(1).
Per grid (n x n cells over the body): largest errors of sigma_zz, of the hoop
(stress_zz) and radial stresses at the points below the top cell, relative to
rho g H; of u_z at every point, relative to the top settlement; |u_r| / that.
Checks on the finest grid: sigma_zz within TOL, hoop and radial within TOL / 2,
u_z within TOL / 4, |u_r| < 1e-10; the sigma_zz error falls with h (order >= ORDER
over the last two grids).
Then the same cylinder, weightless, under a uniform top traction q on the finest
grid (the ring weight 2 pi r_p of a traction on a face normal to the axis): below
the top cell sigma_zz = -q, the hoop stress -nu / (1 - nu) q and u_z within 1e-3,
u_r = 0 to round-off.
Usage: check_implicit_axisymmetric_gravity.py TOOLS_DIR PRM WORKDIR TOL ORDER N1 N2 [...]
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work, tol, min_order = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
ns = [int(n) for n in sys.argv[6:]]
E, nu, rho, g, H = 1e7, 0.3, 1000.0, 9.81, 1.0
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
settlement = rho * g * H * H / (2 * E_oed)
base = open(prm_path).read()
for entry, value in (("loads/traction 0/traction", "0, 0"), ("gravity/acceleration", f"0, {-g}"),
                     ("body 0/lower corner", "0, 0"), ("body 0/upper corner", "1, 1"),
                     ("grid/upper corner", "1, 1.25"), ("boundary conditions/roller", "1, 2"),
                     ("output/directory", "out")):
    base = tv.prm_set(base, entry, value)
rows = []
print(f"{'cells':>5} {'points':>6} {'sigma_zz':>9} {'hoop':>9} {'radial':>9} {'u_z':>9} {'|u_r|':>9} {'Newton':>8} "
      f"{'wall [s]':>8}")
for n in ns:
    h = 1.0 / n
    name = f"n{n}"
    start = time.time()
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(base, "grid/cells", f"{n}, {n + n // 4}"),
                            f"{work}/{name}", name)
    tv.check("the x-min wall is the axis, u_r = 0 there (roller)" in out,
             f"{name}: the axis roller was added (the .prm names only walls 1 and 2)")
    wall = time.time() - start
    t = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    m = len(t["id"])
    Z = [t["pos_y"][i] - t["u_y"][i] for i in range(m)]
    below = [i for i in range(m) if Z[i] < H - h]
    s_ref = rho * g * H
    e_zz = max(abs(t["stress_yy"][i] + rho * g * (H - Z[i])) for i in below) / s_ref
    e_tt = max(abs(t["stress_zz"][i] + nu / (1 - nu) * rho * g * (H - Z[i])) for i in below) / s_ref
    e_rr = max(abs(t["stress_xx"][i] + nu / (1 - nu) * rho * g * (H - Z[i])) for i in below) / s_ref
    e_uz = max(abs(t["u_y"][i] + rho * g / E_oed * (H * Z[i] - Z[i] ** 2 / 2)) for i in range(m)) / settlement
    e_ur = max(abs(t["u_x"][i]) for i in range(m)) / settlement
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    its = [int(k) for k, st in zip(s["newton_iterations"], s["step"]) if st > 0]
    rows.append((h, e_zz, e_tt, e_rr, e_uz, e_ur))
    print(f"{n:5d} {m:6d} {e_zz:9.2e} {e_tt:9.2e} {e_rr:9.2e} {e_uz:9.2e} {e_ur:9.2e} {str(its):>8} {wall:8.2f}")
    tv.check(its and max(its) <= 3, f"{name}: at most 3 Newton iterations per load step ({its})")

h, e_zz, e_tt, e_rr, e_uz, e_ur = rows[-1]
tv.check(e_zz < tol, f"finest grid: sigma_zz below the top cell within {tol} of rho g H ({e_zz:.2e})")
tv.check(e_tt < tol / 2, f"finest grid: hoop stress within {tol / 2} ({e_tt:.2e})")
tv.check(e_rr < tol / 2, f"finest grid: radial stress within {tol / 2} ({e_rr:.2e})")
tv.check(e_uz < tol / 4, f"finest grid: u_z within {tol / 4} of the top settlement ({e_uz:.2e})")
tv.check(e_ur < 1e-10, f"finest grid: u_r = 0 to round-off ({e_ur:.2e} of the settlement)")
if len(rows) >= 2:
    q = math.log(rows[-2][1] / rows[-1][1]) / math.log(rows[-2][0] / rows[-1][0])
    print(f"observed order of the sigma_zz error over the last two grids: {q:.2f}")
    tv.check(q >= min_order, f"sigma_zz error falls with h at order >= {min_order} ({q:.2f})")

# the same confined cylinder, weightless, under a top traction q = 1 kPa (body face
# y+): each top point carries q A_p 2 pi r_p (the midpoint rule of its annulus strip,
# exact for the total q pi R^2), so below the top cell sigma_zz = -q, sigma_rr =
# sigma_tt = -nu / (1 - nu) q, u_z = -q z / E_oed, u_r = 0 (as the plane oedometer of
# check_implicit_traction.py; O(q/E) = 1e-4 from the finite-strain model)
q, n = 1000.0, ns[-1]
h = 1.0 / n
text = tv.prm_set(tv.prm_set(base, "gravity/acceleration", "0, 0"), "loads/traction 0/traction", f"0, {-q}")
text = tv.prm_set(tv.prm_set(text, "loads/traction 0/face", "y+"), "grid/cells", f"{n}, {n + n // 4}")
tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/top", "top")
t = tv.read_csv(f"{work}/top/out/particles_final.csv")
m = len(t["id"])
Z = [t["pos_y"][i] - t["u_y"][i] for i in range(m)]
below = [i for i in range(m) if Z[i] < H - h]
e_zz = max(abs(t["stress_yy"][i] + q) for i in below) / q
e_tt = max(abs(t["stress_zz"][i] + nu / (1 - nu) * q) for i in below) / q
e_uz = max(abs(t["u_y"][i] + q * Z[i] / E_oed) for i in below) / (q * H / E_oed)
e_ur = max(abs(t["u_x"][i]) for i in range(m)) / (q * H / E_oed)
print(f"top traction, n = {n}: below the top cell sigma_zz {e_zz:.2e} of q, hoop {e_tt:.2e}, u_z {e_uz:.2e} of q H / "
      f"E_oed, |u_r| {e_ur:.2e}")
tv.check(max(e_zz, e_tt, e_uz) < 1e-3, f"top traction: sigma_zz, hoop stress and u_z within 1e-3 "
         f"({e_zz:.2e}, {e_tt:.2e}, {e_uz:.2e})")
tv.check(e_ur < 1e-10, f"top traction: u_r = 0 to round-off ({e_ur:.2e})")
tv.finish()
