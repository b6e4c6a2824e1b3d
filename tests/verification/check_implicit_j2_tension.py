"""J2 plane-strain tension test (seed 001 §5.4.2; issue 39 item 4) with talus-implicit,
u and u-p, compressible (nu = 0.3) and incompressible (nu = 0.499999).
parameter_files/implicit/j2_tension_plane_strain.prm: a plate W x H = 0.01 x 0.02 m,
h = 0.001 m, 3 x 3 points per cell, hyperelastic perfectly plastic J2 (E = 200 GPa,
sigma_Y = 200 MPa), bottom fixed, top nodes held in x and pulled in y to 1e-4 m in
20 static load steps (the thesis's figure-only geometry and material replaced by
these decisions, docs/implicit.md "J2 plane-strain tension test").
Signal: the nominal stress S = F / W, F the reaction of the top nodes
(prescribed_force_y of series.csv), against the top displacement d.
References:
  * the limit load of the perfectly plastic strip in plane strain:
    S_lim = 2 sigma_Y / sqrt(3) (uniform sigma_yy = 2k is admissible whatever the grips;
    a 45-degree band gives the same upper bound);
  * the elastic branch: S / (d / H) against the plane-strain modulus E / (1 - nu^2)
    of a strip free to contract (the grips stiffen it: printed, bounded by ELASTIC);
  * the thesis's Fig. 5.15 finding: the compressible and incompressible u-p curves
    agree.
Checks (each able to fail):
  * every run reaches d = 1e-4 m (exit 0) with Newton <= 25 iterations per step;
  * u-p, both nu: S at d = 1e-4 m within TOL of S_lim;
  * u-p: the two nu within TOL of each other at every step past 2 yield strains;
  * u-p, both nu, the first step (elastic): S / (d / H) within ELASTIC of E / (1 - nu^2)
    (above it: the grips hold the contraction);
  * u, nu = 0.499999 locks: S at d = 1e-4 m above (1 + LOCK) S_lim.
  * u, nu = 0.3 is further from S_lim at d = 1e-4 m than u-p (the thesis: u-p is the more
    accurate even in the compressible case).
Usage: check_implicit_j2_tension.py TOOLS_DIR PRM WORKDIR TOL ELASTIC LOCK [entry=value ...]
(the trailing settings apply to every run, e.g. time/time step=0.1)
"""
import math
import sys
import time

import talus_verify as tv

tools, prm_path, work = sys.argv[1], sys.argv[2], sys.argv[3]
tol, elastic_tol, lock = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
base = tv.prm_set_args(open(prm_path).read(), sys.argv[7:])
E, sy, W, H = 2e11, 2e8, 0.01, 0.02
s_lim = 2 * sy / math.sqrt(3)
curves = {}
for form in ("mixed up", "irreducible"):
    for nu in ("0.3", "0.499999"):
        name = f"{form.replace(' ', '')}_nu{nu}"
        text = tv.prm_set(base, "implicit/formulation", form)
        text = tv.prm_set(text, "material 0/j2 plasticity/poisson ratio", nu)
        text = tv.prm_set(text, "output/directory", name)
        start = time.time()
        tv.run_tool(f"{tools}/talus-implicit", text, work, name)
        wall = time.time() - start
        s = tv.read_csv(f"{work}/{name}/series.csv")
        steps = [i for i, st in enumerate(s["step"]) if st > 0]
        d = [1e-4 * s["time"][i] for i in steps]
        S = [s["prescribed_force_y"][i] / W for i in steps]
        its = [int(s["newton_iterations"][i]) for i in steps]
        curves[(form, nu)] = (d, S, its, wall)
        tv.check(abs(s["time"][-1] - 1.0) < 1e-9, f"{name}: reached d = 1e-4 m")
        tv.check(max(its) <= 25, f"{name}: Newton <= 25 iterations per step (largest {max(its)})")

print(f"S_lim = 2 sigma_Y / sqrt(3) = {s_lim / 1e6:.3f} MPa; yield strain sigma_Y / E = {sy / E:.1e}")
keys = list(curves)
print(f"{'d [m]':>9} " + " ".join(f"{k[0][:5] + ' nu ' + k[1]:>18}" for k in keys) + "   (S / S_lim)")
for i in range(len(curves[keys[0]][0])):
    print(f"{curves[keys[0]][0][i]:9.2e} " + " ".join(f"{curves[k][1][i] / s_lim:18.4f}" for k in keys))
for k in keys:
    d, S, its, wall = curves[k]
    print(f"{k[0]:>12} nu {k[1]:>8}: Newton mean {sum(its) / len(its):.1f}, largest {max(its)}, wall {wall:.1f} s")

for nu in ("0.3", "0.499999"):
    d, S, _, _ = curves[("mixed up", nu)]
    err = (S[-1] - s_lim) / s_lim
    tv.check(abs(err) < tol, f"u-p, nu = {nu}: S(1e-4 m) = {S[-1] / 1e6:.2f} MPa within {tol:.1%} of S_lim ({err:+.2%})")
    e_ps = E / (1 - float(nu) ** 2)
    ratio = S[0] / (d[0] / H) / e_ps - 1
    tv.check(0 <= ratio < elastic_tol, f"u-p, nu = {nu}: elastic slope {ratio:+.2%} from E / (1 - nu^2), in "
                                       f"[0, {elastic_tol:.0%})")
d, Sc, _, _ = curves[("mixed up", "0.3")]
_, Si, _, _ = curves[("mixed up", "0.499999")]
past = [i for i in range(len(d)) if d[i] / H > 2 * sy / E]
worst = max(abs(Sc[i] - Si[i]) / s_lim for i in past)
tv.check(worst < tol, f"u-p: compressible and incompressible curves within {tol:.1%} of S_lim past 2 yield strains "
                      f"({worst:.2%})")
S_u = curves[("irreducible", "0.499999")][1][-1]
S_c = curves[("irreducible", "0.3")][1][-1]
S_pc = curves[("mixed up", "0.3")][1][-1]
tv.check(abs(S_c - s_lim) > abs(S_pc - s_lim), f"nu = 0.3: u ({S_c / s_lim - 1:+.2%}) further from S_lim than u-p "
                                               f"({S_pc / s_lim - 1:+.2%})")
tv.check(S_u > (1 + lock) * s_lim, f"u, nu = 0.499999 locks: S(1e-4 m) = {S_u / s_lim:.3f} S_lim > {1 + lock:.2f} S_lim")
tv.finish()
