"""The ghost penalty of talus-implicit ('implicit/ghost penalty'; docs/implicit.md "Ghost penalty").

The seed 001 cantilever (linear shape functions, Newton residual relative 1e-9, the
start imbalance re-balanced every step: 'carry start imbalance = false'). Checks:
  * h = 0.0625 m in 10 load steps: without the penalty the run stops (the nodes of
    freshly entered cells make the tangent near-singular); with gamma = 0.01 it completes
    without cut-backs (the check that the penalty regularises, and that it can fail);
  * in one load step gamma = 0.01 moves the tip deflection by less than 1e-4 of it
    (the penalty is small against the bulk stiffness);
  * h = 0.125 m in 10 steps on 1 and 2 ranks: every point's displacement equal to 1e-10 m
    (points matched by their initial position; the faces between ranks assembled once).
Usage: check_implicit_ghost_penalty.py TOOLS_DIR PRM WORKDIR
"""
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
base = open(prm_path).read()
base = tv.prm_set(base, "output/directory", "out")
base = tv.prm_set(base, "newton/residual relative", "1e-9")
base += "\nsubsection implicit\n  set carry start imbalance = false\nend\n"


def run(name, h, steps, gamma, np=1):
    text = tv.prm_set(base, "grid/cells", f"{round(8.5 / h)}, {round(2.5 / h)}")
    text = tv.prm_set(text, "time/time step", repr(1.0 / steps))
    text = tv.prm_set(text, "implicit/ghost penalty", repr(gamma))
    rc, out, err = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", "cantilever", np=np,
                               expect_rc=None)
    p = tv.read_csv(f"{work}/{name}/out/particles_final.csv") if rc == 0 else None
    return rc, (out + err).count("cut back to"), p


def tip(p, h):
    return tv.cantilever_tip(p, h)[0]


def by_position(p):
    """u per point, keyed by its initial position (the storage order differs between rank counts)."""
    return {(round(x - ux, 9), round(y - uy, 9)): (ux, uy)
            for x, y, ux, uy in zip(p["pos_x"], p["pos_y"], p["u_x"], p["u_y"])}


rc0, cuts0, _ = run("h0.0625_10_off", 0.0625, 10, 0.0)
print(f"h = 0.0625, 10 steps, no penalty: exit {rc0}, {cuts0} cut-backs")
tv.check(rc0 != 0, "without the penalty the 10-step run stops (what the penalty is for)")
rc1, cuts1, p1 = run("h0.0625_10_ghost", 0.0625, 10, 0.01)
print(f"h = 0.0625, 10 steps, gamma = 0.01: exit {rc1}, {cuts1} cut-backs"
      + (f", delta {tip(p1, 0.0625):.6f} m" if p1 else ""))
tv.check(rc1 == 0 and cuts1 == 0, "with gamma = 0.01 the 10-step run completes without cut-backs")

_, _, a = run("h0.0625_1_off", 0.0625, 1, 0.0)
_, _, b = run("h0.0625_1_ghost", 0.0625, 1, 0.01)
da, db = tip(a, 0.0625), tip(b, 0.0625)
print(f"one step: delta {da:.6f} m without, {db:.6f} m with gamma = 0.01 ({(db - da) / abs(da):+.2e})")
tv.check(abs(db - da) / abs(da) < 1e-4, "gamma = 0.01 moves the one-step deflection by < 1e-4 of it")

r1 = by_position(run("ranks1", 0.125, 10, 0.01)[2])
r2 = by_position(run("ranks2", 0.125, 10, 0.01, np=2)[2])
diff = max(abs(r1[k][c] - r2[k][c]) for k in r1 for c in (0, 1))
print(f"h = 0.125, 10 steps, gamma = 0.01: 1 vs 2 ranks max |u1 - u2| = {diff:.2e} m ({len(r1)} points)")
tv.check(len(r1) == len(r2) and diff < 1e-10, "1 vs 2 ranks within 1e-10 m")
tv.finish()
