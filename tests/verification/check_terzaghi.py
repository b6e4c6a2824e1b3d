"""Terzaghi 1D consolidation with the 2-phase single-point formulation (issue 5).

Parameters of seed 002 §5.1 (Table 1), see terzaghi_consolidation.prm. At the
time factors T_v = 0.05, 0.2, 0.5 the pore pressures of all points, normalised
by q, are compared with the series solution (z the depth below the drained top,
from the initial position of the point; terms up to i = 200):
  p / q = sum_i 4 / ((2i+1) pi) sin((2i+1) pi z / (2H)) exp(-(2i+1)^2 pi^2 T_v / 4),
  T_v = c_v t / H^2,  c_v = k E_c / (rho_w g).
Check: the L2 error sqrt(mean((p - p_an)^2)) / q < 3 % (bspline: 2 %) at each T_v (the relative
L2 error ||p - p_an|| / ||p_an|| is reported too).
Usage: check_terzaghi.py TOOL PRM WORKDIR [fast|3d|bspline] [entry=value ...]
  fast: a column one cell (0.025 m) wide instead of 0.1 m (1-D anyway);
  3d:   the same column in 3D, 1 x 1 x 41 hexes, rollers on the four sides and the base;
  bspline: quadratic B-splines (issue 38) on a column three cells (0.075 m, their minimum) wide,
        3 x 3 points per cell (docs/shape-functions.md, "2-phase on B-splines"); check L2 < 2 %;
  entry=value: .prm settings applied last (e.g. 'two phase/pressure relaxation=0').
"""
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
rest = [a for a in sys.argv[4:] if "=" not in a]
settings = [a for a in sys.argv[4:] if "=" in a]
mode = rest[0] if rest else ""
fast = mode == "fast"
tol = 0.02 if mode == "bspline" else 0.03
H, q, k, E, rho_w, g = 1.0, 1e4, 1e-3, 1e7, 1000.0, 9.81
cv = k * E / (rho_w * g)


def analytic(z, Tv):
    s = 0.0
    for i in range(200):
        m = 2 * i + 1
        s += 4 / (m * math.pi) * math.sin(m * math.pi * z / (2 * H)) * math.exp(-m * m * math.pi ** 2 * Tv / 4)
    return s


base = open(prm_path).read()
if fast:
    base = tv.prm_set(base, "grid/upper corner", "0.025, 1.025")
    base = tv.prm_set(base, "grid/cells", "1, 41")
    base = tv.prm_set(base, "body 0/upper corner", "0.025, 1")
if mode == "bspline":
    for k, v in [("numerics/shape function", "quadratic bspline"), ("grid/upper corner", "0.075, 1.025"),
                 ("grid/cells", "3, 41"), ("body 0/upper corner", "0.075, 1"),
                 ("body 0/particles per direction", "3")]:
        base = tv.prm_set(base, k, v)
vert = "y"
if mode == "3d":
    vert = "z"
    for k, v in [("dimension", "3"), ("grid/lower corner", "0, 0, 0"), ("grid/upper corner", "0.025, 0.025, 1.025"),
                 ("grid/cells", "1, 1, 41"), ("boundary conditions/roller", "0, 1, 2, 3, 4"),
                 ("gravity/acceleration", "0, 0, 0"), ("body 0/lower corner", "0, 0, 0"),
                 ("body 0/upper corner", "0.025, 0.025, 1"), ("body 0/traction face", "z+"),
                 ("body 0/traction", "0, 0, -10000")]:
        base = tv.prm_set(base, k, v)
base = tv.prm_set_args(base, settings)
for Tv in (0.05, 0.2, 0.5):
    t = Tv * H * H / cv
    text = tv.prm_set(base, "output/directory", f"out_{Tv}")
    text = tv.prm_set(text, "time/end time", f"{t:.10g}")
    tv.run_tool(tool, text, work, f"terzaghi_{Tv}")
    p = tv.read_csv(f"{work}/out_{Tv}/particles_final.csv")
    z = [H - (y - u) for y, u in zip(p["pos_" + vert], p["u_" + vert])]
    num = [x / q for x in p["pore_pressure"]]
    ref = [analytic(zz, Tv) for zz in z]
    n = len(num)
    l2 = math.sqrt(sum((a - b) ** 2 for a, b in zip(num, ref)) / n)
    rel = math.sqrt(sum((a - b) ** 2 for a, b in zip(num, ref)) / sum(b * b for b in ref))
    # a profile for the log: every 4th depth of the first column of points
    prof = sorted({round(zz, 6): (a, b) for zz, a, b in zip(z, num, ref)}.items())
    print(f"T_v = {Tv}: t = {t:.5f} s, {n} points; L2 error / q = {l2:.4f}, relative L2 = {rel:.4f}")
    for zz, (a, b) in prof[:: max(1, len(prof) // 8)]:
        print(f"   z = {zz:.4f} m: p/q = {a:.4f} (series {b:.4f})")
    tv.check(l2 < tol, f"T_v = {Tv}: normalised pore pressure within {100 * tol:.0f} % (L2) of the series "
             f"(error {l2:.4f})")
tv.finish()
