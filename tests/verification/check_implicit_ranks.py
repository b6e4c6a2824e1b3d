"""talus-implicit on 1 and 2 ranks (issue 13): the same scene must give the same
particle results to 1e-8 relative to the largest value of each field (the
Newton iterates differ by the round-off of distributed sums and of the direct
solve, and the iteration stops at its tolerance, so the runs are not bitwise).
Usage: check_implicit_ranks.py TOOLS_DIR PRM WORKDIR [entry=value ...]
"""
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
text = tv.prm_set_args(open(prm_path).read(), sys.argv[4:])
text = tv.prm_set(text, "output/final particles csv", "true")
for n in (1, 2):
    tv.run_tool(f"{tools}/talus-implicit", tv.prm_set(text, "output/directory", f"np{n}"), work, f"np{n}", np=n)


def by_origin(path):
    # rows in the order of the points' initial positions (pos - u): particle ids
    # follow the seeding order of the ranks' cells, which depends on the partition
    t = tv.read_csv(path)
    dim = 3 if "pos_z" in t else 2
    ax = "xyz"[:dim]
    key = [tuple(round(t["pos_" + c][i] - t["u_" + c][i], 9) for c in ax) for i in range(len(t["id"]))]
    order = sorted(range(len(key)), key=lambda i: key[i])
    return {c: [t[c][i] for i in order] for c in t}


a = by_origin(f"{work}/np1/particles_final.csv")
b = by_origin(f"{work}/np2/particles_final.csv")
tv.check(len(a["id"]) == len(b["id"]) > 0, f"same points on 1 and 2 ranks ({len(a['id'])}, {len(b['id'])})")
diff = tv.relative_differences(a, b, [c for c in a if c != "id"])
worst = max(diff, key=diff.get)
print("largest relative differences: " + ", ".join(f"{k} {d:.1e}" for k, d in sorted(diff.items(), key=lambda x: -x[1])[:4]))
tv.check(diff[worst] < 1e-8, f"1 vs 2 ranks: largest difference {diff[worst]:.2e} ({worst}) below 1e-8")
sa = tv.read_csv(f"{work}/np1/series.csv")
sb = tv.read_csv(f"{work}/np2/series.csv")
tv.check(sa["newton_iterations"] == sb["newton_iterations"], "the same Newton iteration counts per step")
tv.finish()
