"""Load-step independence of talus-implicit (issue 39 item 1; docs/implicit.md "Load steps").

The seed 001 cantilever under self-weight (check_implicit_cantilever.py: delta = u_y
extrapolated to X = 8 m from the two outermost point columns) on one grid, in N load
steps for each N given, for each shape function given. Checks:
  * every run reaches t = 1 (no run stops, no cut-back);
  * the deflections lie within TOL of each other ((max - min) / |ref|) and each within
    TOL of the thesis's non-linear reference -0.67433 m;
  * the start-of-step imbalance (series.csv start_imbalance: the converged state's
    residual on the reset grid over |f_ext|) is printed per run and below MAX_IMB.
With --without-carry=N: the run in N steps with 'implicit/carry start imbalance = false'
is printed beside them (what the carried imbalance removes; not a check).
Usage: check_implicit_load_steps.py TOOLS_DIR PRM WORKDIR H STEPS KERNELS TOL MAX_IMB
       [--without-carry=N] [--set=entry=value ...]
  STEPS: comma-separated step counts; KERNELS: comma-separated 'linear', 'quadratic bspline'.
"""
import sys

import talus_verify as tv

settings = [a[len("--set="):] for a in sys.argv[1:] if a.startswith("--set=")]
without = [int(a[len("--without-carry="):]) for a in sys.argv[1:] if a.startswith("--without-carry=")]
args = [a for a in sys.argv[1:] if not a.startswith(("--set=", "--without-carry="))]
tools, prm_path, work, h = args[0], args[1], args[2], float(args[3])
steps = [int(n) for n in args[4].split(",")]
kernels = args[5].split(",")
tol, max_imbalance = float(args[6]), float(args[7])
l, ref = 8.0, -0.67433
base = tv.prm_set_args(open(prm_path).read(), settings)
base = tv.prm_set(base, "grid/cells", f"{round(8.5 / h)}, {round(2.5 / h)}")
base = tv.prm_set(base, "output/directory", "out")
base = tv.prm_set(base, "output/series interval", "1e-9")
# the verification's round-off tolerance (1e-12) is below what a slender beam's residual reaches after
# many steps; the increment test ends the iteration there, 1e-9 of |f_ext| is the converged state
base = tv.prm_set(base, "newton/residual relative", "1e-9")


def run(kernel, n, carry=True):
    text = tv.prm_set(base, "time/time step", repr(1.0 / n))
    text += f"\nsubsection numerics\n  set shape function = {kernel}\nend\n"
    if not carry:
        text = tv.prm_set(text, "implicit/carry start imbalance", "false")
    name = f"{kernel.split()[-1]}_{n}" + ("" if carry else "_no_carry")
    rc, out, err = tv.run_tool(f"{tools}/talus-implicit", text, f"{work}/{name}", "cantilever", expect_rc=None)
    if rc != 0:
        return None, None, (out + err).count("cut back to")
    s = tv.read_csv(f"{work}/{name}/out/series.csv")
    d, _ = tv.cantilever_tip(tv.read_csv(f"{work}/{name}/out/particles_final.csv"), h, l)
    reached = abs(s["time"][-1] - 1.0) < 1e-12
    return (d if reached else None), max(s["start_imbalance"]), (out + err).count("cut back to")


print(f"h = {h:g} m; reference {ref} m")
print(f"{'kernel':>18} {'steps':>6} {'delta [m]':>11} {'vs ref':>10} {'max start imbalance':>20} {'cut-backs':>9}")
for kernel in kernels:
    deltas = []
    for n in steps:
        d, imb, cuts = run(kernel, n)
        ok = d is not None
        tv.check(ok and cuts == 0, f"{kernel}, {n} steps: the run completes without cut-backs (cut-backs {cuts})")
        if not ok:
            continue
        deltas.append(d)
        print(f"{kernel:>18} {n:6d} {d:11.6f} {(d - ref) / abs(ref):10.2e} {imb:20.3g} {cuts:9d}")
        tv.check(abs(d - ref) / abs(ref) < tol, f"{kernel}, {n} steps: delta within {tol:.2%} of {ref}")
        tv.check(imb < max_imbalance, f"{kernel}, {n} steps: start imbalance {imb:.3g} |f_ext| < {max_imbalance:g}")
    if deltas:
        spread = (max(deltas) - min(deltas)) / abs(ref)
        print(f"{kernel}: spread over {len(deltas)} step counts {spread:.3e} of |ref|")
        tv.check(spread < tol, f"{kernel}: deflections within {tol:.2%} of each other (spread {spread:.3e})")
    for n in without:
        d, imb, cuts = run(kernel, n, carry=False)
        if d is None:
            print(f"{kernel:>18} {n:6d} without carry: the run stops ({cuts} cut-backs)")
            continue
        spread = (max(deltas + [d]) - min(deltas + [d])) / abs(ref)
        print(f"{kernel:>18} {n:6d} without carry: delta {d:.6f} ({(d - ref) / abs(ref):.2e}), spread {spread:.3e}")
tv.finish()
