"""Plane-strain Lame cylinder with talus-implicit (issue 39 item 4): a quarter of
the thick-walled cylinder a = 1, b = 2 m seeded on the box grid (2 x 2 points per
cell inside the quarter annulus), rollers on x = 0 and y = 0, internal pressure
p = 1 kPa as a 'pressure on a circle' (loads/traction 0/pressure centre), Neo-
Hookean E = 10 MPa, nu = 0.3, p / E = 1e-4, against the linear Lame solution
  u_r(r) = (1 + nu) / E A ((1 - 2 nu) r + b^2 / r),  A = a^2 p / (b^2 - a^2)
  sigma_tt(r) = A (1 + b^2 / r^2),  sigma_rr(r) = A (1 - b^2 / r^2)
Per grid (cell size h = 2.5 / n), each point compared at its initial position
X = x - u (R = |X|, e_r = X / R):
  * u_r = u . e_r: the RMS and the largest error over all points, relative to
    u_r(a); the tangential displacement u . e_t, largest, relative to u_r(a);
  * the hoop stress sigma_tt = e_t . sigma . e_t: RMS and largest error relative
    to sigma_tt(a) over the points of the interior (a + 2h < R < b - 2h); the
    layers within 2h of the surfaces are reported separately (the bore carries
    the pressure on its first layer of points, not on the surface, and the
    nodes of that layer's cells reach the next cell; both surfaces are
    staircases of the lattice: an O(1) error next to the bore, measured
    0.5 sigma_tt(a) in its first cell and 0.07-0.11 in the second);
  * the radial stress in the interior, RMS relative to p (printed);
  * Newton iterations per load step (the problem is nearly linear).
Checks: on the finest grid the RMS of the u_r error within U_RMS and its largest
within U_MAX, the tangential displacement within UT_MAX, the interior hoop
stress RMS within S_RMS and its largest within S_MAX (all relative to u_r(a),
sigma_tt(a)); Newton <= 3 iterations per step on every grid; with two grids or
more the RMS errors of u_r and of the interior hoop stress fall at an observed
order >= ORDER over the last two.
Usage: check_implicit_lame_plane_strain.py TOOLS_DIR PRM WORKDIR U_RMS U_MAX UT_MAX S_RMS S_MAX ORDER
       N1 N2 [N3 ...]
(N = cells per direction of the grid [0, 2.5]^2)
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work = sys.argv[1], sys.argv[2], sys.argv[3]
u_rms, u_max, ut_max, s_rms, s_max, min_order = (float(x) for x in sys.argv[4:10])
ns = [int(n) for n in sys.argv[10:]]
a, b, p, E, nu = 1.0, 2.0, 1000.0, 1e7, 0.3
u_exact, hoop_exact, radial_exact = tv.lame_cylinder(a, b, p, E, nu)


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v))


base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
rows = []
print(f"{'n':>4} {'h':>8} {'points':>6} {'u_r rms':>9} {'u_r max':>9} {'u_t max':>9} {'hoop rms':>9} "
      f"{'hoop max':>9} {'bore hoop':>9} {'outer hoop':>10} {'rad rms':>9} {'Newton':>8} {'wall [s]':>8}")
for n in ns:
    h = 2.5 / n
    text = tv.prm_set(base, "grid/cells", f"{n}, {n}")
    name = f"n{n}"
    start = time.time()
    _, out, _ = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", name)
    wall = time.time() - start
    t = tv.read_csv(f"{work}/{name}/out/particles_final.csv")
    m = len(t["id"])
    ua, sa = u_exact(a), hoop_exact(a)
    eu, et, eh, eh_bore, eh_out, er = [], [], [], [], [], []
    for i in range(m):
        X, Y = t["pos_x"][i] - t["u_x"][i], t["pos_y"][i] - t["u_y"][i]
        R = math.hypot(X, Y)
        c, s = X / R, Y / R
        ur = t["u_x"][i] * c + t["u_y"][i] * s
        ut = -t["u_x"][i] * s + t["u_y"][i] * c
        sxx, syy, sxy = t["stress_xx"][i], t["stress_yy"][i], t["stress_xy"][i]
        stt = sxx * s * s + syy * c * c - 2 * sxy * s * c
        srr = sxx * c * c + syy * s * s + 2 * sxy * s * c
        eu.append((ur - u_exact(R)) / ua)
        et.append(ut / ua)
        e = (stt - hoop_exact(R)) / sa
        if R < a + 2 * h:
            eh_bore.append(e)
        elif R > b - 2 * h:
            eh_out.append(e)
        else:
            eh.append(e)
            er.append((srr - radial_exact(R)) / p)
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    its = [int(k) for k, st in zip(s["newton_iterations"], s["step"]) if st > 0]
    tv.check(abs(s["time"][-1] - 1.0) < 1e-9, f"{name}: the run reached t = 1")
    r = dict(n=n, h=h, u_rms=rms(eu), u_max=max(map(abs, eu)), ut=max(map(abs, et)), hoop_rms=rms(eh),
             hoop_max=max(map(abs, eh)), bore=max(map(abs, eh_bore)), outer=max(map(abs, eh_out)), rad=rms(er),
             its=its)
    rows.append(r)
    print(f"{n:4d} {h:8.5f} {m:6d} {r['u_rms']:9.2e} {r['u_max']:9.2e} {r['ut']:9.2e} {r['hoop_rms']:9.2e} "
          f"{r['hoop_max']:9.2e} {r['bore']:9.2e} {r['outer']:10.2e} {r['rad']:9.2e} {str(its):>8} {wall:8.2f}")
    for line in out.splitlines():
        if "pressure" in line and "circle" in line:
            print("     " + line.strip())

r = rows[-1]
tv.check(r["u_rms"] < u_rms, f"finest grid (n = {r['n']}): u_r RMS error {r['u_rms']:.2e} < {u_rms} of u_r(a)")
tv.check(r["u_max"] < u_max, f"finest grid: largest u_r error {r['u_max']:.2e} < {u_max} of u_r(a)")
tv.check(r["ut"] < ut_max, f"finest grid: tangential displacement {r['ut']:.2e} < {ut_max} of u_r(a)")
tv.check(r["hoop_rms"] < s_rms, f"finest grid: interior hoop stress RMS error {r['hoop_rms']:.2e} < {s_rms} "
                                f"of sigma_tt(a)")
tv.check(r["hoop_max"] < s_max, f"finest grid: largest interior hoop stress error {r['hoop_max']:.2e} < {s_max} "
                                f"of sigma_tt(a)")
for q in rows:
    tv.check(max(q["its"]) <= 3, f"n = {q['n']}: at most 3 Newton iterations per load step ({q['its']})")
if len(rows) >= 2:
    r1, r2 = rows[-2], rows[-1]
    q_u = math.log(r1["u_rms"] / r2["u_rms"]) / math.log(r1["h"] / r2["h"])
    q_h = math.log(r1["hoop_rms"] / r2["hoop_rms"]) / math.log(r1["h"] / r2["h"])
    print(f"observed order over the last two grids: u_r RMS {q_u:.2f}, interior hoop stress RMS {q_h:.2f}")
    tv.check(q_u >= min_order, f"u_r RMS error falls with h at order >= {min_order} ({q_u:.2f})")
    tv.check(q_h >= min_order, f"interior hoop stress RMS error falls with h at order >= {min_order} ({q_h:.2f})")
tv.finish()
