"""Cantilever under self-weight: mesh convergence of FEM and MPM against the
Timoshenko deflection at the tip point (seed 001 §4.5.1, Fig. 4.4: quadratic rate).
Cells 32 x 4, 64 x 8, 128 x 16 (h = 0.25, 0.125, 0.0625 m); quasi-static by local
damping + convergence. Checks: FEM observed order log2(e_h / e_h/2) in [1.7, 2.3]
on both refinements; MPM error below 1 % on the finest grid and smaller than on the
coarsest. Label "verify" (about 4 minutes).
Usage: check_fem_cantilever_convergence.py TOOLS_DIR PRM WORKDIR
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
E, rho, g, l, b, h = 9e9, 1000.0, 9.81, 8.0, 1.0, 1.0
q, I, G, As = rho * g * b * h, b * h**3 / 12, E / 2, 5.0 / 6.0 * b * h


def w(x):
    return q * (x**4 - 4 * l * x**3 + 6 * l * l * x * x) / (24 * E * I) + q * (l * x - x * x / 2) / (G * As)


errors = {}
for mode in ("fem", "mpm"):
    for cells in ("32, 4", "64, 8", "128, 16"):
        tag = f"{mode}_{cells.replace(', ', 'x')}"
        text = tv.prm_set(open(prm_path).read(), "output/directory", tag)
        text = tv.prm_set(tv.prm_set(text, "grid/cells", cells), "numerics/integration", mode)
        _, out, _ = tv.run_tool(f"{tools}/talus-fem", text, work, tag)
        p = tv.read_csv(f"{work}/{tag}/particles_final.csv")
        X = [x - u for x, u in zip(p["pos_x"], p["u_x"])]
        Y = [y - u for y, u in zip(p["pos_y"], p["u_y"])]
        k = min(range(len(X)), key=lambda i: ((X[i] - l) ** 2 + (Y[i] - 0.5 * h) ** 2, p["id"][i]))
        e = abs(-p["u_y"][k] - w(X[k])) / w(X[k])
        errors.setdefault(mode, []).append(e)
        print(f"{tag}: tip point x = {X[k]:.5f}, u_y = {p['u_y'][k]:.6e}, Timoshenko {-w(X[k]):.6e}, error {e:.3e}")
fe = errors["fem"]
for i in range(2):
    order = math.log2(fe[i] / fe[i + 1])
    tv.check(1.7 <= order <= 2.3, f"fem: observed order {order:.2f} between h = {0.25 / 2**i} and {0.125 / 2**i} m")
me = errors["mpm"]
tv.check(me[-1] < 0.01 and me[-1] < me[0], f"mpm: errors {', '.join(f'{x:.2e}' for x in me)}: finest < 1e-2 and "
                                          "below the coarsest")
tv.finish()
