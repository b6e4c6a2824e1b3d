"""Prescribed grid-node displacements in talus-implicit (issue 13, item 5).

block_prescribed_displacement.prm: a Neo-Hookean block (E = 1e7 Pa, nu = 0.3,
coupled energy tau = lambda ln J I + mu (b - I)), H = 1 m on a grid of 0.125 m
cells, rollers on the sides and the base, no gravity; the grid nodes of the row
y = 1 move down at v (`loads/velocity 0`, region, component y). Each static step
prescribes the increment v h on those nodes; the grid is reset every step, so the
prescribed row stays at y = 1 and a homogeneous field gives every point the
stretch s_k = 1 + v h / 1 m in step k.
  1. small strain (v = -1e-4 m/s, one step; no point leaves its cell): the
     homogeneous solution holds to round-off: every point has u_y = (s - 1) Y and
     sigma_yy, sigma_xx equal to the Neo-Hookean uniaxial-strain values at s
     (sigma_yy = (lambda ln s + mu (s^2 - 1)) / s, sigma_xx = lambda ln s / s) to
     1e-6 relative; 1 and 2 ranks agree to 1e-10;
  2. large strain in one step (v = -0.2 m/s, h = 1 s: s = 0.8; the prescribed
     increment is 1.6 cell heights): the predictor (one linear solve with the
     increment lifted into the right-hand side) and Newton reach the homogeneous
     finite-strain solution without a cut-back; the same checks, to 1e-6 (a
     predictor that moved only the prescribed row inverted the cell below it:
     det dF = -0.6, cut back);
  3. s = 0.8 in 10 steps (v = -0.2 m/s): the prescribed nodes are fixed in space, so
     once the top points have left the cells next to them the condition acts on
     nothing: the run must say so in its log (a WARNING naming loads/velocity 0)
     rather than let the displacement control go slack silently.
Usage: check_implicit_prescribed.py TOOLS_DIR PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
E, nu = 1e7, 0.3
lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def neo_hookean(s):
    return (lam * math.log(s) + mu * (s * s - 1)) / s, lam * math.log(s) / s


base = tv.prm_set(open(prm_path).read(), "output/final particles csv", "true")
tool = f"{tools}/talus-implicit"

# 1. small strain, 1 and 2 ranks
s = 1 - 1e-4
syy, sxx = neo_hookean(s)
runs = {}
for n in (1, 2):
    tv.run_tool(tool, tv.prm_set(base, "output/directory", f"small_np{n}"), work, f"small_np{n}", np=n)
    runs[n] = tv.read_csv(f"{work}/small_np{n}/particles_final.csv")
p = runs[1]
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
du = max(abs(u - (s - 1) * y) for u, y in zip(p["u_y"], Y)) / (1e-4)
dyy = max(abs(x - syy) for x in p["stress_yy"]) / abs(syy)
dxx = max(abs(x - sxx) for x in p["stress_xx"]) / abs(sxx)
print(f"small strain: s = {s}, sigma_yy {syy:.6e} Pa, sigma_xx {sxx:.6e} Pa (Neo-Hookean)")
tv.check(du < 1e-6, f"small strain: u_y = (s - 1) Y at every point (largest deviation {du:.2e} of the compression)")
tv.check(dyy < 1e-6 and dxx < 1e-6, f"small strain: sigma_yy, sigma_xx at every point within 1e-6 (relative "
                                    f"deviations {dyy:.2e}, {dxx:.2e})")
order = {n: sorted(range(len(r["id"])), key=lambda i: r["id"][i]) for n, r in runs.items()}
worst = max(abs(runs[1][k][i] - runs[2][k][j]) / max(abs(x) for x in runs[1][k])
            for k in ("u_y", "stress_yy") for i, j in zip(order[1], order[2]))
tv.check(worst < 1e-10, f"small strain: 1 and 2 ranks agree (worst relative difference {worst:.2e})")

# 2. large strain in one step
s = 0.8
syy, sxx = neo_hookean(s)
big = tv.prm_set(base, "loads/velocity 0/velocity", "0, -0.2")
_, log, _ = tv.run_tool(tool, tv.prm_set(big, "output/directory", "large"), work, "large")
tv.check("cut back" not in log and "failed" not in log, "large strain: one step, no cut-back")
p = tv.read_csv(f"{work}/large/particles_final.csv")
ser = tv.read_csv(f"{work}/large/series.csv")
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
du = max(abs(u - (s - 1) * y) for u, y in zip(p["u_y"], Y)) / 0.2
dyy = max(abs(x - syy) for x in p["stress_yy"]) / abs(syy)
dxx = max(abs(x - sxx) for x in p["stress_xx"]) / abs(sxx)
print(f"large strain: s = {s}, sigma_yy {syy:.6e} Pa, sigma_xx {sxx:.6e} Pa (Neo-Hookean); "
      f"Newton iterations {int(ser['newton_iterations'][-1])}, order {ser['newton_order'][-1]:.2f}")
tv.check(du < 1e-6, f"large strain: u_y = (s - 1) Y at every point (largest deviation {du:.2e} of the compression)")
tv.check(dyy < 1e-6 and dxx < 1e-6, f"large strain: sigma_yy, sigma_xx at every point within 1e-6 (relative "
                                    f"deviations {dyy:.2e}, {dxx:.2e})")

# 3. s = 0.8 in 10 steps: the material leaves the prescribed nodes
steps = tv.prm_set(big, "time/time step", "0.1")
_, log, _ = tv.run_tool(tool, tv.prm_set(steps, "output/directory", "steps"), work, "steps")
warned = [l for l in log.splitlines() if "WARNING" in l and "loads/velocity 0" in l]
print(warned[0].strip() if warned else "no warning")
tv.check(len(warned) == 1, "10 steps: the log warns once that loads/velocity 0 reaches no node next to material")
tv.finish()
