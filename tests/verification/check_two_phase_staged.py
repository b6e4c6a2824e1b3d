"""Staged 2-phase consolidation with the shared loads (issue 12 item 2).

Scene two_phase_staged_consolidation.prm: saturated elastic column H = 1 m
(E = 10 MPa, nu = 0.3, n = 0.3, k = 1e-3 m/s), stage 0 gravity with local damping
and mass scaling ended by the quasi-static criterion, stage 1 a top traction
q = 10 kPa (loads/traction, ramped over 20 ms) ended by the same criterion once
drained. Three runs of the same scene that differ only in the duration of
stage 1: A (1e-9 s: the state at the end of stage 0), B (0.03 s: right after
loading), C (the full scene).
Checks:
  * C: series.csv 'stage' goes 0 -> 1 once; both stages end by convergence;
  * C: settlement of the top point at the end of stage 0 within 1 % of
    gamma' (H y - y^2/2) / E_oed, gamma' = (1 - n)(rho_S - rho_L) g;
  * C: settlement of stage 1 (final, drained) within 2 % of q y / E_oed,
    E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu)), y the initial height of the point;
  * A: pore pressure hydrostatic, |p - rho_L g (H - Y)| < 2 % of rho_L g H;
  * B (undrained response): excess pore pressure p_B - p_A of the points in the
    lower quarter of the column (drainage only through the top: the Terzaghi
    series gives >= 0.998 q there at T_v = c_v 0.02 s / H^2 = 0.027, counted from
    the middle of the ramp) within 2 % of B q, B = (K_L/n) / (K_L/n + E_oed)
    (Skempton's coefficient for 1-D loading, 0.998); and over the whole column the
    RMS of (p_B - p_A)/q - B p_series(z, T_v)/q below 3 % (the early dissipation
    near the top follows Terzaghi; the ramp makes the step-load series a little
    off within a few cells of the top);
  * C (dissipation): |p_C - p_A| < 2 % of q at every point.
Usage: check_two_phase_staged.py TOOL PRM WORKDIR
"""
import math
import sys
import time

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
E, nu, n, rho_S, rho_L, K_L, g, H, q = 1e7, 0.3, 0.3, 2650.0, 1000.0, 2.2e9, 9.81, 1.0, 1e4
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
gamma_b = (1 - n) * (rho_S - rho_L) * g
B = (K_L / n) / (K_L / n + E_oed)
y = 0.99375  # initial height of the probe (top row of points)
base = open(prm_path).read()
runs = {}
for name, duration in (("A", "1e-9"), ("B", "0.03"), ("C", None)):
    text = tv.prm_set(base, "output/directory", f"out_{name}")
    if duration:
        text = tv.prm_set(text, "stage 1/duration", duration)
    t0 = time.time()
    tv.run_tool(tool, text, work, f"run_{name}")
    print(f"run {name}: {time.time() - t0:.1f} s wall")
    p = tv.read_csv(f"{work}/out_{name}/particles_final.csv")
    runs[name] = {int(i): (yy - uu, pp) for i, yy, uu, pp in zip(p["id"], p["pos_y"], p["u_y"], p["pore_pressure"])}

s = tv.read_csv(f"{work}/out_C/series.csv")
st, t, u = s["stage"], s["time"], s["probe0_uy"]
switches = [i for i in range(1, len(st)) if st[i] != st[i - 1]]
tv.check(len(switches) == 1 and st[0] == 0 and st[-1] == 1, f"one stage switch 0 -> 1 (switch rows {switches})")
i1 = switches[0]
t_switch = t[i1 - 1]
print(f"stage 0 ended at t = {t_switch:.4f} s, stage 1 at t = {t[-1]:.4f} s ({t[-1] - t_switch:.4f} s of consolidation)")
tv.check(t_switch < 9.99, f"stage 0 ended by convergence before its 10 s (t = {t_switch:.4f} s)")
tv.check(t[-1] - t_switch < 9.99, f"stage 1 ended by convergence before its 10 s ({t[-1] - t_switch:.4f} s)")

u0 = u[i1 - 1]
u_g = -gamma_b * (H * y - y * y / 2) / E_oed
e0 = abs(u0 - u_g) / abs(u_g)
tv.check(e0 < 0.01, f"settlement at the end of stage 0: {u0:.6e} m vs {u_g:.6e} m (error {100 * e0:.3f} % < 1 %)")
du = u[-1] - u0
ref = -q * y / E_oed
e1 = abs(du - ref) / abs(ref)
tv.check(e1 < 0.02, f"consolidation settlement of stage 1: {du:.6e} m vs q y / E_oed = {ref:.6e} m "
                    f"(error {100 * e1:.3f} % < 2 %)")

A, Bq, C = runs["A"], runs["B"], runs["C"]
hyd = max(abs(p - rho_L * g * (H - Y)) for Y, p in A.values()) / (rho_L * g * H)
tv.check(hyd < 0.02, f"end of stage 0: pore pressure hydrostatic within {100 * hyd:.3f} % of rho_L g H (< 2 %)")
c_v = 1e-3 * E_oed / (rho_L * g)
Tv = c_v * 0.02 / H ** 2


def series(z):
    return sum(4 / ((2 * i + 1) * math.pi) * math.sin((2 * i + 1) * math.pi * z / (2 * H))
               * math.exp(-(2 * i + 1) ** 2 * math.pi ** 2 * Tv / 4) for i in range(200))


excess = sorted((Y, Bq[i][1] - A[i][1]) for i, (Y, _) in A.items())
low = [dp for Y, dp in excess if Y < H / 4]
worst = max(abs(dp / (B * q) - 1) for dp in low)
print(f"right after loading (0.03 s, T_v = {Tv:.4f} from the middle of the ramp): excess pore pressure of the "
      f"lower quarter / (B q) {min(low) / (B * q):.4f} .. {max(low) / (B * q):.4f} ({len(low)} points, B = {B:.5f})")
for Y, dp in excess[::16]:
    print(f"   Y = {Y:.4f} m: excess p / q = {dp / q:.4f} (B x series {B * series(H - Y):.4f})")
rms = math.sqrt(sum((dp / q - B * series(H - Y)) ** 2 for Y, dp in excess) / len(excess))
tv.check(worst < 0.02, f"undrained response: excess pore pressure of the lower quarter within {100 * worst:.2f} % "
                       f"of B q (< 2 %)")
tv.check(rms < 0.03, f"early dissipation: RMS of excess p / q - B series = {100 * rms:.2f} % (< 3 %)")
left = max(abs(C[i][1] - A[i][1]) for i in A) / q
tv.check(left < 0.02, f"dissipated: largest |p_end - p_stage0| = {100 * left:.3f} % of q (< 2 %)")
tv.finish()
