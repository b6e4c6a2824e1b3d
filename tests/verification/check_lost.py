"""Material points leaving the grid (issue 7 item 4, used by the explicit solver):
'remove' counts every lost point in series.csv and the log and finishes; 'stop' ends
with exit code 3 and a message naming the step and the count.
Usage: check_lost.py TOOL PRM WORKDIR
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
rc, out, err = tv.run_tool(tool, tv.prm_set(base, "output/directory", "remove"), work, "remove", expect_rc=0)
s = tv.read_csv(f"{work}/remove/series.csv")
n0 = s["n_particles"][0]
tv.check(n0 == 64, f"block seeded with 64 points (got {n0:.0f})")
tv.check(s["lost_particles"][-1] == n0 and s["n_particles"][-1] == 0,
         f"all points counted as lost ({s['lost_particles'][-1]:.0f}) and removed ({s['n_particles'][-1]:.0f} left)")
tv.check("left the grid" in out, "the log reports lost points")

t = tv.prm_set(tv.prm_set(base, "output/directory", "stop"), "stability/lost particles", "stop")
rc, out, err = tv.run_tool(tool, t, work, "stop", expect_rc=3)
tv.check("left the grid" in err and "step" in err, "stop policy: exit 3 with a message: " + err.strip()[:160])
tv.finish()
