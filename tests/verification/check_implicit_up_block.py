"""Mixed u-p solved by GMRES with the block preconditioner ('linear solver/method =
gmres block amg', issue 39 item 5; docs/implicit.md "Block-preconditioned GMRES for
mixed u-p"): the scene (parameter_files/implicit/up_block_3d.prm) with the direct
solver on 1 rank and with the block preconditioner on 1 and 2 ranks (2D or 3D) must give the
same point results to 1e-8 relative to the largest value of each field (Newton and
GMRES stop at their tolerances, 1e-12 / 1e-10 relative, so not bitwise), and GMRES
must really iterate (more than one iteration per solve: the preconditioner is not an
exact inverse). Usage: check_implicit_up_block.py TOOLS_DIR PRM WORKDIR [entry=value ...]
"""
import sys

import talus_verify as tv

tools, prm_path, work = sys.argv[1:4]
text = tv.prm_set_args(open(prm_path).read(), sys.argv[4:])
text = tv.prm_set(text, "output/final particles csv", "true")
runs = {"direct_np1": ("direct", 1), "block_np1": ("gmres block amg", 1), "block_np2": ("gmres block amg", 2)}
for name, (method, n) in runs.items():
    t = tv.prm_set(tv.prm_set(text, "linear solver/method", method), "output/directory", name)
    tv.run_tool(f"{tools}/talus-implicit", t, work, name, np=n)


def by_origin(path):
    # rows in the order of the points' initial positions (pos - u): ids depend on the partition
    t = tv.read_csv(path)
    ax = "xyz" if "pos_z" in t else "xy"
    key = [tuple(round(t["pos_" + c][i] - t["u_" + c][i], 9) for c in ax) for i in range(len(t["id"]))]
    order = sorted(range(len(key)), key=lambda i: key[i])
    return {c: [t[c][i] for i in order] for c in t}


ref = by_origin(f"{work}/direct_np1/particles_final.csv")
ax = "xyz" if "pos_z" in ref else "xy"
up = ax[-1]
top = max(range(len(ref["id"])), key=lambda i: (ref["pos_" + up][i] - ref["u_" + up][i], ref["pos_x"][i] - ref["u_x"][i]))
print(f"direct: {len(ref['id'])} points; the top corner point moved u = ("
      + ", ".join(f"{ref['u_' + c][top]:.9e}" for c in ax) + f") m, p = {ref['pressure'][top]:.6e} Pa")
for name in ("block_np1", "block_np2"):
    b = by_origin(f"{work}/{name}/particles_final.csv")
    tv.check(len(b["id"]) == len(ref["id"]) > 0, f"{name}: the same points ({len(b['id'])})")
    diff = tv.relative_differences(ref, b, [c for c in ref if c != "id"])
    worst = max(diff, key=diff.get)
    print(f"{name}: top corner u_x {b['u_x'][top]:.9e}; largest relative differences to direct: "
          + ", ".join(f"{k} {d:.1e}" for k, d in sorted(diff.items(), key=lambda x: -x[1])[:4]))
    tv.check(diff[worst] < 1e-8, f"{name} vs direct: largest difference {diff[worst]:.2e} ({worst}) below 1e-8")
    s = tv.read_csv(f"{work}/{name}/series.csv")
    newton = sum(s["newton_iterations"])
    linear = sum(s["linear_iterations"])
    tv.check(newton > 0 and linear > 2 * newton,
             f"{name}: GMRES iterates ({linear:.0f} linear iterations in {newton:.0f} Newton iterations, "
             f"{linear / max(newton, 1):.1f} per solve)")
tv.finish()
