"""Staged static analysis with talus-implicit (issue 13: stages), on the oedometric
block of parameter_files/implicit/block_staged.prm, run on 2 ranks.
Stage 0 ramps the self-weight in, stage 1 keeps it and ramps a stage traction q in.
Checked (small strain; E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu))):
  * series.csv: the stage column is 0 for the rows of stage 0 and 1 after; the
    load_factor column ramps 0.5, 1 in stage 0 and 0.5, 1 in stage 1 (its own
    ramp over its own time step);
  * after stage 0 (its last series row): the mean vertical displacement of the
    points (centre of mass) vs the mean of -rho g (H Y - Y^2 / 2) / E_oed over the
    points' initial heights Y, within TOL;
  * what stage 1 added to the centre of mass vs the mean of -q Y / E_oed, within
    TOL (the gravity part cancels: this fails if stage 1 loses the weight or the
    traction);
  * at the end, below the top cell (the traction acts at the top layer of points,
    check_implicit_traction.py): every point's u_y vs the sum of both, within TOL
    of the total settlement.
Usage: check_implicit_staged.py TOOLS_DIR PRM WORKDIR TOL
"""
import sys

import talus_verify as tv

tools, prm_path, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
E, nu, rho, g, q, H, h = 1e7, 0.3, 1000.0, 10.0, 1000.0, 1.0, 0.125
E_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def u_gravity(Y):
    return -rho * g * (H * Y - 0.5 * Y * Y) / E_oed


def u_traction(Y):
    return -q * Y / E_oed


text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
tv.run_tool(f"{tools}/talus-implicit", text, work, "staged", np=2)
s = tv.read_csv(f"{work}/out/series.csv")
p = tv.read_csv(f"{work}/out/particles_final.csv")
n = len(p["id"])
Y = [p["pos_y"][i] - p["u_y"][i] for i in range(n)]

stages = [int(v) for v in s["stage"]]
rows0 = [i for i in range(len(stages)) if stages[i] == 0 and s["step"][i] > 0]
rows1 = [i for i in range(len(stages)) if stages[i] == 1]
print("series: stage", stages, "time", s["time"], "load_factor", s["load_factor"])
tv.check(len(rows0) == 2 and len(rows1) == 2, f"two load steps in each stage ({len(rows0)}, {len(rows1)})")
ramp = [s["load_factor"][i] for i in rows0 + rows1]
tv.check(max(abs(a - b) for a, b in zip(ramp, [0.5, 1, 0.5, 1])) < 1e-12,
         f"load factor 0.5, 1 in each stage ({ramp})")

y0 = s["centre_of_mass_y"][0]
mean_u0 = s["centre_of_mass_y"][rows0[-1]] - y0
mean_u1 = s["centre_of_mass_y"][rows1[-1]] - s["centre_of_mass_y"][rows0[-1]]
exp_u0 = sum(u_gravity(y) for y in Y) / n
exp_u1 = sum(u_traction(y) for y in Y) / n
e0, e1 = abs(mean_u0 / exp_u0 - 1), abs(mean_u1 / exp_u1 - 1)
print(f"stage 0: mean u_y {mean_u0:.6e} m vs {exp_u0:.6e} (error {e0:.2e}); "
      f"stage 1 added {mean_u1:.6e} m vs {exp_u1:.6e} (error {e1:.2e})")
tv.check(e0 < tol, f"stage 0 (self-weight) settlement within {tol} ({e0:.2e})")
tv.check(e1 < tol, f"stage 1 (traction, weight kept) added settlement within {tol} ({e1:.2e})")

total = abs(u_gravity(H) + u_traction(H))
below = [i for i in range(n) if Y[i] < H - h]
err = max(abs(p["u_y"][i] - u_gravity(Y[i]) - u_traction(Y[i])) for i in below) / total
print(f"end: {n} points, largest error of u_y below the top cell {err:.2e} of the total settlement {total:.4e} m")
tv.check(err < tol, f"final u_y = self-weight + traction at every point below the top cell within {tol} ({err:.2e})")
tv.finish()
