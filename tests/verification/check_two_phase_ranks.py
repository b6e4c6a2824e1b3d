"""2-phase step on 1 and 2 ranks (issue 5): the Terzaghi column (0.1 m wide, 0.05 s)
must give the same pore pressures, effective stresses, velocities of both phases
and positions on 1 and 2 MPI ranks (ghost exchange of the liquid vectors), to 1e-10
relative to the largest value of each field.
Usage: check_two_phase_ranks.py TOOL PRM WORKDIR [entry=value ...]
  entry=value: .prm settings (e.g. the B-spline column of check_terzaghi.py's bspline mode);
  without them the 0.1 m column has 640 points.
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
settings = sys.argv[4:]
text = tv.prm_set_args(tv.prm_set(open(prm_path).read(), "time/end time", "0.05"), settings)
for n in (1, 2):
    tv.run_tool(tool, tv.prm_set(text, "output/directory", f"np{n}"), work, f"np{n}", np=n)
a = tv.read_csv(f"{work}/np1/particles_final.csv")
b = tv.read_csv(f"{work}/np2/particles_final.csv")
n_expected = len(a["id"]) if settings else 640
tv.check(len(a["id"]) == len(b["id"]) == n_expected and n_expected > 0,
         f"{n_expected} points on 1 and 2 ranks ({len(a['id'])}, {len(b['id'])})")
diff = tv.relative_differences(a, b, ("pore_pressure", "stress_yy", "v_y", "liquid_velocity_y", "pos_y", "porosity"))
for k, d in diff.items():
    tv.check(d < 1e-10, f"{k}: 1 vs 2 ranks differ by {d:.2e} (relative to the largest value)")
tv.finish()
