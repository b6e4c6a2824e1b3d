"""Cook's membrane, mixed u-p without the pressure stabilisation: the "UP No Stab"
column of seed 001 Table 5.1 (issue 39 item 4), beside the stabilised u-p.
The scene of check_implicit_cooks.py (parameter_files/implicit/cooks_membrane.prm:
Neo-Hookean with the split energy, E = 70, nu = 0.33 and 0.499999, plane strain,
static, one load step, n cells along the clamped width, 2 x 2 points per cell)
with 'implicit/stabilisation factor' = 0 (no PPP term: K_pp = -M / K only) and = 1
(the default). u_y(A) as in check_implicit_cooks.py (tv.cooks_corner_uy).
The pressure oscillation is measured on the point pressures (column 'pressure')
by tv.zigzag_index (RMS of the sign-changing neighbour differences over the
range; 0 for a smooth field) and by the range [min, max] (printed).
Checks (each able to fail):
  * every run ends (exit 0) with Newton <= 8 iterations;
  * at every n: the unstabilised u_y(A) below the stabilised one (the thesis's
    ordering in every row of Table 5.1);
  * nu = 0.499999, every n >= 8: the unstabilised pressure zigzag at least ZIG x
    the stabilised one (the oscillation the thesis reports, Fig. 5.4a);
  * nu = 0.499999, finest n: the unstabilised u_y(A) above 0.8 x 0.275 (it does
    not lock, the thesis's finding);
  * at the finest n: the unstabilised u_y(A) within TOL of the thesis's UP No Stab
    value at that n (both nu).
Usage: check_implicit_cooks_nostab.py TOOLS_DIR PRM WORKDIR TOL ZIG N1 [N2 ...]
"""
import math
import sys

import talus_verify as tv

tools, prm_path, work, tol, zig_min = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
ns = [int(n) for n in sys.argv[6:]]
base = open(prm_path).read()
refs = {"0.33": 0.323, "0.499999": 0.275}
thesis = tv.COOKS_TABLE_5_1
results = {}
for nu in ("0.33", "0.499999"):
    for alpha in ("0", "1"):
        for n in ns:
            h = 48.0 / n
            text = tv.cooks_membrane_prm(base, n, nu)
            text = tv.prm_set(text, "implicit/formulation", "mixed up")
            text = tv.prm_set(text, "implicit/stabilisation factor", alpha)
            name = f"nu{nu}_alpha{alpha}_n{n}"
            text = tv.prm_set(text, "output/directory", name)
            tv.run_tool(f"{tools}/talus-implicit", text, work, name)
            t = tv.read_csv(f"{work}/{name}/particles_final.csv")
            uA, npts = tv.cooks_corner_uy(t)
            X = [t["pos_x"][i] - t["u_x"][i] for i in range(npts)]
            Y = [t["pos_y"][i] - t["u_y"][i] for i in range(npts)]
            zig = tv.zigzag_index(X, Y, t["pressure"], h)
            s = tv.read_csv(f"{work}/{name}/series.csv")
            its = int(s["newton_iterations"][-1])
            results[(nu, alpha, n)] = (uA, npts, its, zig, min(t["pressure"]), max(t["pressure"]))
            tv.check(its <= 8, f"{name}: Newton converged in {its} <= 8 iterations")

for nu in ("0.33", "0.499999"):
    print(f"\nnu = {nu} (reference {refs[nu]}): u_y(A), u-p without (alpha 0) and with (alpha 1) stabilisation")
    print(f"{'n':>3} {'points':>6} {'no stab':>8} {'thesis':>7} {'diff':>7} {'zigzag':>7} {'p range':>18} | "
          f"{'stab':>7} {'thesis':>7} {'diff':>7} {'zigzag':>7} {'p range':>18}")
    for n in ns:
        u0, npts, _, z0, lo0, hi0 = results[(nu, "0", n)]
        u1, _, _, z1, lo1, hi1 = results[(nu, "1", n)]
        th = thesis[nu].get(n, (math.nan, math.nan, math.nan))
        print(f"{n:>3} {npts:>6} {u0:8.4f} {th[1]:7.4f} {(u0 - th[1]) / th[1]:+7.1%} {z0:7.4f} "
              f"[{lo0:7.3f}, {hi0:7.3f}] | {u1:7.4f} {th[2]:7.4f} {(u1 - th[2]) / th[2]:+7.1%} {z1:7.4f} "
              f"[{lo1:7.3f}, {hi1:7.3f}]")

for nu in ("0.33", "0.499999"):
    for n in ns:
        u0, u1 = results[(nu, "0", n)][0], results[(nu, "1", n)][0]
        tv.check(u0 < u1, f"nu = {nu}, n = {n}: no stab {u0:.4f} below stab {u1:.4f} (Table 5.1's ordering)")
for n in ns:
    if n >= 8:
        z0, z1 = results[("0.499999", "0", n)][3], results[("0.499999", "1", n)][3]
        tv.check(z0 >= zig_min * z1, f"nu = 0.499999, n = {n}: pressure zigzag no stab {z0:.4f} >= {zig_min} x "
                                     f"stab {z1:.4f}")
fine = ns[-1]
u0 = results[("0.499999", "0", fine)][0]
tv.check(u0 > 0.8 * refs["0.499999"], f"nu = 0.499999, n = {fine}: no stab does not lock ({u0:.4f} > "
                                      f"{0.8 * refs['0.499999']:.4f})")
for nu in ("0.33", "0.499999"):
    u0 = results[(nu, "0", fine)][0]
    th = thesis[nu][fine][1]
    err = abs(u0 - th) / th
    tv.check(err < tol, f"nu = {nu}, n = {fine}: no stab u_y(A) = {u0:.4f} within {tol:.1%} of the thesis's "
                        f"UP No Stab {th} ({err:.2%})")
tv.finish()
