"""Self-weight consolidation (1D Terzaghi with a triangular initial excess pore
pressure), semi-implicit two-phase double-point MPM (issue 14).

The column (H = 1 m, n = 0.3, rho_s = 2650, rho_w = 1000, E_oed = 10 MPa,
k = 1e-3 m/s) is released with p = 0, sigma' = 0 under gravity. With d = H - y
the depth, gamma' = (1-n)(rho_s - rho_w) g, zeta = d / H, M = pi (2m+1) / 2:
  excess pore pressure u = -(p + rho_w g d)   (compression positive)
  u(zeta, T) = sum_m 2 gamma' H (-1)^m / M^2 sin(M zeta) exp(-M^2 T),
  T = c_v t / H^2, c_v = k E_oed / (rho_w g)
(the Fourier series of u(zeta, 0) = gamma' H zeta; drained top, impermeable base).
Per T in {0.05, 0.1, 0.2, 0.5} one run to t = T H^2 / c_v with ~3e-4 s steps;
the relative L2 error over the water points sqrt(sum (u - u_an)^2 / sum u_an^2)
must be below TOL (argument, default 0.03: the 3 % of issue 14).
Usage: check_semi_consolidation.py TOOL PRM WORKDIR [TOL] [T,T,...] [quadratic bspline|linear]
"""
import math
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
tol = float(sys.argv[4]) if len(sys.argv) > 4 else 0.03
times = [float(x) for x in sys.argv[5].split(",")] if len(sys.argv) > 5 else [0.05, 0.1, 0.2, 0.5]
kernel = sys.argv[6] if len(sys.argv) > 6 else None
g, H, n, rs, rw, E, k = 9.81, 1.0, 0.3, 2650.0, 1000.0, 1e7, 1e-3
gamma = (1 - n) * (rs - rw) * g
cv = k * E / (rw * g)


def analytic(zeta, T):
    s = 0.0
    for m in range(200):
        M = math.pi * (2 * m + 1) / 2
        s += 2 * gamma * H * (-1) ** m / M ** 2 * math.sin(M * zeta) * math.exp(-M * M * T)
    return s


base = tv.prm_set(open(prm_path).read(), "output/directory", "out")
if kernel:
    base = tv.prm_set(base, "numerics/shape function", kernel)
for T in times:
    t_end = T * H * H / cv
    n_steps = max(1, round(t_end / 3e-4))
    text = tv.prm_set(base, "time/end time", repr(t_end))
    text = tv.prm_set(text, "time/time step", repr(t_end / n_steps))
    name = f"T{T}"
    tv.run_tool(tool, text, f"{work}/{name}", name)
    w = tv.read_csv(f"{work}/{name}/out/water_final.csv")
    num = den = 0.0
    worst = 0.0
    for p, y in zip(w["pore_pressure"], w["pos_y"]):
        d = H - y
        u = -(p + rw * g * d)
        ua = analytic(min(max(d / H, 0.0), 1.0), T)
        num += (u - ua) ** 2
        den += ua ** 2
        worst = max(worst, abs(u - ua) / (gamma * H))
    e = math.sqrt(num / den)
    print(f"T_v = {T}: t = {t_end:.4f} s, {n_steps} steps; relative L2 error of the excess pore pressure {e:.3e}, "
          f"max |u - u_an| / (gamma' H) = {worst:.3e}")
    tv.check(e < tol, f"T_v = {T}: relative L2 error {e:.2e} < {tol}")
tv.finish()
