"""1D elastic bar, first axial mode (issue 2 verification).

Exact period T = 4 L / c. The total momentum p_x(t) is proportional to cos(omega t);
its zero crossings give the numerical period. Checks:
  * period error < 1 % with 32 cells over the bar and 2 particles per direction;
  * the period error decreases under refinement (8 -> 16 -> 32 -> 64 cells);
  * the total-energy oscillation (O(dt)) is < 2 % at 32 cells and shrinks with h.
Usage: check_bar.py TOOL PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
# quadratic B-splines need 3 cells across (their wall treatment); the bar is then 3 cells high
bspline = "quadratic bspline" in base
across = 3 if bspline else 1
L, E, rho = 1.0, 100.0, 1.0
T_exact = 4 * L / math.sqrt(E / rho)

errors = {}
drifts = {}
for n in (8, 16, 32, 64):
    h = L / n
    text = tv.prm_set(base, "grid/cells", f"{int(1.25 * n)}, {across}")
    text = tv.prm_set(text, "grid/upper corner", f"1.25, {across * h}")
    text = tv.prm_set(text, "body 0/upper corner", f"1, {across * h}")
    text = tv.prm_set(text, "output/directory", f"out_{n}")
    tv.run_tool(tool, text, work, f"bar_{n}")
    s = tv.read_csv(f"{work}/out_{n}/series.csv")
    z = tv.zero_crossings(s["time"], s["momentum_x"])
    tv.check(len(z) >= 3, f"n={n}: at least 3 zero crossings of p_x (got {len(z)})")
    # crossings at T/4, 3T/4, 5T/4, ...: period = 2 * mean spacing
    T_num = 2 * (z[-1] - z[0]) / (len(z) - 1)
    errors[n] = abs(T_num - T_exact) / T_exact
    e_tot = [k + w for k, w in zip(s["kinetic_energy"], s["strain_energy"])]
    drift = max(abs(e - e_tot[0]) for e in e_tot) / e_tot[0]
    print(f"n={n:3d} cells: T = {T_num:.6f} s (exact {T_exact:.6f}), rel. error {errors[n]:.3e}, "
          f"energy drift {drift:.2e}")
    drifts[n] = drift

# Kinetic and strain energy are evaluated half a step apart in the explicit
# scheme, so their sum oscillates by O(dt) = O(h): it must shrink with h.
tv.check(drifts[32] < 0.02, f"energy oscillation with 32 cells {drifts[32]:.2e} < 2 %")
tv.check(drifts[16] < drifts[8] and drifts[32] < drifts[16] and drifts[64] < drifts[32],
         "energy oscillation decreases under refinement")
tv.check(errors[32] < 0.01, f"period error with 32 cells {errors[32]:.3e} < 1 %")
tv.check(errors[16] < errors[8] and errors[32] < errors[16] and errors[64] < errors[32],
         "period error decreases under refinement")
rates = [math.log(errors[a] / errors[b], 2) for a, b in ((8, 16), (16, 32), (32, 64))]
print("observed orders:", ", ".join(f"{r:.2f}" for r in rates))
if bspline:  # issue 12: quadratic B-splines converge at second order or better in the period
    tv.check(min(rates[1:]) >= 1.8, f"B-spline period error order >= 1.8 (16 -> 32 -> 64 cells: "
                                    f"{rates[1]:.2f}, {rates[2]:.2f})")
tv.finish()
