"""Load balancing with strain smoothing and contact (issue 15, talus-explicit) — verification.

The corner collapse of load_balance_collapse.prm (one rank holds nearly all
points when partitioned by cells), shortened to 0.06 s, rebalanced at every
check (threshold 1.0, every 20 steps), once per feature:
  * strain smoothing = cell and = nodal (per-cell values and a nodal vector);
  * contact: the column as two bodies (lower and upper half) with a friction
    pair (per-body nodal fields and the contact node list).
For each: 2 ranks rebalancing at every check agree with 1 rank to 1e-10
relative (particles_final.csv, >= 5 rebalances), and a restart from a
checkpoint between rebalances continues bitwise identically on 2 ranks
(particles_final.csv byte for byte, rebalancing again after the restart).
  * fem: integration = fem (Gauss points of the covered cells, fixed mesh;
    the vertex table is rebuilt after a repartition).
UL-FEM stays refused with load balancing (exit 2 naming the entry).
Usage: check_load_balance_features.py TOOL PRM WORKDIR
"""
import re
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
base = tv.prm_set(base, "time/end time", "0.06")
base = tv.prm_set(base, "load balancing/imbalance threshold", "1.0")

contact = tv.prm_set(base, "number of bodies", "2")
contact = tv.prm_set(contact, "body 0/upper corner", "0.0905, 0.0543")
contact = contact + tv.box_body(1, "top", "0, 0.0543", "0.0905, 0.1086")
contact = tv.prm_set(contact, "contact/pairs", "0, 1, 0.3, 0")

cases = {
    "smoothing_cell": tv.prm_set(base, "numerics/strain smoothing", "cell"),
    "smoothing_nodal": tv.prm_set(base, "numerics/strain smoothing", "nodal"),
    "contact": contact,
    # FEM on the fixed mesh: Gauss points in the cells the column covers, which
    # never change cell; the vertex table is rebuilt after a repartition
    "fem": tv.prm_set(base, "numerics/integration", "fem"),
}


def particles(out):
    return tv.read_csv(f"{work}/{out}/particles_final.csv")


for name, text in cases.items():
    tv.run_tool(tool, tv.prm_set(text, "output/directory", f"out_{name}_np1"), work, f"{name}_np1")
    _, log2, _ = tv.run_tool(tool, tv.prm_set(text, "output/directory", f"out_{name}_np2"), work,
                             f"{name}_np2", np=2)
    n_rebalances = int(re.search(r"rebalances (\d+)", log2).group(1))
    tv.check(n_rebalances >= 5, f"{name}: rebalances during the 2-rank run: {n_rebalances} >= 5")
    a, b = particles(f"out_{name}_np1"), particles(f"out_{name}_np2")
    tv.check(a["id"] == b["id"], f"{name}: same particle ids ({len(a['id'])} points)")
    worst = max(tv.relative_differences(a, b).values())
    tv.check(worst <= 1e-10, f"{name}: 1 rank vs 2 ranks rebalancing at every check agree to 1e-10 relative "
                             f"(worst {worst:.2e})")

    tv.check_restart_across_rebalances(tool, text, work, name, interval=0.03, min_step=100, min_rebalances=2)

for mode in ("ul-fem",):
    rc, out, err = tv.run_tool(tool, tv.prm_set(base, "numerics/integration", mode), work, f"refused_{mode}",
                               expect_rc=2)
    tv.check("load balancing/interval" in out + err, f"load balancing with integration = {mode} is refused "
                                                     f"naming the entry")
tv.finish()
