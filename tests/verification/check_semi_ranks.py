"""1 vs 2 ranks, semi-implicit two-phase double-point MPM (issue 14): the
self-weight consolidation column for 100 steps on 1 and on 2 MPI ranks; every
column of soil_final.csv and water_final.csv (points matched by their initial
position) agrees to 1e-8 relative (max |a - b| / max |a| per column; columns of
a vector or the stress on the scale of the whole vector / stress).
Usage: check_semi_ranks.py TOOL PRM WORKDIR   (PRM: the consolidation column)
"""
import sys

import talus_verify as tv

tool, prm_path, work = sys.argv[1:4]
text = tv.prm_set(open(prm_path).read(), "output/directory", "out")
text = tv.prm_set(text, "time/end time", "0.03")
text = tv.prm_set(text, "time/time step", "3e-4")
tables = {}
for np in (1, 2):
    tv.run_tool(tool, text, f"{work}/np{np}", f"np{np}", np=np)
    for s in ("soil", "water"):
        # order by the initial position X = x - u (the storage order differs between runs)
        tables[(np, s)] = tv.by_initial_position(tv.read_csv(f"{work}/np{np}/out/{s}_final.csv"))
for s in ("soil", "water"):
    a, b = tables[(1, s)], tables[(2, s)]
    tv.check(len(a["pos_x"]) == len(b["pos_x"]), f"{s}: same number of points ({len(a['pos_x'])}, {len(b['pos_x'])})")
    # columns that are zero up to round-off in this 1D problem (horizontal velocity,
    # shear stress) are compared on the scale of their vertical counterpart
    floor = {p: max(abs(v) for v in a[p + "_y" + ("y" if p == "stress" else "")]) for p in ("velocity", "displacement")}
    floor["stress"] = max(abs(v) for v in a["stress_yy"])
    d = {}
    for c in a:
        scale = max(abs(v) for v in a[c])
        for p, f in floor.items():
            if c.startswith(p + "_"):
                scale = max(scale, f)
        # the other components of a vector property (pore_pressure_gradient_x, ...):
        # on the scale of the vertical one
        if c[-2:] in ("_x", "_z") and c[:-2] + "_y" in a and not c.startswith("pos_"):
            scale = max(scale, max(abs(v) for v in a[c[:-2] + "_y"]))
        d[c] = max(abs(x - y) for x, y in zip(a[c], b[c])) / (scale or 1.0)
    worst = max(d, key=d.get)
    print(f"{s}: largest relative difference {d[worst]:.2e} in '{worst}'")
    tv.check(d[worst] < 1e-8, f"{s}: 1 and 2 ranks agree to 1e-8 (largest {d[worst]:.2e} in '{worst}')")
tv.finish()
