"""Point loads in every family (issue 37, 'loads/point load k'): the block of
parameter_files/verification/point_load/block.inc (an elastic block on a rigid
base held still by a displacement-controlled rough plate, roller sides, a
vertical point load P = -100 N/m at the middle of its top face, ramped over
1 s, no gravity) solved by talus-implicit (static), talus-explicit (to
quasi-static rest with local damping) and talus-semi-implicit (saturated, to
the end of consolidation). In static equilibrium the base reaction is the
point load: plate_0_force = -P_y = +100 N. Checks:
  - each family's final plate_0_force: implicit within 1e-8 relative,
    explicit and semi-implicit within TOL (1 %);
  - each family's log names the chosen point: the top point of initial
    position (0.46875, 0.96875) (a tie with (0.53125, 0.96875): the smaller
    initial position), 0.0441942 m from the position;
  - talus-implicit on 2 ranks chooses the same point and its results agree
    with 1 rank to 1e-10: series.csv (every column but the Newton residuals
    and their orders, figures of round-off) and particles_final.csv (by
    initial position), each relative to the largest value of its column.
Usage: check_point_load_families.py TOOLS_DIR PRM_DIR WORKDIR TOL
"""
import os
import re
import sys

import talus_verify as tv

tools, prm_dir, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
P = 100.0
scene = os.path.join(prm_dir, "verification", "point_load")
os.makedirs(work, exist_ok=True)
local_inc = os.path.join(work, "block.inc")
if not os.path.exists(local_inc):
    os.symlink(os.path.join(scene, "block.inc"), local_inc)

line = re.compile(r"loads/point load 0: on the material point (\d+) at \(([^)]*)\) \(initial position\), (\S+) m")


def chosen(stdout, label):
    m = line.search(stdout)
    tv.check(m is not None, f"{label}: the log names the point that carries 'loads/point load 0'")
    if m is None:
        return None
    x = [float(v) for v in m.group(2).split(",")]
    r = float(m.group(3))
    ok = abs(x[0] - 0.46875) < 1e-12 and abs(x[1] - 0.96875) < 1e-12 and abs(r - 0.03125 * 2 ** 0.5) < 1e-5
    tv.check(ok, f"{label}: chosen point {m.group(1)} at ({m.group(2)}), {r} m away "
                 "(expected (0.46875, 0.96875), 0.0441942 m: the tie goes to the smaller x)")
    return m.group(2)


results = {}
for tool, name, np, limit in [("talus-implicit", "block_implicit.prm", 1, 1e-8),
                              ("talus-implicit", "block_implicit.prm", 2, 1e-8),
                              ("talus-explicit", "block_explicit.prm", 1, tol),
                              ("talus-semi-implicit", "block_semi_implicit.prm", 1, tol)]:
    label = f"{tool} ({np} rank{'s' if np > 1 else ''})"
    text = open(os.path.join(scene, name)).read()
    tv.check("include block.inc" in text, f"{name} includes the shared fragment block.inc")
    out = os.path.abspath(os.path.join(work, f"{tool}_{np}"))
    _, stdout, _ = tv.run_tool(os.path.join(tools, tool), tv.prm_set(text, "output/directory", out), work,
                               f"{tool}_{np}", np=np)
    ser = tv.read_csv(os.path.join(out, "series.csv"))
    f, t = ser["plate_0_force"][-1], ser["time"][-1]
    err = abs(f - P) / P
    print(f"{label}: t = {t:g} s, base reaction plate_0_force = {f:.10e} N vs point load {P:g} N: "
          f"relative error {err:.3e}")
    tv.check(err < limit, f"{label}: the base reaction equals the point load within {limit:g} ({err:.3e})")
    results[(tool, np)] = (chosen(stdout, label), ser, out)

(c1, s1, o1), (c2, s2, o2) = results[("talus-implicit", 1)], results[("talus-implicit", 2)]
tv.check(c1 == c2, f"talus-implicit: 1 and 2 ranks choose the same point ({c1} / {c2})")
cols = [c for c in s1 if isinstance(s1[c][0], float) and not c.startswith("residual_") and not c.endswith("_order")]
tv.check(all(len(s1[c]) == len(s2[c]) for c in cols), "talus-implicit: series.csv has as many rows on 2 ranks")
diff = tv.relative_differences(s1, s2, cols)


def by_origin(t):
    """Point rows in the order of their initial positions (pos - u): ids follow the seeding
    order of the ranks' cells."""
    key = sorted(range(len(t["id"])), key=lambda i: (round(t["pos_y"][i] - t["u_y"][i], 9),
                                                     round(t["pos_x"][i] - t["u_x"][i], 9)))
    return {c: [t[c][i] for i in key] for c in t}


p1, p2 = (by_origin(tv.read_csv(os.path.join(o, "particles_final.csv"))) for o in (o1, o2))
for n, p in ((1, p1), (2, p2)):
    carriers = [i for i, f in enumerate(p["point_force_0_y"]) if f != 0.0 or p["point_force_0_x"][i] != 0.0]
    X = [(p["pos_x"][i] - p["u_x"][i], p["pos_y"][i] - p["u_y"][i]) for i in carriers]
    tv.check(len(carriers) == 1 and p["point_force_0_y"][carriers[0]] == -P and abs(X[0][0] - 0.46875) < 1e-9
             and abs(X[0][1] - 0.96875) < 1e-9,
             f"talus-implicit ({n} rank(s)): exactly one point carries the whole force (0, -100), the chosen one "
             f"({len(carriers)} point(s), at {X})")
tv.check(len(p1["pos_x"]) == len(p2["pos_x"]), "talus-implicit: as many points on 2 ranks")
diff.update({"particles " + c: d for c, d in tv.relative_differences(
    p1, p2, [c for c in p1 if c not in ("id", "rank") and isinstance(p1[c][0], float)]).items()})
worst = max(diff, key=diff.get)
print(f"talus-implicit: 1 vs 2 ranks, largest relative difference {diff[worst]:.3e} ({worst})")
tv.check(diff[worst] < 1e-10, f"talus-implicit: 1 and 2 ranks agree to 1e-10 ({diff[worst]:.3e}, {worst})")
tv.finish()
