"""Load balancing by material points (issue 15) — verification.

The scene (load_balance_collapse.prm) is a column collapsing in the corner of a
wide grid: partitioned by cells, one rank holds nearly all points. Checks:
  1. partitioned by points from the start: the initial imbalance (max/mean points
     per rank) printed in the log is above 1.5 before and below the threshold
     (1.05) after the first rebalance, and the imbalance column of series.csv
     stays below 1.25 over the run with rebalancing every 20 steps;
  2. 2 ranks rebalancing every 20 steps whenever the imbalance exceeds 1.0 (so
     at nearly every check: >= 20 rebalances) give the same particle results as
     1 rank to 1e-10 relative (undamped run);
  3. a checkpoint taken after rebalances, restarted on 2 ranks, continues
     bitwise identically (particles_final.csv byte for byte) through further
     rebalances;
  4. load balancing together with a feature whose grid data a repartition does
     not carry yet (UL-FEM integration) is refused with exit 2 naming the entry;
  5. points crossing the rank boundary (translating_bar.prm on 2 ranks, no load
     balancing) are sent to their new owner point to point: no collective full
     sort in the whole run (the log's count), points did move to the other
     rank, and the particle results equal the 1-rank run to 1e-12 relative;
  6. the 2-phase step with load balancing: the corner column saturated (coupled
     pore liquid, porosity 0.4, k = 1e-3 m/s, liquid bulk modulus 2.2e7 Pa so that
     the test stays short), 0.02 s on 2 ranks rebalancing at every check (every 20
     steps) against 1 rank: particle results, pore pressures and liquid
     velocities included, agree to 1e-10 relative, with >= 20 rebalances.
Usage: check_load_balance.py TOOL PRM WORKDIR
"""
import re
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()


def particles(out):
    return tv.read_csv(f"{work}/{out}/particles_final.csv")


def worst_difference(a, b):
    tv.check(a["id"] == b["id"], f"same particle ids ({len(a['id'])} points)")
    return max(tv.relative_differences(a, b).values())


# 1. the corner scene on 2 ranks with the .prm's settings
text = tv.prm_set(base, "output/directory", "out_balanced")
_, log, _ = tv.run_tool(tool, text, work, "balanced", np=2)
m = re.search(r"load balancing: points per rank max/mean ([\d.]+) -> ([\d.]+)", log)
tv.check(m is not None, "the initial rebalance is reported in the log")
before, after = float(m.group(1)), float(m.group(2))
tv.check(before > 1.5, f"partitioned by cells the points sit on one rank: imbalance {before:.3f} > 1.5")
tv.check(after < 1.05, f"after the initial rebalance: imbalance {after:.4f} < threshold 1.05")
s = tv.read_csv(f"{work}/out_balanced/series.csv")
tv.check("imbalance" in s, "series.csv has the imbalance column")
tv.check(max(s["imbalance"]) < 1.25, f"imbalance over the run at most {max(s['imbalance']):.4f} < 1.25 "
         f"(rebalanced when above 1.05 at the checks every 20 steps)")

# 2. 1 vs 2 ranks with a rebalance at nearly every check
eager = tv.prm_set(base, "load balancing/imbalance threshold", "1.0")
tv.run_tool(tool, tv.prm_set(eager, "output/directory", "out_np1"), work, "np1")
_, log2, _ = tv.run_tool(tool, tv.prm_set(eager, "output/directory", "out_np2"), work, "np2", np=2)
n_rebalances = int(re.search(r"rebalances (\d+)", log2).group(1))
tv.check(n_rebalances >= 20, f"rebalances during the 2-rank run: {n_rebalances} >= 20")
worst = worst_difference(particles("out_np1"), particles("out_np2"))
tv.check(worst <= 1e-10, f"1 rank vs 2 ranks rebalancing every 20 steps agree to 1e-10 relative (worst {worst:.2e})")

# 3. restart across rebalances: bitwise on 2 ranks
tv.check_restart_across_rebalances(tool, eager, work, "eager", interval=0.1, min_step=500, min_rebalances=5)

# 4. refused combination
rc, out, err = tv.run_tool(tool, tv.prm_set(base, "numerics/integration", "ul-fem"), work, "refused", expect_rc=2)
tv.check("load balancing/interval" in out + err, "load balancing with UL-FEM integration is refused naming the entry")

# 5. points crossing ranks every few steps: no full sort
import os
bar = open(os.path.join(os.path.dirname(prm_path), "translating_bar.prm")).read()
bar = tv.prm_set(bar, "output/final particles csv", "true")
tv.run_tool(tool, tv.prm_set(bar, "output/directory", "out_bar_np1"), work, "bar_np1")
_, logb, _ = tv.run_tool(tool, tv.prm_set(bar, "output/directory", "out_bar_np2"), work, "bar_np2", np=2)
m = re.search(r"\(to other ranks (\d+)\), full sorts (\d+)", logb)
tv.check(m is not None, "the log reports the moves to other ranks and the full sorts")
sent, sorts = int(m.group(1)), int(m.group(2))
tv.check(sent >= 8, f"material points moved to the other rank: {sent}")
tv.check(sorts == 0, f"collective full sorts in the 2-rank run: {sorts} (expected 0)")
worst = worst_difference(particles("out_bar_np1"), particles("out_bar_np2"))
tv.check(worst <= 1e-12, f"1 vs 2 ranks with points crossing ranks agree to 1e-12 relative (worst {worst:.2e})")

# 6. the 2-phase step with rebalancing
wet = tv.prm_set(eager, "time/end time", "0.02")
for key, value in {"drainage": "coupled", "porosity": "0.4", "liquid density": "1000",
                   "liquid bulk modulus": "2.2e7", "liquid viscosity": "1e-3",
                   "hydraulic conductivity": "1e-3", "permeability gravity": "9.81"}.items():
    wet = tv.prm_set(wet, f"material 0/pore liquid/{key}", value)
tv.run_tool(tool, tv.prm_set(wet, "output/directory", "out_wet_np1"), work, "wet_np1")
_, logw, _ = tv.run_tool(tool, tv.prm_set(wet, "output/directory", "out_wet_np2"), work, "wet_np2", np=2)
n_wet = int(re.search(r"rebalances (\d+)", logw).group(1))
tv.check(n_wet >= 20, f"2-phase: rebalances during the 2-rank run: {n_wet} >= 20")
a, b = particles("out_wet_np1"), particles("out_wet_np2")
tv.check("pore_pressure" in a and max(abs(x) for x in a["pore_pressure"]) > 0,
         "2-phase: the points carry a pore pressure")
worst = worst_difference(a, b)
tv.check(worst <= 1e-10, f"2-phase: 1 rank vs 2 ranks rebalancing every 20 steps agree to 1e-10 relative "
                         f"(worst {worst:.2e})")
tv.finish()
