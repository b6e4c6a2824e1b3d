"""Elastic cantilever under self-weight, small deflection (issue 4; seed 001 §4.5.1).
Runs one integration mode (mpm with talus-explicit; fem / ul-fem with talus-fem)
to the quasi-static state (local damping + convergence criterion) and compares
the vertical deflection of the material point nearest to the tip centre (8, 0.5)
with the Timoshenko beam (seed 001 Eq. 4.39), evaluated at that point's initial
x (bending + shear deflection curve, q = rho g b h):
  w(x) = q (x^4 - 4 l x^3 + 6 l^2 x^2) / (24 E I) + q (l x - x^2 / 2) / (G A_s),
  w(l) = q l^4 / (8 E I) + q l^2 / (2 G A_s) = 6.781e-3 m.
Usage: check_fem_cantilever.py TOOLS_DIR PRM WORKDIR MODE TOLERANCE
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work, mode, tol = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5])
tool = f"{tools}/talus-explicit" if mode == "mpm" else f"{tools}/talus-fem"
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
text = tv.prm_set(text, "numerics/integration", mode)
_, out, _ = tv.run_tool(tool, text, work, "cantilever_" + mode)
print(out.strip().splitlines()[-1])
tv.check("converged" in out, "the run ended by the convergence criterion (quasi-static)")

E, nu, rho, g, l, b, h = 9e9, 0.0, 1000.0, 9.81, 8.0, 1.0, 1.0
q, I, G, As = rho * g * b * h, b * h**3 / 12, E / (2 * (1 + nu)), 5.0 / 6.0 * b * h


def w(x):
    return q * (x**4 - 4 * l * x**3 + 6 * l * l * x * x) / (24 * E * I) + q * (l * x - x * x / 2) / (G * As)


p = tv.read_csv(f"{work}/out/particles_final.csv")
X = [x - u for x, u in zip(p["pos_x"], p["u_x"])]
Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
k = min(range(len(X)), key=lambda i: ((X[i] - l) ** 2 + (Y[i] - 0.5 * h) ** 2, p["id"][i]))
ref, uy = w(X[k]), p["u_y"][k]
err = abs(-uy - ref) / ref
print(f"{mode}: tip point X = ({X[k]:.5f}, {Y[k]:.5f}), u_y = {uy:.6e} m, Timoshenko w(X) = {-ref:.6e} m "
      f"(w(l) = {-w(l):.6e} m)")
tv.check(err < tol, f"{mode}: tip deflection within {tol:.0%} of Timoshenko (error {err:.3e})")
# the deflection line along the beam axis (points nearest y = h/2 below it), x >= l/2
line = [i for i in range(len(X)) if abs(Y[i] - min(Y, key=lambda y: abs(y - 0.5 * h))) < 1e-12 and X[i] > l / 2]
worst = max(abs(-p["u_y"][i] - w(X[i])) / w(X[i]) for i in line)
tv.check(worst < tol, f"{mode}: deflection line for x > l/2 ({len(line)} points) within {tol:.0%} (worst {worst:.3e})")
s = tv.read_csv(f"{work}/out/series.csv")
tv.check(all(math.isfinite(v) for v in s["probe0_stress_xx"]), "probe stresses in series.csv")
tv.finish()
