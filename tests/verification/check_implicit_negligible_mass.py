"""'implicit/negligible nodal mass' cannot return a wrong answer silently (issue 39):
the DoFs it holds and the force they carry are measured at every converged step
(series.csv columns held_dofs, held_load_share = |r over the held displacement
DoFs, assembled without the hold| / |f_ext|), and a run whose held DoFs carry
more than 'negligible mass load limit' (default 0.01) stops with exit 3 and the
figures.

On the seed cantilever (PRM: 2 x 2 points per cell filling its cells, so the
corner nodes of the beam carry a quarter of an interior node's mass, its edge
nodes half):
  * 'negligible nodal mass = 0.2': no node is that light: held_dofs 0,
    held_load_share 0, the tip deflection bitwise that of the run without the
    option (the measurement changes nothing);
  * 0.3: the 4 corner nodes of the beam are light; the 2 of the free end are
    held (4 DoFs; the clamped end's are wall DoFs): they carry much of the weight -> exit 3, the log names the
    entry, the number of held DoFs and the share; series.csv finite;
  * 0.3 with 'negligible mass load limit = 1': the run completes (exit 0) and
    reports the share (> 1e-3) and the held DoFs in series.csv: the answer is
    measurably wrong (tip deflection > 5 % off the unheld run), which is what
    the default limit refuses.
Usage: check_implicit_negligible_mass.py TOOLS_DIR PRM WORKDIR
"""
import math
import os
import shutil
import sys

import talus_verify as tv

tools, prm, work = sys.argv[1:4]
tool = os.path.join(tools, "talus-implicit")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
base = open(prm).read()


def run(name, settings, expect_rc):
    text = tv.prm_set(base, "output/directory", os.path.join(work, name))
    for k, v in settings.items():
        text = tv.prm_set(text, k, v)
    rc, out, err = tv.run_tool(tool, text, work, name, expect_rc=None)
    tv.check(rc == expect_rc, f"{name}: exit {rc} (expected {expect_rc}) {(out + err)[-300:] if rc != expect_rc else ''}")
    return rc, out + err


def tip(name):
    t = tv.read_csv(os.path.join(work, name, "particles_final.csv"))
    # the free end's lowest points: the largest x - u_x, the tip deflection is their mean u_y
    X = [x - u for x, u in zip(t["pos_x"], t["u_x"])]
    xmax = max(X)
    uy = [u for x, u in zip(X, t["u_y"]) if abs(x - xmax) < 1e-9]
    return sum(uy) / len(uy)


run("plain", {}, 0)
u_plain = tip("plain")

run("light", {"implicit/negligible nodal mass": "0.2"}, 0)
s = tv.read_csv(os.path.join(work, "light", "series.csv"))
tv.check(s["held_dofs"][-1] == 0 and s["held_load_share"][-1] == 0,
         f"0.2: no node held: held_dofs {s['held_dofs'][-1]}, held_load_share {s['held_load_share'][-1]}")
tv.check(tip("light") == u_plain, f"0.2: tip deflection {tip('light')!r} bitwise the unheld {u_plain!r}")

rc, log = run("corners", {"implicit/negligible nodal mass": "0.3"}, 3)
tv.check("negligible nodal mass" in log and "4 displacement DoFs" in log and "negligible mass load limit" in log,
         f"0.3: the log names the entry, the 4 held DoFs and the limit: {log[-500:]}")
if os.path.exists(os.path.join(work, "corners", "series.csv")):
    s = tv.read_csv(os.path.join(work, "corners", "series.csv"))
    tv.check(all(math.isfinite(v) for col in s.values() for v in col if isinstance(v, float)),
             "0.3: series.csv holds only finite values")

run("corners_allowed", {"implicit/negligible nodal mass": "0.3", "implicit/negligible mass load limit": "1"}, 0)
s = tv.read_csv(os.path.join(work, "corners_allowed", "series.csv"))
share, held = s["held_load_share"][-1], s["held_dofs"][-1]
u_held = tip("corners_allowed")
tv.check(held == 4 and share > 0.01,
         f"limit 1: held_dofs {held:g} (expected 4), held_load_share {share:.3e} (> 0.01 expected)")
tv.check(abs(u_held / u_plain - 1) > 0.05,
         f"limit 1: the held answer is wrong, as the share says: tip {u_held:.5f} vs {u_plain:.5f} m "
         f"({100 * (u_held / u_plain - 1):+.1f} %)")
tv.finish()
