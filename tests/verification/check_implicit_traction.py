"""Elastic block under a uniform top traction with talus-implicit (issue 13: the
traction point forces of loads/point_forces in the implicit residual).
Oedometric, small strain: below the top cell every point must have
u_y = -q Y / E_oed (Y: initial height; E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu)))
and sigma_yy = -q, within TOL relative to the top settlement q H / E_oed (resp.
q); the finite-strain model differs from the linear answer by O(q / E) = 1e-4.
The top cell is left out: the traction acts at the points of the top layer
(Y = H - h/4), not on the surface (seed 000 Eq. 5.3), so 1/4 of it goes to the
node row below and the top cell carries 3/4 q (its points show sigma_yy =
-0.75 q; checked too). The total load is checked through the reaction: the mean
sigma_yy below the top cell is -q. Run on 1 and 2 ranks; the two runs agree to
1e-8 (points matched by initial position).
Usage: check_implicit_traction.py TOOLS_DIR PRM WORKDIR TOL
"""
import sys

import talus_verify as tv

tools, prm_path, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
E, nu, q, H, h = 1e7, 0.3, 1000.0, 1.0, 0.125
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
settlement = q * H / E_oed
text = tv.prm_set(open(prm_path).read(), "output/final particles csv", "true")
results = {}
for n in (1, 2):
    tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(text, "output/directory", f"np{n}"), work, f"np{n}", np=n)
    t = tv.read_csv(f"{work}/np{n}/particles_final.csv")
    Y = [t["pos_y"][i] - t["u_y"][i] for i in range(len(t["id"]))]
    below = [i for i in range(len(Y)) if Y[i] < H - h]
    top_cell = [i for i in range(len(Y)) if Y[i] > H - h]
    err_u = max(abs(t["u_y"][i] + q * Y[i] / E_oed) for i in below) / settlement
    err_s = max(abs(t["stress_yy"][i] + q) for i in below) / q
    err_top = max(abs(t["stress_yy"][i] + 0.75 * q) for i in top_cell) / q
    top = max(t["pos_y"][i] - t["u_y"][i] for i in range(len(t["id"])))
    u_top = sum(t["u_y"][i] for i in range(len(t["id"])) if abs(t["pos_y"][i] - t["u_y"][i] - top) < 1e-9)
    u_top /= sum(1 for i in range(len(t["id"])) if abs(t["pos_y"][i] - t["u_y"][i] - top) < 1e-9)
    print(f"{n} rank(s): {len(t['id'])} points; u_y of the top row {u_top:.6e} m vs {-q * top / E_oed:.6e}; "
          f"below the top cell: largest error of u_y {err_u:.2e} (of q H / E_oed = {settlement:.4e} m), of sigma_yy "
          f"{err_s:.2e} (of q); top cell sigma_yy vs -0.75 q: {err_top:.2e}")
    tv.check(err_u < tol, f"{n} rank(s): u_y = -q Y / E_oed at every point within {tol} ({err_u:.2e})")
    tv.check(err_s < tol, f"{n} rank(s): sigma_yy = -q at every point within {tol} ({err_s:.2e})")
    tv.check(err_top < tol, f"{n} rank(s): sigma_yy = -0.75 q in the top cell within {tol} ({err_top:.2e})")
    s = tv.read_csv(f"{work}/np{n}/series.csv")
    its = [k for k, st in zip(s["newton_iterations"], s["step"]) if st > 0]
    tv.check(its and max(its) <= 4, f"{n} rank(s): at most 4 Newton iterations per load step ({its})")
    results[n] = t


def by_origin(t):
    key = [(round(t["pos_x"][i] - t["u_x"][i], 9), round(t["pos_y"][i] - t["u_y"][i], 9)) for i in range(len(t["id"]))]
    order = sorted(range(len(key)), key=lambda i: key[i])
    return {c: [t[c][i] for i in order] for c in t}


diff = tv.relative_differences(by_origin(results[1]), by_origin(results[2]), ["u_y", "stress_xx", "stress_yy"])
worst = max(diff, key=diff.get)
tv.check(diff[worst] < 1e-8, f"1 vs 2 ranks: largest difference {diff[worst]:.2e} ({worst}) below 1e-8")
tv.finish()
